"""Shared OpenFOAM test cases: complete, runnable simpleFoam (laminar) cases made by blockMesh,
for the tests and benchmarks of CFD morphs (2-D, axisymmetric, symmetry plane, cyclic), and
thin wrappers around the real OpenFOAM v1912 tools (checkMesh's verdict parsed, a few solver
steps, the points and a patch's faces and points read from polyMesh).

Kinds (every case has a wall patch `body`; the patch types are what the morph must respect):
  channel2d   2-D channel (one cell thick in z) around a square body in its middle;
              patches inlet outlet walls body frontAndBack[empty]
  wedge       axisymmetric pipe (axis along x, wedge angle 5 degrees, +-2.5 about the x-y
              plane), a cylindrical body attached to the axis like OpenFOAM's movingCone;
              patches inlet outlet wall body front back [wedge], axis [empty, 0 faces: the
              blocks at the axis are collapsed, as OpenFOAM's wedge tutorials make them]
  symmetry3d  half of a 3-D tunnel, a box body cut by the symmetry plane y=0;
              patches inlet outlet walls body symmetry [symmetryPlane]
  cyclic      3-D channel around a box body, the side walls z=0 and z=W a cyclic pair;
              patches inlet outlet walls body back front [cyclic, neighbourPatch each other]

Geometry (BODY_BOX holds the body's bounding box of each kind):
  channel2d   x [0, 6], y [0, 2], z [0, 0.1]; body x [2, 2.5], y [0.75, 1.25] (centre 2.25 1)
  wedge       x [0, 6], radius 1; body x [2, 2.5], r <= 0.25 (on the axis)
  symmetry3d  x [0, 6], y [0, 1.5], z [-1, 1]; body x [2, 2.5], y [0, 0.25], z [-0.25, 0.25]
  cyclic      x [0, 6], y [0, 2], z [0, 1.2]; body x [2, 2.5], y [0.75, 1.25], z [0.4, 0.8]
Zones (zones=True): cellZone `wake` (the cells behind the body, x > 2.5), faceZone `plane`
(the internal faces of the plane x = 2 above the body), cellZone `none` (no cells).

make_snappy_case() writes the snappyHexMesh case (a tunnel around a rounded box from an STL,
or a sphere; hexahedra, polyhedra, boundary layers; patches inlet outlet walls body), and
write_dict() any further dictionary file of a case.

All geometry is a lattice of blocks with the body's blocks left out; `scale` multiplies the
cell count (every block's divisions by scale**(1/d), d = 2 for the 2-D and wedge cases, 3
otherwise). Importable by file path from tests/ and benchmarks/ (standard library only).
"""
import math
import os
import re
import shutil
import struct
import subprocess
import sys
import gzip

TOOLS = ("blockMesh", "checkMesh")
KINDS = ("channel2d", "wedge", "symmetry3d", "cyclic")
_S, _C = math.sin(math.radians(2.5)), math.cos(math.radians(2.5))
BODY_BOX = {"channel2d": ((2.0, 0.75, 0.0), (2.5, 1.25, 0.1)),
            "wedge": ((2.0, 0.0, -0.25 * _S), (2.5, 0.25 * _C, 0.25 * _S)),
            "symmetry3d": ((2.0, 0.0, -0.25), (2.5, 0.25, 0.25)),
            "cyclic": ((2.0, 0.75, 0.4), (2.5, 1.25, 0.8))}
HEADER = ("FoamFile\n{\n    version 2.0;\n    format ascii;\n    class %s;\n"
          "    object %s;\n}\n")


def foam_env() -> dict:
    """The environment for OpenFOAM's tools: Debian's package finds its etc/ through
    WM_PROJECT_DIR (no bashrc needs sourcing)."""
    env = dict(os.environ)
    env.setdefault("WM_PROJECT_DIR", "/usr/share/openfoam")
    return env


def foam_available() -> bool:
    """True when blockMesh and checkMesh are on PATH (tests skip otherwise)."""
    return all(shutil.which(t) is not None for t in TOOLS)


class FoamError(subprocess.CalledProcessError):
    """An OpenFOAM tool (or the gmsh run writing make_snappy_case's STL) exited non-zero;
    str() carries the tail of its output."""

    def __str__(self):
        tail = ((self.stdout or "")[-3000:] + "\n" + (self.stderr or "")[-2000:]).strip()
        return "%s exited %s:\n%s" % (" ".join(map(str, self.cmd)), self.returncode, tail)


def run_foam(tool: str, case: str, *args, check: bool = True) -> subprocess.CompletedProcess:
    """Runs an OpenFOAM tool on case (`tool -case CASE args...`) with WM_PROJECT_DIR set;
    raises FoamError (a CalledProcessError) on a non-zero exit when check is true."""
    cmd = [tool, "-case", str(case)] + [str(a) for a in args]
    p = subprocess.run(cmd, env=foam_env(), capture_output=True, text=True)
    if check and p.returncode != 0:
        raise FoamError(p.returncode, cmd, p.stdout, p.stderr)
    return p


