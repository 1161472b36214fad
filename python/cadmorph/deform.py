"""deform and Deformer: handle-based space deformations (the handle metaphor [CMLS §3]) over
deform.h's table (cm_deform_create / cm_deform_apply), as `cadmorph deform`.

Handle points move by given displacements, fixed points stay, every other point follows the
method's space deformation: "rbf" (triharmonic RBF, exact at the constrained points), "mls"
(constrained MLS over a mesh's cells: a weighted fit, exact at the constrained points by
its correction), "shell" (the mesh-based shell of a surface
mesh) or "dmffd" (DM-FFD on a cubic B-spline lattice enclosing the points, least squares).
A Deformer does the work that depends only on the points and on which of them are
constrained (factorisation, SVD, sampling) once; apply maps any number of handle
displacements.
"""
from typing import Any, Dict, Optional, Union

import numpy as np

from ._capi import ffi, lib
from ._context import Context, Progress
from ._inputs import choice, index_array, integer, number, points_of, real_array, struct_dict
from ._options import SOLVERS
from .mesh import Mesh

METHODS = ("rbf", "mls", "shell", "dmffd")
_KERNELS = {"triharmonic": lib.CM_RBF_TRIHARMONIC, "biharmonic": lib.CM_RBF_BIHARMONIC}
_FIXED_GROUP, _HANDLE_GROUP = 1, 2  # the MLS weighs the two regions apart, as the CLI


def _boundary_nodes(ctx: Context, mesh: Mesh) -> np.ndarray:
    """The nodes `cadmorph deform --fix-unlisted-boundary` fixes: the boundary surface's
    nodes of a volume mesh, the border vertices (on an edge of one face) of a surface."""
    m = mesh._ptr
    if lib.cm_mesh_count_dim(m, 3) > 0:
        b = ctx.create(lib.cm_mesh_boundary_create, "cm_mesh_boundary",
                       lib.cm_mesh_boundary_destroy, m)
        return np.frombuffer(ffi.buffer(b.nodes, 8 * b.n_nodes), np.int64).copy() \
            if b.n_nodes else np.zeros(0, np.int64)
    n = int(m.n_nodes)
    H = np.empty(max(n, 1))
    border = np.zeros(max(n, 1), np.uint8)
    ctx.call(lib.cm_mls_mean_curvature, m, ffi.from_buffer("double[]", H),
             ffi.from_buffer("unsigned char[]", border))
    return np.flatnonzero(border[:n]).astype(np.int64)


