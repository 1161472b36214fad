"""optimize: interior node optimisation of a volume mesh (cm_mesh_optimize), as
`cadmorph optimize`: untangles inverted cells and raises the worst ones without moving the
boundary (Knupp's inverse mean ratio, optimize.h)."""
from dataclasses import dataclass
from typing import Any, Tuple

import numpy as np

from ._capi import ffi, lib
from ._context import Context, Progress
from ._inputs import index_array, integer, mesh_of, number
from .mesh import Mesh, _array


@dataclass(frozen=True)
class OptimizeStats:
    """What cm_mesh_optimize did (the numbers of `cadmorph optimize`'s first line).

    Attributes:
        min_sj_before, min_sj_after: the smallest scaled Jacobian before and after.
        inverted_before, inverted_after: inverted volume cells before and after (the CLI
            exits with code 3 when inverted_after > 0; here it is only reported).
        nodes_selected: free nodes the passes worked on.
        moves: node moves kept, over all passes.
        sweeps: passes made.
    """

    min_sj_before: float
    min_sj_after: float
    inverted_before: int
    inverted_after: int
    nodes_selected: int
    moves: int
    sweeps: int


def optimize(mesh: Mesh, fixed: Any = None, sweeps: int = 6, target_sj: float = 0.3,
             newton: int = 4, in_place: bool = False, *, threads: int = 0,
             progress: Progress = None) -> Tuple[np.ndarray, OptimizeStats]:
    """Optimises the interior nodes of a volume mesh; returns (points, stats): the (n, 3)
    optimised coordinates and an OptimizeStats.

    By default the mesh is not changed: a copy of it (cm_mesh_copy) is optimised and points
    is a read-only view onto the copy's coordinates (no further copy). in_place=True
    optimises mesh itself (points is then mesh.points).

    fixed: indices (or a boolean mask) of nodes that never move; None: the boundary nodes
    (as `cadmorph optimize`). Nodes of cells other than tet4, hex8, wedge6 and pyr5 never
    move either. sweeps (1..1000): passes over the selected nodes; target_sj (-1, 1]: cells
    below it and their neighbours are worked on; newton (1..100): Newton iterations per node
    and pass. The result does not depend on threads.

    Raises BadInputError (CM_ERR_UNSUPPORTED) for a mesh without volume cells.
    """
    what = "cadmorph.optimize"
    mesh_of(what, "mesh", mesh)
    opt = ffi.new("cm_optimize_options *")
    lib.cm_optimize_options_init(opt)
    opt.sweeps = integer(what, "sweeps", sweeps, 1, 1000)
    opt.target_sj = number(what, "target_sj", target_sj, -1, 1, lo_open=True)
    opt.newton = integer(what, "newton", newton, 1, 100)
    n = mesh.n_nodes
    flags = ffi.NULL
    if fixed is not None:
        mask = np.zeros(max(n, 1), np.uint8)
        mask[index_array(what, "fixed", fixed, n, mask=True)] = 1
        flags = ffi.from_buffer("unsigned char[]", mask)
    ctx = Context(threads, progress, what)
    if in_place:
        target = mesh._ptr
    else:
        target = ctx.create(lib.cm_mesh_copy, "cm_mesh", lib.cm_mesh_destroy, mesh._ptr)
    st = ffi.new("cm_optimize_stats *")
    ctx.call(lib.cm_mesh_optimize, target, flags, opt, st)
    stats = OptimizeStats(float(st.min_sj_before), float(st.min_sj_after),
                          int(st.inverted_before), int(st.inverted_after),
                          int(st.nodes_selected), int(st.moves), int(st.sweeps))
    if in_place:
        return mesh.points, stats
    return _array(target, target.xyz, (n, 3), np.float64, writable=False), stats