# ---------------------------------------------------------------------------------------
# checkMesh

_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_COUNTS = {"points": "points", "faces": "faces", "internal_faces": "internal faces",
           "cells": "cells", "boundary_patches": "boundary patches",
           "point_zones": "point zones", "face_zones": "face zones", "cell_zones": "cell zones",
           "hexahedra": "hexahedra", "prisms": "prisms", "wedges": "wedges",
           "pyramids": "pyramids", "tetWedges": "tet wedges", "tetrahedra": "tetrahedra",
           "polyhedra": "polyhedra"}


def parse_checkmesh(text: str) -> dict:
    """checkMesh (v1912) output parsed: ok, failed, text; the mesh stats and cell-type counts
    (points faces internal_faces cells boundary_patches point_zones face_zones cell_zones
    hexahedra prisms wedges pyramids tetWedges tetrahedra polyhedra: ints, absent when not
    printed; faces_per_cell: float); directions (geometric)
    and solution_directions; max_aspect, max_non_orth, avg_non_orth, max_skewness,
    min_volume, max_volume, total_volume, max_cell_openness (floats); negative_volume
    (bool: checkMesh found cells with a zero or negative volume) and negative_cells (their
    count, 0 otherwise); wrong_pyramids (int, 0
    when the face pyramids are OK); fatal (the first line of a FOAM FATAL ERROR, e.g.
    cyclic faces that no longer match, else None); errors (the lines of the failed checks, "***..."); patches
    {name: {"faces", "points"}} from the patch topology table."""
    out = {"text": text}
    for key, label in _COUNTS.items():
        m = re.search(r"^\s+%s:\s+(%s)" % (re.escape(label), _NUM), text, re.M)
        if m:
            out[key] = int(float(m.group(1)))
    m = re.search(r"^\s+faces per cell:\s+(%s)" % _NUM, text, re.M)
    if m:
        out["faces_per_cell"] = float(m.group(1))
    m = re.search(r"Mesh has (\d+) geometric \(non-empty/wedge\) directions", text)
    if m:
        out["directions"] = int(m.group(1))
    m = re.search(r"Mesh has (\d+) solution \(non-empty\) directions", text)
    if m:
        out["solution_directions"] = int(m.group(1))
    pats = {"max_aspect": r"Max aspect ratio = (%s)" % _NUM,
            "max_non_orth": r"Mesh non-orthogonality Max: (%s)" % _NUM,
            "avg_non_orth": r"Mesh non-orthogonality Max: %s average: (%s)" % (_NUM, _NUM),
            "max_skewness": r"Max skewness = (%s)" % _NUM,
            "max_cell_openness": r"Max cell openness = (%s)" % _NUM,
            "min_volume": r"Min volume = (%s)\." % _NUM,
            "max_volume": r"Max volume = (%s)\." % _NUM,
            "total_volume": r"Total volume = (%s)\." % _NUM}
    for key, p in pats.items():
        m = re.search(p, text)
        if m:
            out[key] = float(m.group(1))
    m = re.search(r"Error in face pyramids: (\d+) faces", text)
    out["wrong_pyramids"] = int(m.group(1)) if m else 0
    # every failed check's line ("***Zero or negative cell volume detected...", "***Number of
    # edges not aligned with or perpendicular to non-empty directions: 12", ...)
    out["errors"] = [line.strip() for line in text.splitlines() if line.lstrip().startswith("***")]
    out["negative_volume"] = bool(re.search(r"Zero or negative cell volume detected", text))
    m = re.search(r"FOAM FATAL (?:IO )?ERROR:?\s*\n?\s*(.+)", text)
    out["fatal"] = m.group(1).strip() if m else None
    m = re.search(r"Number of negative volume cells: (\d+)", text)
    out["negative_cells"] = int(m.group(1)) if m else 0
    m = re.search(r"Failed (\d+) mesh checks", text)
    out["failed"] = int(m.group(1)) if m else 0
    out["ok"] = m is None and bool(re.search(r"^Mesh OK\.", text, re.M))
    patches = {}
    sec = re.search(r"Checking patch topology for multiply connected surfaces...\n(.*?)\n\n",
                    text, re.S)
    if sec:
        for line in sec.group(1).splitlines():
            f = line.split()
            if len(f) >= 3 and f[1].isdigit() and f[2].isdigit():
                patches[f[0]] = {"faces": int(f[1]), "points": int(f[2])}
    out["patches"] = patches
    return out


def checkmesh(case: str, *args) -> dict:
    """Runs checkMesh on case (extra args e.g. "-allGeometry", "-allTopology") and returns
    parse_checkmesh() of its output; "returncode" is checkMesh's exit status (a failed mesh
    check does not make it non-zero; an unreadable mesh does, and then "ok" is False). The
    face and cell sets checkMesh writes for failed checks are removed again (polyMesh/sets,
    when the case had none): the case is left as it was."""
    sets = os.path.join(str(case), "constant", "polyMesh", "sets")
    had_sets = os.path.exists(sets)
    p = run_foam("checkMesh", case, *args, check=False)
    if not had_sets:
        shutil.rmtree(sets, ignore_errors=True)
    out = parse_checkmesh(p.stdout + p.stderr)
    out["returncode"] = p.returncode
    if p.returncode != 0:
        out["ok"] = False
    return out


