"""Meshes from NumPy arrays and to and from meshio (Mesh.from_arrays, from_meshio, to_meshio):
the checks that keep bad arrays away from the library, the cell type names (cadmorph's and
meshio's) and meshio's node order.

Node order. cadmorph keeps VTK's order for every type (mesh.h). meshio's convention is VTK's
too except for the linear wedge, which meshio keeps in gmsh's orientation (the triangle 0 1 2
wound towards 3 4 5: nodes 1 and 2, 4 and 5 swapped); its VTK reader and writer swap them, and
so do from_meshio and to_meshio. meshio's gmsh reader is not consistent with that for the
second-order wedges: its wedge15 comes mirrored (gmsh's orientation, VTK's numbering) and its
wedge18 and pyramid14 in gmsh's own order, whereas its VTK reader gives all three in VTK's
order; from_meshio follows meshio's VTK convention, so read such .msh files with
cadmorph.read_mesh, which permutes them itself.

Groups. A cm_mesh holds one physical and one entity tag per element and named groups
(dim, tag, name), as gmsh does; meshio holds them the same way for gmsh files: the cell data
"gmsh:physical" and "gmsh:geometrical" and field_data {name: [tag, dim]}. That is the form
used both ways (the library's .vtu reader and writer use the same two names). meshio's
cell_sets are read when there is no "gmsh:physical" (each set a group, tags 1, 2, ... in the
sets' order; a cell in two sets cannot be represented and raises ValueError); to_meshio does
not write them.
"""
from typing import Any, Dict, List, Optional, Tuple

import numpy as np

from ._capi import ffi, lib
from ._inputs import asarray, index_array, integer, text

CELL_NAMES = [ffi.string(lib.cm_cell_type_info(t).name).decode()
              for t in range(lib.CM_CELL_TYPE_COUNT)]
CELL_NODES = [lib.cm_cell_type_info(t).nodes for t in range(lib.CM_CELL_TYPE_COUNT)]
_CELL_DIMS = [lib.cm_cell_type_info(t).dim for t in range(lib.CM_CELL_TYPE_COUNT)]
_TYPE = {name: t for t, name in enumerate(CELL_NAMES)}

# meshio's name of each cadmorph type
MESHIO_NAME = {
    "point": "vertex", "line2": "line", "line3": "line3", "tri3": "triangle",
    "tri6": "triangle6", "quad4": "quad", "quad8": "quad8", "quad9": "quad9", "tet4": "tetra",
    "tet10": "tetra10", "hex8": "hexahedron", "hex20": "hexahedron20",
    "hex27": "hexahedron27", "wedge6": "wedge", "wedge15": "wedge15", "wedge18": "wedge18",
    "pyramid5": "pyramid", "pyramid13": "pyramid13", "pyramid14": "pyramid14",
    "polygon": "polygon", "polyhedron": "polyhedron",
}
_FROM_MESHIO = {v: k for k, v in MESHIO_NAME.items()}
# cadmorph's cell = meshio's cell[order] and meshio's = cadmorph's[order] (a swap: its own
# inverse)
MESHIO_ORDER = {"wedge6": np.array([0, 2, 1, 3, 5, 4])}

TAGS = ("gmsh:physical", "gmsh:geometrical")
_I32 = np.iinfo(np.int32)


def _poly_stream(stream: np.ndarray, n_nodes: int, what: str) -> None:
    """A polyhedron's face stream (nf, n0, nodes of face 0, ...) checked as the library
    checks it: 4 faces or more, 3 nodes or more each, in range, nothing after them."""
    s = stream.tolist()
    if not s or s[0] < 4:
        raise ValueError("%s: a polyhedron needs at least 4 faces (stream %s)"
                         % (what, s[:8]))
    at = 1
    for f in range(s[0]):
        if at >= len(s) or s[at] < 3 or at + 1 + s[at] > len(s):
            raise ValueError("%s: face %d of the face stream is inconsistent" % (what, f))
        for v in s[at + 1:at + 1 + s[at]]:
            if not 0 <= v < n_nodes:
                raise ValueError("%s: node index %d out of range [0, %d)" % (what, v, n_nodes))
        at += 1 + s[at]
    if at != len(s):
        raise ValueError("%s: %d entries after the last face" % (what, len(s) - at))


class Block:
    """One block of cells checked: its cadmorph type and either a (k, nodes) int64 array or
    a list of k 1-D int64 arrays (polygons, polyhedron face streams)."""

    def __init__(self, type_: int, data, count: int) -> None:
        self.type = type_
        self.data = data
        self.count = count


