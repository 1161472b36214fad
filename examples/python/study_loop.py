#!/usr/bin/python3
"""An absolute study from a Python loop: one mesh of G0 morphed onto every STEP file of a
list, each target from G0 (not from the previous one), each morphed mesh written as .vtu.

One Morpher is made for G0 and its mesh (the classification on G0 and the factorisation of
the interior warp happen once); every target then costs Morpher.apply. A target that does
not correspond to G0 (another topology) raises cadmorph.MismatchError: it is reported and the
loop goes on.

    PYTHONPATH=build/python python3 examples/python/study_loop.py OUTDIR G0.step M0 G1.step [G2.step ...]
    PYTHONPATH=build/python python3 examples/python/study_loop.py OUTDIR

Without files it makes its own: the bore model G(0), a mesh of it, and G(0.2), G(0.4), ...,
G(1) as STEP files in OUTDIR (or $CADMORPH_EXAMPLE_OUT). Writes OUTDIR/<target>.vtu and
prints one row per target.
"""
import argparse
import os

import cadmorph


def make_inputs(outdir: str, size: float):
    """The bore's G(0), a mesh of it, and five edits, as files in outdir."""
    g0 = os.path.join(outdir, "bore_0.step")
    cadmorph.model("bore", 0.0, g0)
    m0 = os.path.join(outdir, "bore_0.vtu")
    cadmorph.write_mesh(m0, cadmorph.mesh_step(cadmorph.read_step(g0), size=size))
    targets = []
    for k in range(1, 6):
        targets.append(os.path.join(outdir, "bore_%d.step" % (2 * k)))
        cadmorph.model("bore", 0.2 * k, targets[-1])
    return g0, m0, targets


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("outdir", nargs="?", default=os.environ.get("CADMORPH_EXAMPLE_OUT"))
    ap.add_argument("files", nargs="*", help="G0.step M0 G1.step [G2.step ...]")
    ap.add_argument("--size", type=float, default=0.4,
                    help="mesh edge length when the example makes its own inputs")
    a = ap.parse_args()
    if not a.outdir:
        ap.error("give OUTDIR or set CADMORPH_EXAMPLE_OUT")
    if a.files and len(a.files) < 3:
        ap.error("give G0.step, M0 and at least one target")
    os.makedirs(a.outdir, exist_ok=True)
    g0_path, m0_path, targets = (a.files[0], a.files[1], a.files[2:]) if a.files \
        else make_inputs(a.outdir, a.size)

    g0 = cadmorph.read_step(g0_path)
    mesh = cadmorph.read_mesh(m0_path)
    # every target's warp shares one fit: the RBF solver's AUTO choice counts them all
    morpher = cadmorph.Morpher(g0, mesh, solves=len(targets))
    failed = 0
    for path in targets:
        name = os.path.splitext(os.path.basename(path))[0]
        try:
            points = morpher.apply(cadmorph.read_step(path))
        except cadmorph.Error as e:  # e.g. MismatchError: not the topology of G0
            print("%s: %s" % (name, e))
            failed += 1
            continue
        # the mesh as `cadmorph morph` writes it: fields displacement and scaled_jacobian
        cadmorph.write_mesh(os.path.join(a.outdir, name + ".vtu"), morpher.result_mesh(points))
        row = morpher.steps[-1]
        print("%s: min scaled Jacobian %.4f, %d inverted, boundary %.2g from the target "
              "-> %s.vtu" % (name, row.min_sj, row.inverted, row.max_dist, name))
    raise SystemExit(2 if failed else 0)


if __name__ == "__main__":
    main()