# ---------------------------------------------------------------------------------------
# polyMesh reading (just what patch_points needs: boundary and faces, ASCII or binary, .gz)

def _read_foam_file(path: str) -> bytes:
    if os.path.exists(path):
        with open(path, "rb") as f:
            return f.read()
    with gzip.open(path + ".gz", "rb") as f:
        return f.read()


def _header(data: bytes) -> dict:
    m = re.search(rb"FoamFile\s*\{(.*?)\}", data, re.S)
    h = {}
    for k, v in re.findall(rb"(\w+)\s+([^;]*);", m.group(1) if m else b""):
        h[k.decode()] = v.decode().strip().strip('"')
    h["_end"] = m.end() if m else 0
    return h


def _label_size(h: dict) -> int:
    m = re.search(r"label=(\d+)", h.get("arch", ""))
    return int(m.group(1)) // 8 if m else 4


def _binary_list(data: bytes, pos: int, size: int, fmt: str):
    """A binary list `N(raw bytes)` starting at or after pos: (values, position after ')')."""
    # the first `N(` line after pos (the header's comment line comes between)
    m = re.compile(rb"^(\d+)\s*\(", re.M).search(data, pos)
    n = int(m.group(1))
    start = m.end()
    vals = struct.unpack_from("<%d%s" % (n, fmt), data, start)
    return vals, start + n * size + 1


def _read_faces(path: str) -> list:
    data = _read_foam_file(path)
    h = _header(data)
    pos = h["_end"]
    if h.get("format") == "binary":
        size = _label_size(h)
        fmt = "i" if size == 4 else "q"
        # faceCompactList: offsets (nFaces+1), then the concatenated point labels
        offsets, pos = _binary_list(data, pos, size, fmt)
        labels, _ = _binary_list(data, pos, size, fmt)
        return [labels[offsets[i]:offsets[i + 1]] for i in range(len(offsets) - 1)]
    body = data[pos:].decode()
    body = re.sub(r"//[^\n]*", "", body)
    if h.get("class") == "faceCompactList":
        lists = re.findall(r"(\d+)\s*\(([^)]*)\)", body)
        offsets = [int(v) for v in lists[0][1].split()]
        labels = [int(v) for v in lists[1][1].split()]
        return [labels[offsets[i]:offsets[i + 1]] for i in range(len(offsets) - 1)]
    start = body.find("(")
    return [tuple(int(v) for v in f.split()) for f in re.findall(r"\d+\s*\(([^)]*)\)", body[start + 1:])]


def read_boundary(case: str) -> dict:
    """The patches of case's polyMesh: {name: {"type", "nFaces", "startFace", ...}}, in
    file order."""
    data = _read_foam_file(os.path.join(case, "constant", "polyMesh", "boundary")).decode()
    data = re.sub(r"//[^\n]*", "", data[_header(data.encode())["_end"]:])
    out = {}
    for name, body in re.findall(r"([\w.:-]+)\s*\{([^{}]*)\}", data):
        d = {}
        for k, v in re.findall(r"(\w+)\s+([^;]*);", body):
            v = v.strip()
            d[k] = int(v) if re.fullmatch(r"-?\d+", v) else v
        out[name] = d
    return out


def read_points(case: str, polymesh: str = "constant/polyMesh") -> list:
    """The points of case's polyMesh (ASCII, binary or .gz) as a list of (x, y, z) floats,
    in file order (the node order cadmorph uses)."""
    data = _read_foam_file(os.path.join(case, polymesh, "points"))
    h = _header(data)
    if h.get("format") == "binary":
        m = re.search(r"scalar=(\d+)", h.get("arch", ""))
        size = int(m.group(1)) // 8 if m else 8
        m = re.compile(rb"^(\d+)\s*\(", re.M).search(data, h["_end"])
        n = int(m.group(1))
        flat = struct.unpack_from("<%d%s" % (3 * n, "d" if size == 8 else "f"), data, m.end())
        return [tuple(flat[3 * i:3 * i + 3]) for i in range(n)]
    body = data[h["_end"]:].decode()
    return [(float(a), float(b), float(c)) for a, b, c in
            re.findall(r"\(\s*([-+0-9.eE]+)\s+([-+0-9.eE]+)\s+([-+0-9.eE]+)\s*\)", body)]


def patch_faces(case: str, patch: str) -> list:
    """The faces of patch (tuples of point labels, in file order) read from case's
    constant/polyMesh (ASCII, binary or .gz); [] for a patch with no faces; KeyError for an
    unknown patch."""
    b = read_boundary(case)[patch]
    n, start = int(b["nFaces"]), int(b["startFace"])
    if n == 0:
        return []
    faces = _read_faces(os.path.join(case, "constant", "polyMesh", "faces"))
    return [tuple(f) for f in faces[start:start + n]]


