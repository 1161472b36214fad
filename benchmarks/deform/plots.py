#!/usr/bin/python3
"""SVG plots of the deform benchmark suite: plots.py OUTDIR (the CSVs of bench_deform).

Writes OUTDIR/deform_perf.svg, deform_precision.svg, deform_robust.svg, deform_smooth.svg,
deform_volume.svg (whichever CSVs are present). Debian's python3-matplotlib, python3-meshio.
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("svg")
import matplotlib.pyplot as plt  # noqa: E402

out = sys.argv[1]


def rows(name):
    path = os.path.join(out, name)
    if not os.path.exists(path):
        return None
    return list(csv.DictReader(open(path)))


r = rows("perf.csv")
if r:
    stages = ["ffd_local_affine", "ffd_local_newton_ref", "ffd_local_newton_moved", "ffd_deform",
              "dmffd_svd", "dmffd_B", "dmffd_step_BH", "dmffd_step_direct", "rbf_factor", "rbf_B",
              "rbf_step_direct"]
    fig, ax = plt.subplots(figsize=(9, 4.5))
    threads = sorted({int(x["threads"]) for x in r})
    w = 0.8 / len(threads)
    for k, th in enumerate(threads):
        v = [next((float(x["seconds"]) for x in r if x["stage"] == s and int(x["threads"]) == th),
                  0) for s in stages]
        ax.bar([i + k * w for i in range(len(stages))], v, w, label="%d thread(s)" % th)
    ax.set_xticks([i + w / 2 for i in range(len(stages))])
    ax.set_xticklabels(stages, rotation=35, ha="right", fontsize=8)
    ax.set_yscale("log")
    ax.set_ylabel("seconds (best of 3)")
    ax.set_title("Fig. 6 setting: 100k points, 427 constraints, 8^3 lattice")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "deform_perf.svg"))

r = rows("precision.csv")
if r:
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for m, mk in zip(sorted({int(x["handles"]) for x in r}), "os^"):
        for meth, ls in (("ffd", "--"), ("dmffd", "-")):
            pts = sorted((int(x["lattice"]), float(x["residual_rel"])) for x in r
                         if x["method"] == meth and int(x["handles"]) == m)
            ax.plot([p[0] for p in pts], [max(p[1], 1e-17) for p in pts], ls, marker=mk,
                    label="%s, %d handles" % ("FFD" if meth == "ffd" else "DM-FFD", m))
        rb = [float(x["residual_rel"]) for x in r if x["method"] == "rbf" and int(x["handles"]) == m]
        ax.axhline(max(rb[0], 1e-17), color="k", lw=0.6, ls=":")
    ax.set_yscale("log")
    ax.set_xlabel("control points per axis")
    ax.set_ylabel("|d(h) - H|_inf / |H|_inf")
    ax.set_title("Precision at the handles (dotted: RBF, exact)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "deform_precision.svg"))

if os.path.exists(os.path.join(out, "robust_eps1e-10.vtu")):
    import meshio
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for name, lab in (("robust_sphere.vtu", "undeformed"), ("robust_eps1e-10.vtu", "eps 1e-10"),
                      ("robust_eps0.01.vtu", "eps 1e-2")):
        h = meshio.read(os.path.join(out, name)).point_data["mean_curvature"]
        ax.hist(h, bins=80, histtype="step", label=lab)
    ax.set_xlabel("mean curvature H (unit sphere: 1)")
    ax.set_ylabel("vertices")
    ax.set_title("Fig. 8 setting: DM-FFD 5^3 on a sphere, clamping 1e-10 vs 1e-2")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "deform_robust.svg"))

r = rows("smooth_H.csv")
if r:
    # binned over z (min, mean, max per bin) rather than a scatter: small SVG, same story
    fig, ax = plt.subplots(figsize=(7, 4.5))
    nb = 40
    for meth, lab in (("dmffd", "DM-FFD, 729 control points"), ("rbf", "RBF, 792 kernels")):
        pts = [(float(x["z"]), float(x["H"])) for x in r if x["method"] == meth]
        lo_z, hi_z = min(p[0] for p in pts), max(p[0] for p in pts)
        bins = [[] for _ in range(nb)]
        for z, h in pts:
            bins[min(nb - 1, int((z - lo_z) / (hi_z - lo_z) * nb))].append(h)
        zc = [lo_z + (i + 0.5) * (hi_z - lo_z) / nb for i in range(nb) if bins[i]]
        b = [v for v in bins if v]
        l, = ax.plot(zc, [sum(v) / len(v) for v in b], "-", label=lab + " (mean)")
        ax.fill_between(zc, [min(v) for v in b], [max(v) for v in b], color=l.get_color(),
                        alpha=0.25, label=lab + " (min..max)")
    ax.set_xlabel("z of the undeformed vertex (deformable band 0.2 .. 0.85)")
    ax.set_ylabel("mean curvature H = |Delta x| / 2")
    ax.set_title("Fig. 9 setting: one handle lifted by 0.3")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "deform_smooth.svg"))

r = rows("adapt.csv")
if r:
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for meth, lab in (("dmffd", "DM-FFD, x/y knot insertion at the worst vertex"),
                      ("rbf", "RBF (2D thin plate), greedy at the worst vertex")):
        pts = [(int(x["dof"]), float(x["error_rel"])) for x in r if x["method"] == meth]
        ax.semilogy([p[0] for p in pts], [max(p[1], 1e-17) for p in pts], "-o", ms=2, label=lab)
    ax.set_xlabel("degrees of freedom")
    ax.set_ylabel("max |d - target| / bump height")
    ax.set_title("Fig. 12 setting: plane 41 x 41, every vertex a constraint")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "deform_adapt.svg"))

vol = []
for name in ("volume_pipe_tet.csv", "volume_pipe_hex.csv", "volume_pipe_tet_eps1e-2.csv",
             "volume_pipe_hex_eps1e-2.csv"):
    x = rows(name)
    if x:
        vol.append((name[7:-4].replace("_eps", ", clamping "), x))
if vol:
    fig, axes = plt.subplots(len(vol), 2, figsize=(11, 4 * len(vol)), squeeze=False)
    for row, (tag, r) in enumerate(vol):
        ax, bx = axes[row]
        for meth in ["rbf-s"] + ["dmffd-%d" % n for n in (5, 10, 15, 25)]:
            if meth == "rbf-s":
                pts = [x for x in r if x["method"] == "rbf-s"]
            else:
                n = meth.split("-")[1]
                pts = [x for x in r if x["method"] == "dmffd" and x["lattice"] == n and x["t"]]
            if not pts:
                continue
            t = [float(x["t"]) for x in pts]
            l, = ax.plot(t, [float(x["min_sj"]) for x in pts], "-o", ms=3, label=meth)
            if meth != "rbf-s":
                ax.plot(t, [float(x["min_sj_pure"]) for x in pts], "--", color=l.get_color(), ms=3)
                bx.semilogy(t, [max(float(x["boundary_err_rel"]), 1e-17) for x in pts], "-o",
                            ms=3, color=l.get_color(), label=meth)
        ax.axhline(0, color="k", lw=0.5)
        ax.set_xlabel("t (parameter change)")
        ax.set_ylabel("min scaled Jacobian")
        ax.set_title("%s: solid exact boundary, dashed pure DM-FFD" % tag, fontsize=9)
        ax.legend(fontsize=8)
        bx.set_xlabel("t")
        bx.set_ylabel("max boundary miss / diagonal (pure DM-FFD)")
        bx.set_title("%s: boundary miss of DM-FFD" % tag, fontsize=9)
        bx.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "deform_volume.svg"))
print("plots in", out)