def _block_items(cells: Any, what: str) -> List[Tuple[Any, Any]]:
    if isinstance(cells, dict):
        cells = list(cells.items())
    if isinstance(cells, (str, bytes)) or not isinstance(cells, (list, tuple)):
        raise TypeError("%s: cells must be a list of (type name, array) pairs, not %s"
                        % (what, type(cells).__name__))
    items = []
    for i, c in enumerate(cells):
        if hasattr(c, "type") and hasattr(c, "data"):  # a meshio CellBlock
            items.append((c.type, c.data))
        elif isinstance(c, (tuple, list)) and len(c) == 2:
            items.append((c[0], c[1]))
        else:
            raise TypeError("%s: cells[%d] must be a (type name, array) pair" % (what, i))
    return items


def cell_blocks(cells: Any, n_nodes: int, what: str) -> List[Block]:
    """The cells checked and in cadmorph's order: every name known, every array of the right
    shape and integer dtype, every node index in [0, n_nodes)."""
    blocks = []
    for i, (name, data) in enumerate(_block_items(cells, what)):
        if not isinstance(name, str):
            raise TypeError("%s: cells[%d]: the type name must be a str, not %s"
                            % (what, i, type(name).__name__))
        block = "cells block %d (%s)" % (i, name)
        where = "%s: %s" % (what, block)
        meshio_poly = name.startswith("polyhedron") and name[10:].isdigit()
        if name in _TYPE:
            t, order = _TYPE[name], None
        elif name in _FROM_MESHIO:
            t = _TYPE[_FROM_MESHIO[name]]
            order = MESHIO_ORDER.get(_FROM_MESHIO[name])
        elif meshio_poly:
            t, order = lib.CM_CELL_POLYHEDRON, None
        else:
            raise ValueError("%s: unknown cell type %r (cadmorph's: %s; meshio's: %s)"
                             % (what, name, ", ".join(CELL_NAMES),
                                ", ".join(sorted(_FROM_MESHIO))))
        nodes = CELL_NODES[t]
        if nodes > 0:
            a = index_array(what, block, data, n_nodes, ndim=None)
            if a.size == 0:
                blocks.append(Block(t, np.zeros((0, nodes), np.int64), 0))
                continue
            if a.ndim != 2 or a.shape[1] != nodes:
                raise ValueError("%s: shape (k, %d) expected, not %s" % (where, nodes, a.shape))
            if order is not None:
                a = a[:, order]
            blocks.append(Block(t, np.ascontiguousarray(a), len(a)))
        elif t == lib.CM_CELL_POLYGON:
            rows = _ragged(data, where)
            out = []
            for r, row in enumerate(rows):
                a = index_array(what, "%s row %d" % (block, r), row, n_nodes, ndim=None)
                if a.ndim != 1 or len(a) < 3:
                    raise ValueError("%s row %d: a polygon is 3 node indices or more, not "
                                     "shape %s" % (where, r, a.shape))
                out.append(a)
            blocks.append(Block(t, out, len(out)))
        else:
            out = []
            for r, cell in enumerate(_ragged(data, where)):
                row_name = "%s row %d" % (block, r)
                w = "%s: %s" % (what, row_name)
                if meshio_poly or (name == "polyhedron" and _is_face_list(cell)):
                    faces = [index_array(what, row_name, f, ndim=None) for f in cell]
                    if any(f.ndim != 1 for f in faces):
                        raise ValueError("%s: each face must be a 1-D list of node indices" % w)
                    stream = np.concatenate([[len(faces)]] + [
                        np.concatenate(([len(f)], f)) for f in faces]).astype(np.int64) \
                        if faces else np.zeros(1, np.int64)
                else:
                    stream = index_array(what, row_name, cell, ndim=None)
                    if stream.ndim != 1:
                        raise ValueError("%s: a polyhedron's face stream is 1-D, not shape %s"
                                         % (w, stream.shape))
                _poly_stream(stream, n_nodes, w)
                out.append(stream)
            blocks.append(Block(t, out, len(out)))
    return blocks


def _is_face_list(cell: Any) -> bool:
    """meshio's form of one polyhedron: a list of faces (each a sequence), not a stream."""
    return isinstance(cell, (list, tuple)) and len(cell) > 0 and np.ndim(cell[0]) == 1


