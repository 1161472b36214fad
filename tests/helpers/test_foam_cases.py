#!/usr/bin/python3
"""Self-test of foam_cases.py (the shared OpenFOAM cases) against the real OpenFOAM v1912:
  * every kind meshes, checkMesh says "Mesh OK" with the expected geometric directions, cell
    types and patches (the wedge's axis patch has no faces, its cells at the axis are prisms),
    and 5 simpleFoam steps run;
  * read_points reads every point, the body's points span the body's box; patch_points
    reads the same number of points per patch as checkMesh reports, from ASCII,
    binary and compressed polyMesh files;
  * zones=True writes the cellZones wake and none (empty) and the faceZone plane;
  * scale multiplies the cell count; write_precision reaches controlDict;
  * checkmesh() reports a failed verdict and negative volumes on a mirrored (inside-out) mesh;
    solver_steps reports a solver that fails;
  * write_dict writes the FoamFile header and the body; make_snappy_case's sphere meshes
    (checkMesh OK, polyhedra, the patches, the body's points on the sphere) and simpleFoam
    runs on it; an unknown body or base is a ValueError.
Exit 77 (ctest SKIP) only when OpenFOAM's tools are not installed.
usage: test_foam_cases.py WORKDIR"""
import math
import os
import re
import shutil
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import foam_cases as fc  # noqa: E402

if not fc.foam_available():
    print("SKIP: OpenFOAM (Debian package openfoam: blockMesh, checkMesh) is not installed")
    sys.exit(77)

WORK = os.path.join(sys.argv[1], "foam_cases")
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
failures = []


def check(cond, msg):
    if not cond:
        failures.append(msg)
        print("FAIL:", msg)


EXPECT = {  # kind: (geometric directions, {patch: type})
    "channel2d": (2, {"inlet": "patch", "outlet": "patch", "walls": "wall", "body": "wall",
                      "frontAndBack": "empty"}),
    "wedge": (2, {"inlet": "patch", "outlet": "patch", "wall": "wall", "body": "wall",
                  "front": "wedge", "back": "wedge", "axis": "empty"}),
    "symmetry3d": (3, {"inlet": "patch", "outlet": "patch", "walls": "wall", "body": "wall",
                       "symmetry": "symmetryPlane"}),
    "cyclic": (3, {"inlet": "patch", "outlet": "patch", "walls": "wall", "body": "wall",
                   "back": "cyclic", "front": "cyclic"}),
}
SIN = 0.25 * math.sin(math.radians(2.5))
BODY_BOX = {"channel2d": ((2, 0.75, 0), (2.5, 1.25, 0.1)),
            "wedge": ((2, 0, -SIN), (2.5, 0.25 * math.cos(math.radians(2.5)), SIN)),
            "symmetry3d": ((2, 0, -0.25), (2.5, 0.25, 0.25)),
            "cyclic": ((2, 0.75, 0.4), (2.5, 1.25, 0.8))}
VARIANTS = {"channel2d": {}, "wedge": {"binary": True, "zones": True},
            "symmetry3d": {"compress": True}, "cyclic": {"zones": True}}

