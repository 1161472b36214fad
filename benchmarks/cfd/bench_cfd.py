#!/usr/bin/python3
"""CFD morphs as a CFD user runs them, judged by OpenFOAM itself: the four blockMesh cases
of tests/helpers/foam_cases.py (2-D channel, axisymmetric wedge, half tunnel with a symmetry
plane, cyclic channel) at a realistic resolution and foam_cases.py's snappyHexMesh case (a sphere),
the body moved (2-D: a translation and a rotation; wedge: a radial scale; the 3-D cases: a
translation), each by
    cadmorph warp   --mesh CASE --displacements D.csv -o OUT/
    cadmorph deform --mesh CASE --handles D.csv --fix-unlisted-boundary -o OUT/
under /usr/bin/time -v, then checkMesh on OUT and 5 simpleFoam iterations. One row per case,
motion and command:
  cells, wall s and max RSS (MB) of the cadmorph run, its exit status and the inverted cells
  its summary line counts, checkMesh's verdict (failed checks named), whether simpleFoam ran,
  body miss (largest distance of a body point from its prescribed place, % of the largest
  prescribed motion), outer moved (largest motion of a point of inlet/outlet/walls that is not
  on the body, %), off-plane (largest motion normal to its plane of a point of an empty,
  wedge, symmetryPlane or cyclic patch, %).
Nothing is hidden: a morph that checkMesh fails or the solver dies on is printed as such.
`-o OUT/` writes the whole case; the last line counts the source's files missing from it (0).
usage: bench_cfd.py CADMORPH WORK_DIR [--size F] [--cases LIST] [--morphs warp,deform]
  --size F   multiplies every case's cell count (default 1: the sizes of the README)"""
import argparse
import math
import os
import re
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "tests", "helpers"))
sys.path.insert(0, HERE)
import foam_cases as fc  # noqa: E402
import numpy as np  # noqa: E402  (Debian python3-numpy)

# case: (kind, foam_cases scale or snappy base, [(motion name, function of a point -> target)])
SIN, COS = math.sin(math.radians(5)), math.cos(math.radians(5))


def rotate2d(p, c=(2.25, 1.0)):
    x, y = p[:, 0] - c[0], p[:, 1] - c[1]
    return np.column_stack([c[0] + COS * x - SIN * y, c[1] + SIN * x + COS * y, p[:, 2]])


def shift(d):
    return lambda p: p + np.array(d)


CASES = {
    "channel2d": ("channel2d", 40, [("translate y 0.05", shift((0, 0.05, 0))), ("rotate 5 deg", rotate2d)]),
    "wedge": ("wedge", 40, [("radial x1.2", lambda p: p * np.array([1, 1.2, 1.2]))]),
    "symmetry3d": ("symmetry3d", 30, [("translate x 0.1", shift((0.1, 0, 0)))]),
    "cyclic": ("cyclic", 30, [("translate y 0.1", shift((0, 0.1, 0)))]),
    "snappy": ("snappy", 32, [("translate y 0.05", shift((0, 0.05, 0)))]),
}
CONSTRAINT = ("empty", "wedge", "symmetryPlane", "symmetry", "cyclic")


def timed(cmd):
    """(CompletedProcess, wall s, max RSS MB) of cmd under /usr/bin/time -v."""
    p = subprocess.run(["/usr/bin/time", "-v"] + cmd, capture_output=True, text=True, env=fc.foam_env())
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (\S+)", p.stderr)
    rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", p.stderr)
    secs = 0.0
    for part in (wall.group(1).split(":") if wall else []):
        secs = secs * 60 + float(part)
    return p, secs, (int(rss.group(1)) / 1024 if rss else float("nan"))


def read_points(case):
    """case's points as an (n, 3) array: ASCII points parsed by NumPy, others by foam_cases."""
    path = os.path.join(case, "constant", "polyMesh", "points")
    if os.path.exists(path):
        with open(path) as f:
            text = f.read()
        if not re.search(r"format\s+binary", text[:2000]):
            body = text[text.index("(", text.index("}")) + 1:text.rindex(")")]
            return np.array(body.replace("(", " ").replace(")", " ").split(), dtype=float).reshape(-1, 3)
    return np.array(fc.read_points(case), dtype=float).reshape(-1, 3)


