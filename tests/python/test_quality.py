"""cadmorph.quality against the last line of `cadmorph quality`."""
import subprocess

import numpy as np
import pytest

import cadmorph


def cli_summary(cli, path):
    r = subprocess.run([cli, "quality", str(path)], capture_output=True, text=True, check=True)
    last = r.stdout.strip().splitlines()[-1]
    return dict(kv.split("=") for kv in last.split())


@pytest.mark.parametrize("name", ["msh/box_hole_41.msh", "vtk/meshio_ascii.vtu",
                                  "msh/hybrid_o2_41.msh", "quality/mixed.vtu",
                                  "vtk/vtk_legacy_ascii.vtk"])
def test_quality_equals_cli(cli, data, name):
    q = cadmorph.quality(cadmorph.read_mesh(data / name))
    line = cli_summary(cli, data / name)
    assert "%.6g" % q.min_sj == line["min_scaled_jacobian"]
    assert "%.6g" % q.mean_sj == line["mean_scaled_jacobian"]
    assert q.inverted == int(line["inverted"])
    assert q.cells == int(line["cells"])


def test_per_cell(data):
    mesh = cadmorph.read_mesh(data / "vtk/meshio_ascii.vtu")
    q = cadmorph.quality(mesh)
    assert q.per_cell.shape == (mesh.n_cells,) and q.per_cell.dtype == np.float64
    dims3 = [t in ("hex8", "pyramid5", "wedge6", "tet4") for t in mesh.cell_types]
    assert np.all(np.isnan(q.per_cell[~np.array(dims3)]))
    assert q.min_sj == np.nanmin(q.per_cell)
    assert q.inverted == int(np.sum(q.per_cell <= 0))


def test_quality_sees_moved_points(data):
    mesh = cadmorph.read_mesh(data / "msh/box_hole_41.msh")
    before = cadmorph.quality(mesh)
    mesh.points[:, 0] *= 3.0  # through the view: the library sees the stretch
    after = cadmorph.quality(mesh)
    assert after.min_sj != before.min_sj


def test_quality_rejects_non_mesh():
    with pytest.raises(TypeError, match="cadmorph.Mesh"):
        cadmorph.quality(np.zeros((4, 3)))


def foam_text(q):
    """`cadmorph quality --foam`'s checkMesh block, printed from a FoamQuality in the CLI's
    layout and precision (C's %g is Python's %g)."""
    def vec(v):
        return "(%g %g %g)" % tuple(v)
    fpc = (2 * q.internal_faces + (q.faces - q.internal_faces)) / q.cells if q.cells else 0.0
    out = ["Mesh stats",
           "    points:           %d" % q.points,
           "    faces:            %d" % q.faces,
           "    internal faces:   %d" % q.internal_faces,
           "    cells:            %d" % q.cells,
           "    faces per cell:   %g" % fpc,
           "    boundary patches: %d" % q.patches, "",
           "Overall number of cells of each type:",
           "    hexahedra:     %d" % q.hexahedra,
           "    prisms:        %d" % q.prisms,
           "    wedges:        %d" % q.wedges,
           "    pyramids:      %d" % q.pyramids,
           "    tet wedges:    %d" % q.tet_wedges,
           "    tetrahedra:    %d" % q.tetrahedra,
           "    polyhedra:     %d" % q.polyhedra, "", "Checking topology...",
           "    Boundary definition OK."]
    # the meshes below are 3-D meshes with valid addressing
    assert not q.empty_not_2d and not q.illegal_cells and not q.upper_triangular_error
    assert not q.multiple_face_cells and not q.bad_vertex_faces
    out.append("    Cell to face addressing OK.")
    if q.unused_points_faces:
        out.append(" ***Unused points found in the mesh, number unused by faces: %d number unused "
                   "by cells: %d" % (q.unused_points_faces, q.unused_points_cells))
    else:
        out.append("    Point usage OK.")
    out += ["    Upper triangular ordering OK.", "    Face vertices OK."]
    if q.regions <= 1:
        out += ["    Number of regions: %d (OK)." % q.regions, ""]
    else:
        out += ["   *Number of regions: %d" % q.regions,
                "    The mesh has multiple regions which are not connected by any face.", ""]
    geo = tuple(int(d == 1) for d in q.directions)
    sol = tuple(int(d == 1) for d in q.solution_directions)
    out += ["Checking geometry...",
            "    Overall domain bounding box %s %s" % (vec(q.bbox[:3]), vec(q.bbox[3:])),
            "    Mesh has %d geometric (non-empty/wedge) directions (%d %d %d)"
            % ((sum(geo),) + geo),
            "    Mesh has %d solution (non-empty) directions (%d %d %d)" % ((sum(sol),) + sol)]
    if q.boundary_open:
        out.append(" ***Boundary openness %s possible hole in boundary description."
                   % vec(q.boundary_openness))
    else:
        out.append("    Boundary openness %s OK." % vec(q.boundary_openness))
    if q.open_cells:
        out.append(" ***Open cells found, max cell openness: %g, number of open cells %d"
                   % (q.max_cell_openness, q.open_cells))
    elif q.high_aspect_cells:
        out.append(" ***High aspect ratio cells found, Max aspect ratio: %g, number of cells %d"
                   % (q.max_aspect_ratio, q.high_aspect_cells))
    else:
        out += ["    Max cell openness = %g OK." % q.max_cell_openness,
                "    Max aspect ratio = %g OK." % q.max_aspect_ratio]
    if q.min_face_area < 1e-300:
        out.append(" ***Zero or negative face area detected.  Minimum area: %g" % q.min_face_area)
    else:
        out.append("    Minimum face area = %g. Maximum face area = %g.  Face area magnitudes OK."
                   % (q.min_face_area, q.max_face_area))
    if q.min_volume < 1e-300:
        out.append(" ***Zero or negative cell volume detected.  Minimum negative volume: %g, "
                   "Number of negative volume cells: %d" % (q.min_volume, q.negative_volume_cells))
    else:
        out.append("    Min volume = %g. Max volume = %g.  Total volume = %g.  Cell volumes OK."
                   % (q.min_volume, q.max_volume, q.total_volume))
    if q.internal_faces:
        out.append("    Mesh non-orthogonality Max: %g average: %g"
                   % (q.max_non_orthogonality, q.avg_non_orthogonality))
    if q.severe_non_orthogonal_faces:
        out.append("   *Number of severely non-orthogonal (> 70 degrees) faces: %d."
                   % q.severe_non_orthogonal_faces)
    if q.non_orthogonality_errors:
        out.append(" ***Number of non-orthogonality errors: %d." % q.non_orthogonality_errors)
    else:
        out.append("    Non-orthogonality check OK.")
    if q.wrong_pyramids:
        out.append(" ***Error in face pyramids: %d faces are incorrectly oriented."
                   % q.wrong_pyramids)
    else:
        out.append("    Face pyramids OK.")
    if q.high_skew_faces:
        out.append(" ***Max skewness = %g, %d highly skew faces detected which may impair the "
                   "quality of the results" % (q.max_skewness, q.high_skew_faces))
    else:
        out.append("    Max skewness = %g OK." % q.max_skewness)
    assert not q.coupled_point_errors
    out.append("    Coupled point location match (average %g) OK." % q.coupled_avg_mismatch)
    out += ["", "Failed %d mesh checks." % q.failed_checks if q.failed_checks else "Mesh OK.", "",
            "max_aspect_ratio=%.9g max_non_orthogonality=%.9g avg_non_orthogonality=%.9g "
            "max_skewness=%.9g wrong_pyramids=%d negative_volumes=%d failed_checks=%d cells=%d"
            % (q.max_aspect_ratio, q.max_non_orthogonality, q.avg_non_orthogonality,
               q.max_skewness, q.wrong_pyramids, q.negative_volume_cells, q.failed_checks,
               q.cells)]
    return "\n".join(out)


