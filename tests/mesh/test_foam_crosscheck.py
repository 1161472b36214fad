#!/usr/bin/python3
"""Cross-check of cadmorph's OpenFOAM support against the real OpenFOAM v1912 (Debian's
openfoam package) and VTK's vtkOpenFOAMReader:

  * meshes made by blockMesh (a hex box, ASCII; graded and skewed blocks, binary and .gz)
    and by snappyHexMesh around a body whose STL gmsh writes (tests/helpers/foam_cases.py);
  * every number of checkMesh's "Checking geometry..." block (and the mesh stats) equals
    `cadmorph quality CASE --foam` to checkMesh's printed precision; values that are
    round-off noise (|x| < 1e-10, e.g. the openness of a closed box) only to 1e-12;
  * a warped case written by `cadmorph warp -o CASE/`: only points differs from the input
    polyMesh, other content of CASE is left alone, checkMesh runs on it and agrees with
    cadmorph, vtkOpenFOAMReader reads the same points, and Verdict's scaled Jacobian from
    vtkMeshQuality on its hexahedra equals cadmorph's;
  * a broken case exits 2 naming the file.
Exit 77 (ctest SKIP) only when OpenFOAM's tools are not installed.
usage: test_foam_crosscheck.py CADMORPH WORKDIR"""
import os
import re
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

CADMORPH, WORK = sys.argv[1], os.path.join(sys.argv[2], "foam_cross")
TOOLS = ["blockMesh", "snappyHexMesh", "checkMesh"]
if any(shutil.which(t) is None for t in TOOLS):
    print("SKIP: OpenFOAM (Debian package openfoam: blockMesh, snappyHexMesh, checkMesh) is not installed")
    sys.exit(77)

ENV = dict(os.environ)
# Debian's package keeps OpenFOAM's etc/ under /usr/share/openfoam; the tools find it through
# WM_PROJECT_DIR (no bashrc needs sourcing).
if "WM_PROJECT_DIR" not in ENV:
    ENV["WM_PROJECT_DIR"] = "/usr/share/openfoam"
from foam_compare import FoamCompare, metrics  # noqa: E402  (this folder: shared with test_foam_car.py)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "helpers"))
import foam_cases  # noqa: E402

FC = FoamCompare(CADMORPH, ENV)
check, run, compare, failures = FC.check, FC.run, FC.compare, FC.failures


HEADER = "FoamFile { version 2.0; format ascii; class dictionary; object %s; }\n"


def make_case(name, block_mesh, binary=False, compress=False):
    case = os.path.join(WORK, name)
    shutil.rmtree(case, ignore_errors=True)
    os.makedirs(os.path.join(case, "system"))
    os.makedirs(os.path.join(case, "constant"))
    write_system(case, binary, compress)
    with open(os.path.join(case, "system", "blockMeshDict"), "w") as f:
        f.write(HEADER % "blockMeshDict" + block_mesh)
    p = run(["blockMesh", "-case", case], foam=True)
    if p.returncode != 0:
        print(p.stdout[-2000:], p.stderr[-2000:])
        sys.exit("blockMesh failed for " + name)
    return case


def write_system(case, binary=False, compress=False):
    d = os.path.join(case, "system")
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, "controlDict"), "w") as f:
        f.write(HEADER % "controlDict" +
                "application blockMesh; startFrom startTime; startTime 0; stopAt endTime; endTime 1;\n"
                "deltaT 1; writeControl timeStep; writeInterval 1; writeFormat %s; writePrecision 6;\n"
                "writeCompression %s; timeFormat general; timePrecision 6;\n"
                % ("binary" if binary else "ascii", "on" if compress else "off"))
    with open(os.path.join(d, "fvSchemes"), "w") as f:
        f.write(HEADER % "fvSchemes" +
                "ddtSchemes { default steadyState; } gradSchemes { default Gauss linear; }\n"
                "divSchemes { default none; } laplacianSchemes { default Gauss linear corrected; }\n"
                "interpolationSchemes { default linear; } snGradSchemes { default corrected; }\n")
    with open(os.path.join(d, "fvSolution"), "w") as f:
        f.write(HEADER % "fvSolution")


os.makedirs(WORK, exist_ok=True)

# 1. a hex box (ASCII)
box = make_case("box", """convertToMeters 1;
vertices ( (0 0 0) (1 0 0) (1 1 0) (0 1 0) (0 0 1) (1 0 1) (1 1 1) (0 1 1) );
blocks ( hex (0 1 2 3 4 5 6 7) (6 4 3) simpleGrading (1 1 1) );
boundary ( walls { type wall; faces ( (0 4 7 3) (1 2 6 5) (0 1 5 4) (3 7 6 2) (0 3 2 1) (4 5 6 7) ); } );
""")
compare("box", box)

