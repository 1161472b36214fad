#!/usr/bin/python3
"""[SMB14]'s Table 2 on a snappyHexMesh mesh (section 3.6.2): lift three roof handles
of the car-like body with the tunnel boundary fixed, by RBF, DM-FFD (lattices 10/15/25) and
MLS, write each result as an OpenFOAM case (points only), and judge it by the real checkMesh
and by `cadmorph quality --foam`: worst aspect ratio, non-orthogonality, skewness, wrongly
oriented face pyramids, pass/fail by checkMesh's thresholds (aspect 1000, non-orthogonality
70 degrees, skewness 4, no wrong pyramids). Also read/morph/write CPU times and peak memory of
the polyMesh against the same mesh as .vtu.
usage: morph_table.py CADMORPH CASE WORKDIR [--lift D] [--handles-only]"""
import argparse
import math
import os
import re
import resource
import shutil
import subprocess
import sys

ap = argparse.ArgumentParser()
ap.add_argument("cadmorph")
ap.add_argument("case")
ap.add_argument("work")
ap.add_argument("--lift", type=float, default=0.03)
ap.add_argument("--handles-only", action="store_true", help="write handles.csv and fixed.csv only")
a = ap.parse_args()
ENV = dict(os.environ)
ENV.setdefault("WM_PROJECT_DIR", "/usr/share/openfoam")
os.makedirs(a.work, exist_ok=True)