class Deformer:
    """A deformation of points constrained at handle (moving) and fixed (still) points,
    set up once (cm_deform_create): apply(displacements) then maps any number of handle
    displacements to every point.

    points: a Mesh (its nodes; needed by "mls" and "shell", which work on its cells) or an
        (n, 3) array of coordinates ("rbf", "dmffd"; copied by the library).
    handles: the indices of the handle points (or a boolean mask of length n).
    fixed: the indices of the fixed points, or "boundary": every boundary node of the mesh
        that is not a handle (`--fix-unlisted-boundary`: the boundary surface of a volume
        mesh, the border edges of a surface mesh), or None.
    method: "rbf" (default), "mls", "shell" or "dmffd". Options, as `cadmorph deform`:
        kernel ("triharmonic" | "biharmonic"), solver ("auto" | "dense" | "iterative" |
        "petsc"), tolerance (0: the RBF's default) and solves (the fields you expect to apply,
        >= 1, weighed by "auto": cm_deform_options.solves) for rbf; lattice (4..200 control points
        per axis, default 10) and clamp (singular values <= clamp x the largest are dropped,
        default 1e-10) for dmffd; samples, cubature, cover, stretch, bend, fix, blend, graded,
        seed and exact_constraints (True, the library's default: the handle and fixed points
        get their prescribed values, the field's miss carried into the free points near them;
        False: the field's value, the paper's weighted fit, as `--approximate-constraints`)
        for mls; stretch, bend and fix also
        weigh the shell. None leaves the library's default.
    threads: 0 = all; progress: see cadmorph's Context (a callable (stage, done, total),
        None for the terminal line, False for none).

    The Deformer holds the mesh it deforms (the shell borrows it); not for two threads at
    once (the C API's rule); two Deformers in two threads run in parallel.
    """

    def __init__(self, points: Union[Mesh, np.ndarray], handles: Any,
                 fixed: Union[None, str, Any] = None, method: str = "rbf", *,
                 kernel: Optional[str] = None, solver: Optional[str] = None,
                 tolerance: Optional[float] = None, solves: Optional[int] = None,
                 lattice: Optional[int] = None,
                 clamp: Optional[float] = None, samples: Optional[int] = None,
                 cubature: Optional[int] = None, cover: Optional[int] = None,
                 stretch: Optional[float] = None, bend: Optional[float] = None,
                 fix: Optional[float] = None, blend: Optional[float] = None,
                 graded: Optional[float] = None, seed: Optional[int] = None,
                 exact_constraints: Optional[bool] = None, threads: int = 0,
                 progress: Progress = None) -> None:
        what = "cadmorph.Deformer"
        method = choice(what, "method", method, METHODS)
        xyz, mesh = points_of(what, "points", points)
        n = xyz.shape[0]
        if method in ("mls", "shell") and mesh is None:
            raise ValueError("%s: method %r works on a mesh's cells: points must be a "
                             "cadmorph.Mesh" % (what, method))
        if method == "shell" and lib.cm_mesh_count_dim(mesh._ptr, 3) > 0:
            raise ValueError("%s: method 'shell' deforms surface meshes only" % what)
        self._ctx = Context(threads, progress, what)
        h = index_array(what, "handles", handles, n, mask=True, unique=True, empty=False)
        if isinstance(fixed, str):
            choice(what, "fixed", fixed, ("boundary",))
            if mesh is None:
                raise ValueError("%s: fixed='boundary' needs a cadmorph.Mesh" % what)
            f = _boundary_nodes(self._ctx, mesh)
            f = f[~np.isin(f, h)]
        elif fixed is None:
            f = np.zeros(0, np.int64)
        else:
            f = index_array(what, "fixed", fixed, n, mask=True, unique=True)
            both = np.intersect1d(h, f)
            if len(both):
                raise ValueError("%s: point %d is both a handle and fixed" % (what, both[0]))
        con = np.zeros(max(n, 1), np.uint8)
        con[f] = _FIXED_GROUP
        con[h] = _HANDLE_GROUP
        opt = ffi.new("cm_deform_options *")
        lib.cm_deform_options_init(opt)
        opt.method = lib.cm_deform_method_from_name(method.encode())
        if kernel is not None:
            opt.kernel = _KERNELS[choice(what, "kernel", kernel, tuple(_KERNELS))]
        if solver is not None:
            opt.solver = SOLVERS[choice(what, "solver", solver, tuple(SOLVERS))]
        if tolerance is not None:
            opt.tolerance = number(what, "tolerance", tolerance, 0, 1, hi_open=True)
        if solves is not None:
            opt.solves = integer(what, "solves", solves, 1, 2 ** 31 - 1)
        opt.lattice = integer(what, "lattice", 10 if lattice is None else lattice, 4, 200)
        if clamp is not None:
            opt.clamp = number(what, "clamp", clamp, 0, 1, lo_open=True, hi_open=True)
        mls = opt.mls
        if samples is not None:
            mls.samples = integer(what, "samples", samples, 1, 2 ** 62)
        if cubature is not None:
            mls.cubature = integer(what, "cubature", cubature, 1, 2 ** 62)
        if cover is not None:
            mls.cover = integer(what, "cover", cover, 1, 64)
        if stretch is not None:
            mls.stretch = number(what, "stretch", stretch, 0)
        if bend is not None:
            mls.bend = number(what, "bend", bend, 0)
        if fix is not None:
            mls.fix = number(what, "fix", fix, 0, lo_open=True)
        if blend is not None:
            mls.blend = number(what, "blend", blend, 0)
        if graded is not None:
            mls.graded = number(what, "graded", graded, 0, 1)
        if seed is not None:
            mls.seed = integer(what, "seed", seed, 0, 2 ** 64 - 1)
        if exact_constraints is not None:
            mls.keep_constrained = bool(exact_constraints)
        if method in ("mls", "shell") and mls.stretch + mls.bend <= 0:
            raise ValueError("%s: stretch + bend must be > 0" % what)
        self._mesh_owner = mesh._ptr if mesh is not None else None  # the shell borrows it
        self._con = con
        self._ptr = self._ctx.create(
            lib.cm_deform_create, "cm_deform", lib.cm_deform_destroy, opt, n,
            ffi.from_buffer("double[]", xyz) if n else ffi.NULL,
            ffi.from_buffer("unsigned char[]", con),
            self._mesh_owner if self._mesh_owner is not None else ffi.NULL)
        self._xyz = xyz.copy()  # the reference the displacements are added to
        self.method: str = method
        """The method's name."""
        self.handles: np.ndarray = h
        """The handle indices, int64, in the order apply's displacements follow."""
        self.fixed: np.ndarray = f
        """The fixed indices, int64 (fixed='boundary' resolved)."""
        self.residual: float = 0.0
        """The last apply's largest miss at the constrained points (rbf: 0)."""

    @property
    def n_points(self) -> int:
        """Number of points."""
        return self._xyz.shape[0]

    def displacement(self, displacements: Any) -> np.ndarray:
        """The (n, 3) displacement of every point when the handles move by displacements
        ((len(handles), 3), in the order of handles) and the fixed points stay
        (cm_deform_apply)."""
        what = "cadmorph.Deformer.apply"
        d = real_array(what, "displacements", displacements, (len(self.handles), 3))
        n = self.n_points
        disp = np.zeros((max(n, 1), 3))
        disp[self.handles] = d
        res = ffi.new("double *")
        self._ctx.call(lib.cm_deform_apply, self._ptr, ffi.from_buffer("double[]", disp), res)
        self.residual = float(res[0])
        return disp[:n]

    def apply(self, displacements: Any) -> np.ndarray:
        """The (n, 3) new coordinates of the points (points + displacement(displacements),
        the sum `cadmorph deform` writes)."""
        return self._xyz + self.displacement(displacements)

    @property
    def stats(self) -> Dict[str, Any]:
        """cm_deform_get_stats as a dict: method, constrained, free, residual, t_solve,
        t_evaluate and the method's own (rbf, dmffd, lattice, control_points, mls)."""
        st = ffi.new("cm_deform_stats *")
        lib.cm_deform_get_stats(self._ptr, st)
        out = struct_dict(st)
        out["method"] = self.method
        return out

    def __repr__(self) -> str:
        return "<cadmorph.Deformer %s: %d points, %d handles, %d fixed>" % (
            self.method, self.n_points, len(self.handles), len(self.fixed))


def deform(points: Union[Mesh, np.ndarray], handles: Any, displacements: Any,
           method: str = "rbf", fixed: Union[None, str, Any] = None, *, threads: int = 0,
           progress: Progress = None, **options: Any) -> np.ndarray:
    """The (n, 3) new coordinates of points (a Mesh or an (n, 3) array) when the handle
    points move by displacements ((len(handles), 3)), the fixed points stay and the others
    follow the method: Deformer(points, handles, fixed, method, **options).apply(
    displacements), as `cadmorph deform --handles H.csv [--fixed F.csv |
    --fix-unlisted-boundary] --method M` (whose default method is mls; here rbf).
    The mesh itself is not changed."""
    what = "cadmorph.deform"
    # the arrays checked before the set-up, which may take long
    xyz, _ = points_of(what, "points", points)
    h = index_array(what, "handles", handles, xyz.shape[0], mask=True, unique=True,
                    empty=False)
    d = real_array(what, "displacements", displacements, (len(h), 3))
    return Deformer(points, h, fixed, method, threads=threads, progress=progress,
                    **options).apply(d)