# 2. graded, skewed blocks; binary, and ASCII gzip-compressed
SKEW = """convertToMeters 1;
vertices ( (0 0 0) (1 0 0) (1.3 1 0) (0.2 1.1 0) (0 0 1) (1.1 0.1 1.2) (1.5 1.2 1) (0.1 1 1.3)
           (2 0.2 0) (2.1 1.1 0.2) (2.2 0 1) (2.4 1.3 1.1) );
blocks ( hex (0 1 2 3 4 5 6 7) (5 4 3) simpleGrading (3 0.5 2)
         hex (1 8 9 2 5 10 11 6) (4 4 3) simpleGrading (0.25 0.5 2) );
boundary ( walls { type wall; faces ( (0 4 7 3) (0 1 5 4) (3 7 6 2) (0 3 2 1) (4 5 6 7) ); }
           outlet { type patch; faces ( (8 9 11 10) ); }
           sides { type wall; faces ( (1 8 10 5) (2 6 11 9) (1 2 9 8) (5 10 11 6) ); } );
"""
skew = make_case("skew", SKEW, binary=True)
compare("skew", skew)
# (OpenFOAM compresses ASCII files only: it resets compressed binary to plain binary)
skewgz = make_case("skew_gz", SKEW, binary=False, compress=True)
check(os.path.exists(os.path.join(skewgz, "constant/polyMesh/faces.gz")), "blockMesh wrote no faces.gz")
compare("skew_gz", skewgz)

# 3. snappyHexMesh around a rounded box (STL from gmsh; tests/helpers/foam_cases.py)
t = time.time()
try:
    snappy = foam_cases.make_snappy_case(os.path.join(WORK, "snappy"), body="rounded_box")
except foam_cases.FoamError as e:
    print(e)
    sys.exit("snappy case failed")
# blockMesh and snappyHexMesh (and gmsh's STL) count against the OpenFOAM budget below
FC.foam_seconds += time.time() - t
ref, _ = compare("snappy", snappy)
cm = run(["checkMesh", "-case", snappy], foam=True).stdout
poly = re.search(r"polyhedra:\s+(\d+)", cm)
check(poly and int(poly.group(1)) > 0, "snappy mesh has no polyhedra: %s" % (poly.group(1) if poly else "?"))

# 4. a warped case: points only, other content left alone, OpenFOAM and VTK read it
out = os.path.join(WORK, "snappy_warped")
shutil.rmtree(out, ignore_errors=True)
os.makedirs(out)
write_system(out)
with open(os.path.join(out, "keep.txt"), "w") as f:
    f.write("not cadmorph's\n")
# a boundary node of the body moved: the first point of the first face of patch 'body'
pm = os.path.join(snappy, "constant", "polyMesh")
btxt = open(os.path.join(pm, "boundary")).read()
start = int(re.search(r"body\s*\{[^}]*startFace\s+(\d+)", btxt).group(1))
ftxt = open(os.path.join(pm, "faces")).read()
body = ftxt[ftxt.find("\n(\n") + 3:].splitlines()
node = int(re.match(r"\d+\((\d+)", body[start]).group(1))
csv = os.path.join(WORK, "snappy_disp.csv")
with open(csv, "w") as f:
    f.write("node,dx,dy,dz\n%d,0,0.02,0.01\n" % node)
w = run([CADMORPH, "warp", "--mesh", snappy, "--displacements", csv, "-o", out])
check(w.returncode == 0, "warp -o case/: exit %d %s" % (w.returncode, w.stderr))
w2 = run([CADMORPH, "warp", "--mesh", snappy, "--displacements", csv, "-o", os.path.join(WORK, "snappy_warped.vtu")])
check(w2.returncode == 0, "warp -o .vtu: exit %d %s" % (w2.returncode, w2.stderr))
for name in os.listdir(pm):
    a, b = os.path.join(pm, name), os.path.join(out, "constant", "polyMesh", name)
    if name == "points":
        check(open(a, "rb").read() != open(b, "rb").read(), "points unchanged by the warp")
        # a point that did not move keeps the text OpenFOAM wrote (the shortest exact numbers)
        def lines(p):
            t = open(p).read()
            return t[t.find("\n(\n") + 3:t.rfind("\n)")].splitlines()
        la, lb = lines(a), lines(b)
        same = [i for i in range(len(la)) if [float(v) for v in la[i].strip("()").split()]
                == [float(v) for v in lb[i].strip("()").split()]]
        check(len(la) == len(lb) and len(same) > 0 and all(la[i] == lb[i] for i in same),
              "points: %d of %d did not move, %d of them with other text"
              % (len(same), len(la), sum(la[i] != lb[i] for i in same)))
    elif os.path.isfile(a):
        check(os.path.exists(b) and open(a, "rb").read() == open(b, "rb").read(), "%s is not a byte copy" % name)
check(open(os.path.join(out, "keep.txt")).read() == "not cadmorph's\n", "other case content was touched")
compare("warped", out)

import vtk  # noqa: E402  (Debian python3-vtk9)
from vtk.util.numpy_support import vtk_to_numpy  # noqa: E402