def run(cmd):
    """Runs cmd: (returncode, stdout, stderr, CPU seconds of the child, peak RSS so far MiB)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run(cmd, env=ENV, capture_output=True, text=True)
    rc, out, err = p.returncode, p.stdout, p.stderr
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return rc, out, err, cpu, after.ru_maxrss / 1024.0


# ---- the polyMesh: body nodes, roof handles, tunnel nodes ----
pm = os.path.join(a.case, "constant", "polyMesh")
btxt = open(os.path.join(pm, "boundary")).read()
patches = {m.group(1): (int(m.group(3)), int(m.group(2)))
           for m in re.finditer(r"(\w+)\s*\{[^}]*?nFaces\s+(\d+);\s*startFace\s+(\d+);", btxt)}
ftxt = open(os.path.join(pm, "faces")).read()
body = ftxt[ftxt.find("\n(\n") + 3:].splitlines()
ptxt = open(os.path.join(pm, "points")).read()
pts = [tuple(map(float, l[1:-1].split())) for l in ptxt[ptxt.find("\n(\n") + 3:].splitlines() if l.startswith("(")]


def nodes_of(name):
    start, n = patches[name]
    s = set()
    for l in body[start:start + n]:
        s.update(int(x) for x in l[l.find("(") + 1:l.find(")")].split())
    return s


body_nodes = nodes_of("body")
fixed = set()
for name in patches:
    if name != "body":
        fixed |= nodes_of(name)
roof = max(pts[i][2] for i in body_nodes)
centres = [(0.22, 0.0), (0.38, 0.0), (0.52, 0.0)]
R = 0.05
handles = {}
for i in body_nodes:
    x, y, z = pts[i]
    if z < roof - 0.01:
        continue
    for cx, cy in centres:
        r = math.hypot(x - cx, y - cy)
        if r < R:
            # a smooth bump: full lift at the centre, zero at the rim
            handles[i] = max(handles.get(i, 0.0), a.lift * 0.5 * (1 + math.cos(math.pi * r / R)))
print("mesh: %d points; body %d nodes, tunnel %d fixed, %d handle nodes on the roof (z = %.3f), lift %.3f"
      % (len(pts), len(body_nodes), len(fixed), len(handles), roof, a.lift))
H = os.path.join(a.work, "handles.csv")
F = os.path.join(a.work, "fixed.csv")
with open(H, "w") as f:
    f.write("node,dx,dy,dz\n" + "".join("%d,0,0,%.17g\n" % (i, d) for i, d in sorted(handles.items())))
with open(F, "w") as f:
    f.write("node\n" + "".join("%d\n" % i for i in sorted(fixed)))
if a.handles_only:
    sys.exit(0)


NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


def judge(text):
    g = text[text.find("Checking geometry..."):]
    def num(p):
        m = re.search(p, g)
        return float(m.group(1)) if m else float("nan")
    ar = num(r"[Aa]spect ratio(?: =|:) (%s)" % NUM)
    no = num(r"non-orthogonality Max: (%s)" % NUM)
    sk = num(r"Max skewness = (%s)" % NUM)
    m = re.search(r"Error in face pyramids: (\d+)", g)
    pyr = int(m.group(1)) if m else 0
    m = re.search(r"Failed (\d+) mesh checks", g)
    failed = int(m.group(1)) if m else 0
    return ar, no, sk, pyr, failed


def verdict(ar, no, sk, pyr):
    return "pass" if ar <= 1000 and no <= 70 and sk <= 4 and pyr == 0 else "FAIL"


runs = [("RBF (deform, body free)", ["deform", "--method", "rbf", "--handles", H, "--fixed", F]),
        ("MLS (deform, body free)", ["deform", "--method", "mls", "--handles", H, "--fixed", F]),
        ("RBF (warp, body fixed)", ["warp", "--method", "rbf", "--displacements", H])]
for L in (10, 15, 25):
    runs.append(("DM-FFD-%d (warp, body fixed)" % L, ["warp", "--method", "dmffd", "--lattice", str(L),
                                                        "--displacements", H]))
rows = []
base = run(["checkMesh", "-case", a.case])
rows.append(("snappyHexMesh (input)", judge(base[1]), None, None, 0.0))
for label, args in runs:
    tag = re.sub(r"[^a-z0-9]+", "_", label.lower()).strip("_")
    out = os.path.join(a.work, tag)
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    shutil.copytree(os.path.join(a.case, "system"), os.path.join(out, "system"))
    rc, so, se, cpu, rss = run([a.cadmorph, args[0], "--mesh", a.case] + args[1:] + ["-o", out])
    if rc != 0:
        print("%s: exit %d: %s" % (label, rc, se.strip()[-300:]))
        rows.append((label, None, None, None, cpu))
        continue
    ref = run(["checkMesh", "-case", out])
    ours = run([a.cadmorph, "quality", out, "--foam"])
    rows.append((label, judge(ref[1]), judge(ours[1]), so.strip().splitlines()[-1] if so.strip() else "", cpu))

print()
print("| method | max aspect ratio | max non-orth. (deg) | max skewness | wrong face pyramids | checkMesh | cadmorph --foam agrees | CPU s |")
print("|---|---|---|---|---|---|---|---|")
for label, ref, ours, line, cpu in rows:
    if ref is None:
        print("| %s | - | - | - | - | morph failed | - | %.1f |" % (label, cpu))
        continue
    ar, no, sk, pyr, failed = ref
    agree = "-" if ours is None else ("yes" if all(
        (math.isnan(x) and math.isnan(y)) or abs(x - y) <= 1e-5 * max(1, abs(x)) for x, y in zip(ref[:3], ours[:3]))
        and ref[3] == ours[3] else "NO %s" % (ours[:4],))
    print("| %s | %.4g | %.4g | %.4g | %d | %s (%d failed) | %s | %.1f |"
          % (label, ar, no, sk, pyr, verdict(ar, no, sk, pyr), failed, agree, cpu))

# ---- read / morph / write: polyMesh vs .vtu of the same mesh ----
vtu = os.path.join(a.work, "input.vtu")
# the .vtu twin: the polyMesh read and written by cadmorph (warp with an empty displacement table)
Z = os.path.join(a.work, "none.csv")
with open(Z, "w") as f:
    f.write("node,dx,dy,dz\n%d,0,0,0\n" % sorted(handles)[0])
run([a.cadmorph, "warp", "--mesh", a.case, "--displacements", Z, "-o", vtu])
print()
print("| step | polyMesh CPU s | .vtu CPU s |")
print("|---|---|---|")
rq_f = run([a.cadmorph, "quality", a.case])
rq_v = run([a.cadmorph, "quality", vtu])
print("| read + scaled Jacobian (`quality`) | %.2f | %.2f |" % (rq_f[3], rq_v[3]))
wf = os.path.join(a.work, "t_case")
shutil.rmtree(wf, ignore_errors=True)
r_f = run([a.cadmorph, "warp", "--mesh", a.case, "--displacements", H, "-o", wf])
r_v = run([a.cadmorph, "warp", "--mesh", vtu, "--displacements", H, "-o", os.path.join(a.work, "t.vtu")])
print("| read + RBF warp + write (`warp`) | %.2f | %.2f |" % (r_f[3], r_v[3]))
print("peak RSS of the largest run: %.0f MiB" % (resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0))
