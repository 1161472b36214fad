"""Warp: a volume warp of a mesh, factorised once (cm_warp_create), applied to any motion of
its constrained nodes (cm_warp_apply), to many at once (cm_warp_apply_many) and, for adjoint
gradients, its reverse product (cm_warp_apply_transpose); warp(): the one-shot form.

A warp carries a prescribed displacement of some nodes (by default the boundary nodes) into
every other node of the volume cells, by one of the library's methods (docs/DESIGN.md, "The
warp interface"): "rbf" (triharmonic RBF, the method), "rbf-biharmonic", "femwarp",
"lbwarp", "simplex", "dmffd", "mls".
"""
import threading
from typing import Any, Optional

import numpy as np

from ._capi import ffi, lib
from ._context import Context, Progress
from ._inputs import index_array, integer, mesh_of, points
from ._options import MAX_DISPLACEMENT, WarpSettings
from .mesh import Mesh


class Warp:
    """A warp of mesh whose constrained nodes are `nodes` (None: the boundary nodes, those of
    faces used by one volume cell), made once: `apply` then maps any displacement of those
    nodes to the displacement of every node, sharing the factorisation.

    Arguments (the options of `cadmorph warp`, with its defaults):
        mesh: a cadmorph.Mesh with volume cells; copied what the warp needs (the Mesh may be
            changed or closed afterwards, the warp stays that of the mesh as it was).
        nodes: 1-D integer array-like of distinct node indices (0-based, any order), or None
            for the boundary nodes. `cadmorph warp` constrains the boundary nodes and the
            nodes of its D.csv: pass their union for the same warp.
        method: "rbf" (default: phi = r^3 + linear, one interpolant per connected component),
            "rbf-biharmonic", "femwarp", "lbwarp", "simplex", "dmffd", "mls" (the CLI's
            --method); kernel: "triharmonic" or "biharmonic", the CLI's --kernel (another
            name for method "rbf" / "rbf-biharmonic").
        solver: RBF methods: "auto" (dense below a measured size, iterative above), "dense",
            "iterative", "petsc" (only in a build with PETSc).
        tolerance: RBF, iterative solvers: the CLI's --rbf-tol, in [0, 0.5]; 0 = from the
            mesh: 1e-3 x the shortest spacing between a constrained and a free node of a
            cell over the constrained nodes' diagonal, within [1e-10, 1e-6] (the property
            tolerance says what was taken).
        solves: RBF methods, solver "auto": how many displacement fields you expect to apply
            with this warp (apply_many's k counting k), >= 1 (default 1); the dense
            factorisation, shared by them all, then wins to more nodes
            (cm_warp_options.solves).
        warm_groups: RBF methods, iterative solver: apply_many's k fields solved in this many
            groups, each starting from the solutions of the groups before it, the fields that
            span the others first (cm_warp_options.warm_groups: what a study does with its
            variants); 0 or 1 (default 0): all at once.
        lattice: dmffd: control points per axis, 4..200 (None: 10); clamp: dmffd: singular
            values <= clamp x the largest are dropped, in (0, 1) (None: 1e-10).
        samples, cubature (None: automatic), cover (1..64), stretch, bend, blend (>= 0),
            graded (0..1): the MLS options of the CLI (mls.h).
        threads: the library's threads for this warp's calls, 0 = all.
        progress: a callable (stage, done, total) receiving the library's progress reports,
            None for the CLI's progress line on a terminal, False for none. Raising in it
            (or Ctrl-C) stops the call and is raised from it.

    Raises ValueError/TypeError for bad arguments, BadInputError and its subclasses for what
    the library refuses (e.g. a mesh without volume cells, a flat boundary of an RBF
    component), with the library's message. Calls on one Warp from several threads wait for
    each other; two Warp objects run in parallel in two threads (the GIL is released in the
    library). Bit for bit what `cadmorph warp` computes when OpenBLAS runs as in the CLI
    (started with OPENBLAS_NUM_THREADS=1): the sparse methods' sums depend on its threads.
    """

    def __init__(self, mesh: Mesh, nodes: Any = None, *, method: str = "rbf",
                 kernel: Optional[str] = None, solver: str = "auto", tolerance: float = 0.0,
                 lattice: Optional[int] = None, clamp: Optional[float] = None,
                 samples: Optional[int] = None, cubature: Optional[int] = None, cover: int = 5,
                 stretch: float = 1.0, bend: float = 1.0, blend: float = 1.5,
                 graded: float = 0.0, solves: int = 1, warm_groups: int = 0,
                 threads: int = 0, progress: Progress = None) -> None:
        what = "cadmorph.Warp"
        self._warp = None
        self._lock = threading.Lock()  # the C API: one call at a time on a warp
        m = mesh_of(what, "mesh", mesh)._ptr
        n = int(m.n_nodes)
        settings = WarpSettings(what, method=method, kernel=kernel, solver=solver,
                                tolerance=tolerance, lattice=lattice, clamp=clamp,
                                samples=samples, cubature=cubature, cover=cover,
                                stretch=stretch, bend=bend, blend=blend, graded=graded,
                                solves=solves)
        groups = integer(what, "warm_groups", warm_groups, 0, 2 ** 31 - 1)
        self._ctx = ctx = Context(threads, progress, what)
        opt = ffi.new("cm_warp_options *")
        settings.fill(opt)
        opt.warm_groups = groups
        b = ctx.create(lib.cm_mesh_boundary_create, "cm_mesh_boundary",
                       lib.cm_mesh_boundary_destroy, m)
        if nodes is None:
            k = int(b.n_nodes)
            self._nodes = (np.frombuffer(ffi.buffer(b.nodes, 8 * k), np.int64).copy() if k
                           else np.zeros(0, np.int64))
            constrained = ffi.NULL
        else:
            self._nodes = index_array(what, "nodes", nodes, n, unique=True, empty=False).copy()
            flags = np.zeros(max(n, 1), np.uint8)
            flags[self._nodes] = 1
            constrained = ffi.from_buffer("unsigned char[]", flags)
        self._nodes.flags.writeable = False
        self._warp = ctx.create(lib.cm_warp_create, "cm_warp", lib.cm_warp_destroy, m, b,
                                constrained, opt)
        self._n = n
        self._settings = settings

    @property
    def nodes(self) -> np.ndarray:
        """The constrained nodes (read-only int64 array), in the order the rows of apply's D
        refer to: as given, or the boundary nodes ascending."""
        return self._nodes

    @property
    def n_nodes(self) -> int:
        """Number of nodes of the mesh (rows of apply's result)."""
        return self._n

    @property
    def method(self) -> str:
        """The warp's method name ("rbf", "femwarp", ...)."""
        return ffi.string(lib.cm_warp_method_name(lib.cm_warp_get_method(self._warp))).decode()

    @property
    def residual(self) -> float:
        """Largest |displacement - prescribed| at the constrained nodes after the last apply:
        0 for the interpolating methods (RBF, FEMWARP); what DM-FFD and MLS miss by."""
        return float(lib.cm_warp_residual(self._warp))

    @property
    def tolerance(self) -> float:
        """The tolerance the RBF methods' iterative solves stop at: the one given, or the one
        from the mesh (the tightest over the mesh's components); 0 for the other methods."""
        return float(lib.cm_warp_tolerance(self._warp))

    @property
    def fallback_nodes(self) -> int:
        """Nodes the method treated by its documented fallback (LBWARP: no positive
        log-barrier weights; simplex: outside every Delaunay tet); 0 for the others."""
        return int(lib.cm_warp_fallback_nodes(self._warp))

    def apply(self, D: Any) -> np.ndarray:
        """The displacement of every node, (n_nodes, 3) float64, for the displacements D of
        the constrained nodes: an array-like of shape (len(nodes), 3), row k for nodes[k]
        (for a displacement of every node, pass D_all[w.nodes]); finite, each component at
        most 1e150 in magnitude, as in `cadmorph warp`'s table (else ValueError). Constrained
        nodes get their row of D exactly; nodes of no volume cell that are not constrained
        get 0.

        The result is a new array the library fills in place; on an exception (Ctrl-C, the
        progress callable) nothing is returned and the warp stays usable.
        """
        d = points("cadmorph.Warp.apply", "D", D, len(self._nodes), MAX_DISPLACEMENT)
        out = np.zeros((self._n, 3), np.float64)
        out[self._nodes] = d
        if self._n:
            with self._lock:
                self._ctx.call(lib.cm_warp_apply, self._warp, ffi.from_buffer("double[]", out))
        return out

    def apply_many(self, Ds: Any) -> np.ndarray:
        """The displacement of every node for k motions of the constrained nodes at once: a
        (k, n_nodes, 3) float64 array whose [j] is what apply(Ds[j]) returns. Ds: an
        array-like of shape (k, len(nodes), 3), or a sequence of k array-likes each as
        apply's D (checked as there; k >= 0).

        The RBF methods solve and evaluate the 3k columns together (cm_warp_apply_many):
        their kernel passes serve every column, so k fields cost a fraction of k applies;
        the result equals k applies to rounding with the dense solver and to the tolerance
        with the iterative one (warm_groups: its fields in groups, each starting from the
        solutions before it). The other methods apply field by field. The library holds
        3k values per node of the largest component besides the result: k up to tens.
        """
        what = "cadmorph.Warp.apply_many"
        try:
            fields = Ds if isinstance(Ds, np.ndarray) and Ds.ndim == 3 else list(Ds)
        except TypeError:
            raise TypeError("%s: Ds must be an array-like (k, %d, 3) or a sequence of k "
                            "array-likes, not %s" % (what, len(self._nodes),
                                                     type(Ds).__name__)) from None
        k = len(fields)
        out = np.zeros((k, self._n, 3), np.float64)
        for j in range(k):
            out[j, self._nodes] = points(what, "Ds[%d]" % j, fields[j], len(self._nodes),
                                         MAX_DISPLACEMENT)
        if self._n and k:
            with self._lock:
                self._ctx.call(lib.cm_warp_apply_many, self._warp, k,
                               ffi.from_buffer("double[]", out))
        return out

    def apply_transpose(self, V: Any) -> np.ndarray:
        """The reverse product of apply, for adjoint gradients (docs/DESIGN.md, "Gradients"):
        apply is a linear map J from D (len(nodes), 3) to the displacement of every node
        (n_nodes, 3); this is its transpose, J^T V, a (len(nodes), 3) float64 array whose row
        k belongs to nodes[k] (apply's D layout), such that

            np.vdot(V, w.apply(D)) == np.vdot(w.apply_transpose(V), D)

        for every D (to round-off). V: an array-like (n_nodes, 3), e.g. the sensitivity dJ/dX
        of an objective at every node (then J^T V is dJ/dD, the sensitivity to the motion of
        the constrained nodes); finite (else ValueError). Rows of nodes that apply leaves at 0
        (nodes of no volume cell that are not constrained) are not read. One solve with the
        factorisation of the warp, the three components at once; a float64 C-contiguous V is
        passed to the library without a copy.

        Raises BadInputError (the library's CM_ERR_UNSUPPORTED, its message naming the
        method and why) for a method whose apply is not linear in D.
        """
        v = points("cadmorph.Warp.apply_transpose", "V", V, self._n)
        out = np.zeros((self._n, 3), np.float64)
        if self._n:
            with self._lock:
                self._ctx.call(lib.cm_warp_apply_transpose, self._warp,
                               ffi.from_buffer("double[]", v), ffi.from_buffer("double[]", out))
        return out[self._nodes]

    def __repr__(self) -> str:
        return "<cadmorph.Warp %s, %d nodes, %d constrained>" % (self.method, self._n,
                                                                 len(self._nodes))


def warp(mesh: Mesh, nodes: Any, D: Any, method: str = "rbf", **options: Any) -> np.ndarray:
    """One warp, one apply: the displacement (n_nodes, 3) of every node of mesh when the
    nodes `nodes` (None: the boundary nodes) move by D (len(nodes), 3). The options are
    Warp's (solver, tolerance, lattice, clamp, the MLS options, threads, progress).

    Equals `cadmorph warp --mesh M --displacements D.csv --method M` (its written
    "displacement" field), with nodes = the boundary nodes and the listed ones.
    """
    return Warp(mesh, nodes, method=method, **options).apply(D)
