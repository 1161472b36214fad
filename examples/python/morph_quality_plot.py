#!/usr/bin/python3
"""Morph one mesh of the bore model onto several of its edits and plot the minimum scaled
Jacobian against the edit's parameter (matplotlib, Agg backend: no display needed).

The bore G(t) (cadmorph.model: a block with a through-bore whose radius grows and whose
axis tilts as t goes from 0 to 1) is meshed once at t = 0; one Morpher classifies that mesh
on G(0) and factorises the interior warp once, then every Morpher.apply(G(t)) is a surface
morph and an evaluation: the morphed node coordinates as an (n, 3) array, made a mesh by
Morpher.result_mesh to measure its quality with cadmorph.quality.

    PYTHONPATH=build/python python3 examples/python/morph_quality_plot.py OUTDIR [--size H] [--t 0.25 0.5 ...]

OUTDIR (or $CADMORPH_EXAMPLE_OUT) gets M0.vtu, M1.vtu (the last target's mesh), min_sj.svg,
min_sj.png and min_sj.csv; one line per t is printed.
"""
import argparse
import os

import matplotlib

matplotlib.use("Agg")  # files only: runs without a display
import matplotlib.pyplot as plt  # noqa: E402

import cadmorph  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("outdir", nargs="?", default=os.environ.get("CADMORPH_EXAMPLE_OUT"))
    ap.add_argument("--size", type=float, default=0.4, help="mesh edge length (default 0.4)")
    ap.add_argument("--t", type=float, nargs="+", default=[0.25, 0.5, 0.75, 1.0],
                    help="the parameters of the targets G(t)")
    a = ap.parse_args()
    if not a.outdir:
        ap.error("give OUTDIR or set CADMORPH_EXAMPLE_OUT")
    os.makedirs(a.outdir, exist_ok=True)

    g0 = cadmorph.model("bore", 0.0)
    mesh = cadmorph.mesh_step(g0, size=a.size)
    cadmorph.write_mesh(os.path.join(a.outdir, "M0.vtu"), mesh)
    print("M0: %d nodes, %d cells, min scaled Jacobian %.4f"
          % (mesh.n_nodes, mesh.n_cells, cadmorph.quality(mesh).min_sj))

    morpher = cadmorph.Morpher(g0, mesh)
    rows = []
    for t in a.t:
        points = morpher.apply(cadmorph.model("bore", t))  # (n_nodes, 3) float64
        moved = morpher.result_mesh(points)
        q = cadmorph.quality(moved)
        rows.append((t, q.min_sj, q.inverted))
        print("t = %.3f: min scaled Jacobian %.4f, %d inverted" % (t, q.min_sj, q.inverted))

    cadmorph.write_mesh(os.path.join(a.outdir, "M1.vtu"), moved)
    with open(os.path.join(a.outdir, "min_sj.csv"), "w") as f:
        f.write("t,min_sj,inverted\n")
        f.writelines("%g,%.6f,%d\n" % r for r in rows)
    fig, ax = plt.subplots(figsize=(5, 3.5))
    ax.plot([r[0] for r in rows], [r[1] for r in rows], "o-")
    ax.axhline(0, color="grey", lw=0.8)
    ax.set_xlabel("bore parameter t")
    ax.set_ylabel("min scaled Jacobian")
    ax.set_title("M0 of G(0) morphed onto G(t)")
    fig.tight_layout()
    for ext in ("svg", "png"):
        fig.savefig(os.path.join(a.outdir, "min_sj." + ext), dpi=100)
    print("wrote", os.path.join(a.outdir, "min_sj.svg"), "and .png")


if __name__ == "__main__":
    main()
