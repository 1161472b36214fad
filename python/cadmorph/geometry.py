"""Geometry: a STEP model held by libcadmorph (a cm_cad_model), its topology and the
correspondence of G and G'; read_step and the built-in parametric models.

Faces, edges and vertices are numbered from 0 in OpenCASCADE's order, the order cadmorph uses
everywhere (`cadmorph info`). Lengths are in the unit the model was read in (millimetre by
default). The topology is read from the library at each access, never cached, so that it stays
true when another part of the package renumbers a G' in place (cm_cad_match).
"""
import math
import os
import tempfile
from dataclasses import dataclass
from typing import Optional, Tuple

import numpy as np

from ._capi import ffi, lib
from ._context import Context
from ._inputs import integer, model_of, number, path_bytes, text
from .errors import Error, MismatchError
from .mesh import PathLike

_TOKEN = object()  # Geometry objects are made here only


def _text(p) -> str:
    return ffi.string(p).decode("utf-8", "replace") if p != ffi.NULL else ""


@dataclass(frozen=True)
class Counts:
    """The topology's entity counts (cm_cad_counts), as `cadmorph info` prints them."""

    solids: int
    shells: int
    faces: int
    wires: int
    edges: int
    vertices: int


@dataclass(frozen=True)
class Face:
    """One face of a Geometry (cm_cad_face_info and its wires).

    Attributes:
        index: the face's number (0-based, OpenCASCADE's order).
        type: the surface type: "plane", "cylinder", "cone", "sphere", "torus", "bezier",
            "bspline", "revolution", "extrusion", "offset" or "other".
        uv_range: (umin, umax, vmin, vmax) of the trimmed face.
        periodic: (u periodic, v periodic).
        period: the periods in u and v (0 if not periodic).
        reversed: the face's orientation is opposite to its surface's normal.
        n_wires: number of wires; wire 0 is the outer one.
        area: the face's area.
        bbox: (xmin, ymin, zmin, xmax, ymax, zmax).
        wires: each wire's edges in the wire's order (a seam edge appears twice).
        wire_reversed: for each entry of `wires`, True where the edge runs against its own
            direction in this face.
    """

    index: int
    type: str
    uv_range: Tuple[float, float, float, float]
    periodic: Tuple[bool, bool]
    period: Tuple[float, float]
    reversed: bool
    n_wires: int
    area: float
    bbox: Tuple[float, float, float, float, float, float]
    wires: Tuple[Tuple[int, ...], ...]
    wire_reversed: Tuple[Tuple[bool, ...], ...]


@dataclass(frozen=True)
class Edge:
    """One edge of a Geometry (cm_cad_edge_info and its faces).

    Attributes:
        index: the edge's number (0-based, OpenCASCADE's order).
        type: the curve type: "line", "circle", "ellipse", "hyperbola", "parabola", "bezier",
            "bspline", "offset" or "other" ("other" for a degenerate edge).
        t_range: the curve parameter's range (first, last).
        vertices: (first vertex, last vertex), -1 where there is none.
        degenerate: a collapsed edge (at a sphere's pole, say), without a 3D curve.
        closed: its first vertex is its last.
        length: the edge's length.
        bbox: (xmin, ymin, zmin, xmax, ymax, zmax).
        flipped: in a G' renumbered by the correspondence, the edge runs against its
            counterpart in G (cm_cad_edge_info.flipped); False otherwise.
        faces: the faces the edge bounds (1 for a free or seam edge, 2 for a manifold one).
    """

    index: int
    type: str
    t_range: Tuple[float, float]
    vertices: Tuple[int, int]
    degenerate: bool
    closed: bool
    length: float
    bbox: Tuple[float, float, float, float, float, float]
    flipped: bool
    faces: Tuple[int, ...]


