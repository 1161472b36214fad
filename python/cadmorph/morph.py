"""Morpher: a mesh of G classified on G once (cm_morpher_create), then morphed onto any G' of
G's topology (cm_morpher_apply), sharing the warp's factorisation between targets; and
morph(), the one-shot form that returns the mesh `cadmorph morph` writes.

The pipeline is docs/DESIGN.md's: boundary nodes follow their CAD vertex, edge or face onto
G' (the surface morph [SMB12 §4]), the interior follows by a warp [SMB12 §3].
"""
import inspect
import threading
from dataclasses import dataclass, fields
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from ._capi import ffi, lib
from ._context import Context, Progress
from ._inputs import choice, flag, integer, mesh_of, model_of, number, path_bytes, points, real_array
from ._options import WarpSettings
from .errors import MismatchError, RejectedError
from .design import DesignTable, differences
from .geometry import Geometry
from .mesh import _TOKEN, Mesh

# cm_cad_match renumbers a target in place: one at a time, so that a Morpher in another
# thread never compares against a model being renumbered
_MATCH_LOCK = threading.Lock()


@dataclass(frozen=True)
class MorphStep:
    """One row of a morph (cm_morph_step): a step of the boundary motion, accepted or (for
    adaptive steps) rejected. Times in seconds.

    Attributes:
        step: 1-based row number.
        min_sj, mean_sj: scaled Jacobian of the volume cells after the step.
        inverted: volume cells with scaled Jacobian <= 0; cells: volume cells.
        max_dist: largest distance of the boundary nodes to G' after the step (before the
            last step the boundary is a linear blend, so this is how far it still is).
        outside: face nodes whose (u', v') left their trimmed face.
        residual: the warp's miss at the constrained nodes (Warp.residual).
        fraction: of the boundary motion this row reaches (1 for the last).
        accepted: False for a rejected adaptive step (the next row retries a smaller one).
        optimized_moves: node moves kept by the interior optimisation of this step.
        note: why a step was rejected: its worst cells with their scaled Jacobians.
        t_read, t_sample, t_classify, t_surface, t_volume_solve, t_evaluation, t_distance,
        t_write: stage times (read, classify and write are the CLI's: 0 here; sample is the
            target's sampling).
    """

    step: int
    min_sj: float
    mean_sj: float
    inverted: int
    cells: int
    max_dist: float
    outside: int
    residual: float
    fraction: float
    accepted: bool
    optimized_moves: int
    note: str
    t_read: float
    t_sample: float
    t_classify: float
    t_surface: float
    t_volume_solve: float
    t_evaluation: float
    t_distance: float
    t_write: float


@dataclass(frozen=True)
class MorpherInfo:
    """What creating the Morpher (or its last rebase) found (cm_morpher_info).

    Attributes:
        nodes, cells: of the mesh (cells: volume cells); boundary_nodes: on G and off it;
        components: connected components of volume cells.
        counts: boundary nodes on CAD (vertices, edges, faces).
        h: sampling step used on G; class_dist: largest distance of a boundary node to its
            entity of G; diagonal: G's bounding-box diagonal.
        t_sample, t_classify: seconds.
        off_cad_nodes, off_cad_components: boundary nodes off G (off_cad="fixed") and
            the boundary components they form; off_cad_slide: those of them that slide on
            their patches (docs/DESIGN.md, "Boundary motion by patch kind"), the rest stay.
    """

    nodes: int
    cells: int
    boundary_nodes: int
    components: int
    counts: Tuple[int, int, int]
    h: float
    class_dist: float
    diagonal: float
    t_sample: float
    t_classify: float
    off_cad_nodes: int
    off_cad_components: int
    off_cad_slide: int


