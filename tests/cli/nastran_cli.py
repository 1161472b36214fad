#!/usr/bin/python3
"""`cadmorph` on Nastran bulk data: `model --hex-mesh` writes a new deck (gmsh reads it), then
`quality`, `morph`, `warp`, `deform` and `optimize` read a .bdf and write a .bdf back: every
line but the GRID cards' as in the input, the quality of the written deck the command's own
summary line, and gmsh reads each output.

usage: nastran_cli.py <cadmorph> <work dir>
"""
import os
import shutil
import subprocess
import sys

import gmsh

cli, work = sys.argv[1], os.path.join(sys.argv[2], "nastran_cli")
shutil.rmtree(work, ignore_errors=True)
os.makedirs(os.path.join(work, "out"))
failures = []


def check(cond, msg):
    if not cond:
        failures.append(msg)
        print("FAIL:", msg)


def run(*args):
    p = subprocess.run([cli] + list(args), cwd=work, capture_output=True, text=True, timeout=240)
    check(p.returncode == 0, "cadmorph %s: exit %d: %s" % (" ".join(args), p.returncode, p.stderr.strip()))
    lines = p.stdout.strip().splitlines()
    return lines[-1] if lines else ""


def others(path):
    with open(os.path.join(work, path)) as f:
        return [line for line in f.read().splitlines() if not line.startswith(("GRID", "*"))]


gmsh.initialize()
gmsh.option.setNumber("General.Verbosity", 2)


def gmsh_nodes(path):
    gmsh.clear()
    gmsh.open(os.path.join(work, path))
    return len(gmsh.model.mesh.getNodes()[0])


run("model", "bore", "0", "bore_0.step", "--hex-mesh", "bore.bdf", "--scale", "0.4")
run("model", "bore", "1", "bore_1.step")
n = gmsh_nodes("bore.bdf")
check(n == 2520, "gmsh reads %d nodes of the new deck (want 2520)" % n)
check(run("quality", "bore.bdf").endswith("inverted=0 cells=1920"), "quality of bore.bdf")
with open(os.path.join(work, "D.csv"), "w") as f:
    f.write("node,dx,dy,dz\n0,0.05,0,0\n1,0.05,0.01,0\n")
steps = [("morph.bdf", "bore.bdf", ["morph", "--from", "bore_0.step", "--to", "bore_1.step", "--mesh", "bore.bdf"]),
         ("warp.bdf", "bore.bdf", ["warp", "--mesh", "bore.bdf", "--displacements", "D.csv"]),
         ("deform.bdf", "bore.bdf", ["deform", "--mesh", "bore.bdf", "--handles", "D.csv", "--fix-unlisted-boundary",
                                     "--method", "rbf"]),
         ("optimize.bdf", "out/morph.bdf", ["optimize", "out/morph.bdf"])]
for out, source, args in steps:
    summary = run(*(args + ["-o", "out/" + out]))
    check(others("out/" + out) == others(source), "%s: lines other than GRID cards changed" % out)
    again = run("quality", "out/" + out)
    check(again == summary, "%s: quality of the written deck '%s', the command printed '%s'" % (out, again, summary))
    check(gmsh_nodes("out/" + out) == 2520, "gmsh cannot read out/%s" % out)
    with open(os.path.join(work, "out", out)) as f, open(os.path.join(work, source)) as g:
        changed = sum(a != b for a, b in zip(f.read().splitlines(), g.read().splitlines()))
    print("%-13s %s (%d lines differ from %s)" % (out, summary, changed, source))
check(others("out/morph.bdf") and open(os.path.join(work, "out/morph.bdf")).read() != open(os.path.join(work, "bore.bdf")).read(),
      "morph wrote the input unchanged")
gmsh.finalize()
if failures:
    print("%d failures" % len(failures))
    sys.exit(1)
print("ok")
