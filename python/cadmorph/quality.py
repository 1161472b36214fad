"""quality(mesh): the scaled Jacobian of every cell and its summary, as `cadmorph quality`;
quality(mesh, foam=True): OpenFOAM checkMesh's geometry checks, as `cadmorph quality --foam`."""
from dataclasses import dataclass
from typing import Tuple, Union

import numpy as np

from ._capi import ffi, lib
from ._context import Context
from ._inputs import flag, mesh_of
from .mesh import Mesh


@dataclass(frozen=True)
class Quality:
    """Verdict's scaled Jacobian of a mesh.

    Attributes:
        min_sj: the smallest over volume cells (collapsed cells count as 0).
        mean_sj: the mean over volume cells.
        p01_sj: the 1st percentile.
        inverted: volume cells with a scaled Jacobian <= 0.
        cells: number of volume cells (the CLI's `cells=`).
        per_cell: (n_cells,) float64 over every element in file order, NaN for elements of
            dimension < 3.
    """

    min_sj: float
    mean_sj: float
    p01_sj: float
    inverted: int
    cells: int
    per_cell: np.ndarray


@dataclass(frozen=True)
class FoamQuality:
    """OpenFOAM checkMesh's mesh statistics, topology and geometry checks (what checkMesh of
    OpenFOAM v1912 runs by default, cm_mesh_quality_foam), the numbers
    `cadmorph quality --foam` prints. On a mesh read
    from a polyMesh its own faces; on other meshes the faces of the volume cells.

    Attributes:
        points, faces, internal_faces, cells, patches: the mesh's counts.
        hexahedra, prisms, wedges, pyramids, tet_wedges, tetrahedra, polyhedra: cells by
            OpenFOAM's cell models (checkMesh's table).
        illegal_cells (fewer than 4 faces), unused_points_faces, unused_points_cells,
            upper_triangular_error, multiple_face_cells, bad_vertex_faces (out-of-range or
            repeated vertices), regions, empty_not_2d: the topology checks.
        bbox: (xmin, ymin, zmin, xmax, ymax, zmax).
        directions: per axis 1 (a geometric direction) or -1 (taken by empty or wedge
            patches); solution_directions: the same, taken by empty patches only.
        alignment_checked (0 none, 1 2-D edge alignment, 2 wedge checks), non_aligned_edges,
            wedge_error (0 none, 1 no opposite wedge, 3 a wedge patch not planar),
            wedge_angle (degrees), wedge_off_plane, wedge_patch (0-based, -1 if none): the
            checks of 2-D and wedge meshes.
        boundary_openness: the sum of the boundary's face area vectors over its total, per
            axis; boundary_open: it exceeds 1e-6 (a hole in the boundary).
        max_cell_openness, open_cells: the same per cell, and cells past 1e-6.
        max_aspect_ratio, high_aspect_cells (> 1000), worst_aspect_cell.
        min_face_area, max_face_area, zero_area_faces.
        min_volume, max_volume, total_volume, negative_volume_cells (volume < 1e-300).
        max_non_orthogonality, avg_non_orthogonality: degrees over internal faces;
            severe_non_orthogonal_faces (> 70), non_orthogonality_errors (> 90),
            worst_non_orthogonal_face.
        wrong_pyramids: faces whose pyramid (owner or neighbour) has a negative volume.
        max_skewness, high_skew_faces (> 4), worst_skew_face.
        coupled_faces, coupled_point_errors, coupled_avg_mismatch, uncoupled_patches: the
            match of translational cyclic pairs (rotational ones are not checked).
        failed_checks: as checkMesh counts them ("Failed N mesh checks."), 0 for "Mesh OK."
    """

    points: int
    faces: int
    internal_faces: int
    cells: int
    patches: int
    hexahedra: int
    prisms: int
    wedges: int
    pyramids: int
    tet_wedges: int
    tetrahedra: int
    polyhedra: int
    bbox: Tuple[float, float, float, float, float, float]
    directions: Tuple[int, int, int]
    solution_directions: Tuple[int, int, int]
    illegal_cells: int
    unused_points_faces: int
    unused_points_cells: int
    upper_triangular_error: bool
    multiple_face_cells: int
    bad_vertex_faces: int
    regions: int
    empty_not_2d: bool
    alignment_checked: int
    non_aligned_edges: int
    wedge_error: int
    wedge_angle: float
    wedge_off_plane: float
    wedge_patch: int
    boundary_openness: Tuple[float, float, float]
    max_cell_openness: float
    open_cells: int
    max_aspect_ratio: float
    high_aspect_cells: int
    worst_aspect_cell: int
    min_face_area: float
    max_face_area: float
    zero_area_faces: int
    min_volume: float
    max_volume: float
    total_volume: float
    negative_volume_cells: int
    max_non_orthogonality: float
    avg_non_orthogonality: float
    severe_non_orthogonal_faces: int
    non_orthogonality_errors: int
    worst_non_orthogonal_face: int
    wrong_pyramids: int
    max_skewness: float
    high_skew_faces: int
    worst_skew_face: int
    boundary_open: bool
    coupled_faces: int
    coupled_point_errors: int
    coupled_avg_mismatch: float
    uncoupled_patches: int
    failed_checks: int

    @property
    def ok(self) -> bool:
        """No check failed (checkMesh's "Mesh OK.")."""
        return self.failed_checks == 0


def _foam_quality(q) -> FoamQuality:
    """The dataclass of a cm_foam_quality, field by field."""
    values = {}
    for name, kind in FoamQuality.__annotations__.items():
        v = getattr(q, name)
        if kind is int:
            values[name] = int(v)
        elif kind is float:
            values[name] = float(v)
        elif kind is bool:
            values[name] = bool(v)
        else:  # a fixed array of the struct
            values[name] = tuple(type(x)(x) for x in v)
    return FoamQuality(**values)


def quality(mesh: Mesh, threads: int = 0, *,
            foam: bool = False) -> Union[Quality, FoamQuality]:
    """The scaled Jacobian of every cell of mesh and the summary that `cadmorph quality`
    prints on its last line (cm_mesh_quality, cm_quality_summarize): a Quality.

    foam=True: OpenFOAM checkMesh's geometry checks instead (cm_mesh_quality_foam), the
    numbers `cadmorph quality --foam` prints: a FoamQuality. Raises ValueError for a mesh
    without volume cells.
    """
    m = mesh_of("cadmorph.quality", "mesh", mesh)._ptr
    foam = flag("cadmorph.quality", "foam", foam)
    ctx = Context(threads, False, "cadmorph.quality")
    if foam:
        if lib.cm_mesh_count_dim(m, 3) == 0:  # as the CLI checks it
            raise ValueError("cadmorph.quality: foam=True needs volume cells (tet, hex, wedge, "
                             "pyramid, polyhedron); the mesh has none")
        q = ffi.new("cm_foam_quality *")
        ctx.call(lib.cm_mesh_quality_foam, m, q)
        return _foam_quality(q)
    sj = np.empty(max(int(m.n_cells), 1), np.float64)
    buf = ffi.from_buffer("double[]", sj)
    ctx.call(lib.cm_mesh_quality, m, buf)
    all_ = ffi.new("cm_quality_stats *")
    ctx.call(lib.cm_quality_summarize, m, buf, ffi.NULL, all_)
    return Quality(min_sj=float(all_.min), mean_sj=float(all_.mean), p01_sj=float(all_.p01),
                   inverted=int(all_.inverted), cells=int(all_.count),
                   per_cell=sj[:int(m.n_cells)])