@dataclass(frozen=True)
class SurfaceStats:
    """The surface morph of the last apply (cm_surface_morph_stats).

    Attributes:
        faces_warped: faces with nodes, one 2D RBF each; faces_skipped: without interior
            nodes.
        outside: face nodes whose (u', v') left the trimmed face of G'; worst_outside_node
            (-1 if none) and worst_outside_dist: the worst of them.
        edges_affine, faces_affine: moved as affine images; affine: the vertices moved by
            one affine map; affine_residual: its largest miss at the vertices (inf: no fit).
    """

    faces_warped: int
    faces_skipped: int
    outside: int
    worst_outside_node: int
    worst_outside_dist: float
    edges_affine: int
    faces_affine: int
    affine: bool
    affine_residual: float


def _record(cls: type, c: Any) -> Any:
    """A dataclass of cls from the C struct c, field by field (same names)."""
    values = {}
    for f in fields(cls):
        v = getattr(c, f.name)
        if f.type is str:
            v = ffi.string(v).decode("utf-8", "replace")
        elif f.type is bool:
            v = bool(v)
        elif f.type is float:
            v = float(v)
        elif f.type is int:
            v = int(v)
        else:  # the counts
            v = tuple(int(x) for x in v)
        values[f.name] = v
    return cls(**values)


_SURFACES = {"rbf": lib.CM_SURFACE_RBF, "project": lib.CM_SURFACE_PROJECT}
_OFF_CAD = {"refuse": lib.CM_OFF_CAD_REFUSE, "fixed": lib.CM_OFF_CAD_FIXED}


def _morph_options(what: str, method: str = "rbf", kernel: Optional[str] = None,
                   surface: str = "rbf", steps: Union[int, str] = "auto",
                   min_sj: float = 0.0, min_step: float = 1.0 / 256,
                   keep_fraction: float = 0.0, allow_inverted: bool = False,
                   escalate: bool = True, optimize: bool = False, optimize_sweeps: int = 6,
                   optimize_target_sj: float = 0.3, optimize_newton: int = 4,
                   solver: str = "auto", tolerance: float = 0.0,
                   lattice: Optional[int] = None, clamp: Optional[float] = None,
                   samples: Optional[int] = None, cubature: Optional[int] = None,
                   cover: int = 5, stretch: float = 1.0, bend: float = 1.0,
                   blend: float = 1.5, graded: float = 0.0, solves: int = 1,
                   cad_tol: float = 1e-6,
                   cad_abs_tol: float = 1e-9, off_cad: str = "refuse",
                   keep_offset: bool = False, max_samples: Optional[int] = None,
                   target_h_scale: float = 1.0, surface_spacing: float = 0.0,
                   surface_min_per_edge: int = 8, surface_max_per_edge: int = 200,
                   affine_tol: float = 1e-9) -> Tuple[Any, WarpSettings, str]:
    """The Morpher's options checked (see Morpher), as a cm_morph_options (cffi-owned), the
    warp settings and the surface method's name."""
    warp = WarpSettings(what, method=method, kernel=kernel, solver=solver,
                        tolerance=tolerance, lattice=lattice, clamp=clamp, samples=samples,
                        cubature=cubature, cover=cover, stretch=stretch, bend=bend,
                        blend=blend, graded=graded, solves=solves)
    surface_ = choice(what, "surface", surface, list(_SURFACES))
    o = ffi.new("cm_morph_options *")
    lib.cm_morph_options_init(o)
    _fill_method(ffi.addressof(o, "method"), warp, surface_)
    if isinstance(steps, str):
        if steps != "auto":
            raise ValueError("%s: steps must be 1..4096 or 'auto', not %r" % (what, steps))
        o.steps = lib.CM_MORPH_STEPS_AUTO
    else:
        o.steps = integer(what, "steps", steps, 1, 4096)
    o.min_sj = number(what, "min_sj", min_sj, -1.0, 1.0, hi_open=True)
    o.min_fraction = number(what, "min_step", min_step, 0.0, 1.0, lo_open=True,
                            hi_open=True)
    o.keep_fraction = number(what, "keep_fraction", keep_fraction, 0.0, 1.0)
    o.escalate = flag(what, "escalate", escalate)
    o.allow_inverted = flag(what, "allow_inverted", allow_inverted)
    o.optimize = flag(what, "optimize", optimize)
    o.optimize_options.sweeps = integer(what, "optimize_sweeps", optimize_sweeps, 0, 10000)
    o.optimize_options.target_sj = number(what, "optimize_target_sj", optimize_target_sj,
                                          -1.0, 1.0)
    o.optimize_options.newton = integer(what, "optimize_newton", optimize_newton, 1, 100)
    o.classify.rel_tol = number(what, "cad_tol", cad_tol, 0.0, 1.0, lo_open=True)
    o.classify.abs_tol = number(what, "cad_abs_tol", cad_abs_tol, 0.0, 1.0)
    o.off_cad = _OFF_CAD[choice(what, "off_cad", off_cad, list(_OFF_CAD))]
    o.keep_offset = flag(what, "keep_offset", keep_offset)
    if max_samples is not None:
        o.max_samples = integer(what, "max_samples", max_samples, 1, 10 ** 12)
    o.target_h_scale = number(what, "target_h_scale", target_h_scale, 1.0, 1e6)
    o.morph.spacing = number(what, "surface_spacing", surface_spacing, 0.0)
    o.morph.min_per_edge = integer(what, "surface_min_per_edge", surface_min_per_edge, 2,
                                   100000)
    o.morph.max_per_edge = integer(what, "surface_max_per_edge", surface_max_per_edge,
                                   o.morph.min_per_edge, 100000)
    o.morph.affine_tol = number(what, "affine_tol", affine_tol, 0.0, 1.0, hi_open=True)
    return o, warp, surface_