def patch_points(case: str, patch: str) -> list:
    """Sorted list of the point labels on patch (read from case's constant/polyMesh; ASCII,
    binary or .gz); [] for a patch with no faces; KeyError for an unknown patch."""
    pts = set()
    for f in patch_faces(case, patch):
        pts.update(f)
    return sorted(pts)


# ---------------------------------------------------------------------------------------
# solver

def solver_steps(case: str, n: int = 5, solver: str = None, *,
                 check: bool = True) -> subprocess.CompletedProcess:
    """Runs the case's solver (controlDict's application unless solver is given) for n
    iterations (sets endTime in system/controlDict; nothing is written: writeInterval is
    larger than any run). Raises FoamError on a non-zero exit (a diverged or unreadable
    case: OpenFOAM traps floating-point exceptions) when check is true."""
    cd = os.path.join(case, "system", "controlDict")
    with open(cd) as f:
        text = f.read()
    if solver is None:
        solver = re.search(r"^\s*application\s+(\w+)\s*;", text, re.M).group(1)
    new = re.sub(r"^(\s*endTime\s+)[^;]*;", r"\g<1>%d;" % n, text, flags=re.M)
    if new != text:
        with open(cd, "w") as f:
            f.write(new)
    return run_foam(solver, case, check=check)


# ---------------------------------------------------------------------------------------
# case writing

def _write(path: str, text: str):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(text)


def write_dict(case: str, rel: str, body: str, cls: str = "dictionary") -> str:
    """Writes the OpenFOAM file rel (e.g. "system/blockMeshDict", "0/U") into case: the
    FoamFile header (format ascii, class cls, object the file's name) followed by body, the
    folders made as needed; an existing file is replaced. Returns the file's path."""
    path = os.path.join(str(case), rel)
    _write(path, HEADER % (cls, os.path.basename(rel)) + body)
    return path


def _divisions(base, s):
    return [max(1, int(round(n * s))) for n in base]


class _Lattice:
    """A lattice of blocks between coordinate planes X, Y, Z with cell counts NX, NY, NZ per
    interval; `removed` blocks (the body) are left out; patch(i, j, k, axis, side) names the
    patch of a block face on the boundary (side -1 low, +1 high)."""

    def __init__(self, X, Y, Z, NX, NY, NZ, removed, patch):
        self.X, self.Y, self.Z = X, Y, Z
        self.N = (NX, NY, NZ)
        self.removed = set(removed)
        self.patch = patch

    def vertex(self, i, j, k):
        return (k * len(self.Y) + j) * len(self.X) + i

    def vertices(self):
        return [(x, y, z) for z in self.Z for y in self.Y for x in self.X]

    def blocks(self):
        for k in range(len(self.Z) - 1):
            for j in range(len(self.Y) - 1):
                for i in range(len(self.X) - 1):
                    if (i, j, k) not in self.removed:
                        yield i, j, k

    def hex(self, i, j, k):
        v = self.vertex
        return (v(i, j, k), v(i + 1, j, k), v(i + 1, j + 1, k), v(i, j + 1, k),
                v(i, j, k + 1), v(i + 1, j, k + 1), v(i + 1, j + 1, k + 1), v(i, j + 1, k + 1))

    # a block face by axis and side, as vertex labels ordered so its normal points out
    _FACES = {(0, -1): (0, 4, 7, 3), (0, 1): (1, 2, 6, 5), (1, -1): (0, 1, 5, 4),
              (1, 1): (3, 7, 6, 2), (2, -1): (0, 3, 2, 1), (2, 1): (4, 5, 6, 7)}

    def boundary_faces(self):
        """{patch: [face vertex tuples]} of the block faces without a neighbour block."""
        dims = (len(self.X) - 1, len(self.Y) - 1, len(self.Z) - 1)
        out = {}
        for b in self.blocks():
            h = self.hex(*b)
            for (axis, side), idx in self._FACES.items():
                nb = list(b)
                nb[axis] += side
                inside = 0 <= nb[axis] < dims[axis]
                if inside and tuple(nb) not in self.removed:
                    continue
                name = self.patch(b, axis, side, inside)
                out.setdefault(name, []).append(tuple(h[q] for q in idx))
        return out


def _fmt(v):
    return "%.12g" % v


def _block_mesh_dict(vertices, blocks, patches, types, extra=""):
    """blockMeshDict text: vertices, blocks [(hex labels, (nx ny nz))], patches {name:
    faces}, types {name: "type ...; more entries"}."""
    lines = ["convertToMeters 1;", "vertices", "("]
    lines += ["    (%s %s %s)" % tuple(_fmt(c) for c in v) for v in vertices]
    lines += [");", "blocks", "("]
    for h, n in blocks:
        lines.append("    hex (%s) (%d %d %d) simpleGrading (1 1 1)" % ((" ".join(map(str, h)),) + tuple(n)))
    lines += [");", "edges ();", "boundary", "("]
    for name in types:
        faces = patches.get(name, [])
        lines.append("    %s\n    {\n        type %s;\n        faces\n        (" % (name, types[name]))
        lines += ["            (%s)" % " ".join(map(str, f)) for f in faces]
        lines.append("        );\n    }")
    lines += [");", "mergePatchPairs ();", extra]
    return "\n".join(lines) + "\n"


