#!/usr/bin/python3
"""One row of [SMB14]'s Table 2 on the car case (§3.6.2), run on its own so
that a ~1M-cell case can be measured one job at a time: the morph under GNU time (CPU s =
user + sys, peak RSS), the written case judged by the real checkMesh and by
`cadmorph quality --foam` (every printed metric string-equal to checkMesh's, the parser of
tests/mesh/foam_compare.py), one Markdown row printed and appended to WORK/rows.md.
Handles and fixed nodes: morph_table.py --handles-only (three roof bumps, tunnel fixed).
usage: table_row.py CADMORPH CASE WORK ROW [extra cadmorph options ...]
  ROW: input | rbf | mls | rbf_warp | dmffd10 | dmffd15 | dmffd25 | cad | cad_vtu (then
       WORK/input.vtu must exist: perf_1m.sh writes it) | any name with the command given
       after -- as extra options"""
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tests", "mesh"))
from foam_compare import metrics, same_number  # noqa: E402

CM, CASE, WORK, ROW = sys.argv[1:5]
extra = [x for x in sys.argv[5:] if x != "--"]
ENV = dict(os.environ)
ENV.setdefault("WM_PROJECT_DIR", "/usr/share/openfoam")
H, F = os.path.join(WORK, "handles.csv"), os.path.join(WORK, "fixed.csv")
G0 = os.path.join(CASE, "constant", "body.step")
G1 = os.path.join(WORK, "body_h.step")
here = os.path.dirname(os.path.abspath(__file__))
if ROW.startswith("cad") and not os.path.exists(G1):
    subprocess.run(["/usr/bin/python3", os.path.join(here, "make_case.py"), "x", "--height", "0.336",
                    "--step-only", G1], check=True, capture_output=True)
CADOPT = ["--off-cad", "fixed", "--cad-tol", "0.5", "--keep-offset"]
cmds = {  # ROW: the command (extra options are appended)
    "rbf": ["deform", "--method", "rbf", "--mesh", CASE, "--handles", H, "--fixed", F],
    "mls": ["deform", "--method", "mls", "--mesh", CASE, "--handles", H, "--fixed", F],
    "rbf_warp": ["warp", "--method", "rbf", "--solver", "iterative", "--mesh", CASE, "--displacements", H],
    "cad": ["morph", "--from", G0, "--to", G1, "--mesh", CASE] + CADOPT,
    "cad_vtu": ["morph", "--from", G0, "--to", G1, "--mesh", os.path.join(WORK, "input.vtu")] + CADOPT,
}
for L in (10, 15, 25):
    cmds["dmffd%d" % L] = ["warp", "--method", "dmffd", "--lattice", str(L), "--mesh", CASE, "--displacements", H]


def timed(cmd):
    p = subprocess.run(["/usr/bin/time", "-f", "TIME %U %S %M %e"] + cmd, env=ENV, capture_output=True, text=True)
    m = re.findall(r"^TIME (\S+) (\S+) (\d+) (\S+)$", p.stderr, re.M)
    u, s, rss, wall = m[-1] if m else ("nan", "nan", "0", "nan")
    return p, float(u) + float(s), int(rss) / 1024.0, float(wall)


def judge(text):
    g = metrics(text)
    f = lambda k, i=0: float(g[k][i]) if k in g else float("nan")  # noqa: E731
    pyr = int(g["wrong pyramids"][0]) if "wrong pyramids" in g else 0
    ar = f("max aspect ratio")
    m = re.search(r"High aspect ratio cells found, Max aspect ratio: (\S+),", text)
    if m:  # above the threshold checkMesh words it differently
        ar = float(m.group(1))
    m = re.search(r"Max skewness = (\S+),", text)  # likewise ("***High skewness: ...")
    sk = float(m.group(1)) if m and "max skewness" not in g else f("max skewness")
    return g, (ar, f("non-orthogonality"), f("non-orthogonality", 1), sk, pyr)


def verdict(ar, no, sk, pyr):
    return "pass" if ar <= 1000 and no <= 70 and sk <= 4 and pyr == 0 else "FAIL"


if ROW == "input":
    out, p, cpu, rss, wall = CASE, None, 0.0, 0.0, 0.0
else:
    if ROW in cmds:
        cmd = cmds[ROW] + extra
    else:
        cmd = extra
    vtu = ROW.endswith("_vtu")
    out = os.path.join(WORK, ROW + (".vtu" if vtu else ""))
    shutil.rmtree(out, ignore_errors=True)
    if not vtu:
        os.makedirs(out)
        shutil.copytree(os.path.join(CASE, "system"), os.path.join(out, "system"))
    p, cpu, rss, wall = timed([CM] + cmd + ["-o", out])
    open(os.path.join(WORK, ROW + ".log"), "w").write(" ".join(cmd) + "\n" + p.stdout + p.stderr)
    if p.returncode != 0:
        msg = [ln for ln in p.stderr.splitlines() if ln.startswith("cadmorph")] or p.stderr.strip().splitlines()[-1:]
        row = "| %s | - | - | - | - | exit %d: %s | - | %.1f | %.0f |" % (ROW, p.returncode, msg[-1][:300], cpu, rss)
        print(row)
        open(os.path.join(WORK, "rows.md"), "a").write(row + "\n")
        sys.exit(0)
    if vtu:
        row = "| %s | (.vtu: no checkMesh) | | | | %s | - | %.1f | %.0f |" % (ROW, p.stdout.strip().splitlines()[-1], cpu, rss)
        print(row)
        open(os.path.join(WORK, "rows.md"), "a").write(row + "\n")
        sys.exit(0)
ref, c_cpu, c_rss, _ = timed(["checkMesh", "-case", out])
gr, (ar, no, avg, sk, pyr) = judge(ref.stdout)
ours = subprocess.run([CM, "quality", out, "--foam"], env=ENV, capture_output=True, text=True)
go, _ = judge(ours.stdout)
keys = ["max aspect ratio", "non-orthogonality", "max skewness", "wrong pyramids", "volume", "failed checks"]
diff = [k for k in keys if (k in gr) != (k in go) or (k in gr and not all(same_number(x, y) for x, y in zip(gr[k], go[k])))]
failed = int(gr["failed checks"][0]) if "failed checks" in gr else 0
qline = ours.stdout.strip().splitlines()[-1] if ours.stdout.strip() else ""
inv = re.search(r"inverted=(\d+)", qline)
row = "| %s | %.4g | %.4g (%.4g) | %.4g | %d | %s (%s) | %s | %s | %.1f | %.0f |" % (
    ROW, ar, no, avg, sk, pyr, verdict(ar, no, sk, pyr), "Mesh OK" if gr.get("mesh OK") else "%d failed" % failed,
    "yes" if not diff else "NO: " + ", ".join(diff), inv.group(1) if inv else "?", cpu, rss)
print(row)
print("checkMesh: %.1f CPU s, %.0f MiB" % (c_cpu, c_rss))
open(os.path.join(WORK, "rows.md"), "a").write(row + "\n")