def _fill_method(c, warp: WarpSettings, surface: str) -> None:
    """Writes a method (surface and warp) into a cm_morph_method *."""
    c.surface = _SURFACES[surface]
    warp.fill(ffi.addressof(c, "warp"))


_OPTION_NAMES = frozenset(inspect.signature(_morph_options).parameters) - {"what"}


class Morpher:
    """A mesh of the CAD model g0, ready to be morphed onto edited models of the same
    topology: `apply(g1)` returns the morphed node coordinates; the classification of the
    boundary on g0 and the warp's factorisation are made once and shared by every target
    (an absolute study: one Morpher, many `apply`).

    Arguments: g0, a cadmorph.Geometry the mesh lies on; mesh, a cadmorph.Mesh with volume
    cells (copied: the Mesh may change or close afterwards). Keyword options, those of
    `cadmorph morph` with its defaults (CLI option in brackets):

    Method:
        method: interior warp [--method]: "rbf" (triharmonic RBF), "rbf-biharmonic",
            "femwarp", "lbwarp", "simplex", "dmffd", "mls"; kernel [--kernel]:
            "triharmonic" / "biharmonic", other names of "rbf" / "rbf-biharmonic".
        surface: how the boundary reaches G' [--surface]: "rbf" (parameter-space warp per
            face, the method) or "project" (closest point, the baseline).
        solver [--solver], tolerance [--rbf-tol], lattice [--lattice], clamp [--clamp],
            samples, cubature, cover, stretch, bend, blend, graded [the MLS options]: as
            cadmorph.Warp; solves: as cadmorph.Warp, the targets you will apply from G0
            (their warps share one fit: a loop over many targets, as `cadmorph study`
            counts its variants; later steps of an adaptive morph count one).
    Steps (a result is valid when no cell is inverted and, for min_sj > 0, every scaled
    Jacobian is above min_sj; apply returns valid meshes only, unless allow_inverted):
        steps [--steps]: "auto" (the default): adaptive steps, the whole motion first (a
            valid one-step morph costs what steps=1 costs and is the same mesh), halved
            on failure, until the mesh is valid; or 1..4096 equal increments (each after
            the first refits the warp on the last mesh; 1: the plain one-step morph of the
            papers), the first increment that is not valid raising RejectedError.
        min_sj [--min-sj]: the floor of a valid mesh, in [-1, 1) (<= 0: no inverted cell).
        min_step [--min-step]: smallest adaptive step, a fraction of the motion in (0, 1)
            (the library's min_fraction; default 1/256).
        keep_fraction: steps="auto": while steps can still shrink, also keep the minimum
            scaled Jacobian above keep_fraction x the mesh's own, in [0, 1] (0: off).
        escalate: steps="auto" without optimize: when no step is valid, the rest of the
            motion is retried with interior optimisation (a CadmorphWarning says so);
            False: RejectedError there [--no-escalate].
        allow_inverted [--allow-inverted]: return the result whatever its cells (never a
            RejectedError for inverted cells; check `steps[-1].inverted`): fixed steps run
            to the end, steps="auto" morphs the rest of the motion in one step when no step
            is valid (a CadmorphWarning says so). Default False.
        optimize [--optimize]: optimise the interior after every step (boundary nodes stay
            on G'); optimize_sweeps (0..10000, default 6), optimize_target_sj ([-1, 1],
            default 0.3), optimize_newton (1..100, default 4): its options (optimize.h).
    Classification:
        cad_tol [--cad-tol]: a boundary node is on G within cad_tol x its shortest
            boundary edge, in (0, 1] (default 1e-6); cad_abs_tol: plus cad_abs_tol x G's
            diagonal, in [0, 1] (default 1e-9).
        off_cad [--off-cad]: boundary nodes not on G: "refuse" (MismatchError) or "fixed"
            (kept in place: whole boundary components off G, e.g. a wind tunnel).
        keep_offset [--keep-offset]: boundary nodes keep their offset from G (a mesh
            snapped near G) instead of landing on G'.
        max_samples: cap on the samples of G for its locator (None: 64 per boundary
            node, at least 250,000, at most 4e6); target_h_scale: no longer used (the
            targets are not sampled), >= 1.
        surface_spacing (>= 0, 0: automatic), surface_min_per_edge (2..100000, default 8),
            surface_max_per_edge (default 200), affine_tol ([0, 1), default 1e-9; 0 off):
            the surface morph's options (surface.h).
    Calls:
        threads [--threads]: the library's threads, 0 = all; progress: a callable
            (stage, done, total), None for the CLI's progress line on a terminal, False for
            none; raising in it (or Ctrl-C) stops the call and is raised from it.

    Not here: --from/--to/--mesh/-o/--report/--cad-unit (files: read_step's unit,
    read_mesh, write_mesh, and `steps` for the report), --fail-on-inverted (the default:
    RejectedError), --keep-partial (RejectedError always carries the last valid mesh),
    --relative --via (`rebase`, or `morph(..., via=[...])`), --verbose (the "cadmorph"
    logger).

    Lifetimes: the library borrows G and the last target; the Morpher holds references to
    those Geometry objects, so deleting them while the Morpher lives is safe. The mesh is
    copied: a caller who no longer needs `mesh` may drop it (`del mesh`, with its views) to
    free that copy before a large morph.
    Threads: one Morpher is used by one thread at a time (calls from several threads wait
    for each other); two Morphers run in parallel in two threads (the GIL is released in
    the library). Results are bit for bit those of `cadmorph morph` with the same options
    and threads when OpenBLAS runs as in the CLI (started with OPENBLAS_NUM_THREADS=1):
    the sparse methods' sums, and dense factorisations in concurrent threads, depend on its
    thread count.

    Raises TypeError/ValueError for bad arguments, MismatchError (the library's message)
    when the mesh is not a mesh of g0, BadInputError for other input the library refuses.
    """

    def __init__(self, g0: Geometry, mesh: Mesh, *, method: str = "rbf",
                 kernel: Optional[str] = None, surface: str = "rbf",
                 steps: Union[int, str] = "auto", min_sj: float = 0.0,
                 min_step: float = 1.0 / 256, keep_fraction: float = 0.0,
                 allow_inverted: bool = False, escalate: bool = True, optimize: bool = False,
                 optimize_sweeps: int = 6, optimize_target_sj: float = 0.3,
                 optimize_newton: int = 4, solver: str = "auto", tolerance: float = 0.0,
                 lattice: Optional[int] = None, clamp: Optional[float] = None,
                 samples: Optional[int] = None, cubature: Optional[int] = None, cover: int = 5,
                 stretch: float = 1.0, bend: float = 1.0, blend: float = 1.5,
                 graded: float = 0.0, solves: int = 1, cad_tol: float = 1e-6,
                 cad_abs_tol: float = 1e-9,
                 off_cad: str = "refuse", keep_offset: bool = False,
                 max_samples: Optional[int] = None, target_h_scale: float = 1.0,
                 surface_spacing: float = 0.0, surface_min_per_edge: int = 8,
                 surface_max_per_edge: int = 200, affine_tol: float = 1e-9,
                 threads: int = 0, progress: Progress = None) -> None:
        what = "cadmorph.Morpher"
        self._mp = None
        self._lock = threading.Lock()
        options = {k: v for k, v in locals().items() if k in _OPTION_NAMES}
        gp = model_of(what, "g0", g0)
        m = mesh_of(what, "mesh", mesh)._ptr
        o, self._warp, self._surface = _morph_options(what, **options)
        self._ctx = ctx = Context(threads, progress, what)
        self._mp = ctx.create(lib.cm_morpher_create, "cm_morpher", lib.cm_morpher_destroy,
                              gp, m, o)
        self._n = int(m.n_nodes)
        # what the library borrows: G (the Geometry and its pointer object) and, after an
        # apply, the last target; a failed rebase may have switched G, so its model is held
        # too (_held)
        self._base: Tuple[Any, Any] = (g0, gp)
        self._target: Optional[Tuple[Any, Any]] = None
        self._held: List[Tuple[Any, Any]] = []
        self._checked: Optional[Tuple[Any, Any]] = None  # (base ptr, target) known to match
        self._steps: List[MorphStep] = []

    def _correspond(self, g: Any, gp) -> None:
        """g numbered like G (cm_cad_match renumbers it in place when it corresponds to G
        with another numbering, as `cadmorph morph` does with its G1); MismatchError with
        the differences when it does not correspond."""
        base = self._base[1]
        if gp == base or (self._checked is not None and self._checked[0] == base
                          and self._checked[1] is g):
            return
        with _MATCH_LOCK:
            try:
                self._ctx.call(lib.cm_cad_compare, base, gp, 5)
            except MismatchError:
                self._ctx.call(lib.cm_cad_match, base, gp, 5, ffi.NULL)
        self._checked = (base, g)

    def _rows(self) -> List[MorphStep]:
        n = ffi.new("size_t *")
        rows = lib.cm_morpher_steps(self._mp, n)
        return [_record(MorphStep, rows[i]) for i in range(int(n[0]))]

    def apply(self, g1: Geometry, method: Optional[str] = None,
              **method_options: Any) -> np.ndarray:
        """The mesh morphed onto g1: node coordinates, a new (n_nodes, 3) float64 array the
        library fills in place. Boundary nodes lie on g1 (exactly where the surface morph
        sent them), the interior follows by the warp.

        g1: a cadmorph.Geometry of G's topology. When it numbers its faces, edges or
        vertices otherwise (a re-export), it is renumbered in place like G, once, as the CLI
        does (cm_cad_match); do that first (one apply) before sharing g1 between threads.

        method and method_options (surface, kernel, solver, tolerance, lattice, clamp and
        the MLS options): another method for this call (cm_morpher_apply_method), the
        others as the Morpher's; each set of warp options is factorised once and kept. A
        kept RBF warp with the iterative solver also keeps its last solutions, and each
        apply starts from the combination of them nearest its data (cm_rbf_options
        warm_start): over nearby targets, an optimiser's steps, an apply takes 2-3 Krylov
        iterations (the bore's variants; 6-7 from zero).

        Afterwards `steps` holds every row of this apply, `quality` the cells' scaled
        Jacobian, `surface_stats` the surface morph's figures.

        Raises MismatchError when g1 does not correspond to G (the library's message lists
        the differences); RejectedError when no valid mesh is reached (see `steps`; never
        with allow_inverted): the exception's `points` is the last valid mesh (n_nodes, 3;
        the Morpher's own mesh when the first step failed) and its `steps` the rows,
        rejected ones included. A CadmorphWarning when face nodes left their trimmed face.
        """
        what = "cadmorph.Morpher.apply"
        tp = model_of(what, "g1", g1)
        c_method = None
        if method is not None or method_options:
            unknown = set(method_options) - (set(WarpSettings.NAMES) | {"surface"})
            if unknown:
                raise TypeError("%s: unknown option %s (method options: surface, %s)"
                                % (what, ", ".join(sorted(unknown)),
                                   ", ".join(WarpSettings.NAMES)))
            surface = choice(what, "surface", method_options.pop("surface", self._surface),
                             list(_SURFACES))
            if method is not None:
                method_options["method"] = method
            warp = self._warp.replaced(what, **method_options)
            c_method = ffi.new("cm_morph_method *")
            lib.cm_morph_method_init(c_method)
            _fill_method(c_method, warp, surface)
        out = np.empty((self._n, 3), np.float64)
        row = ffi.new("cm_morph_step *")
        buf = ffi.from_buffer("double[]", out)
        with self._lock:
            self._correspond(g1, tp)
            # from here the library holds a pointer to g1: so does this object
            self._target = (g1, tp)
            try:
                if c_method is None:
                    self._ctx.call(lib.cm_morpher_apply, self._mp, tp, buf, row)
                else:
                    self._ctx.call(lib.cm_morpher_apply_method, self._mp, tp, c_method, buf,
                                   row)
            except RejectedError as e:
                e.points = out
                e.steps = self._steps = self._rows()
                raise
            finally:
                self._steps = self._rows()
        return out

    def rebase(self, g: Geometry, pts: Any) -> None:
        """Relative morphing: the Morpher now starts from the mesh at pts (n_nodes, 3),
        e.g. the last apply's result, lying on g (e.g. that apply's target): its boundary is
        classified on g again and the warps are refactorised when next used. g is renumbered
        like G when needed, as in apply.

        Raises MismatchError when g does not correspond to G or the mesh at pts is not on
        g; ValueError for pts of another shape or not finite. After a failed or interrupted
        rebase, apply raises cadmorph.Error until a rebase succeeds.
        """
        what = "cadmorph.Morpher.rebase"
        gp = model_of(what, "g", g)
        p = points(what, "pts", pts, self._n)
        with self._lock:
            self._correspond(g, gp)
            try:
                self._ctx.call(lib.cm_morpher_rebase, self._mp, gp, ffi.from_buffer("double[]", p))
            except BaseException:
                # the library may have switched to g before failing: keep it alive
                self._held.append((g, gp))
                raise
            self._base = (g, gp)
            self._held.clear()
            self._checked = None

    @property
    def steps(self) -> List[MorphStep]:
        """The rows of the last apply, in order (accepted and rejected adaptive steps);
        [] before the first apply."""
        return list(self._steps)

    @property
    def info(self) -> MorpherInfo:
        """What creating the Morpher (or the last rebase) found: counts, h, distances."""
        return _record(MorpherInfo, lib.cm_morpher_get_info(self._mp))

    @property
    def surface_stats(self) -> SurfaceStats:
        """The surface morph's figures of the last apply (zeros before the first)."""
        return _record(SurfaceStats, lib.cm_morpher_surface_stats(self._mp))

    @property
    def quality(self) -> np.ndarray:
        """Per-cell scaled Jacobian of the last apply's last trial (of the mesh itself before
        the first apply): an (n_cells,) float64 copy over every element in file order, NaN
        for elements of dimension < 3. After a RejectedError it is that of the rejected
        trial, not of the exception's points."""
        with self._lock:
            m = lib.cm_morpher_mesh(self._mp)
            n = int(m.n_cells)
            q = lib.cm_morpher_quality(self._mp)
            if n == 0 or q == ffi.NULL:
                return np.zeros(n, np.float64)
            return np.frombuffer(ffi.buffer(q, 8 * n), np.float64).copy()

    @property
    def mesh(self) -> Mesh:
        """A copy of the mesh the Morpher starts from (the mesh given, or the mesh of the
        last rebase), as a new cadmorph.Mesh: changing it does not change the Morpher."""
        with self._lock:
            return _copy_mesh(self._ctx, lib.cm_morpher_mesh(self._mp))

    @property
    def n_nodes(self) -> int:
        """Number of nodes (rows of apply's result)."""
        return self._n

    def result_mesh(self, pts: Any) -> Mesh:
        """The Morpher's mesh at pts (e.g. apply's result) as `cadmorph morph` writes it: a
        new Mesh with the per-node field "displacement" (pts minus the Morpher's mesh) and
        the per-cell "scaled_jacobian"."""
        p = points("cadmorph.Morpher.result_mesh", "pts", pts, self._n)
        with self._lock:
            mesh = _copy_mesh(self._ctx, lib.cm_morpher_mesh(self._mp))
            m = mesh._ptr
            # as cm_morph_run: the quality field before the displacement field
            self._ctx.call(lib.cm_mesh_add_field, m, b"scaled_jacobian", lib.CM_FIELD_CELL, 1,
                           ffi.NULL)
            x = mesh.points
            disp = p - x
            x[...] = p
            self._ctx.call(lib.cm_mesh_apply_displacement, m, ffi.from_buffer("double[]", disp),
                           lib.CM_DISPLACEMENT_QUALITY, ffi.NULL)
        return mesh

    def _velocities(self, what: str, table: DesignTable, base: Union[None, int, Any],
                    interior: bool) -> Any:
        """cm_design_velocity on this Morpher's mesh (owned cm_design_velocities *)."""
        if not isinstance(table, DesignTable):
            raise TypeError("%s: table must be a cadmorph.DesignTable, not %s"
                            % (what, type(table).__name__))
        g0, gp = self._base
        if base is None:
            if not g0.path:
                raise ValueError("%s: the Morpher's geometry has no file: give base, the row "
                                 "of the table it is" % what)
            row = table.row_of(g0.path)
        elif isinstance(base, (int, np.integer)) and not isinstance(base, bool):
            row = integer(what, "base", base, 0, len(table.rows) - 1)
        else:
            row = table.row_of(path_bytes(what, "base", base).decode())
        ro = ffi.new("cm_cad_read_options *")
        lib.cm_cad_read_options_init(ro)
        unit = ffi.new("char[]", g0.unit.encode())
        ro.unit = unit
        with self._lock:
            return self._ctx.create(lib.cm_design_velocity, "cm_design_velocities",
                                    lib.cm_design_velocities_destroy, self._mp, gp, table._ptr,
                                    row, ro, 1 if interior else 0)

    def design_velocity(self, table: DesignTable,
                        base: Union[None, int, str] = None) -> Dict[str, np.ndarray]:
        """Design velocities dX/dp of every node for each parameter of a design table
        (cm_design_velocity): parameter name -> (n_nodes, 3) float64 array, in mesh unit
        per parameter unit. The boundary part is a difference of the surface morphs onto the
        table's rows that change the parameter alone (central where rows lie on both sides,
        else one-sided: `design_differences`), the interior the warp's forward product with
        this Morpher's factorisation. Parameters that no row changes alone are left out (a
        CadmorphWarning names them).

        table: a cadmorph.DesignTable whose rows are variants of this Morpher's G.
        base: the row of G: its index, or its STEP path; None: the row whose file is the
        one G was read from.

        Raises MismatchError when no row is G's file or a row does not correspond to G,
        BadInputError (FormatError) when no parameter can be differenced, cadmorph.Error
        (unsupported) for a warp that is not linear in the boundary motion.
        """
        v = self._velocities("cadmorph.Morpher.design_velocity", table, base, True)
        self._differences = dict(zip(table.parameters, differences(v)))
        n, nn = int(v.n_parameters), int(v.n_nodes)
        data = np.frombuffer(ffi.buffer(v.v, 8 * n * nn * 3), np.float64).reshape(n, nn, 3)
        return {name: data[j].copy() for j, name in enumerate(table.parameters)
                if v.diff[j].scheme != lib.CM_DESIGN_NONE}

    @property
    def design_differences(self) -> Dict[str, Tuple[str, float, float]]:
        """For the last design_velocity or gradient: parameter -> (difference, dp_plus,
        dp_minus), difference "central", "forward", "backward" or "none" (skipped), dp_* the
        rows' values minus the base row's."""
        return dict(getattr(self, "_differences", {}))

    def gradient(self, table: DesignTable, dJdX: Any, base: Union[None, int, str] = None,
                 boundary_only: bool = False) -> Dict[str, float]:
        """dJ/dp = sum over nodes of dJdX . dX/dp for each parameter of a design table
        (cm_design_gradient): parameter name -> float (skipped parameters left out).

        dJdX: (n_nodes, 3) sensitivity of an objective J to the node coordinates.
        boundary_only: dJdX is read at the boundary nodes only (a surface sensitivity map);
        else the sum runs over every node, computed as <J^T dJdX, dX_b/dp> with one reverse
        product of the warp for all parameters. base: as design_velocity.
        """
        what = "cadmorph.Morpher.gradient"
        s = real_array(what, "dJdX", dJdX, (self._n, 3))
        flag(what, "boundary_only", boundary_only)
        v = self._velocities(what, table, base, False)
        self._differences = dict(zip(table.parameters, differences(v)))
        n = int(v.n_parameters)
        out = ffi.new("double[]", max(n, 1))
        with self._lock:
            self._ctx.call(lib.cm_design_gradient, self._mp, v, ffi.from_buffer("double[]", s),
                           1 if boundary_only else 0, out, ffi.NULL)
        return {name: float(out[j]) for j, name in enumerate(table.parameters)
                if v.diff[j].scheme != lib.CM_DESIGN_NONE}

    def __repr__(self) -> str:
        i = self.info
        return "<cadmorph.Morpher %d nodes, %d boundary nodes>" % (i.nodes, i.boundary_nodes)


