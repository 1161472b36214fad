"""cadmorph.read_step, model and Geometry against `cadmorph info` (counts, units, bounding box,
faces and edges, --compare and its --map), and the lifetime of the model a Geometry holds."""
import csv
import gc
import math
import os
import re
import subprocess
from collections import Counter

import numpy as np
import pytest

import cadmorph
from morph_helpers import reversed_shell

STEPS = ["cad/bore_a.step", "cad/bore_2holes.step", "freecad/bracket_0.step",
         "freecad/shaft_1.step", "models/bore_0.step"]


def info(cli, *args):
    r = subprocess.run([cli, "info", *map(str, args)], capture_output=True, text=True)
    return r


def parse_info(text):
    """The numbers of `cadmorph info G --faces --edges`."""
    out = {"faces": [], "edges": []}
    for line in text.splitlines():
        if line.startswith("unit: "):
            m = re.match(r"unit: (\S+) \(file: (.*)\)$", line)
            out["unit"], out["file_unit"] = m.group(1), m.group(2)
        elif line.startswith("solids "):
            w = line.split()
            out["counts"] = {w[i]: int(w[i + 1]) for i in range(0, len(w), 2)}
        elif line.startswith("bbox: "):
            v = re.findall(r"\[([^,]+), ([^\]]+)\]", line)
            out["bbox"] = [v[0][0], v[1][0], v[2][0], v[0][1], v[1][1], v[2][1]]
        elif line.startswith("faces by type:"):
            head, area = line.split("  (total area ")
            w = head.split()[3:]
            out["face_types"] = {w[i]: int(w[i + 1]) for i in range(0, len(w), 2)}
            out["area"] = area.rstrip(")")
        elif line.startswith("edges by type:"):
            head, length = line.split("  (total length ")
            w = head.split()[3:]
            out["edge_types"] = {w[i]: int(w[i + 1]) for i in range(0, len(w), 2)}
            out["length"] = length.rstrip(")")
        elif line.startswith("face "):
            out["faces"].append(line)
        elif line.startswith("edge "):
            out["edges"].append(line)
    return out


@pytest.mark.parametrize("name", STEPS)
def test_geometry_equals_cli_info(cli, data, name):
    g = cadmorph.read_step(data / name)
    r = info(cli, data / name, "--faces", "--edges")
    assert r.returncode == 0, r.stderr
    ref = parse_info(r.stdout)
    c = g.counts
    assert ref["counts"] == {"solids": c.solids, "shells": c.shells, "faces": c.faces,
                             "wires": c.wires, "edges": c.edges, "vertices": c.vertices}
    assert (g.n_faces, g.n_edges, g.n_vertices) == (c.faces, c.edges, c.vertices)
    assert ref["bbox"] == ["%g" % x for x in g.bbox]
    assert (ref["unit"], ref["file_unit"]) == (g.unit, g.file_unit or "not given")
    assert g.path == str(data / name)
    faces, edges = g.faces, g.edges
    assert [f.index for f in faces] == list(range(c.faces))
    assert ref["face_types"] == dict(Counter(f.type for f in faces))
    assert ref["area"] == "%g" % sum(f.area for f in faces)
    assert ref["edge_types"] == dict(Counter("degenerate" if e.degenerate else e.type
                                             for e in edges))
    assert ref["length"] == "%g" % sum(e.length for e in edges)
    for f, line in zip(faces, ref["faces"]):
        assert line == "face %d: %s area %g wires %d edges %d u [%g, %g] v [%g, %g]%s" % (
            (f.index, f.type, f.area, f.n_wires, sum(len(w) for w in f.wires)) + f.uv_range
            + (" reversed" if f.reversed else "",))
    for e, line in zip(edges, ref["edges"]):
        assert line == "edge %d: %s length %g vertices (%d,%d) t [%g, %g]" % (
            (e.index, "degenerate" if e.degenerate else e.type, e.length) + e.vertices
            + e.t_range)
    assert len(ref["faces"]) == c.faces and len(ref["edges"]) == c.edges


