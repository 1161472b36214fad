#!/usr/bin/python3
"""Hostile OpenFOAM polyMesh input: small files (plain or gzip'ed) that claim or inflate to
gigabytes, counts that disagree with each other, cell labels out of range. Each case writes a
small hex-block polyMesh here (no OpenFOAM needed), breaks one file, and checks exit 2, one
stderr line naming the broken file, bounded peak memory, no hang (hostile.py's frame).

usage: hostile_foam.py CADMORPH DATA_DIR WORK_DIR CASE       (CASE 'list' prints the cases)
"""
import gzip
import os
import shutil
import struct

import hostile
from hostile import case, run, path, fail

MAX_MB = 200
HEADER = ("FoamFile\n{\n    version     2.0;\n    format      %s;\n    class       %s;\n"
          "%s    object      %s;\n}\n"
          "// * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * //\n\n")
CLASSES = {"points": "vectorField", "faces": "faceList", "owner": "labelList",
           "neighbour": "labelList", "boundary": "polyBoundaryMesh"}


def header(name, fmt="ascii"):
    arch = '    arch        "LSB;label=32;scalar=64";\n' if fmt == "binary" else ""
    return HEADER % (fmt, CLASSES.get(name, "regIOobject"), arch, name)


def block(n=(2, 2, 2)):
    """The polyMesh of an nx x ny x nz block of unit hexahedra, as OpenFOAM orders it:
    internal faces upper-triangular (owner < neighbour, by owner then neighbour), each
    oriented out of its owner, then one patch `walls` of every boundary face."""
    nx, ny, nz = n
    P = lambda i, j, k: i + (nx + 1) * (j + (ny + 1) * k)
    C = lambda i, j, k: i + nx * (j + ny * k)
    points = [(i, j, k) for k in range(nz + 1) for j in range(ny + 1) for i in range(nx + 1)]

    def quad(axis, i, j, k):
        """The face of the cell corner (i, j, k) normal to axis at the cell's + side, +axis."""
        if axis == 0:
            return [P(i + 1, j, k), P(i + 1, j + 1, k), P(i + 1, j + 1, k + 1), P(i + 1, j, k + 1)]
        if axis == 1:
            return [P(i, j + 1, k), P(i, j + 1, k + 1), P(i + 1, j + 1, k + 1), P(i + 1, j + 1, k)]
        return [P(i, j, k + 1), P(i + 1, j, k + 1), P(i + 1, j + 1, k + 1), P(i, j + 1, k + 1)]

    faces, owner, neighbour, bfaces, bowner = [], [], [], [], []
    step = (1, nx, nx * ny)
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                c, ijk = C(i, j, k), (i, j, k)
                for axis in range(3):
                    if ijk[axis] + 1 < n[axis]:
                        faces.append(quad(axis, i, j, k))
                        owner.append(c)
                        neighbour.append(c + step[axis])
                    else:
                        bfaces.append(quad(axis, i, j, k))
                        bowner.append(c)
                    if ijk[axis] == 0:  # the - side: the + face of the cell before, reversed
                        q = list(ijk)
                        q[axis] -= 1
                        f = quad(axis, *q)
                        bfaces.append([f[0]] + f[1:][::-1])
                        bowner.append(c)
    return points, faces + bfaces, owner + bowner, neighbour


def binary_files(points, faces, owner, neighbour):
    """The block's lists in binary (label=32, scalar=64; faces as a faceCompactList)."""
    lab = lambda v: b"%d\n(" % len(v) + struct.pack("<%di" % len(v), *v) + b")\n"
    offsets = [0]
    for f in faces:
        offsets.append(offsets[-1] + len(f))
    nodes = [x for f in faces for x in f]
    xyz = [c for p in points for c in p]
    return {
        "points": header("points", "binary").encode() + b"%d\n(" % len(points) +
        struct.pack("<%dd" % len(xyz), *xyz) + b")\n",
        "faces": header("faces", "binary").replace("faceList", "faceCompactList").encode() +
        lab(offsets) + b"\n" + lab(nodes),
        "owner": header("owner", "binary").encode() + lab(owner),
        "neighbour": header("neighbour", "binary").encode() + lab(neighbour),
    }