def boundary_sets(case, xyz):
    """(body point ids, outer point ids (inlet/outlet/walls, not on the body), constraint
    point ids and a unit normal of a face of their planar patch), reading faces once."""
    patches = fc.read_boundary(case)
    faces = fc._read_faces(os.path.join(case, "constant", "polyMesh", "faces"))

    def of(name):
        d = patches[name]
        return faces[d["startFace"]:d["startFace"] + d["nFaces"]]
    body = np.unique(np.concatenate([np.array(f) for f in of("body")]))
    outer = set()
    ids, normals = [], []
    for name, d in patches.items():
        if d["type"] in ("patch", "wall") and name != "body":
            for f in of(name):
                outer.update(f)
        elif d["type"] in CONSTRAINT:
            for f in of(name):
                p = xyz[list(f)]
                n = np.cross(p[1] - p[0], p[2] - p[0]) if len(f) == 3 else np.cross(p[2] - p[0], p[3] - p[1])
                n /= np.linalg.norm(n)
                ids.extend(f)
                normals.extend([n] * len(f))
    outer = np.array(sorted(outer - set(body.tolist())), dtype=int)
    return body, outer, np.array(ids, dtype=int), np.array(normals).reshape(-1, 3)


SHORT = [(r"Number of negative volume cells: (\d+)", "negative volume %s"),
         (r"Zero or negative face area", "face area"),
         (r"High aspect ratio cells found.*number of cells (\d+)", "aspect ratio %s"),
         (r"Number of non-orthogonality errors: (\d+)", "non-orthogonality %s"),
         (r"Error in face pyramids: (\d+) faces", "face pyramids %s"),
         (r"(\d+) highly skew faces", "skewness %s"),
         (r"edges not aligned with or perpendicular to non-empty directions: (\d+)", "2-D edges %s"),
         (r"Wedge patch (\w+) not planar", "wedge %s not planar"),
         (r"Wedge patch (\w+) not aligned", "wedge %s not aligned"),
         (r"open cells", "open cells"),
         (r"Concave cells", "concave cells")]


def short_errors(errors):
    """checkMesh's failed-check lines in a few words each."""
    tags = []
    for e in errors:
        for pat, tag in SHORT:
            m = re.search(pat, e)
            if m:
                tags.append(tag % m.groups() if m.groups() else tag)
                break
        else:
            tags.append(re.sub(r"\s+", " ", e.strip("* "))[:40])
    return ", ".join(tags)


def verdict(cm):
    if cm["ok"]:
        return "Mesh OK"
    if cm.get("fatal"):
        return "ERROR: " + cm["fatal"].split(" -- ")[0][:70]
    return "FAILED %d: %s" % (cm["failed"], short_errors(cm["errors"]))