def test_topology_is_consistent(data):
    g = cadmorph.read_step(data / "freecad/bracket_0.step")
    v = g.vertices
    assert v.shape == (g.n_vertices, 3) and v.dtype == np.float64
    lo, hi = np.array(g.bbox[:3]), np.array(g.bbox[3:])
    assert np.all(v >= lo - 1e-9) and np.all(v <= hi + 1e-9)
    assert g.diagonal == pytest.approx(math.dist(lo, hi))
    faces = g.faces
    for e in g.edges:
        if e.type == "line":  # a straight edge is as long as its ends are apart
            assert np.linalg.norm(v[e.vertices[1]] - v[e.vertices[0]]) == \
                pytest.approx(e.length, rel=1e-9)
        for f in e.faces:  # each face of an edge has the edge in one of its wires
            assert any(e.index in w for w in faces[f].wires)
    for f in faces:
        assert len(f.wires) == f.n_wires == len(f.wire_reversed)
        assert all(len(a) == len(b) for a, b in zip(f.wires, f.wire_reversed))
    with pytest.raises(dataclasses_frozen_error()):
        faces[0].area = 0.0


def dataclasses_frozen_error():
    import dataclasses
    return dataclasses.FrozenInstanceError


def test_units(cli, data):
    path = data / "freecad/bracket_0.step"
    mm, m = cadmorph.read_step(path), cadmorph.read_step(path, unit="m")
    assert (mm.unit, m.unit, m.file_unit) == ("mm", "m", mm.file_unit)
    assert np.allclose(np.array(m.bbox) * 1000.0, mm.bbox)
    r = info(cli, path, "--cad-unit", "m")
    assert parse_info(r.stdout)["bbox"] == ["%g" % x for x in m.bbox]
    with pytest.raises(ValueError, match="unknown length unit 'furlong'"):
        cadmorph.read_step(path, unit="furlong")
    with pytest.raises(TypeError, match="unit"):
        cadmorph.read_step(path, unit=1000)


def test_bad_files(cli, data, work):
    with pytest.raises(cadmorph.BadInputError) as e:
        cadmorph.read_step(work / "absent.step")
    assert str(work / "absent.step") in str(e.value)
    broken = data / "cad/broken.step"
    r = info(cli, broken)
    with pytest.raises(cadmorph.BadInputError) as e:
        cadmorph.read_step(broken)
    assert r.returncode == 2 and r.stderr.strip() == "cadmorph info: " + e.value.message
    with pytest.raises(TypeError):
        cadmorph.read_step(None)
    with pytest.raises(ValueError):
        cadmorph.read_step("")


def test_compare_equals_cli_map(cli, data, work):
    g0 = cadmorph.read_step(data / "cad/bore_a.step")
    reversed_shell(data / "cad/bore_a.step", work / "bore_rev.step")
    g1 = cadmorph.read_step(work / "bore_rev.step")
    c = g0.compare(g1)
    assert c and c.corresponds and c.renumbered
    r = info(cli, data / "cad/bore_a.step", "--compare", work / "bore_rev.step",
             "--map", work / "map.csv")
    assert r.returncode == 0 and "numbered otherwise" in r.stdout
    rows = list(csv.reader(open(work / "map.csv")))[1:]
    for kind, index, target, orient in ((row[0], int(row[1]), int(row[2]), row[3])
                                        for row in rows):
        assert getattr(c, kind)[index] == target
        if kind == "face":
            assert c.face_reversed[index] == (orient == "reversed")
        if kind == "edge":
            assert c.edge_flipped[index] == (orient == "reversed")
    assert sorted(c.face) == list(range(g0.n_faces)) and not np.array_equal(
        c.face, np.arange(g0.n_faces))
    assert len(rows) == g0.n_faces + g0.n_edges + g0.n_vertices
    assert f"{c.face_type_changes} faces, {c.edge_type_changes} edges" in r.stdout
    # neither model changed: G' keeps its own numbering
    assert [f.type for f in g1.faces] == [g0.faces[i].type for i in np.argsort(c.face)]