def _lattice_case(kind, s):
    """(blockMeshDict text, patch types, zone boxes) of the lattice kinds."""
    if kind == "channel2d":
        d = s ** 0.5
        X, Y, Z = [0.0, 2.0, 2.5, 6.0], [0.0, 0.75, 1.25, 2.0], [0.0, 0.1]
        NX, NY, NZ = _divisions([40, 10, 70], d), _divisions([15, 10, 15], d), [1]
        removed = [(1, 1, 0)]

        def patch(b, axis, side, inside):
            if inside:
                return "body"
            return {0: "inlet" if side < 0 else "outlet", 1: "walls", 2: "frontAndBack"}[axis]
        types = {"inlet": "patch", "outlet": "patch", "walls": "wall", "body": "wall",
                 "frontAndBack": "empty"}
    elif kind == "symmetry3d":
        d = s ** (1 / 3)
        X, Y, Z = [0.0, 2.0, 2.5, 6.0], [0.0, 0.25, 1.5], [-1.0, -0.25, 0.25, 1.0]
        NX, NY, NZ = _divisions([8, 4, 16], d), _divisions([3, 7], d), _divisions([6, 4, 6], d)
        removed = [(1, 0, 1)]

        def patch(b, axis, side, inside):
            if inside:
                return "body"
            if axis == 0:
                return "inlet" if side < 0 else "outlet"
            return "symmetry" if (axis == 1 and side < 0) else "walls"
        types = {"inlet": "patch", "outlet": "patch", "walls": "wall", "body": "wall",
                 "symmetry": "symmetryPlane"}
    elif kind == "cyclic":
        d = s ** (1 / 3)
        X, Y, Z = [0.0, 2.0, 2.5, 6.0], [0.0, 0.75, 1.25, 2.0], [0.0, 0.4, 0.8, 1.2]
        NX, NY, NZ = _divisions([8, 4, 16], d), _divisions([5, 4, 5], d), _divisions([4, 4, 4], d)
        removed = [(1, 1, 1)]

        def patch(b, axis, side, inside):
            if inside:
                return "body"
            return {0: "inlet" if side < 0 else "outlet", 1: "walls",
                    2: "back" if side < 0 else "front"}[axis]
        types = {"inlet": "patch", "outlet": "patch", "walls": "wall", "body": "wall",
                 "back": "cyclic;\n        neighbourPatch front;\n        transform translational;\n"
                         "        separationVector (0 0 %s)" % _fmt(Z[-1] - Z[0]),
                 "front": "cyclic;\n        neighbourPatch back;\n        transform translational;\n"
                          "        separationVector (0 0 %s)" % _fmt(Z[0] - Z[-1])}
    lat = _Lattice(X, Y, Z, NX, NY, NZ, removed, patch)
    blocks = [(lat.hex(*b), (NX[b[0]], NY[b[1]], NZ[b[2]])) for b in lat.blocks()]
    text = _block_mesh_dict(lat.vertices(), blocks, lat.boundary_faces(), types)
    # zones: the cells behind the body (x beyond its back face), the faces of the plane of
    # the body's front face beside it (internal faces only)
    eps = 1e-6 * (X[-1] - X[0])
    zones = {"cells": ((X[2], Y[0] - 1, Z[0] - 1), (X[-1] + 1, Y[-1] + 1, Z[-1] + 1)),
             "faces": ((X[1] - eps, Y[-2] + eps, Z[0] - 1), (X[1] + eps, Y[-1] + 1, Z[-1] + 1))}
    return text, types, zones