def _ragged(data: Any, what: str) -> list:
    """The rows of a 2-D array or the items of a list (cells of varying size)."""
    if isinstance(data, np.ndarray):
        if data.ndim == 2:
            return list(data)
        if data.dtype == object and data.ndim == 1:
            return list(data)
        raise ValueError("%s: a (k, n) array or a list of cells, not shape %s"
                         % (what, data.shape))
    if isinstance(data, (list, tuple)):
        return list(data)
    raise TypeError("%s: a (k, n) array or a list of cells, not %s" % (what, type(data).__name__))


def field_array(name: str, value: Any, count: int, blocks: Optional[List[Block]],
                what: str) -> np.ndarray:
    """A field as (count, components) float64: from (count,), (count, c) or (count, a, b, ...)
    real numbers (trailing axes flattened) or, for cell data (blocks given), a list with one
    array per block as meshio keeps it."""
    where = "%s: field %r" % (what, name)
    if blocks is not None and isinstance(value, (list, tuple)) and len(value) == len(blocks) \
            and all(np.ndim(v) >= 1 for v in value):
        parts = [asarray(what, "field %r" % name, v) for v in value]
        if all(len(p) == b.count for p, b in zip(parts, blocks)):
            shapes = {p.shape[1:] for p in parts if len(p)}
            if len(shapes) > 1:
                raise ValueError("%s: the blocks' arrays differ in shape (%s)"
                                 % (where, sorted(shapes)))
            for p in parts:
                if p.dtype.kind not in "fiub":
                    raise TypeError("%s: real numbers, not dtype %s" % (where, p.dtype))
            value = np.concatenate(parts) if parts else np.zeros(0)
    a = asarray(what, "field %r" % name, value)
    if a.dtype.kind not in "fiub":
        raise TypeError("%s: real numbers, not dtype %s" % (where, a.dtype))
    if a.ndim == 0 or a.shape[0] != count:
        raise ValueError("%s: %d values expected (one per %s), not shape %s"
                         % (where, count, "cell" if blocks is not None else "point", a.shape))
    a = a.reshape(count, -1) if a.ndim > 1 else a.reshape(count, 1)
    if a.shape[1] == 0:
        raise ValueError("%s: no components" % where)
    return a.astype(np.float64)


def tag_array(name: str, value: Any, count: int, blocks: List[Block], what: str) -> np.ndarray:
    """gmsh:physical / gmsh:geometrical as (count,) int32: integers that fit."""
    a = field_array(name, value, count, blocks, what)
    if a.shape[1] != 1:
        raise ValueError("%s: %r must have one value per cell, not %d"
                         % (what, name, a.shape[1]))
    a = a[:, 0]
    ok = np.isfinite(a) & (a == np.round(a)) & (a >= _I32.min) & (a <= _I32.max)
    if not ok.all():
        row = int(np.flatnonzero(~ok)[0])
        raise ValueError("%s: %r row %d: %r is not a 32-bit integer tag"
                         % (what, name, row, a[row]))
    return a.astype(np.int32)


def groups_list(groups: Any, what: str) -> List[Tuple[int, int, bytes]]:
    """(dim, tag, name) triples checked."""
    if groups is None:
        return []
    if isinstance(groups, (str, bytes, dict)) or not isinstance(groups, (list, tuple)):
        raise TypeError("%s: groups must be a list of (dim, tag, name), not %s"
                        % (what, type(groups).__name__))
    out = []
    for i, g in enumerate(groups):
        if not isinstance(g, (list, tuple)) or len(g) != 3:
            raise TypeError("%s: groups[%d] must be (dim, tag, name)" % (what, i))
        dim, tag, name = g
        out.append((integer(what, "groups[%d]: dim" % i, dim, 0, 3),
                    integer(what, "groups[%d]: tag" % i, tag, int(_I32.min), int(_I32.max)),
                    text(what, "groups[%d]: name" % i, name)))
    return out


