"""Mesh: a cm_mesh owned by Python, its arrays as NumPy views; read_mesh and write_mesh;
Mesh.from_arrays, from_meshio and to_meshio (meshio's names and cell blocks in _convert.py, the
generic argument checks in _inputs.py).

Views (points, fields, connectivity) point into the library's memory. Each holds, through
its `.base`, the owner of the cm_mesh, so the memory lives while any view does, also after
Mesh.close() or after the Mesh is gone; nothing in this package resizes a mesh, so a view
never dangles.
"""
import os
from typing import TYPE_CHECKING, Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
from numpy.typing import ArrayLike

from ._capi import ffi, lib
from ._context import Context
from . import _inputs

PathLike = Union[str, bytes, "os.PathLike[str]"]

if TYPE_CHECKING:
    import meshio

CellBlocks = Sequence[Tuple[str, Any]]
"""Cells as meshio keeps them: a list of (type name, array or list of cells)."""

_TOKEN = object()  # Mesh objects are made here only
_CELL_NAMES = [ffi.string(lib.cm_cell_type_info(t).name).decode()
               for t in range(lib.CM_CELL_TYPE_COUNT)]
_CELL_NODES = [lib.cm_cell_type_info(t).nodes for t in range(lib.CM_CELL_TYPE_COUNT)]


class _View:
    """The base of an array onto library memory: holds the memory's owner."""

    def __init__(self, owner, address: int, shape: Tuple[int, ...], typestr: str,
                 writable: bool) -> None:
        self.owner = owner
        self.__array_interface__ = {"shape": shape, "typestr": typestr, "version": 3,
                                    "data": (address, not writable)}


def _array(owner, ptr, shape: Tuple[int, ...], dtype, writable: bool = True) -> np.ndarray:
    dtype = np.dtype(dtype)
    if ptr == ffi.NULL or 0 in shape:
        a = np.zeros(shape, dtype)
        a.flags.writeable = writable
        return a
    address = int(ffi.cast("uintptr_t", ptr))
    return np.asarray(_View(owner, address, shape, dtype.str, writable))