t0 = time.time()
for kind, (ndir, types) in EXPECT.items():
    opts = VARIANTS[kind]
    case = fc.make_case(kind, os.path.join(WORK, kind), **opts)
    r = fc.checkmesh(case)
    check(r["ok"] and r["failed"] == 0, "%s: checkMesh verdict not OK:\n%s" % (kind, r["text"][-1500:]))
    check(r.get("directions") == ndir, "%s: %s geometric directions, expected %d"
          % (kind, r.get("directions"), ndir))
    check(1000 <= r["cells"] <= 10000, "%s: %d cells at scale 1" % (kind, r["cells"]))
    check(not r["negative_volume"] and r["max_non_orth"] < 1e-6, "%s: not an orthogonal mesh" % kind)
    b = fc.read_boundary(case)
    check({n: p["type"] for n, p in b.items()} == types, "%s: patches %s" % (kind, b))
    check(b["body"]["nFaces"] > 0, "%s: no body faces" % kind)
    if kind == "wedge":
        check(b["axis"]["nFaces"] == 0 and r["prisms"] > 0 and r["hexahedra"] + r["prisms"] == r["cells"],
              "wedge: axis faces %d, prisms %s" % (b["axis"]["nFaces"], r.get("prisms")))
    if kind == "cyclic":
        check(b["back"].get("neighbourPatch") == "front", "cyclic: back's neighbourPatch %s" % b["back"])
    for name in b:
        pts = fc.patch_points(case, name)
        want = r["patches"].get(name, {}).get("points")
        check(len(pts) == want and pts == sorted(set(pts)) and (not pts or pts[-1] < r["points"]),
              "%s: patch_points(%s) gives %d points, checkMesh %s" % (kind, name, len(pts), want))
    # read_points: every point, and the body's points span the body's box
    xyz = fc.read_points(case)
    body = [xyz[i] for i in fc.patch_points(case, "body")]
    lo = [min(p[a] for p in body) for a in range(3)]
    hi = [max(p[a] for p in body) for a in range(3)]
    check(len(xyz) == r["points"], "%s: read_points gives %d points" % (kind, len(xyz)))
    box = BODY_BOX[kind]
    check(all(abs(a - b) < 1e-12 for u, v in zip(box, fc.BODY_BOX[kind]) for a, b in zip(u, v)),
          "%s: foam_cases.BODY_BOX %s" % (kind, fc.BODY_BOX[kind]))
    check(all(abs(lo[a] - box[0][a]) < 1e-9 and abs(hi[a] - box[1][a]) < 1e-9 for a in range(3)),
          "%s: body points span %s %s, not %s" % (kind, lo, hi, box))
    pm = os.path.join(case, "constant", "polyMesh")
    if opts.get("compress"):
        check(os.path.exists(os.path.join(pm, "faces.gz")), "%s: no faces.gz" % kind)
    if opts.get("binary"):
        check(re.search(rb"format\s+binary;", open(os.path.join(pm, "faces"), "rb").read(1000)), "%s: faces not binary" % kind)
    if opts.get("zones"):
        cz = open(os.path.join(pm, "cellZones"), "rb").read()
        fz = open(os.path.join(pm, "faceZones"), "rb").read()
        check(re.search(rb"\bwake\s*\{", cz) and re.search(rb"\bnone\s*\{", cz) and re.search(rb"\bplane\s*\{", fz),
              "%s: zones missing" % kind)
        check(re.search(rb"none\s*\{[^}]*cellLabels\s+(List<label>\s+)?0", cz), "%s: zone none not empty" % kind)
    p = fc.solver_steps(case, 5)
    check(p.returncode == 0 and "Time = 5" in p.stdout, "%s: simpleFoam did not run 5 steps" % kind)
    check(not any(re.fullmatch(r"[1-9]\d*", d) for d in os.listdir(case)), "%s: the solver wrote a time" % kind)
    print("%-10s %5d cells, %d directions, Mesh OK, 5 simpleFoam steps" % (kind, r["cells"], r["directions"]))

# scale multiplies the cell count; write_precision reaches controlDict
big = fc.make_case("channel2d", os.path.join(WORK, "channel2d_x4"), scale=4, write_precision=12)
n1, n4 = fc.checkmesh(os.path.join(WORK, "channel2d"))["cells"], fc.checkmesh(big)["cells"]
check(3.5 < n4 / n1 < 4.5, "scale=4: %d cells against %d" % (n4, n1))
check(re.search(r"writePrecision\s+12;", open(os.path.join(big, "system", "controlDict")).read()),
      "write_precision not in controlDict")

# an inside-out mesh (x mirrored): checkMesh fails it with negative volumes
bad = os.path.join(WORK, "mirrored")
shutil.copytree(os.path.join(WORK, "channel2d"), bad)
pts = os.path.join(bad, "constant", "polyMesh", "points")
text = open(pts).read()
text = re.sub(r"^\(([-+\d.eE]+) ", lambda m: "(%r " % -float(m.group(1)), text, flags=re.M)
open(pts, "w").write(text)
r = fc.checkmesh(bad)
check(not r["ok"] and r["failed"] >= 1 and r["negative_volume"] and r["negative_cells"] == n1
      and any("negative" in e for e in r["errors"]) and r["fatal"] is None
      and not os.path.exists(os.path.join(bad, "constant", "polyMesh", "sets")), "mirrored mesh: ok %s failed %s negative %s"
      % (r["ok"], r["failed"], r["negative_volume"]))
# a cyclic pair that no longer matches (one side's points moved): checkMesh stops with a
# FOAM FATAL ERROR, checkmesh() reports it
cyc = os.path.join(WORK, "cyclic_broken")
shutil.copytree(os.path.join(WORK, "cyclic"), cyc)
xyz = fc.read_points(cyc)
front = set(fc.patch_points(cyc, "front"))
with open(os.path.join(cyc, "constant", "polyMesh", "points"), "w") as f:
    f.write(fc.HEADER % ("vectorField", "points") + "%d\n(\n" % len(xyz))
    for i, p in enumerate(xyz):
        f.write("(%r %r %r)\n" % ((p[0] * 1.01 if i in front else p[0]), p[1], p[2]))
    f.write(")\n")