# a clean tet mesh, a mixed mesh, a mesh with prisms and boundary faces, and one with a
# polyhedron, inverted cells and an open boundary (every branch of the failed checks)
@pytest.mark.parametrize("name", ["msh/box_hole_41.msh", "quality/mixed.vtu",
                                  "vtk/gmsh_blocks.msh", "vtk/vtk_ascii.vtu"])
def test_foam_equals_cli(cli, data, name):
    q = cadmorph.quality(cadmorph.read_mesh(data / name), foam=True)
    assert isinstance(q, cadmorph.FoamQuality)
    r = subprocess.run([cli, "quality", "--foam", str(data / name)], capture_output=True,
                       text=True, check=True)
    expect = foam_text(q)
    assert r.stdout.startswith(expect + "\n"), (r.stdout, expect)
    assert q.ok == (q.failed_checks == 0)


def test_foam_values(data):
    q = cadmorph.quality(cadmorph.read_mesh(data / "quality/mixed.vtu"), foam=True)
    # a unit hex, a pyramid and a unit-high prism on an equilateral triangle of side 1
    # (volume sqrt(3)/4)
    assert (q.hexahedra, q.prisms, q.pyramids, q.tetrahedra, q.cells) == (1, 1, 1, 0, 3)
    assert q.total_volume == pytest.approx(q.max_volume + q.min_volume + 0.4330127, rel=1e-6)
    assert q.ok and not q.boundary_open
    bad = cadmorph.quality(cadmorph.read_mesh(data / "vtk/vtk_ascii.vtu"), foam=True)
    assert not bad.ok and bad.negative_volume_cells == 2 and bad.wrong_pyramids == 9


def test_quality_keeps_its_form(data):
    mesh = cadmorph.read_mesh(data / "msh/box_hole_41.msh")
    assert isinstance(cadmorph.quality(mesh), cadmorph.Quality)
    assert cadmorph.quality(mesh, 1).min_sj == cadmorph.quality(mesh).min_sj  # threads
    with pytest.raises(TypeError, match="foam"):
        cadmorph.quality(mesh, foam="yes")


def test_foam_needs_volume_cells(cli, work):
    tri = cadmorph.Mesh.from_arrays(np.eye(3), [("triangle", [[0, 1, 2]])])
    with pytest.raises(ValueError, match="volume cells"):
        cadmorph.quality(tri, foam=True)
    cadmorph.write_mesh(work / "tri.vtu", tri)
    r = subprocess.run([cli, "quality", "--foam", str(work / "tri.vtu")], capture_output=True,
                       text=True)
    assert r.returncode == 2 and "no volume cells" in r.stderr


def test_foam_quality_message_names_itself():
    """The library's own refusal (the package refuses first) names cm_mesh_quality_foam, not
    the polyMesh writer whose face addressing it shares."""
    from cadmorph._capi import ffi, lib
    from cadmorph._context import Context
    tri = cadmorph.Mesh.from_arrays(np.eye(3), [("triangle", [[0, 1, 2]])])
    q = ffi.new("cm_foam_quality *")
    with pytest.raises(cadmorph.Error, match=r"^cm_mesh_quality_foam: an OpenFOAM polyMesh "
                                             r"needs volume cells"):
        Context(1, False).call(lib.cm_mesh_quality_foam, tri._ptr, q)