def _wedge_case(s):
    """Axisymmetric pipe, axis x, radius R, wedge of 5 degrees; a body of radius rb on the
    axis between x0 and x1. The lattice is in (x, r); the blocks at r=0 have their two axis
    vertices collapsed (one vertex for front and back), so the axis patch has no faces."""
    d = s ** 0.5
    X, R = [0.0, 2.0, 2.5, 6.0], [0.0, 0.25, 1.0]
    NX, NR = _divisions([40, 10, 70], d), _divisions([10, 25], d)
    half = math.radians(2.5)
    c, sn = math.cos(half), math.sin(half)
    label, vertices = {}, []
    for j, r in enumerate(R):
        for i, x in enumerate(X):
            if r == 0.0:
                label[i, j, 0] = label[i, j, 1] = len(vertices)
                vertices.append((x, 0.0, 0.0))
            else:
                label[i, j, 0] = len(vertices)
                vertices.append((x, r * c, -r * sn))
                label[i, j, 1] = len(vertices)
                vertices.append((x, r * c, r * sn))
    removed = {(1, 0)}
    blocks, patches = [], {}
    faces = {(0, -1): (0, 4, 7, 3), (0, 1): (1, 2, 6, 5), (1, -1): (0, 1, 5, 4),
             (1, 1): (3, 7, 6, 2), (2, -1): (0, 3, 2, 1), (2, 1): (4, 5, 6, 7)}
    for j in range(len(R) - 1):
        for i in range(len(X) - 1):
            if (i, j) in removed:
                continue
            L = label
            h = (L[i, j, 0], L[i + 1, j, 0], L[i + 1, j + 1, 0], L[i, j + 1, 0],
                 L[i, j, 1], L[i + 1, j, 1], L[i + 1, j + 1, 1], L[i, j + 1, 1])
            blocks.append((h, (NX[i], NR[j], 1)))
            for (axis, side), idx in faces.items():
                if axis == 2:
                    name = "back" if side < 0 else "front"
                else:
                    nb = [i, j]
                    nb[axis] += side
                    inside = 0 <= nb[0] < len(X) - 1 and 0 <= nb[1] < len(R) - 1
                    if inside and tuple(nb) not in removed:
                        continue
                    if inside:
                        name = "body"
                    elif axis == 0:
                        name = "inlet" if side < 0 else "outlet"
                    else:
                        name = "axis" if side < 0 else "wall"
                patches.setdefault(name, []).append(tuple(h[q] for q in idx))
    types = {"inlet": "patch", "outlet": "patch", "wall": "wall", "body": "wall",
             "front": "wedge", "back": "wedge", "axis": "empty"}
    text = _block_mesh_dict(vertices, blocks, patches, types)
    eps = 1e-6 * X[-1]
    zones = {"cells": ((X[2], -1, -1), (X[-1] + 1, R[-1] + 1, 1)),
             "faces": ((X[1] - eps, R[1] * c + eps, -1), (X[1] + eps, R[-1] + 1, 1))}
    return text, types, zones


_FIELD_BC = {
    "U": {"inlet": "type fixedValue; value uniform (1 0 0);",
          "outlet": "type inletOutlet; inletValue uniform (0 0 0); value uniform (0 0 0);",
          "wall": "type noSlip;"},
    "p": {"inlet": "type zeroGradient;", "outlet": "type fixedValue; value uniform 0;",
          "wall": "type zeroGradient;"},
}


def _write_fields(case, types):
    for field, cls, dim, internal in (("U", "volVectorField", "[0 1 -1 0 0 0 0]", "uniform (0 0 0)"),
                                      ("p", "volScalarField", "[0 2 -2 0 0 0 0]", "uniform 0")):
        lines = ["dimensions %s;" % dim, "internalField %s;" % internal, "boundaryField", "{"]
        for name, t in types.items():
            ptype = t.split(";")[0].strip()
            if ptype in ("empty", "wedge", "symmetryPlane", "cyclic"):
                bc = "type %s;" % ptype
            elif ptype == "wall":
                bc = _FIELD_BC[field]["wall"]
            else:
                bc = _FIELD_BC[field][name]
            lines.append("    %s { %s }" % (name, bc))
        lines.append("}")
        write_dict(case, "0/" + field, "\n".join(lines) + "\n", cls)


def _write_system(case, binary, compress, write_precision):
    write_dict(case, "system/controlDict", """application simpleFoam;
startFrom startTime;
startTime 0;
stopAt endTime;
endTime 5;
deltaT 1;
writeControl timeStep;
writeInterval 100000;
purgeWrite 0;
writeFormat %s;
writePrecision %d;
writeCompression %s;
timeFormat general;
timePrecision 6;
runTimeModifiable false;
""" % ("binary" if binary else "ascii", 6 if write_precision is None else int(write_precision),
       "on" if compress else "off"))
    write_dict(case, "system/fvSchemes", """ddtSchemes { default steadyState; }
gradSchemes { default Gauss linear; }
divSchemes
{
    default none;
    div(phi,U) bounded Gauss linearUpwind grad(U);
    div((nuEff*dev2(T(grad(U))))) Gauss linear;
}
laplacianSchemes { default Gauss linear limited corrected 0.5; }
interpolationSchemes { default linear; }
snGradSchemes { default limited corrected 0.5; }
wallDist { method meshWave; }
""")
    write_dict(case, "system/fvSolution", """solvers
{
    p { solver GAMG; smoother GaussSeidel; tolerance 1e-7; relTol 0.1; }
    U { solver smoothSolver; smoother symGaussSeidel; tolerance 1e-7; relTol 0.1; }
}
SIMPLE
{
    nNonOrthogonalCorrectors 0;
    consistent yes;
    pRefCell 0;
    pRefValue 0;
}
relaxationFactors
{
    equations { U 0.9; ".*" 0.9; }
}
""")
    write_dict(case, "constant/transportProperties", "transportModel Newtonian;\nnu 0.01;\n")
    # v1912 (ESI) reads turbulenceProperties; momentumTransport is the Foundation's later name
    write_dict(case, "constant/turbulenceProperties", "simulationType laminar;\n")


