#!/usr/bin/python3
"""The CAD-driven morph of the snappyHexMesh case: the body's STEP edited (make_case.py
--height: the roof higher, same topology) and `cadmorph morph --off-cad fixed` of the polyMesh
onto it, the tunnel patches (not on the body's STEP) kept fixed. snappyHexMesh snaps the body
to an STL of the STEP, so its nodes lie up to a few percent of a cell off the STEP: they are
classified with a loose tolerance (--cad-tol), and --keep-offset moves them as their points on
the STEP move (without it they are put onto the edited STEP exactly). Each result is written
as an OpenFOAM case and judged by the real checkMesh and by `cadmorph quality --foam`; CPU
seconds and peak RSS of each cadmorph run.
usage: cad_morph.py CADMORPH CASE WORKDIR [--height H] [--cad-tol F]"""
import argparse
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
ap.add_argument("--height", type=float, default=0.336, help="edited body height (default 0.336: +5%%)")
ap.add_argument("--cad-tol", default="0.5")
a = ap.parse_args()
ENV = dict(os.environ)
ENV.setdefault("WM_PROJECT_DIR", "/usr/share/openfoam")
os.makedirs(a.work, exist_ok=True)
HERE = os.path.dirname(os.path.abspath(__file__))
NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


def run(cmd):
    """(returncode, stdout, stderr, CPU s of this child, its peak RSS in MiB)."""
    p = subprocess.run(["/usr/bin/time", "-f", "TIME %U %S %M"] + cmd, env=ENV, capture_output=True, text=True)
    m = re.search(r"TIME (%s) (%s) (\d+)\s*$" % (NUM, NUM), p.stderr)
    cpu, rss = (float(m.group(1)) + float(m.group(2)), int(m.group(3)) / 1024.0) if m else (0.0, 0.0)
    return p.returncode, p.stdout, p.stderr, cpu, rss


def judge(text):
    g = text[text.find("Checking geometry..."):]
    def num(p):
        m = re.search(p, g)
        return float(m.group(1)) if m else float("nan")
    m = re.search(r"Error in face pyramids: (\d+)", g)
    f = re.search(r"Failed (\d+) mesh checks", g)
    return (num(r"[Aa]spect ratio(?: =|:) (%s)" % NUM), num(r"non-orthogonality Max: (%s)" % NUM),
            num(r"average: (%s)" % NUM), num(r"Max skewness = (%s)" % NUM),
            int(m.group(1)) if m else 0, int(f.group(1)) if f else 0)


g0 = os.path.join(a.case, "constant", "body.step")
g1 = os.path.join(a.work, "body_h.step")
subprocess.run([sys.executable, os.path.join(HERE, "make_case.py"), "x", "--height", str(a.height),
                "--step-only", g1], check=True, capture_output=True)
runs = [("default (refuse)", g1, []),
        ("--off-cad fixed, onto G1 exactly", g1, ["--off-cad", "fixed", "--cad-tol", a.cad_tol]),
        ("--off-cad fixed --keep-offset", g1, ["--off-cad", "fixed", "--cad-tol", a.cad_tol, "--keep-offset"]),
        ("--off-cad fixed --keep-offset, G0 -> G0", g0, ["--off-cad", "fixed", "--cad-tol", a.cad_tol,
                                                         "--keep-offset"])]
rows = [("snappyHexMesh (input)", judge(run(["checkMesh", "-case", a.case])[1]), "", 0.0, 0.0, "")]
for label, target, args in runs:
    out = os.path.join(a.work, re.sub(r"[^a-z0-9]+", "_", label.lower()).strip("_"))
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    shutil.copytree(os.path.join(a.case, "system"), os.path.join(out, "system"))
    cmd = [a.cadmorph, "morph", "--from", g0, "--to", target, "--mesh", a.case, "-o", out] + args
    print("$", " ".join(cmd))
    rc, so, se, cpu, rss = run(cmd)
    if rc != 0:
        msg = [l for l in se.splitlines() if l.startswith("cadmorph morph:")][-1]
        print("  exit %d: %s" % (rc, msg))
        rows.append((label, None, msg, cpu, rss, ""))
        continue
    summary = [l for l in so.splitlines() if l.startswith("boundary nodes:")][0]
    inv = re.search(r"inverted=(\d+)", so).group(1)
    print("  " + summary + "; Verdict inverted hexes " + inv)
    ref = judge(run(["checkMesh", "-case", out])[1])
    q = run([a.cadmorph, "quality", out, "--foam"])[1]
    m = re.search(r"max_aspect_ratio=(%s) max_non_orthogonality=(%s) avg_non_orthogonality=(%s) "
                  r"max_skewness=(%s) wrong_pyramids=(\d+)" % (NUM, NUM, NUM, NUM), q)
    agree = m is not None and all(abs(float(m.group(k + 1)) - ref[k]) <= 1e-5 * max(1, abs(ref[k]))
                                  for k in range(4)) and int(m.group(5)) == ref[4]
    d = re.search(r"largest distance to G1: (%s)" % NUM, summary).group(1)
    rows.append((label, ref, "yes" if agree else "NO", cpu, rss, "%s; SJ<=0 %s" % (d, inv)))

print()
print("| run | max aspect ratio | max non-orth. (avg) | max skewness | wrong pyramids | checkMesh | --foam agrees | dist. to G1; Verdict SJ<=0 | CPU s | peak MiB |")
print("|---|---|---|---|---|---|---|---|---|---|")
for label, ref, agree, cpu, rss, extra in rows:
    if ref is None:
        print("| %s | - | - | - | - | refused: %s | - | - | %.1f | %.0f |" % (label, agree, cpu, rss))
        continue
    ar, no, avg, sk, pyr, failed = ref
    ok = "pass" if ar <= 1000 and no <= 70 and sk <= 4 and pyr == 0 else "FAIL"
    print("| %s | %.4g | %.4g (%.3g) | %.4g | %d | %s (%d failed) | %s | %s | %.1f | %.0f |"
          % (label, ar, no, avg, sk, pyr, ok, failed, agree or "-", extra or "-", cpu, rss))