def write_case(name, n=(2, 2, 2), gz=(), replace=None, binary=False):
    """The block's case name/constant/polyMesh; the files in gz gzip'ed; replace maps a
    file name to its whole content (str or bytes) instead of the block's."""
    root = path(name)
    if os.path.exists(root):
        shutil.rmtree(root)
    d = os.path.join(root, "constant", "polyMesh")
    os.makedirs(d)
    points, faces, owner, neighbour = block(n)
    n_int = len(neighbour)
    body = {
        "points": "%d\n(\n%s)\n" % (len(points), "".join("(%g %g %g)\n" % p for p in points)),
        "faces": "%d\n(\n%s)\n" % (len(faces), "".join("4(%s)\n" % " ".join(map(str, f)) for f in faces)),
        "owner": "%d\n(\n%s)\n" % (len(owner), "".join("%d\n" % o for o in owner)),
        "neighbour": "%d\n(\n%s)\n" % (n_int, "".join("%d\n" % o for o in neighbour)),
        "boundary": "1\n(\n    walls\n    {\n        type wall;\n        nFaces %d;\n        startFace %d;\n"
                    "    }\n)\n" % (len(faces) - n_int, n_int),
    }
    if binary:
        replace = dict(binary_files(points, faces, owner, neighbour), **(replace or {}))
    for f, text in body.items():
        data = (replace or {}).get(f, header(f) + text)
        if isinstance(data, str):
            data = data.encode()
        p = os.path.join(d, f + (".gz" if f in gz else ""))
        with open(p, "wb") as out:
            out.write(gzip.compress(data, 6) if f in gz else data)
    return root, d, {"faces": faces, "owner": owner, "neighbour": neighbour, "points": points}