class Mesh:
    """A mixed-cell mesh held by libcadmorph (a cm_mesh), as read by read_mesh.

    Node order inside a cell is VTK's for every type; node indices are 0-based. The arrays
    are views onto the library's memory (see the module's docstring); `close()` lets the
    memory go once no view is left.
    """

    def __init__(self, _owner=None, _token=None) -> None:
        """Not for users: a Mesh comes from read_mesh, from_arrays or from_meshio (a
        TypeError otherwise)."""
        if _token is not _TOKEN or ffi.typeof(_owner) is not ffi.typeof("cm_mesh *") \
                or _owner == ffi.NULL:
            raise TypeError("cadmorph.Mesh: made by cadmorph.read_mesh, Mesh.from_arrays "
                            "or Mesh.from_meshio, not directly")
        self._owner = _owner

    @property
    def _ptr(self):
        if self._owner is None:
            raise ValueError("cadmorph.Mesh: the mesh is closed")
        return self._owner

    def close(self) -> None:
        """Drops this object's hold on the cm_mesh; it is freed when no view holds it."""
        self._owner = None

    def __enter__(self) -> "Mesh":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    @property
    def closed(self) -> bool:
        """True after close()."""
        return self._owner is None

    @property
    def n_nodes(self) -> int:
        """Number of nodes."""
        return int(self._ptr.n_nodes)

    @property
    def n_cells(self) -> int:
        """Number of elements of every dimension (volume cells, faces, edges, points)."""
        return int(self._ptr.n_cells)

    @property
    def points(self) -> np.ndarray:
        """Node coordinates: (n_nodes, 3) float64, a writable view onto the mesh (no copy):
        writing to it moves the nodes that write_mesh and quality see."""
        m = self._ptr
        return _array(m, m.xyz, (int(m.n_nodes), 3), np.float64)

    @points.setter
    def points(self, value) -> None:
        """Sets every node's coordinates (copied into the mesh): an array-like of shape
        (n_nodes, 3) of real numbers."""
        a = _inputs.real_array("cadmorph.Mesh.points", "value", value, (self.n_nodes, 3),
                               finite=False)
        self.points[...] = a

    def _cell_arrays(self) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        m = self._ptr
        n = int(m.n_cells)
        types = _array(m, m.type, (n,), np.uint8, writable=False)
        offset = _array(m, m.offset, (n + 1,), np.int64, writable=False)
        conn = _array(m, m.conn, (int(offset[-1]) if n else 0,), np.int64, writable=False)
        return types, offset, conn

    @property
    def cell_types(self) -> List[str]:
        """The type name of each element in file order ("tet4", "hex8", "tri3", ...)."""
        return [_CELL_NAMES[t] for t in self._cell_arrays()[0]]

    @property
    def cells(self) -> List[Tuple[str, Union[np.ndarray, List[np.ndarray]]]]:
        """The elements in file order, one block per run of consecutive elements of one type:
        a list of (type name, array). For fixed-size types the array is (k, nodes) int64, a
        read-only view onto the mesh's connectivity (the library stores every element's
        nodes one after the other, so a run is dense; no copy). For "polygon" and
        "polyhedron" it is a list of k 1-D int64 copies: a polygon's nodes in order, a
        polyhedron's face stream (nf, n0, nodes of face 0, n1, ...)."""
        types, offset, conn = self._cell_arrays()
        if len(types) == 0:
            return []
        starts = np.flatnonzero(np.diff(types.astype(np.int16))) + 1
        bounds = np.concatenate(([0], starts, [len(types)]))
        blocks = []
        for a, b in zip(bounds[:-1], bounds[1:]):
            t = int(types[a])
            nodes = _CELL_NODES[t]
            if nodes > 0:
                block = conn[offset[a]:offset[b]].reshape(b - a, nodes)
            else:
                block = [conn[offset[c]:offset[c + 1]].copy() for c in range(a, b)]
            blocks.append((_CELL_NAMES[t], block))
        return blocks

    def _field_dict(self, location: int, count: int) -> Dict[str, np.ndarray]:
        m = self._ptr
        out = {}
        for i in range(int(m.n_fields)):
            f = m.fields[i]
            if f.location != location:
                continue
            shape = (count,) if f.components == 1 else (count, int(f.components))
            out[ffi.string(f.name).decode("utf-8", "replace")] = _array(m, f.data, shape,
                                                                         np.float64)
        return out

    @property
    def point_data(self) -> Dict[str, np.ndarray]:
        """Per-node fields by name: (n_nodes,) or (n_nodes, components) float64 views."""
        return self._field_dict(lib.CM_FIELD_NODE, self.n_nodes)

    @property
    def cell_data(self) -> Dict[str, np.ndarray]:
        """Per-element fields by name: (n_cells,) or (n_cells, components) float64 views,
        over every element in file order (as cells, concatenated)."""
        return self._field_dict(lib.CM_FIELD_CELL, self.n_cells)

    @property
    def physical(self) -> np.ndarray:
        """Each element's physical group tag, 0 if none: (n_cells,) int32, a read-only view
        (gmsh's physical tags, Medit's references; "gmsh:physical" in a .vtu)."""
        m = self._ptr
        return _array(m, m.physical, (int(m.n_cells),), np.intc, writable=False)

    @property
    def entity(self) -> np.ndarray:
        """Each element's geometric (elementary) entity tag, 0 if none: (n_cells,) int32, a
        read-only view ("gmsh:geometrical" in a .vtu)."""
        m = self._ptr
        return _array(m, m.entity, (int(m.n_cells),), np.intc, writable=False)

    @property
    def groups(self) -> List[Tuple[int, int, str]]:
        """Named physical groups as (dim, tag, name)."""
        m = self._ptr
        return [(int(g.dim), int(g.tag), ffi.string(g.name).decode("utf-8", "replace"))
                for g in (m.groups[i] for i in range(int(m.n_groups)))]

    @classmethod
    def from_arrays(cls, points: ArrayLike, cells: CellBlocks,
                    point_data: Optional[Dict[str, ArrayLike]] = None,
                    cell_data: Optional[Dict[str, Any]] = None,
                    groups: Optional[List[Tuple[int, int, str]]] = None,
                    threads: int = 0) -> "Mesh":
        """A mesh from arrays (copied into a new cm_mesh), checked before the library sees
        them.

        points: (n, 3) real numbers (or (n, 2): z = 0), all finite, n > 0.
        cells: a list of (type name, array), as meshio keeps them (meshio CellBlocks and a
            {name: array} dict work too). Names are cadmorph's ("tet4", "hex20", ...,
            Mesh.cells' names, nodes in VTK's order) or meshio's ("tetra", "hexahedron20",
            "wedge", ..., nodes in meshio's order: VTK's except "wedge", whose nodes 1 and 2,
            4 and 5 are swapped). The array is (k, nodes) integers for fixed-size types;
            "polygon" takes a (k, n) array or a list of 1-D node lists; "polyhedron" a list
            of face streams (nf, n0, nodes of face 0, n1, ...) or of lists of faces, and
            meshio's "polyhedron<n>" a list of lists of faces.
        point_data: {name: (n,) or (n, c) reals} (trailing axes are flattened into
            components). cell_data: {name: reals over every cell, in the order of `cells`
            concatenated, or a list with one array per block as meshio keeps them}; the names
            "gmsh:physical" and "gmsh:geometrical" are the cells' physical and entity tags
            (Mesh.physical, Mesh.entity; integers), not fields.
        groups: named physical groups as (dim, tag, name), as Mesh.groups gives them.

        Raises TypeError for a wrong type or dtype (strings, complex, float node indices)
        and ValueError for a wrong shape, an unknown type name, a node index out of range or
        a non-finite point (naming the block and the row).
        """
        from . import _convert
        what = "cadmorph.Mesh.from_arrays"
        xyz = _inputs.points(what, "points", points, planar=True)
        n = len(xyz)
        if n == 0:
            raise ValueError("%s: no points" % what)
        blocks = _convert.cell_blocks(cells, n, what)
        n_cells = sum(b.count for b in blocks)
        fields, tags = [], {}
        for data, location, count, bl in ((point_data, lib.CM_FIELD_NODE, n, None),
                                          (cell_data, lib.CM_FIELD_CELL, n_cells, blocks)):
            if data is None:
                continue
            if not isinstance(data, dict):
                raise TypeError("%s: point_data and cell_data must be dicts, not %s"
                                % (what, type(data).__name__))
            for name, value in data.items():
                key = _inputs.text(what, "field name", name)
                if bl is not None and name in _convert.TAGS:
                    tags[name] = _convert.tag_array(name, value, count, bl, what)
                else:
                    fields.append((key, location,
                                   _convert.field_array(name, value, count, bl, what)))
        group_list = _convert.groups_list(groups, what)

        ctx = Context(threads, False, what)
        m = ctx.create(lib.cm_mesh_create, "cm_mesh", lib.cm_mesh_destroy)
        ctx.call(lib.cm_mesh_resize_nodes, m, n, 0)
        _array(m, m.xyz, (n, 3), np.float64)[...] = xyz
        n_conn = sum(b.data.size if isinstance(b.data, np.ndarray) else
                     sum(len(r) for r in b.data) for b in blocks)
        ctx.call(lib.cm_mesh_reserve_cells, m, n_cells, n_conn)
        physical = tags.get("gmsh:physical", np.zeros(n_cells, np.int32)).tolist()
        entity = tags.get("gmsh:geometrical", np.zeros(n_cells, np.int32)).tolist()
        add, p, c = lib.cm_mesh_add_cell, ctx.ptr, 0
        for b in blocks:
            if b.count == 0:
                continue
            if isinstance(b.data, np.ndarray):
                k = b.data.shape[1]
                buf = ffi.from_buffer("int64_t[]", b.data)
                rows = ((buf + i * k, k) for i in range(b.count))
            else:
                rows = ((ffi.from_buffer("int64_t[]", r), len(r)) for r in b.data)
            for ptr, k in rows:
                status = add(p, m, b.type, ptr, k, physical[c], entity[c], 0)
                if status != lib.CM_OK:
                    ctx.check(status)
                c += 1
        for key, location, a in fields:
            data = ffi.new("double *[1]")
            ctx.call(lib.cm_mesh_add_field, m, key, location, a.shape[1], data)
            _array(m, data[0], a.shape, np.float64)[...] = a
        for dim, tag, key in group_list:
            ctx.call(lib.cm_mesh_add_group, m, dim, tag, key)
        ctx.call(lib.cm_mesh_validate, m, what.encode())  # what Python checked, once more
        return cls(m, _TOKEN)

    @classmethod
    def from_meshio(cls, mesh: "meshio.Mesh", threads: int = 0) -> "Mesh":
        """A mesh from a meshio.Mesh: points, cells (meshio's node order, see from_arrays),
        point_data and cell_data as fields, "gmsh:physical" and "gmsh:geometrical" as the
        cells' tags and field_data's {name: [tag, dim]} as groups (meshio's form of gmsh's
        physical groups). Without "gmsh:physical", meshio's cell_sets become groups (tags 1,
        2, ... in their order; a cell in two sets raises ValueError). meshio's bookkeeping
        "gmsh:dim_tags" is dropped. Checked as from_arrays checks.

        meshio's gmsh reader gives wedge15 mirrored and wedge18, pyramid14 in gmsh's order
        (its VTK reader in VTK's): read such .msh files with read_mesh instead.
        """
        from . import _convert
        return cls.from_arrays(threads=threads,
                               **_convert.from_meshio_args(mesh, "cadmorph.Mesh.from_meshio"))

    def to_meshio(self) -> "meshio.Mesh":
        """A meshio.Mesh with copies of the points, cells (meshio's names and node order: the
        wedge's nodes 1 and 2, 4 and 5 swapped; one block per run of one type, polygons per
        run of one size, polyhedra as "polyhedron<n>" lists of faces), point_data, cell_data
        (per block), the cells' tags as "gmsh:physical" and "gmsh:geometrical" (when any is
        set) and the groups as field_data {name: array([tag, dim])}, as meshio reads gmsh
        files; meshio.write then writes every format meshio knows."""
        try:
            import meshio
        except ImportError as e:
            raise ImportError("cadmorph.Mesh.to_meshio needs meshio (Debian python3-meshio, "
                              "pip install meshio): %s" % e) from None
        from . import _convert
        types, offset, conn = self._cell_arrays()
        blocks = _convert.meshio_blocks(types, offset, conn)
        cell_data = {}
        for name, a in self.cell_data.items():
            cell_data[name] = [a[b0:b1].copy() for _, _, b0, b1 in blocks]
        for name, a in zip(_convert.TAGS, (self.physical, self.entity)):
            if (self.physical != 0).any() or (self.entity != 0).any():
                cell_data[name] = [a[b0:b1].copy() for _, _, b0, b1 in blocks]
        field_data = {name: np.array([tag, dim]) for dim, tag, name in self.groups}
        try:
            return meshio.Mesh(self.points.copy(), [(t, data) for t, data, _, _ in blocks],
                               point_data={k: v.copy() for k, v in self.point_data.items()},
                               cell_data=cell_data, field_data=field_data)
        except KeyError as e:  # meshio 5.0 has no wedge15 and pyramid13 (no dimension)
            raise ValueError("cadmorph.Mesh.to_meshio: meshio %s cannot hold cells of type %s"
                             % (meshio.__version__, e)) from None

    def __repr__(self) -> str:
        if self.closed:
            return "<cadmorph.Mesh (closed)>"
        return "<cadmorph.Mesh %d nodes, %d cells>" % (self.n_nodes, self.n_cells)


