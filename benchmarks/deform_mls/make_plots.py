#!/usr/bin/python3
"""The SVG figures of the MLS benchmarks [CMLS], drawn by cadmorph's plot writer
(cm_plot_write_svg through the mls_plot tool) from the CSVs the run scripts write:
  sphere.svg      run_sphere.sh's sphere_rows.csv: min SJ against k, per method and DX
  hex.svg         run_hex_options.sh's hex_rows.csv: min SJ against k, blend on/off, RBF
  plane_bending.svg, plane_stretching.svg   plane_profile.py's profiles
  perf.svg        run_perf.sh's perf_rows.csv: time against k (Figure 4)
  scale.svg       run_scale_shell.sh's scale_rows.csv: CPU s against nodes
usage: make_plots.py MLS_PLOT OUT_DIR SPHERE_DIR HEX_DIR PLANE_DIR PERF_DIR SCALE_DIR"""
import csv
import os
import subprocess
import sys

plot, out = sys.argv[1], sys.argv[2]
sphere_dir, hex_dir, plane_dir, perf_dir, scale_dir = sys.argv[3:8]
os.makedirs(out, exist_ok=True)


def rows(path):
    return list(csv.DictReader(open(path))) if os.path.exists(path) else []


def draw(name, points, title, xl, yl, *flags):
    """points: (series, x, y, style, colour) tuples."""
    src = os.path.join(out, name + ".csv")
    with open(src, "w") as f:
        f.write("series,x,y,style,colour\n")
        for p in points:
            f.write("%s,%.6g,%.6g,%s,%d\n" % p)
    subprocess.run([plot, src, os.path.join(out, name + ".svg"), title, xl, yl, *flags], check=True)
    os.remove(src)


# --- sphere handle
r = rows(os.path.join(sphere_dir, "sphere_rows.csv"))
if r:
    ks = sorted({int(x["k"]) for x in r if x["k"] != "-"})
    pts = []
    colours = {"mls gs=1 gb=1": 0, "mls bending (gs=0 gb=1)": 1, "mls stretching (gs=1 gb=0)": 2,
               "rbf (triharmonic)": 3, "femwarp (exact stretching minimiser)": 4}
    for dx in ("0.8", "0.5"):
        style = "solid+markers" if dx == "0.8" else "dashed+markers"
        for x in r:
            if x["dx"] != dx:
                continue
            label = "%s / DX %s" % (x["method"].replace(",", ";"), dx)
            kk = [int(x["k"])] if x["k"] != "-" else ks  # a method without samples: a level
            for k in kk:
                pts.append((label, k, float(x["min_sj"]), style if x["k"] != "-" else style.split("+")[0],
                            colours.get(x["method"], 5)))
    draw("sphere", pts, "Sphere handle (13,342 nodes, min SJ 0.181): min scaled Jacobian", "MLS samples k",
         "min scaled Jacobian", "ymin=-0.25", "ymax=0.15",
         "note=below -0.25: triangles on the frame (FEMWARP -0.44 at DX 0.8); RBF and FEMWARP have no k")

# --- hex one step
r = rows(os.path.join(hex_dir, "hex_rows.csv"))
if r:
    default_k = {"pipe": 500, "bore": 685}  # max(500, nodes / 50): 19,929 and 34,272 nodes
    pts = []
    for ci, model in enumerate(("pipe", "bore")):
        rbf = [float(x["min_sj"]) for x in r if x["model"] == model and x["method"] == "rbf"]
        curves = {"blend 1.5 (default)": [], "blend 0": []}
        for x in r:
            if x["model"] != model or x["method"] != "mls":
                continue
            o = x["options"].split()
            if any(w in o for w in ("--cubature", "--cover", "--stretch", "--bend")):
                continue
            k = int(o[o.index("--samples") + 1]) if "--samples" in o else default_k[model]
            key = "blend 0" if "--blend" in o else "blend 1.5 (default)"
            curves[key].append((k, float(x["min_sj"])))
        for key, v in curves.items():
            for k, y in sorted(v):
                pts.append(("%s mls / %s" % (model, key), k, y,
                            "solid+markers" if key.startswith("blend 1.5") else "dashed+markers", 2 * ci))
        for k in (500, 3000):
            if rbf:
                pts.append(("%s rbf" % model, k, rbf[0], "solid", 2 * ci + 1))
    draw("hex", pts, "Hex O-grids, one absolute step: min scaled Jacobian (M0: 0.707)", "MLS samples k",
         "min scaled Jacobian", "ymin=0.1", "ymax=0.75")

# --- plane profiles (Figure 3)
for label, ymax in (("bending", "8"), ("stretching", "22")):
    r = rows(os.path.join(plane_dir, "plane_profile_%s.csv" % label))
    if not r:
        continue
    names = list(dict.fromkeys(x["series"] for x in r))
    pts = [(x["series"].replace(",", ";"), float(x["x"]), float(x["y"]), x["style"], names.index(x["series"]))
           for x in r]
    draw("plane_" + label, pts, "Plane, pure %s: mean curvature along y = 0.5" % label, "x",
         "mean curvature H", "ymin=0", "ymax=" + ymax)

# --- Figure 4
r = rows(os.path.join(perf_dir, "perf_rows.csv"))
if r:
    pts = []
    for x in r:
        k = int(x["k"])
        pts.append(("dense RBF fit + evaluation (best of 2)", k, float(x["rbf_total"]), "solid+markers", 1))
        pts.append(("MLS set-up (CPU)", k, float(x["mls_setup"]), "solid+markers", 0))
        pts.append(("MLS per deformation (CPU)", k, float(x["mls_apply"]), "dashed+markers", 0))
    draw("perf", pts, "Figure 4: time against centres / samples (13,342-node mesh, 1 thread)",
         "centres / samples k", "seconds", "logx", "logy")

# --- scale
r = rows(os.path.join(scale_dir, "scale_rows.csv"))
if r:
    pts = []
    for x in r:
        n = int(x["nodes"])
        for key, name, st, c in (("setup_cpu", "set-up", "solid+markers", 0),
                                 ("basis_cpu", "shape functions", "dashed+markers", 2),
                                 ("factor_cpu", "factorisation", "dashed+markers", 3),
                                 ("sample_cpu", "sampling", "dashed+markers", 4),
                                 ("apply_cpu", "per deformation", "solid+markers", 1)):
            pts.append((name, n, float(x[key]), st, c))
    draw("scale", pts, "MLS at scale: 7,000 samples, 28,000 cubature points (CPU s)", "mesh nodes",
         "CPU seconds", "logx", "logy")