r = vtk.vtkOpenFOAMReader()
r.SetFileName(os.path.join(out, "system", "controlDict"))
r.SetDecomposePolyhedra(0)
r.Update()
internal = r.GetOutput().GetBlock(0)
x = vtk.vtkXMLUnstructuredGridReader()
x.SetFileName(os.path.join(WORK, "snappy_warped.vtu"))
x.Update()
ours = x.GetOutput()
nc = int(ref["cells"])
check(internal.GetNumberOfCells() == nc, "vtkOpenFOAMReader: %d cells, checkMesh %d" % (internal.GetNumberOfCells(), nc))
pv, po = vtk_to_numpy(internal.GetPoints().GetData()), vtk_to_numpy(ours.GetPoints().GetData())
# vtkOpenFOAMReader keeps ASCII points as float32: equal to float32 precision
check(pv.shape == po.shape and abs(pv - po).max() < 1e-6 * max(1.0, abs(po).max()),
      "vtkOpenFOAMReader's points differ from cadmorph's")
# VTK's cells (its own reading of OpenFOAM's cell shapes) on cadmorph's float64 points
internal.SetPoints(ours.GetPoints())
q = vtk.vtkMeshQuality()
q.SetInputData(internal)
q.SetHexQualityMeasureToScaledJacobian()
q.Update()
vq = vtk_to_numpy(q.GetOutput().GetCellData().GetArray("Quality"))
sj = vtk_to_numpy(ours.GetCellData().GetArray("scaled_jacobian"))
hexes = [c for c in range(nc) if internal.GetCellType(c) == vtk.VTK_HEXAHEDRON]
worst = max(abs(vq[c] - sj[c]) for c in hexes) if hexes else 1.0
check(len(hexes) > nc // 2 and worst < 1e-9,
      "scaled Jacobian of %d VTK hexahedra vs cadmorph's: worst difference %g" % (len(hexes), worst))
print("warped: vtkOpenFOAMReader reads %d cells; %d hexahedra with Verdict's scaled Jacobian equal (worst %.2g)"
      % (internal.GetNumberOfCells(), len(hexes), worst))

# 5. a gmsh tet mesh written as a polyMesh (faces matched between cells, patches from the
#    physical groups): checkMesh's topology checks pass and its metrics equal cadmorph's on
#    the .msh itself (the faces cadmorph builds from the cells)
msh = os.path.join(WORK, "tets.msh")
gm = subprocess.run([sys.executable, "-c", """
import gmsh, sys
gmsh.initialize(); gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.occ.addBox(0, 0, 0, 1, 0.6, 0.4); gmsh.model.occ.synchronize()
for s in gmsh.model.getEntities(2):
    t = gmsh.model.addPhysicalGroup(2, [s[1]]); gmsh.model.setPhysicalName(2, t, "side%d" % s[1])
gmsh.model.addPhysicalGroup(3, [1])
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.15); gmsh.model.mesh.generate(3)
gmsh.write(sys.argv[1]); gmsh.finalize()
""", msh], capture_output=True, text=True)
check(gm.returncode == 0, "gmsh tets: " + gm.stderr[-300:])
conv = os.path.join(WORK, "tets_case")
shutil.rmtree(conv, ignore_errors=True)
zero = os.path.join(WORK, "zero.csv")
with open(zero, "w") as f:
    f.write("node,dx,dy,dz\n0,0,0,0\n")
c = run([CADMORPH, "warp", "--mesh", msh, "--displacements", zero, "-o", conv])
check(c.returncode == 0, "warp .msh -> case/: %s" % c.stderr)
write_system(conv)
cm = run(["checkMesh", "-case", conv], foam=True).stdout
for ok in ("Upper triangular ordering OK.", "Cell to face addressing OK.", "Boundary definition OK."):
    check(ok in cm, "converted tets: checkMesh lacks '%s'" % ok)
check(len(re.findall(r"^\s+side\d+\s+\d+", cm, re.M)) == 6, "converted tets: not 6 patches")
ref = metrics(cm)
ours = metrics(run([CADMORPH, "quality", msh, "--foam"]).stdout)
for k in ("max aspect ratio", "non-orthogonality", "max skewness", "volume", "face area"):
    check(k in ref and ref.get(k) == ours.get(k), "converted tets: %s: checkMesh %s, cadmorph on .msh %s"
          % (k, ref.get(k), ours.get(k)))
print("tets       converted .msh: checkMesh topology OK, metrics equal cadmorph's on the .msh")

# 6. broken input: exit 2 with the file
bad = os.path.join(WORK, "broken")
shutil.rmtree(bad, ignore_errors=True)
shutil.copytree(box, bad)
os.remove(os.path.join(bad, "constant", "polyMesh", "owner"))
b = run([CADMORPH, "quality", bad, "--foam"])
check(b.returncode == 2 and "polyMesh/owner" in b.stderr, "broken case: exit %d, %s" % (b.returncode, b.stderr))

print("OpenFOAM tools ran %.1f s in total" % FC.foam_seconds)
check(FC.foam_seconds < 60, "OpenFOAM runs took %.1f s (budget 60 s)" % FC.foam_seconds)
if failures:
    print("%d failures" % len(failures))
    sys.exit(1)
print("all OpenFOAM cross-checks passed")