def read_mesh(path: PathLike, threads: int = 0) -> Mesh:
    """Reads a mesh; the format is chosen by the name, as in the CLI (mesh_formats() lists
    them: gmsh, VTK, Medit, surface formats, CGNS, SU2, Fluent, Abaqus, Nastran, Exodus II, an
    OpenFOAM case directory). threads: for the library's OpenMP loops, 0 = all the machine has.

    Raises BadInputError (with the library's message naming the file, and the line or the
    byte offset) for a file that is missing, unreadable or malformed.
    """
    p = _inputs.path_bytes("cadmorph.read_mesh", "path", path)
    ctx = Context(threads, False, "cadmorph.read_mesh")
    return Mesh(ctx.create(lib.cm_mesh_read, "cm_mesh", lib.cm_mesh_destroy, p), _TOKEN)


def mesh_formats() -> str:
    """The mesh formats read_mesh and write_mesh know, as the CLI's messages name them:
    ".msh .vtu ... , or an OpenFOAM case directory"."""
    return ffi.string(lib.cm_mesh_format_list()).decode()


def write_mesh(path: PathLike, mesh: Mesh, binary: Optional[bool] = None,
               msh_version: Optional[int] = None, compress: Optional[bool] = None,
               threads: int = 0) -> None:
    """Writes a mesh in the format its name says (as read_mesh); through a temporary file
    renamed at the end, so a failed write leaves no partial file. A mesh read from a solver's
    file (CGNS, SU2, Fluent, Abaqus, Nastran, Exodus II, OpenFOAM) and written to a name of
    that format, with the nodes and cells it was read with, changes only the coordinates:
    every other byte of the file stays.

    binary: msh, vtk, stl binary, vtu base64 (library default when None); msh_version: 22 or
    41 (default 41); compress: vtu zlib compression (default on).
    """
    _inputs.mesh_of("cadmorph.write_mesh", "mesh", mesh)
    p = _inputs.path_bytes("cadmorph.write_mesh", "path", path)
    opt = ffi.new("cm_mesh_write_options *")
    lib.cm_mesh_write_options_init(opt)
    if msh_version is not None:
        if msh_version not in (22, 41):
            raise ValueError("cadmorph.write_mesh: msh_version must be 22 or 41, not %r"
                             % (msh_version,))
        opt.msh_version = msh_version
    if binary is not None:
        opt.binary = bool(binary)
    if compress is not None:
        opt.compress = bool(compress)
    ctx = Context(threads, False, "cadmorph.write_mesh")
    ctx.call(lib.cm_mesh_write, mesh._ptr, p, opt)