def missing_files(src, dst):
    """The files of case src that the written case dst lacks: `-o OUT/` writes the whole case,
    so a non-zero count is a defect of the run (checkMesh and the solver then fail on it)."""
    n = 0
    for root, dirs, files in os.walk(src):
        rel = os.path.relpath(root, src)
        if rel.split(os.sep)[0].startswith("processor"):
            continue
        n += sum(not os.path.exists(os.path.join(dst, rel, f)) for f in files)
    return n


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("cadmorph")
    ap.add_argument("work")
    ap.add_argument("--size", type=float, default=1.0)
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--morphs", default="warp,deform")
    a = ap.parse_args()
    if not fc.foam_available() or shutil.which("snappyHexMesh") is None or shutil.which("simpleFoam") is None:
        sys.exit("bench_cfd: OpenFOAM (blockMesh, snappyHexMesh, checkMesh, simpleFoam) is not installed")
    cadmorph = os.path.abspath(a.cadmorph)
    os.makedirs(a.work, exist_ok=True)
    t_start = time.time()
    print("machine: %d cores, %s; OPENBLAS_CORETYPE=%s; cadmorph's default threads (all)" % (
        os.cpu_count(), (re.search(r"model name\s*:\s*(.*)", open("/proc/cpuinfo").read()) or [None, "?"])[1],
        os.environ.get("OPENBLAS_CORETYPE", "unset")))
    hdr = ("| case | cells | motion | command | exit | cadmorph inverted | wall s | MB | checkMesh | simpleFoam 5 it"
           " | body miss % | outer moved % | off-plane % |")
    rows, missing = [], 0
    for name in a.cases.split(","):
        kind, size, motions = CASES[name]
        case = os.path.join(a.work, name)
        t = time.time()
        if kind == "snappy":
            fc.make_snappy_case(case, body="sphere", base=max(4, int(round(size * a.size ** (1 / 3)))))
        else:
            fc.make_case(kind, case, scale=size * a.size)
        src = fc.checkmesh(case)
        t_mesh = time.time() - t
        print("%s: %d cells, meshed in %.1f s, checkMesh on the input: %s" % (
            name, src["cells"], t_mesh, verdict(src)),
            flush=True)
        xyz = read_points(case)
        body, outer, plane_ids, plane_n = boundary_sets(case, xyz)
        for motion, f in motions:
            target = f(xyz[body])
            disp = target - xyz[body]
            scale = np.linalg.norm(disp, axis=1).max()
            csv = os.path.join(a.work, "%s_%s.csv" % (name, re.sub(r"\W+", "_", motion)))
            with open(csv, "w") as fh:
                fh.write("node,dx,dy,dz\n")
                for i, d in zip(body.tolist(), disp.tolist()):
                    fh.write("%d,%.17g,%.17g,%.17g\n" % (i, d[0], d[1], d[2]))
            for morph in a.morphs.split(","):
                out = os.path.join(a.work, "%s_%s_%s" % (name, re.sub(r"\W+", "_", motion), morph))
                shutil.rmtree(out, ignore_errors=True)
                if morph == "warp":
                    cmd = [cadmorph, "warp", "--mesh", case, "--displacements", csv, "-o", out + "/"]
                else:
                    cmd = [cadmorph, "deform", "--mesh", case, "--handles", csv, "--fix-unlisted-boundary",
                           "-o", out + "/"]
                p, wall, mb = timed(cmd)
                inv = re.search(r"inverted=(\d+)", p.stdout)
                row = {"case": name, "cells": src["cells"], "motion": motion, "command": morph,
                       "exit": p.returncode, "inv": inv.group(1) if inv else "-", "wall": wall, "mb": mb}
                if p.returncode != 0 or not os.path.exists(os.path.join(out, "constant", "polyMesh", "points")):
                    row.update(check="not written", solver="-", miss="-", outer="-", plane="-")
                    print("  %s %s: exit %d: %s" % (motion, morph, p.returncode, p.stderr.strip()[-300:]))
                else:
                    missing += missing_files(case, out)
                    t = time.time()
                    cm = fc.checkmesh(out)
                    row["t_check"] = time.time() - t
                    row["check"] = verdict(cm)
                    t = time.time()
                    s = fc.solver_steps(out, 5, check=False)
                    row["t_solver"] = time.time() - t
                    sig = re.search(r"(Floating point exception|sigFpe|FOAM FATAL \w+)", s.stdout + s.stderr)
                    row["solver"] = "ok" if s.returncode == 0 else "FAILED (%s)" % (sig.group(1) if sig else "exit %d" % s.returncode)
                    d = read_points(out) - xyz
                    row["miss"] = "%.3g" % (100 * np.linalg.norm(xyz[body] + d[body] - target, axis=1).max() / scale)
                    row["outer"] = "%.3g" % (100 * np.linalg.norm(d[outer], axis=1).max() / scale) if len(outer) else "-"
                    row["plane"] = "%.3g" % (100 * np.abs((d[plane_ids] * plane_n).sum(axis=1)).max() / scale) \
                        if len(plane_ids) else "-"
                rows.append(row)
                print("  %-16s %-6s exit %d, %.1f s, %.0f MB, %s (checkMesh %.0f s), simpleFoam %s (%.0f s)" % (
                    motion, morph, row["exit"], wall, mb, row["check"], row.get("t_check", 0), row["solver"],
                    row.get("t_solver", 0)), flush=True)
    print()
    print(hdr)
    print("|" + "---|" * hdr.count(" | ") + "---|")
    for r in rows:
        print("| %s | %d | %s | %s | %d | %s | %.1f | %.0f | %s | %s | %s | %s | %s |" % (
            r["case"], r["cells"], r["motion"], r["command"], r["exit"], r["inv"], r["wall"], r["mb"],
            r["check"], r["solver"], r["miss"], r["outer"], r["plane"]))
    print()
    print("%d files of the source cases missing from the written cases; total %.0f s"
          % (missing, time.time() - t_start))


if __name__ == "__main__":
    main()