def test_compare_mismatch_is_not_an_error(cli, data):
    g0 = cadmorph.read_step(data / "cad/bore_a.step")
    g1 = cadmorph.read_step(data / "cad/bore_2holes.step")
    c = g0.compare(g1)
    assert not c and c.corresponds is False and c.face is None
    r = info(cli, data / "cad/bore_a.step", "--compare", data / "cad/bore_2holes.step")
    assert r.returncode == 2 and r.stderr.strip() == "cadmorph info: " + c.message
    assert "faces: 9 in G, 10 in G'" in c.message
    short = g0.compare(g1, max_report=1)
    assert short.message.count("has no counterpart") == 1 and "..." in short.message
    with pytest.raises(TypeError, match="Geometry"):
        g0.compare(data / "cad/bore_2holes.step")
    with pytest.raises(ValueError, match="max_report"):
        g0.compare(g1, max_report=-1)


def test_compare_units(data):
    mm = cadmorph.read_step(data / "freecad/bracket_0.step")
    m = cadmorph.read_step(data / "freecad/bracket_0.step", unit="m")
    c = mm.compare(m)  # 1000x apart: G and G' in different units
    assert not c and "differ in size by 1e+03x" in c.message


def test_model(data, work):
    g0, g1 = cadmorph.model("bore", 0), cadmorph.model("bore", 1.0)
    assert not os.path.exists(g0.path)  # the temporary file is gone
    assert g0.counts == g1.counts
    c = g0.compare(g1)
    assert c and not c.renumbered and np.array_equal(c.face, np.arange(g0.n_faces))
    assert g0.bbox == pytest.approx((-2, -2, 0, 2, 2, 2), abs=1e-6)
    # the same solid as the independent fixture (written by gmsh's OpenCASCADE kernel)
    ref = cadmorph.read_step(data / "models/bore_0.step")
    assert g0.compare(ref)
    kept = cadmorph.model("pipe", 0.5, path=work / "pipe.step")
    assert (work / "pipe.step").exists() and kept.path == str(work / "pipe.step")
    assert cadmorph.model_names() == ("bore", "pipe", "bracket")


@pytest.mark.parametrize("args, exc", [(("wing", 0), ValueError), (("bore", 1.5), ValueError),
                                       (("bore", float("nan")), ValueError),
                                       (("bore", "0.5"), TypeError), ((3, 0), TypeError),
                                       (("bore", True), TypeError)])
def test_model_arguments(args, exc):
    with pytest.raises(exc):
        cadmorph.model(*args)


def test_write_step(data, work):
    g = cadmorph.read_step(data / "freecad/bracket_0.step")
    g.write_step(work / "copy.step")
    back = cadmorph.read_step(work / "copy.step")
    assert back.counts == g.counts
    assert back.bbox == pytest.approx(g.bbox, abs=1e-6)
    assert g.compare(back)
    with pytest.raises(cadmorph.BadInputError):
        g.write_step(work / "missing" / "x.step")
    assert not (work / "missing").exists()


def test_the_model_outlives_the_geometry(data):
    g = cadmorph.read_step(data / "cad/bore_a.step")
    ptr = g._ptr  # what a Morpher keeps: the model lives as long as this reference
    expect = g.counts
    del g
    gc.collect()
    for _ in range(3):
        cadmorph.read_step(data / "cad/bore_2holes.step")
    counts = cadmorph._ffi.new("cm_cad_counts *")
    cadmorph._lib.cm_cad_get_counts(ptr, counts)
    assert (counts.faces, counts.edges, counts.vertices) == (expect.faces, expect.edges,
                                                             expect.vertices)


def test_no_direct_construction():
    for args in ((), (None,), (cadmorph._ffi.NULL,)):
        with pytest.raises(TypeError, match="read_step"):
            cadmorph.Geometry(*args)


def test_model_after_a_read_in_metres(data):
    # OpenCASCADE's session unit is process-wide: a model (in mm) written after a read in
    # metres must not come out 1000x too large
    cadmorph.read_step(data / "freecad/bracket_0.step", unit="m")
    assert cadmorph.model("bore", 0).bbox == pytest.approx((-2, -2, 0, 2, 2, 2), abs=1e-6)
    assert cadmorph.model("bore", 0, unit="m").bbox == pytest.approx(
        (-2e-3, -2e-3, 0, 2e-3, 2e-3, 2e-3), abs=1e-9)