@dataclass(frozen=True, eq=False)
class Comparison:
    """Whether G' corresponds to G (Geometry.compare), and how.

    `bool(comparison)` is `corresponds`. The arrays are indexed by G's entities and hold the
    index of the counterpart in G'; they are None when the models do not correspond.

    Attributes:
        corresponds: the same solids, shells, faces, wires, edges, vertices and incidences in
            some numbering (surface and curve types may change).
        message: the library's words: when they do not correspond, the differences (up to
            max_report of them) and the counts that differ; "" (or a warning, such as file
            units that differ) when they do.
        renumbered: G' numbers faces, edges, vertices or wire starts otherwise, or has edges
            that run the other way.
        face, face_reversed, edge, edge_flipped, vertex: (n,) int32 arrays of the
            correspondence (reversed: the counterpart's surface normal runs against the face;
            flipped: the counterpart edge runs the other way).
        wires_restarted: wires of G whose counterpart is another wire or starts elsewhere.
        face_type_changes, edge_type_changes: faces and edges whose surface or curve type
            differs.
    """

    corresponds: bool
    message: str
    renumbered: bool
    face: Optional[np.ndarray]
    face_reversed: Optional[np.ndarray]
    edge: Optional[np.ndarray]
    edge_flipped: Optional[np.ndarray]
    vertex: Optional[np.ndarray]
    wires_restarted: int
    face_type_changes: int
    edge_type_changes: int

    def __bool__(self) -> bool:
        """corresponds."""
        return self.corresponds


def _ints(ptr, n: int) -> np.ndarray:
    """A copy of n ints of the library's memory as int32."""
    if n == 0:
        return np.zeros(0, np.int32)
    return np.frombuffer(ffi.buffer(ptr, n * ffi.sizeof("int")), np.intc).astype(np.int32)