r = fc.checkmesh(cyc)
check(not r["ok"] and r["fatal"] and "match" in r["fatal"], "broken cyclic: ok %s fatal %s" % (r["ok"], r["fatal"]))
faces = fc.patch_faces(cyc, "front")
check(len(faces) == fc.read_boundary(cyc)["front"]["nFaces"] and all(len(f) == 4 for f in faces)
      and sorted(set(i for f in faces for i in f)) == sorted(front), "patch_faces(front)")

# a solver that cannot run (no 0/p): solver_steps returns the failure or raises FoamError
nop = os.path.join(WORK, "no_p")
shutil.copytree(os.path.join(WORK, "channel2d"), nop)
os.remove(os.path.join(nop, "0", "p"))
p = fc.solver_steps(nop, 1, check=False)
check(p.returncode != 0, "simpleFoam ran without 0/p")
try:
    fc.solver_steps(nop, 1)
    check(False, "solver_steps did not raise on a failing run")
except fc.FoamError as e:
    check("simpleFoam" in str(e) and "0/p" in str(e), "FoamError text: %s" % e)

# write_dict: the FoamFile header (class, object) and the body, the folders made
path = fc.write_dict(os.path.join(WORK, "dicts"), "constant/sub/fieldX", "value 1;\n", "volScalarField")
text = open(path).read()
check(path == os.path.join(WORK, "dicts", "constant", "sub", "fieldX") and text.endswith("}\nvalue 1;\n")
      and re.search(r"class\s+volScalarField;", text) and re.search(r"object\s+fieldX;", text)
      and text.startswith("FoamFile\n{"), "write_dict wrote %r" % text)

# make_snappy_case: the benchmark's sphere, small (the tests' rounded box is meshed by
# test_foam_crosscheck and test_checkmesh_verdict): checkMesh OK, hexahedra and polyhedra,
# the patches and their types, the body's points snapped onto the sphere, base the
# background's divisions, and simpleFoam runs on it
sph = fc.make_snappy_case(os.path.join(WORK, "snappy_sphere"), body="sphere", base=4)
r = fc.checkmesh(sph)
check(r["ok"] and r.get("polyhedra", 0) > 0 and r.get("hexahedra", 0) > r["cells"] // 2,
      "snappy sphere: verdict %s, %s hexahedra, %s polyhedra of %s cells"
      % (r["ok"], r.get("hexahedra"), r.get("polyhedra"), r.get("cells")))
b = fc.read_boundary(sph)
check({n: p["type"] for n, p in b.items()} == {"inlet": "patch", "outlet": "patch", "walls": "wall",
                                                "body": "wall"} and b["body"]["nFaces"] > 0,
      "snappy sphere: patches %s" % b)
xyz = fc.read_points(sph)
radii = [math.sqrt(sum(c * c for c in xyz[i])) for i in fc.patch_points(sph, "body")]
check(radii and max(abs(x - 0.35) for x in radii) < 1e-3, "snappy sphere: body points at radii %s to %s"
      % (min(radii or [0]), max(radii or [0])))
check(re.search(r"\(9 4 4\)", open(os.path.join(sph, "system", "blockMeshDict")).read()),
      "snappy sphere: base 4 is not a (9 4 4) background")
p = fc.solver_steps(sph, 2)
check(p.returncode == 0 and "Time = 2" in p.stdout, "snappy sphere: simpleFoam did not run 2 steps")
for kw in ({"body": "cube"}, {"base": 1}, {"base": 4.5}):
    try:
        fc.make_snappy_case(os.path.join(WORK, "snappy_bad"), **kw)
        check(False, "make_snappy_case(%s) did not raise" % kw)
    except ValueError:
        pass
check(not os.path.exists(os.path.join(WORK, "snappy_bad")), "a rejected make_snappy_case wrote its folder")
print("snappy sphere: %d cells (%d polyhedra), Mesh OK, body on the sphere to %.1e, 2 simpleFoam steps"
      % (r["cells"], r.get("polyhedra", 0), max(abs(x - 0.35) for x in radii or [0])))

print("%.1f s" % (time.time() - t0))
if failures:
    print("%d failures" % len(failures))
    sys.exit(1)
print("all foam_cases checks passed")