def _copy_mesh(ctx: Context, m) -> Mesh:
    return Mesh(ctx.create(lib.cm_mesh_copy, "cm_mesh", lib.cm_mesh_destroy, m), _TOKEN)


def morph(g0: Geometry, g1: Geometry, mesh: Mesh, *, via: Sequence[Geometry] = (),
          **options: Any) -> Mesh:
    """`cadmorph morph` in memory: mesh (a mesh of g0) morphed onto g1, returned as a new
    Mesh with the fields the CLI writes ("displacement" per node, "scaled_jacobian" per
    cell); write_mesh writes what `cadmorph morph -o` would. Options: those of Morpher.

    via: intermediate Geometry objects for a relative morph g0 -> via[0] -> ... -> g1
    (`--relative --via`): each leg starts from the last result (Morpher.rebase), with
    `steps` increments each; the displacement field is that of the last leg, as in the CLI.

    Returns a valid mesh (no inverted cell) or raises RejectedError, as `cadmorph morph`
    writes M1 or exits 3; allow_inverted=True returns the mesh whatever its cells, as
    `--allow-inverted` (its "scaled_jacobian" field and `quality` say which are inverted).
    Raises as Morpher and Morpher.apply; a RejectedError also carries `mesh`, the last
    valid mesh (with its fields), as `cadmorph morph --keep-partial` writes it.
    """
    if isinstance(via, (str, bytes)) or not isinstance(via, Sequence):
        raise TypeError("cadmorph.morph: via must be a sequence of Geometry objects, not %s"
                        % type(via).__name__)
    morpher = Morpher(g0, mesh, **options)
    chain = list(via) + [g1]
    pts = None
    for k, g in enumerate(chain):
        if k:
            morpher.rebase(chain[k - 1], pts)
        try:
            pts = morpher.apply(g)
        except RejectedError as e:
            e.mesh = morpher.result_mesh(e.points)
            raise
    return morpher.result_mesh(pts)