def _write_topo_set(case, zones):
    """cellZone `wake` (the cells behind the body), faceZone `plane` (internal faces of a
    plane beside the body), and the cellZone `none` with no cells (what decomposePar pieces
    have)."""
    (c0, c1), (f0, f1) = zones["cells"], zones["faces"]
    box = "box (%s %s %s) (%s %s %s);"
    write_dict(case, "system/topoSetDict", """actions
(
    { name wakeSet; type cellSet; action new; source boxToCell; %s }
    { name wake; type cellZoneSet; action new; source setToCellZone; set wakeSet; }
    { name planeSet; type faceSet; action new; source boxToFace; %s }
    { name plane; type faceZoneSet; action new; source setToFaceZone; faceSet planeSet; }
    { name noneSet; type cellSet; action new; source boxToCell; box (1e6 1e6 1e6) (2e6 2e6 2e6); }
    { name none; type cellZoneSet; action new; source setToCellZone; set noneSet; }
);
""" % (box % (c0 + c1), box % (f0 + f1)))


def make_case(kind: str, case_dir: str, *, scale: float = 1.0, binary: bool = False,
              compress: bool = False, zones: bool = False, write_precision: int = None) -> str:
    """Writes a complete simpleFoam (laminar) case of kind (see the module docstring) into
    case_dir (emptied first) and runs blockMesh (and topoSet for zones=True: cellZones
    `wake` and `none` (no cells), faceZone `plane`). binary/compress/write_precision set
    controlDict's writeFormat, writeCompression (OpenFOAM compresses ASCII files only) and
    writePrecision (default 6, OpenFOAM's). scale multiplies the cell count. Returns case_dir."""
    if kind not in KINDS:
        raise ValueError("kind must be one of %s, not %r" % (", ".join(KINDS), kind))
    if not scale > 0:
        raise ValueError("scale must be positive")
    case_dir = str(case_dir)
    shutil.rmtree(case_dir, ignore_errors=True)
    os.makedirs(case_dir)
    if kind == "wedge":
        text, types, zone_boxes = _wedge_case(scale)
    else:
        text, types, zone_boxes = _lattice_case(kind, scale)
    _write_system(case_dir, binary, compress, write_precision)
    write_dict(case_dir, "system/blockMeshDict", text)
    _write_fields(case_dir, types)
    run_foam("blockMesh", case_dir)
    if zones:
        _write_topo_set(case_dir, zone_boxes)
        run_foam("topoSet", case_dir)
        # topoSet leaves its sets in polyMesh/sets: the zones are what the case carries
        shutil.rmtree(os.path.join(case_dir, "constant", "polyMesh", "sets"), ignore_errors=True)
    return case_dir


# ---------------------------------------------------------------------------------------
# snappyHexMesh

SNAPPY_BODIES = ("rounded_box", "sphere")
# body: tunnel start x0, snappy's geometry entry, surface refinement levels, refinement
# regions, nCellsBetweenLevels, implicitFeatureSnap. Changing any of them changes the meshes
# the tests' expectations (folded tet decompositions on valid cells, byte-identical copies)
# and the benchmark's recorded sizes were established on.
_SNAPPY = {
    "rounded_box": (-1.0, "body.stl { type triSurfaceMesh; name body; }", "1 2", "", 2, "true"),
    "sphere": (-1.5, "body { type searchableSphere; centre (0 0 0); radius 0.35; }", "2 2",
               "body { mode distance; levels ((0.25 1)); }", 3, "false"),
}
_SNAPPY_DICT = """castellatedMesh true; snap true; addLayers true;
geometry { %s }
castellatedMeshControls { maxLocalCells 10000000; maxGlobalCells 20000000; minRefinementCells 0;
  maxLoadUnbalance 0.1; nCellsBetweenLevels %d; features ( );
  refinementSurfaces { body { level (%s); patchInfo { type wall; } } }
  resolveFeatureAngle 30;
  refinementRegions { %s }
  locationInMesh (2.71 0.831 0.771); allowFreeStandingZoneFaces true; }
snapControls { nSmoothPatch 3; tolerance 2.0; nSolveIter 30; nRelaxIter 5; nFeatureSnapIter 10;
  implicitFeatureSnap %s; explicitFeatureSnap false; multiRegionFeatureSnap false; }
addLayersControls { relativeSizes true; layers { body { nSurfaceLayers 2; } }
  expansionRatio 1.2; finalLayerThickness 0.4; minThickness 0.05; nGrow 0; featureAngle 120;
  slipFeatureAngle 30; nRelaxIter 3; nSmoothSurfaceNormals 1; nSmoothNormals 3; nSmoothThickness 10;
  maxFaceThicknessRatio 0.5; maxThicknessToMedialRatio 0.3; minMedialAxisAngle 90;
  nBufferCellsNoExtrude 0; nLayerIter 50; }
meshQualityControls { maxNonOrtho 65; maxBoundarySkewness 20; maxInternalSkewness 4; maxConcave 80;
  minVol 1e-13; minTetQuality 1e-15; minArea -1; minTwist 0.02; minDeterminant 0.001;
  minFaceWeight 0.05; minVolRatio 0.01; minTriangleTwist -1; nSmoothScale 4; errorReduction 0.75; }
mergeTolerance 1e-6;
"""
# the rounded box's surface, triangulated by gmsh (run by the same Python as a separate
# process: this module stays importable without gmsh)
_ROUNDED_BOX_STL = """
import gmsh, sys
gmsh.initialize(); gmsh.option.setNumber("General.Terminal", 0)
b = gmsh.model.occ.addBox(-0.4, -0.3, -0.25, 1.0, 0.6, 0.5)
gmsh.model.occ.synchronize()
edges = [e[1] for e in gmsh.model.getEntities(1)]
gmsh.model.occ.fillet([b], edges, [0.1])
gmsh.model.occ.synchronize()
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.06)
gmsh.model.mesh.generate(2)
gmsh.write(sys.argv[1])
gmsh.finalize()
"""


