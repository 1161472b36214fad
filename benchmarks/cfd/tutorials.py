#!/usr/bin/python3
"""OpenFOAM v1912's own tutorial meshes (Debian package openfoam-examples) morphed by
`cadmorph warp`, judged by checkMesh and by `cadmorph quality --foam` (whose verdict must be
checkMesh's), then run by the tutorial's solver:
  airFoil2D (simpleFoam; the mesh ships in the package, 2-D, empty front and back): the
    airfoil (patch walls) turned 2 degrees nose-up about its quarter chord; simpleFoam to
    its own convergence criterion (at most 500 iterations);
  movingCone (pimpleFoam/laminar; blockMesh, a 5-degree wedge): the cone (movingWall) moved
    0.5 mm along the axis; 10 pimpleFoam time steps (to t = 5e-5 s).
One row per tutorial: cells, wall s and max RSS (MB) of the warp, the inverted cells of its
summary line, checkMesh's verdict on the input and on the result, whether cadmorph's verdict
equals checkMesh's, and the solver's result.
usage: tutorials.py CADMORPH WORK_DIR"""
import math
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "tests", "helpers"))
sys.path.insert(0, HERE)
import foam_cases as fc  # noqa: E402
from bench_cfd import timed, verdict  # noqa: E402

EXAMPLES = "/usr/share/doc/openfoam-examples/examples"


def airfoil(points, ids):
    """The airfoil turned 2 degrees nose-up about its quarter chord: {point: displacement}."""
    xs = [points[i][0] for i in ids]
    x0 = min(xs) + 0.25 * (max(xs) - min(xs))
    y0 = sum(points[i][1] for i in ids) / len(ids)
    c, s = math.cos(math.radians(-2)), math.sin(math.radians(-2))
    out = {}
    for i in ids:
        x, y = points[i][0] - x0, points[i][1] - y0
        out[i] = (c * x - s * y - x, s * x + c * y - y, 0.0)
    return out


def cone(points, ids):
    """The cone moved 0.5 mm along the axis (x): {point: displacement}."""
    return {i: (0.0005, 0.0, 0.0) for i in ids}


# name, tutorial directory, body patch, motion, mesh command (None: shipped), solver, solver args
TUTORIALS = [
    ("airFoil2D", "incompressible/simpleFoam/airFoil2D", "walls", airfoil, None, "simpleFoam",
     []),
    ("movingCone", "incompressible/pimpleFoam/laminar/movingCone", "movingWall", cone,
     "blockMesh", "pimpleFoam", ["endTime", "5e-05"]),
]


def set_entry(case, key, value):
    """Sets a top-level entry of system/controlDict (foamDictionary, OpenFOAM's own editor)."""
    fc.run_foam("foamDictionary", case, os.path.join(case, "system", "controlDict"), "-entry", key,
                "-set", value)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    cad, work = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    if not os.path.isdir(EXAMPLES) or not fc.foam_available():
        sys.exit("tutorials.py: needs OpenFOAM and its tutorials (Debian packages openfoam, "
                 "openfoam-examples)")
    os.makedirs(work, exist_ok=True)
    print("| tutorial | cells | motion | wall s | MB | inverted | checkMesh input | checkMesh result "
          "| `quality --foam` agrees | solver |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, rel, body, motion, mesher, solver, stop in TUTORIALS:
        case, out = os.path.join(work, name), os.path.join(work, name + "_warped")
        for d in (case, out):
            shutil.rmtree(d, ignore_errors=True)
        shutil.copytree(os.path.join(EXAMPLES, rel), case)
        subprocess.run(["chmod", "-R", "u+w", case], check=True)
        if mesher:
            fc.run_foam(mesher, case)
        points = fc.read_points(case)
        disp = motion(points, fc.patch_points(case, body))
        csv = os.path.join(work, name + ".csv")
        with open(csv, "w") as f:
            f.write("node,dx,dy,dz\n")
            f.writelines("%d,%.17g,%.17g,%.17g\n" % ((i,) + d) for i, d in sorted(disp.items()))
        p, wall, mb = timed([cad, "warp", "--mesh", case + "/", "--displacements", csv, "-o", out + "/"])
        if p.returncode != 0:
            print("| %s | | %s | %.1f | %.0f | exit %d: %s | | | | |"
                  % (name, motion.__doc__.split(":")[0], wall, mb, p.returncode, p.stderr.strip()[-200:]))
            continue
        inv = p.stdout.strip().splitlines()[-1].split("inverted=")[-1].split()[0]
        before, after = fc.checkmesh(case), fc.checkmesh(out)
        q = subprocess.run([cad, "quality", out + "/", "--foam"], capture_output=True, text=True)
        mine = "Mesh OK." in q.stdout
        agrees = mine == after["ok"] and ("Failed %d mesh checks" % after["failed"] in q.stdout or mine)
        if stop:
            set_entry(out, *stop)
        r = fc.run_foam(solver, out, check=False)
        iters = r.stdout.count("\nTime = ")
        solved = "ok, %d steps" % iters if r.returncode == 0 else "exit %d" % r.returncode
        print("| %s | %d | %s | %.2f | %.0f | %s | %s | %s | %s | %s |"
              % (name, after.get("cells", 0), motion.__doc__.split(":")[0].split(" ", 1)[1], wall, mb,
                 inv, verdict(before), verdict(after), "yes" if agrees else "NO", solved))


if __name__ == "__main__":
    main()
