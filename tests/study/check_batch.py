"""`cadmorph study --batch K`: the rows and meshes of a study do not depend on the batch size.

On the built-in bore (`cadmorph model bore`: G0 and six variants, a tet mesh of G0 small
enough for the dense RBF solver), with a pipe (another topology: mismatch) and a file that is
not STEP among the variants, and two methods of which one (closest-point surface, one step)
has rejected results: studies with --batch 1 (one at a time), 3, 20 and auto give the same
rows in the same order (variant, mode, method, status, inverted equal; min/mean scaled
Jacobian and the boundary's distance within TOL) and the same meshes (coordinates within
1e-9 x the diagonal). Dense (both modes) and iterative (--solver iterative, absolute, at
--rbf-tol 1e-10); and iterative at the default tolerance (from the mesh: 1e-6 on this one)
against its one-at-a-time rows at 1e-10.
usage: check_batch.py CADMORPH WORK
"""
import csv
import os
import shutil
import subprocess
import sys

import vtk

failures = []


def check(cond, msg):
    if not cond:
        failures.append(msg)
        print("FAIL:", msg)


def run(cmd, expect):
    p = subprocess.run(cmd, capture_output=True, text=True)
    check(p.returncode == expect, f"{' '.join(cmd)}: exit {p.returncode}, expected {expect}\n"
          f"{p.stdout}\n{p.stderr}")
    return p


def read_points(path):
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    pts = r.GetOutput().GetPoints()
    return [pts.GetPoint(i) for i in range(pts.GetNumberOfPoints())]


def compare(ref_dir, dir, diag, tol, coord_tol=1e-9):
    a = list(csv.DictReader(open(os.path.join(ref_dir, "study.csv"))))
    b = list(csv.DictReader(open(os.path.join(dir, "study.csv"))))
    check(len(a) == len(b) and len(a) > 0, f"{dir}: {len(b)} rows, {len(a)} one at a time")
    for i, (x, y) in enumerate(zip(a, b)):
        for k in ("variant", "mode", "method", "status", "inverted"):
            check(x[k] == y[k], f"{dir} row {i + 1}: {k} {y[k]!r}, one at a time {x[k]!r}")
        for k in ("min_scaled_jacobian", "mean_scaled_jacobian", "max_distance"):
            if x[k] or y[k]:
                check(x[k] and y[k] and abs(float(x[k]) - float(y[k])) <= tol,
                      f"{dir} row {i + 1}: {k} {y[k]}, one at a time {x[k]}")
    meshes = sorted(f for f in os.listdir(ref_dir) if f.endswith(".vtu"))
    check(meshes == sorted(f for f in os.listdir(dir) if f.endswith(".vtu")),
          f"{dir}: other meshes than one at a time")
    for f in meshes:
        p, q = read_points(os.path.join(ref_dir, f)), read_points(os.path.join(dir, f))
        worst = max((abs(u - v) for s, t in zip(p, q) for u, v in zip(s, t)), default=0)
        check(len(p) == len(q) and worst <= coord_tol * diag,
              f"{dir}/{f}: coordinates differ by {worst:g} (diagonal {diag:g})")
    return a


def main():
    cli, work = sys.argv[1], sys.argv[2]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    g0 = os.path.join(work, "G0.step")
    run([cli, "model", "bore", "0", g0], 0)
    names = []
    for k in range(1, 7):
        names.append(f"v{k}.step")
        run([cli, "model", "bore", f"{0.15 * k:g}", os.path.join(work, names[-1])], 0)
        if k == 3:
            names.append("v3b_pipe.step")
            run([cli, "model", "pipe", "0", os.path.join(work, names[-1])], 0)
        if k == 5:
            names.append("v5b_junk.step")
            open(os.path.join(work, names[-1]), "w").write("not a STEP file\n")
    with open(os.path.join(work, "list.txt"), "w") as f:
        f.write("\n".join(names) + "\n")
    mesh = os.path.join(work, "M0.vtu")
    run([cli, "mesh", g0, "-o", mesh, "--size", "0.5"], 0)
    pts = read_points(mesh)
    diag = sum((max(p[c] for p in pts) - min(p[c] for p in pts)) ** 2 for c in range(3)) ** 0.5

    # (relative series run one variant at a time whatever the batch: both modes once, to see
    # the rows of a variant stay in order around the batches)
    for solver, modes, batches, tol in (("dense", "both", ("1", "3"), 1e-9),
                                        ("dense", "absolute", ("1", "20", "auto"), 1e-9),
                                        ("iterative", "absolute", ("1", "3", "auto"), 1e-6)):
        dirs = []
        tight = ["--rbf-tol", "1e-10"] if solver == "iterative" else []
        for b in batches:
            d = os.path.join(work, f"{solver}_{modes}_{b}")
            dirs.append(d)
            run([cli, "study", "--from", g0, "--mesh", mesh, "--variants",
                 os.path.join(work, "list.txt"), "-o", d, "--methods", "rbf-s,project",
                 "--steps", "1", "--mode", modes, "--solver", solver, "--batch", b,
                 "--threads", "2"] + tight, 3)
        rows = list(csv.DictReader(open(os.path.join(dirs[0], "study.csv"))))
        # the rows one at a time are what the study is about: the odd variants' errors, the
        # closest-point morphs rejected at the larger motions, the rest complete
        status = {(r["variant"], r["method"], r["mode"]): r["status"] for r in rows}
        check(len(rows) == 8 * 2 * (2 if modes == "both" else 1), f"{solver}: {len(rows)} rows")
        check(status.get(("v3b_pipe", "rbf-s", "absolute")) == "mismatch",
              f"{solver}: pipe {status.get(('v3b_pipe', 'rbf-s', 'absolute'))}")
        check(status.get(("v5b_junk", "rbf-s", "absolute")) not in (None, "ok", "warning"),
              f"{solver}: junk {status.get(('v5b_junk', 'rbf-s', 'absolute'))}")
        check(status.get(("v6", "project", "absolute")) == "result rejected",
              f"{solver}: v6 project {status.get(('v6', 'project', 'absolute'))}")
        check(status.get(("v1", "rbf-s", "absolute")) == "ok", f"{solver}: v1 not ok")
        for d in dirs[1:]:
            compare(dirs[0], d, diag, tol)
    # the default tolerance, from the mesh (1e-3 x its wall spacing over the diagonal, at most
    # 1e-6: 1e-6 here): the iterative warps stop at a miss of 1e-6 x the motion and evaluate
    # with plain sums; the interior then moves by about that much, and no more
    loose = os.path.join(work, "iterative_loose")
    run([cli, "study", "--from", g0, "--mesh", mesh, "--variants", os.path.join(work, "list.txt"),
         "-o", loose, "--methods", "rbf-s,project", "--steps", "1", "--solver", "iterative",
         "--threads", "2"], 3)
    compare(dirs[0], loose, diag, 1e-5, 1e-6)
    if failures:
        sys.exit(f"{len(failures)} failures")
    print("rows and meshes agree for every batch size")


if __name__ == "__main__":
    main()