def blank_members(total_mb, text=b" "):
    """total_mb MiB of text repeated, as concatenated gzip members of 16 MiB each."""
    one = gzip.compress(text * ((16 << 20) // len(text)), 9)
    return one * (total_mb // 16)


def gz_faces_case(name, head, tail_mb, text=b" "):
    """faces.gz = gzip(head) followed by tail_mb MiB of text in further gzip members."""
    root, d, _ = write_case(name)
    os.remove(os.path.join(d, "faces"))
    with open(os.path.join(d, "faces.gz"), "wb") as f:
        f.write(gzip.compress(head.encode(), 6))
        f.write(blank_members(tail_mb, text))
    return root


def quality(root, pattern, names, code=2):
    return run(["quality", root], code, pattern, names, max_mb=MAX_MB)


# ---- the block reads (so that each case below fails for its own reason) ----
@case
def foam_block_reads():
    root, _, _ = write_case("foam_ok")
    run(["quality", root], 0, None, lines=None, max_mb=MAX_MB)
    root, _, _ = write_case("foam_ok_gz", gz=("points", "faces", "owner", "neighbour", "boundary"))
    run(["quality", root], 0, None, lines=None, max_mb=MAX_MB)
    # 27,000 cells: faces inflate to more than the first MiB, read within their budget
    every = ("points", "faces", "owner", "neighbour", "boundary")
    for binary in (False, True):
        root, d, _ = write_case("foam_big_gz", n=(30, 30, 30), gz=every, binary=binary)
        with gzip.open(os.path.join(d, "faces.gz")) as f:
            if len(f.read()) <= 1 << 20:
                fail("faces.gz inflates to less than 1 MiB")
        p = run(["quality", root], 0, None, lines=None, max_mb=MAX_MB)
        if "27000" not in p.stdout:
            fail("not 27000 cells read")


# ---- inflated streams: bounded by what their content can hold ----
@case
def foam_gz_blanks_after_faces():
    """The real faces, then 256 MiB of blanks in concatenated gzip members (~250 KB)."""
    _, _, b = write_case("foam_gzb_src")
    faces = b["faces"]
    head = header("faces") + "%d\n(\n%s" % (len(faces), "".join("4(%s)\n" % " ".join(map(str, f)) for f in faces))
    root = gz_faces_case("foam_gzb", head, 256)
    quality(root, r"faces\.gz: inflated offset \d+: more than", ["foam_gzb/constant/polyMesh/faces.gz"])


@case
def foam_gz_blanks_no_count():
    """A header, then only blanks: no list size within the first MiB."""
    root = gz_faces_case("foam_gzn", header("faces"), 256)
    quality(root, r"faces\.gz: inflated offset \d+: no FoamFile header and list size",
            ["foam_gzn/constant/polyMesh/faces.gz"])


@case
def foam_gz_blanks_huge_count():
    """A count of 10^8 faces (a budget of 100 GB), then blanks: refused at the blank run."""
    root = gz_faces_case("foam_gzh", header("faces") + "100000000\n(\n", 256)
    quality(root, r"faces\.gz: inflated offset \d+: more than \d+ blank bytes in a row",
            ["foam_gzh/constant/polyMesh/faces.gz"])


@case
def foam_gz_comment():
    """The real count, then a comment of 256 MiB."""
    _, _, b = write_case("foam_gzc_src")
    root = gz_faces_case("foam_gzc", header("faces") + "%d\n(\n/*" % len(b["faces"]), 256, b"comment ")
    quality(root, r"faces\.gz: inflated offset \d+: more than", ["foam_gzc/constant/polyMesh/faces.gz"])


@case
def foam_gz_owner_blanks():
    """owner.gz with its real count, then blanks: the budget is the faces' count."""
    root, d, b = write_case("foam_gzo")
    os.remove(os.path.join(d, "owner"))
    text = header("owner") + "%d\n(\n%s" % (len(b["owner"]), "".join("%d\n" % o for o in b["owner"]))
    with open(os.path.join(d, "owner.gz"), "wb") as f:
        f.write(gzip.compress(text.encode()))
        f.write(blank_members(64, b"\n"))
    quality(root, r"owner\.gz: inflated offset \d+: more than", ["foam_gzo/constant/polyMesh/owner.gz"])


# ---- counts against each other, before allocation ----
@case
def foam_uniform_owner():
    root, _, _ = write_case("foam_uo", replace={"owner": header("owner") + "500000000{0}\n"})
    quality(root, r"owner:\d+: owner has 500000000 entries, expected as many as the 36 faces",
            ["foam_uo/constant/polyMesh/owner"])


@case
def foam_uniform_neighbour():
    root, _, _ = write_case("foam_un", replace={"neighbour": header("neighbour") + "500000000{1}\n"})
    quality(root, r"neighbour:\d+: neighbour has 500000000 entries, expected at most the 36 faces",
            ["foam_un/constant/polyMesh/neighbour"])


@case
def foam_huge_count_owner():
    """A non-uniform list whose count disagrees with faces (and with its own length)."""
    root, _, b = write_case("foam_ho")
    text = header("owner") + "400000000\n(\n%s)\n" % "".join("%d\n" % o for o in b["owner"])
    write_case("foam_ho", replace={"owner": text})
    quality(root, r"owner:\d+: owner has 400000000 entries, expected as many as the 36 faces",
            ["foam_ho/constant/polyMesh/owner"])


@case
def foam_uniform_points():
    root, _, _ = write_case("foam_up", replace={"points": header("points") + "500000000{(0 0 0)}\n"})
    quality(root, r"points:\d+: points: uniform list of 500000000 entries, expected at most 144",
            ["foam_up/constant/polyMesh/points"])


@case
def foam_huge_count_points():
    """10^9 points in a file of a few hundred bytes: the count cannot fit the file."""
    root, _, _ = write_case("foam_hp", replace={"points": header("points") + "1000000000\n(\n(0 0 0)\n)\n"})
    quality(root, r"points:\d+: points has size 1000000000, more than the \d+ bytes left",
            ["foam_hp/constant/polyMesh/points"])


@case
def foam_binary_owner_count():
    """A binary owner whose count needs 2 GB: the block's exact size is checked first."""
    _, _, b = write_case("foam_bo_src")
    data = header("owner", "binary").encode() + b"500000000\n(" + struct.pack("<36i", *b["owner"]) + b")\n"
    root, _, _ = write_case("foam_bo", replace={"owner": data})
    quality(root, r"owner:\d+: owner has 500000000 entries, expected as many as the 36 faces",
            ["foam_bo/constant/polyMesh/owner"])
    # the right count, a truncated block: refused as truncated, not allocated
    data = header("owner", "binary").encode() + b"36\n(" + struct.pack("<30i", *b["owner"][:30])
    root, _, _ = write_case("foam_bo", replace={"owner": data})
    quality(root, r"owner: byte \d+: truncated binary block of owner", ["foam_bo/constant/polyMesh/owner"])


@case
def foam_face_vertex_count():
    """One face claims 10^9 vertices."""
    _, _, b = write_case("foam_fv_src")
    faces = ["4(%s)" % " ".join(map(str, f)) for f in b["faces"]]
    faces[3] = "1000000000(0 1 2)"
    root, _, _ = write_case("foam_fv", replace={"faces": header("faces") + "%d\n(\n%s\n)\n" % (len(faces), "\n".join(faces))})
    quality(root, r"faces:\d+: a face has size 1000000000, more than", ["foam_fv/constant/polyMesh/faces"])


@case
def foam_many_patches():
    text = header("boundary") + "100000000\n(\n    walls\n    {\n        type wall;\n        nFaces 24;\n" \
                                "        startFace 12;\n    }\n)\n"
    root, _, _ = write_case("foam_mp", replace={"boundary": text})
    quality(root, r"boundary:\d+: 100000000 patches, more than", ["foam_mp/constant/polyMesh/boundary"])


@case
def foam_zone_counts():
    root, d, _ = write_case("foam_zc")
    zones = os.path.join(d, "cellZones")
    for body, pattern in [
            ("1\n(\nz\n{\n    type cellZone;\n    cellLabels List<label> 500000000{0};\n}\n)\n",
             r"cellLabels has 500000000 entries, expected at most the 8 cells"),
            ("100000000\n(\nz\n{\n    type cellZone;\n    cellLabels List<label> 1(0);\n}\n)\n",
             r"100000000 zones, more than"),
            ("1\n(\nz\n{\n    type cellZone;\n    cellLabels List<label> 300000000(0 1);\n}\n)\n",
             r"cellLabels has 300000000 entries, expected at most the 8 cells")]:
        with open(zones, "w") as f:
            f.write(header("cellZones") + body)
        quality(root, pattern, ["foam_zc/constant/polyMesh/cellZones"])
    # many zones, each a uniform list of the mesh's size: all of them together at most one mesh
    with open(zones, "w") as f:
        f.write(header("cellZones") + "%d\n(\n%s)\n" % (
            100000, "".join("z%d{cellLabels 8{%d};}\n" % (i, i % 8) for i in range(100000))))
    quality(root, r"cellZones: zone 'z1': 16 labels repeated in the zones so far, more than the 8 cells",
            ["foam_zc/constant/polyMesh/cellZones"])


# ---- cell labels: out of range, beyond int64, named in their own file ----
@case
def foam_huge_owner_labels():
    for label, pattern in [("4000000000", r"owner: entry 5: cell label 4000000000 beyond the 12 cells"),
                           ("9223372036854775807", r"owner: entry 5: cell label 9223372036854775807 beyond"),
                           ("99999999999999999999", r"owner:\d+: expected one of the 36 entries of owner, "
                                                    r"got '99999999999999999999'"),
                           ("-9223372036854775808", r"owner:\d+: expected one of the 36 entries of owner, "
                                                    r"got '-9223372036854775808'"),
                           ("-5", r"owner: entry 5: cell label -5 is negative")]:
        _, _, b = write_case("foam_hl")
        owner = [str(o) for o in b["owner"]]
        owner[5] = label
        root, _, _ = write_case("foam_hl", replace={"owner": header("owner") + "36\n(\n%s\n)\n" % "\n".join(owner)})
        quality(root, pattern, ["foam_hl/constant/polyMesh/owner"])


@case
def foam_neighbour_out_of_range():
    """One neighbour label past the 8 cells: named in neighbour, not as a cell of owner."""
    _, _, b = write_case("foam_nr")
    nei = list(b["neighbour"])
    nei[11] = 8
    root, _, _ = write_case("foam_nr", replace={"neighbour": header("neighbour") + "12\n(\n%s\n)\n" %
                                                "\n".join(map(str, nei))})
    quality(root, r"neighbour: entry 11: cell label 8 beyond the 8 cells numbered 0 to 7",
            ["foam_nr/constant/polyMesh/neighbour"])
    # an owner label past the cells, with a gap before it
    owner = list(b["owner"])
    owner[30] = 10
    root, _, _ = write_case("foam_nr", replace={"owner": header("owner") + "36\n(\n%s\n)\n" %
                                                "\n".join(map(str, owner))})
    quality(root, r"owner: entry 30: cell label 10 beyond the 8 cells numbered 0 to 7",
            ["foam_nr/constant/polyMesh/owner"])


if __name__ == "__main__":
    hostile.main()
