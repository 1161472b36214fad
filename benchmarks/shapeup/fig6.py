#!/usr/bin/python3
"""Figure 6 of [CMLS]: one synthetic example per constraint type (plane, circle,
feature line, cylinder, rigid), each deformed by `cadmorph deform --method mls` without and
with the constraint (bending only: gamma_s = 0, gamma_b = 1, gamma_c = 10, the paper's).
Writes OUT/fig6.csv (residual before/after, iterations, times) and OUT/fig6.svg (original,
without, with; constrained nodes in red).
usage: fig6.py CADMORPH OUT [extra deform options...]
Also gamma_c = 1000 (nearly hard constraints), plain and with Anderson acceleration (m = 5)."""
import csv, os, re, subprocess, sys
import numpy as np
import meshio
import matplotlib

matplotlib.use("svg")
import matplotlib.pyplot as plt  # noqa: E402

cad, out = sys.argv[1], sys.argv[2]
extra = sys.argv[3:]
os.makedirs(out, exist_ok=True)
os.chdir(out)


def grid(nx, ny, f):
    """quads over (u, v) in [0,1]^2 mapped by f(u, v) -> (x, y, z)"""
    u, v = np.meshgrid(np.linspace(0, 1, nx + 1), np.linspace(0, 1, ny + 1))
    pts = np.array([f(a, b) for a, b in zip(u.ravel(), v.ravel())])
    quads = [[j * (nx + 1) + i, j * (nx + 1) + i + 1, (j + 1) * (nx + 1) + i + 1, (j + 1) * (nx + 1) + i]
             for j in range(ny) for i in range(nx)]
    return pts, np.array(quads)


def write_csv(name, nodes, disp=None):
    with open(name, "w") as f:
        if disp is None:
            f.write("node\n" + "".join("%d\n" % v for v in nodes))
        else:
            f.write("node,dx,dy,dz\n" + "".join("%d,%.17g,%.17g,%.17g\n" % (v, *disp(v)) for v in nodes))


cases = []

# 1 plane: a plate, both side strips fixed, the middle strip lifted (a tent); a square patch
p, q = grid(40, 40, lambda u, v: (u, v, 0))
fixed = np.where((p[:, 0] < 0.08) | (p[:, 0] > 0.92))[0]
handle = np.where(abs(p[:, 0] - 0.5) < 0.04)[0]
patch = np.where((p[:, 0] > 0.6) & (p[:, 0] < 0.85) & (p[:, 1] > 0.25) & (p[:, 1] < 0.75))[0]
cases.append(("plane", p, q, fixed, handle, lambda v: (0, 0, 0.3), patch))

# 2 circle: an annulus plate (quads in polar coordinates) around a hole of radius 0.15,
# stretched along x (left end fixed, right end pulled): the hole would become an ellipse
p, q = grid(24, 64, lambda u, v: ((0.15 + 0.85 * u) * np.cos(2 * np.pi * v),
                                   (0.15 + 0.85 * u) * np.sin(2 * np.pi * v), 0))
# merge the seam (v = 0 and v = 1)
n1 = 25
for i in range(n1):
    q[q == 64 * n1 + i] = i
fixed = np.where(p[:, 0] < -0.7)[0]
fixed = fixed[fixed < 64 * n1]
handle = np.where(p[:, 0] > 0.7)[0]
handle = handle[handle < 64 * n1]
ring = np.arange(0, 64 * n1, n1)
cases.append(("circle", p, q, fixed, handle, lambda v: (0.3, 0.1 * p[v, 1], 0), ring))

# 3 feature line: the tent plate, a slanted straight line of grid nodes on one flank
# ((24 + k, 4 + 4k) / 40, k = 0..8): the tent bends it
p, q = grid(40, 40, lambda u, v: (u, v, 0))
line = np.array([(4 + 4 * k) * 41 + 24 + k for k in range(9)])
cases.append(("line", p, q, np.where((p[:, 0] < 0.08) | (p[:, 0] > 0.92))[0],
              np.where(abs(p[:, 0] - 0.5) < 0.04)[0], lambda v: (0, 0, 0.3), line))

# 4 cylinder: a tube, bottom rows fixed, top rows moved sideways; the middle band
p, q = grid(48, 30, lambda u, v: (0.3 * np.cos(2 * np.pi * u), 0.3 * np.sin(2 * np.pi * u), 1.5 * v))
n1 = 49
for j in range(31):
    q[q == j * n1 + 48] = j * n1
used = np.unique(q)
fixed = np.intersect1d(np.where(p[:, 2] < 0.11)[0], used)
handle = np.intersect1d(np.where(p[:, 2] > 1.39)[0], used)
band = np.intersect1d(np.where((p[:, 2] > 0.45) & (p[:, 2] < 1.05))[0], used)
cases.append(("cylinder", p, q, fixed, handle, lambda v: (0.4, 0, 0), band))

# 5 rigid: the tent plate with a square block that must move rigidly
p, q = grid(40, 40, lambda u, v: (u, v, 0))
block = np.where((p[:, 0] > 0.55) & (p[:, 0] < 0.8) & (p[:, 1] > 0.35) & (p[:, 1] < 0.65))[0]
cases.append(("rigid", p, q, np.where((p[:, 0] < 0.08) | (p[:, 0] > 0.92))[0],
              np.where(abs(p[:, 0] - 0.5) < 0.04)[0], lambda v: (0, 0, 0.3), block))