def from_meshio_args(m: Any, what: str) -> Dict[str, Any]:
    """from_arrays' arguments from a meshio.Mesh (see the module's docstring)."""
    for attr in ("points", "cells", "point_data", "cell_data", "field_data"):
        if not hasattr(m, attr):
            raise TypeError("%s: a meshio.Mesh expected, not %s" % (what, type(m).__name__))
    cells = _block_items(m.cells, what)
    point_data = {k: v for k, v in m.point_data.items() if k != "gmsh:dim_tags"}
    cell_data = dict(m.cell_data)
    groups = []
    for name, v in (m.field_data or {}).items():
        v = np.asarray(v)
        if v.shape == (2,) and v.dtype.kind in "iu":  # gmsh's [tag, dim]
            groups.append((int(v[1]), int(v[0]), name))
    sets = {k: v for k, v in (getattr(m, "cell_sets", None) or {}).items()
            if not k.startswith("gmsh:")}
    if "gmsh:physical" not in cell_data and sets:
        physical = [np.zeros(len(d), np.int32) for _, d in cells]
        owner = [np.full(len(d), -1) for _, d in cells]
        names = list(sets)
        for tag, name in enumerate(names, 1):
            dim = 0
            members = sets[name]
            if len(members) != len(cells):
                raise ValueError("%s: cell set %r has %d blocks, the mesh %d"
                                 % (what, name, len(members), len(cells)))
            for b, idx in enumerate(members):
                if idx is None:
                    continue
                idx = np.asarray(idx, dtype=np.int64).reshape(-1)
                if idx.size == 0:
                    continue
                if idx.min() < 0 or idx.max() >= len(cells[b][1]):
                    raise ValueError("%s: cell set %r: cell index out of range in block %d"
                                     % (what, name, b))
                taken = owner[b][idx]
                if (taken >= 0).any():
                    other = names[int(taken[taken >= 0][0])]
                    raise ValueError("%s: a cell is in cell sets %r and %r: cadmorph keeps one "
                                     "group per cell" % (what, other, name))
                owner[b][idx] = tag - 1
                physical[b][idx] = tag
                dim = max(dim, _dim_of(cells[b][0]))
            groups.append((dim, tag, name))
        cell_data["gmsh:physical"] = physical
    return {"points": m.points, "cells": cells, "point_data": point_data,
            "cell_data": cell_data, "groups": groups}


def _dim_of(name: str) -> int:
    if name in _TYPE:
        return _CELL_DIMS[_TYPE[name]]
    if name in _FROM_MESHIO:
        return _CELL_DIMS[_TYPE[_FROM_MESHIO[name]]]
    return 3  # polyhedronN


def meshio_blocks(types: np.ndarray, offset: np.ndarray,
                  conn: np.ndarray) -> List[Tuple[str, Any, int, int]]:
    """The cells in meshio's form, as (meshio name, data, first cell, end cell): one block
    per run of one type; polygons split further into runs of one size (meshio's blocks are
    arrays), polyhedra into runs of one node count ("polyhedron<n>", a list of cells, each a
    list of faces)."""
    out: List[Tuple[str, Any, int, int]] = []
    n = len(types)
    if n == 0:
        return out
    starts = np.flatnonzero(np.diff(types.astype(np.int16))) + 1
    bounds = np.concatenate(([0], starts, [n]))
    for a, b in zip(bounds[:-1].tolist(), bounds[1:].tolist()):
        t = int(types[a])
        name = CELL_NAMES[t]
        nodes = CELL_NODES[t]
        if nodes > 0:
            block = conn[offset[a]:offset[b]].reshape(b - a, nodes)
            if name in MESHIO_ORDER:
                block = block[:, MESHIO_ORDER[name]]
            out.append((MESHIO_NAME[name], np.array(block), a, b))
        elif t == lib.CM_CELL_POLYGON:
            sizes = np.diff(offset[a:b + 1])
            cuts = np.concatenate(([0], np.flatnonzero(np.diff(sizes)) + 1, [b - a]))
            for c0, c1 in zip(cuts[:-1].tolist(), cuts[1:].tolist()):
                k = int(sizes[c0])
                block = conn[offset[a + c0]:offset[a + c1]].reshape(c1 - c0, k)
                out.append(("polygon", np.array(block), a + c0, a + c1))
        else:
            run: List[Any] = []
            run_nodes, run_start = -1, a
            for c in range(a, b):
                s = conn[offset[c]:offset[c + 1]].tolist()
                faces, at = [], 1
                for _ in range(s[0]):
                    faces.append(np.array(s[at + 1:at + 1 + s[at]], dtype=np.int64))
                    at += 1 + s[at]
                k = len(set(np.concatenate(faces).tolist())) if faces else 0
                if k != run_nodes and run:
                    out.append(("polyhedron%d" % run_nodes, run, run_start, c))
                    run, run_start = [], c
                run_nodes = k
                run.append(faces)
            out.append(("polyhedron%d" % run_nodes, run, run_start, b))
    return out