class Geometry:
    """A STEP model held by libcadmorph (a cm_cad_model), as read by read_step or model.

    The topology (faces, edges, vertices, counts) and the bounding box are those that
    `cadmorph info` prints. The model lives as long as this object (and whatever else holds
    its `_ptr`).
    """

    def __init__(self, _owner=None, _token=None) -> None:
        """Not for users: a Geometry comes from read_step or model (a TypeError otherwise)."""
        if _token is not _TOKEN or ffi.typeof(_owner) is not ffi.typeof("cm_cad_model *") \
                or _owner == ffi.NULL:
            raise TypeError("cadmorph.Geometry: made by cadmorph.read_step or cadmorph.model, "
                            "not directly")
        self._ptr = _owner  # ffi.gc: cm_cad_destroy once nothing holds it

    @property
    def path(self) -> str:
        """The path the model was read from."""
        return _text(lib.cm_cad_path(self._ptr))

    @property
    def unit(self) -> str:
        """The length unit of the coordinates ("mm", "m", "in", ...)."""
        return _text(lib.cm_cad_unit(self._ptr))

    @property
    def file_unit(self) -> str:
        """The length unit the file names ("millimetre", "inch", ...; "" if none)."""
        return _text(lib.cm_cad_file_unit(self._ptr))

    @property
    def counts(self) -> Counts:
        """Solids, shells, faces, wires, edges and vertices."""
        c = ffi.new("cm_cad_counts *")
        lib.cm_cad_get_counts(self._ptr, c)
        return Counts(c.solids, c.shells, c.faces, c.wires, c.edges, c.vertices)

    @property
    def n_faces(self) -> int:
        """Number of faces."""
        return self.counts.faces

    @property
    def n_edges(self) -> int:
        """Number of edges."""
        return self.counts.edges

    @property
    def n_vertices(self) -> int:
        """Number of vertices."""
        return self.counts.vertices

    @property
    def bbox(self) -> Tuple[float, float, float, float, float, float]:
        """The model's bounding box (xmin, ymin, zmin, xmax, ymax, zmax)."""
        b = ffi.new("double[6]")
        lib.cm_cad_bbox(self._ptr, b)
        return tuple(float(x) for x in b)

    @property
    def diagonal(self) -> float:
        """The length of the bounding box's diagonal (the model's size, which the library's
        relative tolerances scale with)."""
        b = self.bbox
        return math.sqrt(sum((b[k + 3] - b[k]) ** 2 for k in range(3)))

    @property
    def faces(self) -> Tuple[Face, ...]:
        """Every face, by index."""
        ctx = Context(0, False, "cadmorph.Geometry.faces")
        info = ffi.new("cm_cad_face_info *")
        edges, rev, n = ffi.new("int *[1]"), ffi.new("int *[1]"), ffi.new("int *")
        out = []
        for f in range(self.counts.faces):
            ctx.call(lib.cm_cad_face_get_info, self._ptr, f, info)
            wires, wrev = [], []
            for w in range(info.n_wires):
                ctx.call(lib.cm_cad_face_wire, self._ptr, f, w, edges, rev, n)
                wires.append(tuple(int(e) for e in _ints(edges[0], n[0])))
                wrev.append(tuple(bool(r) for r in _ints(rev[0], n[0])))
            out.append(Face(
                index=f, type=_text(lib.cm_cad_surface_type_name(info.type)),
                uv_range=tuple(float(x) for x in info.uv_range),
                periodic=(bool(info.periodic[0]), bool(info.periodic[1])),
                period=(float(info.period[0]), float(info.period[1])),
                reversed=bool(info.reversed), n_wires=int(info.n_wires),
                area=float(info.area), bbox=tuple(float(x) for x in info.bbox),
                wires=tuple(wires), wire_reversed=tuple(wrev)))
        return tuple(out)

    @property
    def edges(self) -> Tuple[Edge, ...]:
        """Every edge, by index."""
        ctx = Context(0, False, "cadmorph.Geometry.edges")
        info = ffi.new("cm_cad_edge_info *")
        faces, n = ffi.new("int *[1]"), ffi.new("int *")
        out = []
        for e in range(self.counts.edges):
            ctx.call(lib.cm_cad_edge_get_info, self._ptr, e, info)
            ctx.call(lib.cm_cad_edge_faces, self._ptr, e, faces, n)
            out.append(Edge(
                index=e, type=_text(lib.cm_cad_curve_type_name(info.type)),
                t_range=(float(info.t_range[0]), float(info.t_range[1])),
                vertices=(int(info.vertex[0]), int(info.vertex[1])),
                degenerate=bool(info.degenerate), closed=bool(info.closed),
                length=float(info.length), bbox=tuple(float(x) for x in info.bbox),
                flipped=bool(info.flipped),
                faces=tuple(int(x) for x in _ints(faces[0], n[0]))))
        return tuple(out)

    @property
    def vertices(self) -> np.ndarray:
        """The vertices' points: (n_vertices, 3) float64 (a copy)."""
        nv = self.counts.vertices
        out = np.empty((nv, 3), np.float64)
        ctx = Context(0, False, "cadmorph.Geometry.vertices")
        for v in range(nv):
            ctx.call(lib.cm_cad_vertex_point, self._ptr, v, ffi.from_buffer("double[]", out[v]))
        return out

    def compare(self, other: "Geometry", max_report: int = 5, threads: int = 0) -> Comparison:
        """Whether other (G') corresponds to this model (G): the same topology as a graph in
        any numbering (cm_cad_correspond; neither model changes), as
        `cadmorph info G --compare G'` decides.

        Returns a Comparison; models that do not correspond (or differ in size by 100x or
        more: units) give corresponds=False and the library's message naming up to
        max_report differences, never an exception. Raises TypeError when other is not a
        Geometry, cadmorph.Error for anything else the library reports.
        """
        model_of("cadmorph.Geometry.compare", "other", other)
        max_report = integer("cadmorph.Geometry.compare", "max_report", max_report, 0,
                             1_000_000)
        ctx = Context(threads, False, "cadmorph.Geometry.compare")
        out = ffi.new("cm_cad_correspondence *[1]")
        try:
            ctx.call(lib.cm_cad_correspond, self._ptr, other._ptr, int(max_report), out)
        except MismatchError as e:
            return Comparison(corresponds=False, message=e.message, renumbered=False, face=None,
                              face_reversed=None, edge=None, edge_flipped=None, vertex=None,
                              wires_restarted=0, face_type_changes=0, edge_type_changes=0)
        c = out[0]
        try:
            k = c.counts
            return Comparison(
                corresponds=True, message=ctx.message(), renumbered=bool(c.renumbered),
                face=_ints(c.face, k.faces), face_reversed=_ints(c.face_reversed, k.faces),
                edge=_ints(c.edge, k.edges), edge_flipped=_ints(c.edge_flipped, k.edges),
                vertex=_ints(c.vertex, k.vertices), wires_restarted=int(c.wires_restarted),
                face_type_changes=int(c.face_type_changes),
                edge_type_changes=int(c.edge_type_changes))
        finally:
            lib.cm_cad_correspondence_destroy(out)

    def write_step(self, path: PathLike, threads: int = 0) -> None:
        """Writes the model as STEP (AP214) in its unit (cm_cad_write), through a temporary
        file renamed at the end. Raises BadInputError when path cannot be written."""
        p = path_bytes("cadmorph.Geometry.write_step", "path", path)
        Context(threads, False, "cadmorph.Geometry.write_step").call(lib.cm_cad_write,
                                                                     self._ptr, p)

    def __repr__(self) -> str:
        c = self.counts
        return "<cadmorph.Geometry %s: %d faces, %d edges, %d vertices (%s)>" % (
            self.path or "?", c.faces, c.edges, c.vertices, self.unit)