rows = []
plot_only = os.environ.get("FIG6_PLOT_ONLY")
for r, (name, p, q, fixed, handle, disp, cset) in enumerate(cases):
    used = np.unique(q)
    meshio.write("%s.vtk" % name, meshio.Mesh(p, [("quad", q)]), binary=False)
    write_csv("%s_H.csv" % name, handle, disp)
    write_csv("%s_F.csv" % name, fixed)
    write_csv("%s_set.csv" % name, cset)
    common = ["deform", "--mesh", "%s.vtk" % name, "--handles", "%s_H.csv" % name, "--fixed",
              "%s_F.csv" % name, "--method", "mls", "--stretch", "0", "--bend", "1", *extra]
    res = {}
    if plot_only:
        continue
    for tag, opts in (("free", []), ("con", ["--constraint", "%s:%s_set.csv" % (name, name)]),
                      ("con1000", ["--constraint", "%s:%s_set.csv" % (name, name),
                                   "--constraint-weight", "1000", "--constraint-iterations", "50000"]),
                      ("aa1000", ["--constraint", "%s:%s_set.csv" % (name, name),
                                  "--constraint-weight", "1000", "--constraint-iterations", "50000",
                                  "--constraint-anderson", "5"])):
        cmd = [cad, *common, *opts, "-o", "%s_%s.vtu" % (name, tag)]
        pr = subprocess.run(cmd, capture_output=True, text=True)
        if pr.returncode:
            sys.exit("%s: %s" % (" ".join(cmd), pr.stderr))
        res[tag] = (pr.stdout, meshio.read("%s_%s.vtu" % (name, tag)).point_data["displacement"])
    o3 = res["con1000"][0]
    m3 = re.search(r"residual before (\S+) after (\S+) \((\S+) of the diagonal", o3)
    it3 = re.search(r"shape-up: (\d+) iterations, (\S+) ", o3)
    o4 = res["aa1000"][0]
    m4 = re.search(r"residual before (\S+) after (\S+) \((\S+) of the diagonal", o4)
    it4 = re.search(r"shape-up: (\d+) iterations, (\S+) .* iterations (\S+) s", o4)
    it3t = re.search(r"shape-up: .* iterations (\S+) s", o3)
    o = res["con"][0]
    m = re.search(r"residual before (\S+) after (\S+) \((\S+) of the diagonal", o)
    it = re.search(r"shape-up: (\d+) iterations, (\S+) .* update (\S+) s, iterations (\S+) s", o)
    t = re.search(r", (\S+) s, residual (\S+)", o)
    diag = np.linalg.norm(p[used].max(0) - p[used].min(0))
    rows.append({"case": name, "nodes": len(used), "set_nodes": len(cset),
                 "residual_before": m.group(1), "residual_after": m.group(2),
                 "before_rel_diag": "%.3g" % (float(m.group(1)) / diag), "after_rel_diag": m.group(3),
                 "iterations": it.group(1), "converged": it.group(2), "update_s": it.group(3),
                 "iterate_s": it.group(4), "total_s": t.group(1), "handle_residual": t.group(2),
                 "after_gc1000": m3.group(2), "iterations_gc1000": it3.group(1),
                 "converged_gc1000": it3.group(2), "iterate_s_gc1000": it3t.group(1),
                 "after_gc1000_anderson5": m4.group(2), "iterations_gc1000_anderson5": it4.group(1),
                 "converged_gc1000_anderson5": it4.group(2), "iterate_s_gc1000_anderson5": it4.group(3)})

# the picture: original, without, with (gamma_c = 10); constrained nodes red
from mpl_toolkits.mplot3d.art3d import Line3DCollection  # noqa: E402

fig = plt.figure(figsize=(12, 17))
for r, (name, p, q, fixed, handle, disp, cset) in enumerate(cases):
    used = np.unique(q)
    dfree = meshio.read("%s_free.vtu" % name).point_data["displacement"]
    dcon = meshio.read("%s_con.vtu" % name).point_data["displacement"]
    edges = np.unique(np.sort(np.vstack([q[:, [0, 1]], q[:, [1, 2]], q[:, [2, 3]], q[:, [3, 0]]]), 1), axis=0)
    for c, (title, d) in enumerate((("original", 0 * p), ("without constraint", dfree),
                                     ("with %s constraint" % name, dcon))):
        ax = fig.add_subplot(5, 3, 3 * r + c + 1, projection="3d")
        y = p + d
        lc = Line3DCollection(y[edges], colors="0.55", linewidths=0.25)
        ax.add_collection3d(lc)
        ax.scatter(*y[cset].T, s=3, color="red", depthshade=False)
        allp = np.vstack([p[used], (p + dfree)[used], (p + dcon)[used]])
        lo, hi = allp.min(0) - 0.02, allp.max(0) + 0.02
        ax.set_xlim(lo[0], hi[0]), ax.set_ylim(lo[1], hi[1]), ax.set_zlim(lo[2], hi[2])
        ax.set_title("%s: %s" % (name, title), fontsize=9)
        ax.set_box_aspect(np.maximum(hi - lo, 0.3))
        ax.set_axis_off()
        ax.view_init(elev=25 if name != "circle" else 89, azim=-60 if name != "circle" else -90)
        ax.set_rasterized(True)
fig.tight_layout()
fig.savefig("fig6.svg", dpi=80)
if os.environ.get("FIG6_PNG"):
    fig.savefig("fig6.png", dpi=60)
if plot_only:
    sys.exit(0)
with open("fig6.csv", "w") as f:
    w = csv.DictWriter(f, fieldnames=list(rows[0]))
    w.writeheader()
    w.writerows(rows)
for rr in rows:
    print(rr)