def make_snappy_case(case_dir: str, *, body: str = "rounded_box", base: int = 8) -> str:
    """Writes a complete simpleFoam (laminar) case meshed by snappyHexMesh into case_dir
    (emptied first): a tunnel, y and z in [-1, 1], around a body at the origin,
    castellated, snapped, with 2 boundary layers on the body; patches inlet (x low), outlet
    (x high), walls, body (all but the body from blockMesh's background box). Runs blockMesh
    and snappyHexMesh -overwrite, then writes 0/U and 0/p. The mesh is mostly hexahedra,
    with polyhedra where refinement levels meet and at the snapped body. body:
      rounded_box  tunnel x [-1, 3]; the box [-0.4, 0.6] x [-0.3, 0.3] x [-0.25, 0.25] with
                   every edge filleted (radius 0.1), an STL that gmsh writes
                   (constant/triSurface/body.stl; needs gmsh's Python module for this
                   Python); surface refinement levels 1 to 2 (base 8: 5,076 cells)
      sphere       tunnel x [-1.5, 3]; a sphere of radius 0.35 (snappyHexMesh's
                   searchableSphere: no STL); surface level 2 and level 1 within 0.25 of it
                   (base 6: 3,132 cells; base 32: 126,912)
    base is the number of background cells across the tunnel's height (cells of about 2/base
    on a side); the cell count grows as base**3. Raises ValueError for an unknown body or a
    base below 2, FoamError when gmsh or an OpenFOAM tool fails. Returns case_dir."""
    if body not in _SNAPPY:
        raise ValueError("body must be one of %s, not %r" % (", ".join(SNAPPY_BODIES), body))
    if int(base) != base or base < 2:
        raise ValueError("base must be an integer of at least 2, not %r" % (base,))
    x0, geometry, level, regions, between, implicit = _SNAPPY[body]
    case_dir = str(case_dir)
    shutil.rmtree(case_dir, ignore_errors=True)
    os.makedirs(case_dir)
    _write_system(case_dir, False, False, None)
    n = int(base)
    write_dict(case_dir, "system/blockMeshDict", """convertToMeters 1;
vertices ( (X0 -1 -1) (3 -1 -1) (3 1 -1) (X0 1 -1) (X0 -1 1) (3 -1 1) (3 1 1) (X0 1 1) );
blocks ( hex (0 1 2 3 4 5 6 7) (%d %d %d) simpleGrading (1 1 1) );
edges ();
boundary ( inlet { type patch; faces ((0 4 7 3)); } outlet { type patch; faces ((1 2 6 5)); }
  walls { type wall; faces ((0 1 5 4) (3 7 6 2) (0 3 2 1) (4 5 6 7)); } );
mergePatchPairs ();
""".replace("X0", _fmt(x0)) % (int(round(n * (3.0 - x0) / 2)), n, n))
    write_dict(case_dir, "system/snappyHexMeshDict",
               _SNAPPY_DICT % (geometry, between, level, regions, implicit))
    if body == "rounded_box":
        stl = os.path.join(case_dir, "constant", "triSurface", "body.stl")
        os.makedirs(os.path.dirname(stl))
        cmd = [sys.executable, "-c", _ROUNDED_BOX_STL, stl]
        p = subprocess.run(cmd, capture_output=True, text=True)
        if p.returncode != 0:
            raise FoamError(p.returncode, [sys.executable, "-c", "<gmsh: the body's STL>", stl],
                            p.stdout, p.stderr)
    run_foam("blockMesh", case_dir)
    run_foam("snappyHexMesh", case_dir, "-overwrite")
    # the fields after meshing: snappyHexMesh would map (and then need) fields it found in 0/
    _write_fields(case_dir, {"inlet": "patch", "outlet": "patch", "walls": "wall", "body": "wall"})
    return case_dir