def read_step(path: PathLike, unit: str = "mm", threads: int = 0) -> Geometry:
    """Reads a STEP file (every root, as one compound) into a Geometry whose coordinates are
    in `unit`: "mm" (default), "cm", "m", "km", "in", "ft", "mi" or "um"; the file's own unit
    is converted (as `cadmorph info --cad-unit`).

    Raises ValueError for an unknown unit (the library's message lists the known ones),
    BadInputError for a file that is missing, unreadable, not STEP or without a face.
    """
    what = "cadmorph.read_step"
    p = path_bytes(what, "path", path)
    u = text(what, "unit", unit, empty=True)
    opt = ffi.new("cm_cad_read_options *")
    lib.cm_cad_read_options_init(opt)
    keep = ffi.new("char[]", u)
    opt.unit = keep
    ctx = Context(threads, False, what)
    try:
        return Geometry(ctx.create(lib.cm_cad_read, "cm_cad_model", lib.cm_cad_destroy, p, opt),
                        _TOKEN)
    except Error as e:
        if e.status == lib.CM_ERR_ARGUMENT:  # the unit: a wrong argument, not bad input
            raise ValueError(e.message) from None
        raise


def model_names() -> Tuple[str, ...]:
    """The built-in parametric models ("bore", "pipe", "bracket"), as `cadmorph demo` and
    `cadmorph sweep` know them."""
    return tuple(s.strip() for s in _text(lib.cm_model_list()).split(","))


def model(name: str, t: float, path: Optional[PathLike] = None, unit: str = "mm",
          threads: int = 0) -> Geometry:
    """The built-in parametric model `name` at t in [0, 1] (cm_model_write_step): every t
    gives the same topology in the same order, so model(name, 0) and model(name, 1) are a
    G and G' that correspond.

    The model is written as STEP (in mm) to path, or to a temporary file removed after
    reading when path is None, and read back in `unit` (as read_step). Raises ValueError for
    an unknown name or a t outside [0, 1].
    """
    what = "cadmorph.model"
    if not lib.cm_model_known(text(what, "name", name, empty=True)):
        raise ValueError("%s: unknown model %r (known: %s)"
                         % (what, name, _text(lib.cm_model_list())))
    t = number(what, "t", t, 0.0, 1.0)
    text(what, "unit", unit, empty=True)
    ctx = Context(threads, False, what)
    if path is not None:
        p = path_bytes(what, "path", path)
        ctx.call(lib.cm_model_write_step, name.encode(), t, p)
        return read_step(path, unit, threads)
    with tempfile.TemporaryDirectory(prefix="cadmorph_model_") as d:
        tmp = os.path.join(d, "%s_t%g.step" % (name, t))
        ctx.call(lib.cm_model_write_step, name.encode(), t, os.fsencode(tmp))
        return read_step(tmp, unit, threads)
