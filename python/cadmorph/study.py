"""study and sweep: a mesh M0 of G0 morphed onto every member of a family of geometries by
one or more methods, absolutely and/or relatively (study.h, cm_study_run and cm_sweep_run),
as `cadmorph study` and `cadmorph sweep`; the rows as frozen dataclasses, the CSV table and
the SVG plot written by the library."""
import os
import tempfile
from dataclasses import dataclass
from typing import Any, List, Optional, Sequence, Tuple, Union

from ._capi import ffi, lib
from ._context import Context, Progress
from ._inputs import choice, flag, integer, mesh_of, model_of, number, path_bytes, text
from .mesh import Mesh, PathLike
from .geometry import Geometry

_MODES = {"absolute": lib.CM_STUDY_ABSOLUTE, "relative": lib.CM_STUDY_RELATIVE,
          "both": lib.CM_STUDY_BOTH}
_WRITE = {"none": lib.CM_STUDY_WRITE_NONE, "all": lib.CM_STUDY_WRITE_ALL,
          "failed": lib.CM_STUDY_WRITE_FAILED}
_MAX_METHODS = 16  # as the CLI


@dataclass(frozen=True)
class StudyRow:
    """One variant x method x mode of a study (cm_study_row). Times in seconds.

    Attributes:
        mode: "absolute" or "relative".
        method: the method's name as given ("rbf-s", "project", ...).
        variant: 0-based index of the target (the CSV's step is variant + 1).
        label: the variant's name (the STEP file's stem).
        t: its parameter in [0, 1].
        status: cm_status (0 done, > 0 done with a warning, < 0 the error that stopped
            the row: the quality fields are then 0); status_name its name; message the
            library's message.
        min_sj, mean_sj, inverted, cells: quality of the morphed mesh.
        max_dist: largest distance of the boundary nodes to their G.
        outside: face nodes that left their trimmed face.
        residual: the warp's miss at the constrained nodes.
        t_sample, t_classify, t_surface, t_volume_solve, t_evaluation, t_quality,
        t_distance, t_write: stage times (study.h says which row carries shared work).
    """

    mode: str
    method: str
    variant: int
    label: str
    t: float
    status: int
    status_name: str
    message: str
    min_sj: float
    mean_sj: float
    inverted: int
    cells: int
    max_dist: float
    outside: int
    residual: float
    t_sample: float
    t_classify: float
    t_surface: float
    t_volume_solve: float
    t_evaluation: float
    t_quality: float
    t_distance: float
    t_write: float

    @property
    def ok(self) -> bool:
        """True for a complete row (status >= 0)."""
        return self.status >= 0


def _str(chars) -> str:
    return ffi.string(chars).decode("utf-8", "replace")


class StudyResult:
    """The result of study or sweep (a cm_study_result): the summary as attributes, rows
    (a list of StudyRow, variant-major: per variant the absolute rows then the relative),
    write_csv and write_svg as the CLI writes them.

    Attributes: model, mesh (names in the CSV), nodes, cells, boundary_nodes, diagonal (bbox
    diagonal of G0), min_sj0, mean_sj0, inverted0 (quality of M0), threads, methods (names),
    n_variants, n_failed (rows with an error), t_total (seconds), rows.
    """

    def __init__(self, ptr, csv_format: int) -> None:
        """Not for users: made by study and sweep."""
        self._ptr = ptr
        self._csv_format = csv_format
        r = ptr
        self.model: str = _str(r.model)
        self.mesh: str = _str(r.mesh)
        self.nodes: int = int(r.nodes)
        self.cells: int = int(r.cells)
        self.boundary_nodes: int = int(r.boundary_nodes)
        self.diagonal: float = float(r.diagonal)
        self.min_sj0: float = float(r.min_sj0)
        self.mean_sj0: float = float(r.mean_sj0)
        self.inverted0: int = int(r.inverted0)
        self.threads: int = int(r.threads)
        self.methods: List[str] = [_str(r.methods[i].name) for i in range(int(r.n_methods))]
        self.n_variants: int = int(r.n_variants)
        self.n_failed: int = int(r.n_failed)
        self.t_total: float = float(r.t_total)
        rows = []
        for i in range(int(r.n_rows)):
            w = r.rows[i]
            rows.append(StudyRow(
                mode=_str(lib.cm_study_mode_name(w.mode)), method=self.methods[w.method],
                variant=int(w.variant), label=_str(w.label), t=float(w.t),
                status=int(w.status), status_name=_str(lib.cm_status_name(w.status)),
                message=_str(w.message), min_sj=float(w.min_sj), mean_sj=float(w.mean_sj),
                inverted=int(w.inverted), cells=int(w.cells), max_dist=float(w.max_dist),
                outside=int(w.outside), residual=float(w.residual),
                t_sample=float(w.t_sample), t_classify=float(w.t_classify),
                t_surface=float(w.t_surface), t_volume_solve=float(w.t_volume_solve),
                t_evaluation=float(w.t_evaluation), t_quality=float(w.t_quality),
                t_distance=float(w.t_distance), t_write=float(w.t_write)))
        self.rows: List[StudyRow] = rows

    def write_csv(self, path: PathLike, format: Optional[str] = None) -> None:
        """Writes the table (cm_study_write_csv, through a temporary file): format "full"
        (study.csv of `cadmorph study`: every row with variant, status and message) or
        "sweep" (sweep.csv of `cadmorph sweep`: complete rows, its columns); None: the
        format of the command the result matches."""
        what = "cadmorph.StudyResult.write_csv"
        fmt = self._csv_format if format is None else \
            {"full": lib.CM_STUDY_CSV_FULL, "sweep": lib.CM_STUDY_CSV_SWEEP}[
                choice(what, "format", format, ("full", "sweep"))]
        Context(0, False, what).call(lib.cm_study_write_csv, self._ptr,
                                     path_bytes(what, "path", path), fmt)

    def write_svg(self, path: PathLike) -> None:
        """Writes the plot of the min scaled Jacobian per variant (cm_study_write_svg)."""
        what = "cadmorph.StudyResult.write_svg"
        p = path_bytes(what, "path", path)
        Context(0, False, what).call(lib.cm_study_write_svg, self._ptr, p)

    def __repr__(self) -> str:
        return "<cadmorph.StudyResult %s: %d variants, %d rows, %d failed>" % (
            self.model, self.n_variants, len(self.rows), self.n_failed)


def _methods(ctx: Context, methods: Union[None, str, Sequence[str]], default: str,
             what: str) -> Tuple[Any, int]:
    """methods (a comma-separated str or a list of names) parsed by cm_study_methods_parse."""
    if methods is None:
        methods = default
    if not isinstance(methods, str):
        if not all(isinstance(m, str) for m in methods):
            raise TypeError("%s: methods: names (str)" % what)
        methods = ",".join(methods)
    if "\0" in methods:
        raise ValueError("%s: methods: a NUL byte" % what)
    out = ffi.new("cm_study_method[]", _MAX_METHODS)
    n = ffi.new("size_t *")
    status = lib.cm_study_methods_parse(ctx.ptr, methods.encode(), out, _MAX_METHODS, n)
    if status < 0:  # a wrong argument of this call, as the CLI's usage error
        raise ValueError("%s: methods: %s" % (what, ctx.message()))
    return out, int(n[0])


def _steps(steps: Union[int, str], what: str) -> int:
    if isinstance(steps, str):
        choice(what, "steps", steps, ("auto",))
        return lib.CM_MORPH_STEPS_AUTO
    return integer(what, "steps", steps, 1, 1000)


def _batch(batch: Union[int, str], what: str) -> int:
    if isinstance(batch, str):
        choice(what, "batch", batch, ("auto",))
        return 0
    return integer(what, "batch", batch, 1, 1000)


def _stem(path: bytes) -> str:
    base = os.path.basename(path)
    stem = os.path.splitext(base)[0] if not base.startswith(b".") else base
    return os.fsdecode(stem or base)


def study(g0: Geometry, mesh: Mesh, targets: Sequence[Union[PathLike, Geometry]],
          methods: Union[None, str, Sequence[str]] = None, mode: str = "absolute",
          steps: Union[int, str] = "auto", optimize: bool = False, write_meshes: str = "none",
          out_dir: Optional[PathLike] = None, model_name: Optional[str] = None,
          mesh_name: Optional[str] = None, *, allow_inverted: bool = False,
          batch: Union[int, str] = "auto", threads: int = 0,
          progress: Progress = None) -> StudyResult:
    """Morphs mesh (a cadmorph.Mesh of g0, a cadmorph.Geometry) onto every target, as
    `cadmorph study --from G0.step --mesh M0 --variants LIST -o DIR`.

    targets: STEP paths and/or Geometry objects of G0's topology, in order (a variant that
    cannot be read or does not match G0 is a row with its error, not an exception). Paths
    are read in g0's unit; a Geometry is written to a temporary STEP file and read back (a
    user's file goes through the same), named by the stem of the file it was read from, else
    "G<i>" (1-based). methods: a comma-separated str or a list of names ("rbf-s",
    "project", "rbf-s-biharmonic", "<warp>", "rbf-s-<warp>", "project-<warp>"); None:
    "rbf-s", the CLI's default. mode: "absolute" (default), "relative" or "both". steps:
    "auto" (default: adaptive steps, as Morpher) or increments of each morph (1..1000; 1:
    the plain one-step morph). A morph that reaches no valid mesh is a row with status
    CM_ERR_REJECTED ("result rejected") and its message, and no mesh; allow_inverted=True
    keeps such results (rows with their inverted cells, meshes written). optimize: interior
    optimisation after each step. write_meshes: "none" (default here; the CLI's is "all"), "all" or "failed"; the
    meshes go to out_dir (created if missing) as <method>_<mode>_<label>.vtu. model_name,
    mesh_name: the CSV's model and mesh columns (default: g0's file name and "file").
    batch: absolute variants morphed together, as `--batch` ("auto", the default: all the
    variants, at most what half the free memory holds and 20, solved in 4 groups, each later
    group starting from the solutions before it; 1: one at a time; K: K): their warps share
    one multi-column solve and evaluation; the rows are those of one at a time to the solver's
    tolerance, in the same order. Relative series run one variant at a time.

    Errors that end the study (mesh not a mesh of g0, ...) raise; failed rows are a
    CadmorphWarning and rows with status < 0 (n_failed > 0: where the CLI exits 3).
    """
    what = "cadmorph.study"
    model = model_of(what, "g0", g0)
    mesh_of(what, "mesh", mesh)
    if isinstance(targets, (str, bytes, os.PathLike)):
        raise TypeError("%s: targets is a list (of paths and/or Geometry objects)" % what)
    targets = list(targets)
    if not targets:
        raise ValueError("%s: no target" % what)
    ctx = Context(threads, progress, what)
    so = ffi.new("cm_study_options *")
    lib.cm_study_options_init(so)
    so.modes = _MODES[choice(what, "mode", mode, tuple(_MODES))]
    ms, nm = _methods(ctx, methods, "rbf-s", what)
    so.methods, so.n_methods = ms, nm
    so.morph.steps = _steps(steps, what)
    so.morph.optimize = bool(optimize)
    so.morph.allow_inverted = flag(what, "allow_inverted", allow_inverted)
    so.batch = _batch(batch, what)
    so.write_meshes = _WRITE[choice(what, "write_meshes", write_meshes, tuple(_WRITE))]
    keep = [ms]
    if so.write_meshes != lib.CM_STUDY_WRITE_NONE:
        if out_dir is None:
            raise ValueError("%s: write_meshes=%r needs out_dir" % (what, write_meshes))
        d = path_bytes(what, "out_dir", out_dir)
        os.makedirs(d, exist_ok=True)
        c = ffi.new("char[]", d)
        keep.append(c)
        so.out_dir = c
    unit = lib.cm_cad_unit(model)
    so.morph.cad_unit = unit
    g0_path = lib.cm_cad_path(model)
    g0_path = ffi.string(g0_path) if g0_path != ffi.NULL else b""
    for name, value, default in (("model", model_name, os.path.basename(g0_path) or b"G0"),
                                 ("mesh", mesh_name, None)):
        if value is not None:
            value = text(what, name + "_name", value, empty=True)
        else:
            value = default
        if value is not None:
            c = ffi.new("char[]", value)
            keep.append(c)
            setattr(so, name, c)
    ro = ffi.new("cm_cad_read_options *")
    lib.cm_cad_read_options_init(ro)
    ro.unit = unit
    with tempfile.TemporaryDirectory(prefix="cadmorph_study_") as tmp:
        paths = []
        for i, t in enumerate(targets):
            if isinstance(t, (str, bytes, os.PathLike)):
                paths.append(path_bytes(what, "targets[%d]" % i, t))
                continue
            g = model_of(what, "targets[%d]" % i, t)
            gp = lib.cm_cad_path(g)
            gp = ffi.string(gp) if gp != ffi.NULL else b""
            label = _stem(gp) if gp else "G%d" % (i + 1)
            sub = os.path.join(os.fsencode(tmp), b"%d" % i)
            os.mkdir(sub)
            p = os.path.join(sub, os.fsencode(label) + b".step")
            ctx.call(lib.cm_cad_write, g, p)
            paths.append(p)
        cpaths = [ffi.new("char[]", p) for p in paths]
        arr = ffi.new("const char *[]", cpaths) if cpaths else ffi.NULL
        fam = ffi.new("cm_study_family *")
        ctx.call(lib.cm_study_family_files, arr, len(cpaths), ro, fam)
        try:
            result = ctx.create(lib.cm_study_run, "cm_study_result",
                                lib.cm_study_result_destroy, model, mesh._ptr, fam, so)
        finally:
            lib.cm_study_family_release(fam)
    return StudyResult(result, lib.CM_STUDY_CSV_FULL)


def sweep(model: str = "bore", mesh: Union[str, PathLike] = "tet", steps: int = 10,
          mode: str = "both", size: Optional[float] = None,
          methods: Union[None, str, Sequence[str]] = None, adaptive: bool = False,
          optimize: bool = False, out_dir: Optional[PathLike] = None, write_step: bool = False,
          write_meshes: bool = False, *, threads: int = 0,
          progress: Progress = None) -> StudyResult:
    """A sweep of a built-in model, as `cadmorph sweep MODEL --mesh M --steps N -o DIR`:
    G(k / steps), k = 1 .. steps, written as STEP and read back, M(0) meshed and morphed onto
    each (cm_sweep_run).

    model: "bore", "pipe" or "bracket". mesh: "tet" (TetGen at size, default 0.2), "hex"
    (the O-grid hex mesh, bore and pipe; cells of about size, default 0.1) or the path of a
    mesh of G(0). mode: "absolute", "relative" or "both" (default). methods: as study's
    (None: rbf-s, project, rbf-s-biharmonic), put in the sweeps' table order as the CLI
    does. adaptive: adaptive steps in each morph (a morph that reaches no valid mesh is a
    failed row); default the plain one-step morph of the papers, inverted cells kept (what
    a sweep measures). optimize: interior optimisation.
    out_dir: where G_<t>.step goes (kept with write_step) and, with write_meshes, the
    meshes at 50 % and 100 %; None: a temporary directory (nothing kept).
    """
    what = "cadmorph.sweep"
    choice(what, "model", model, ("bore", "pipe", "bracket"))
    if out_dir is None and (write_step or write_meshes):
        raise ValueError("%s: write_step and write_meshes need out_dir" % what)
    if isinstance(mesh, str) and mesh in ("tet", "hex"):
        mesh_b = mesh.encode()
        if mesh == "hex" and model == "bracket":
            raise ValueError("%s: no hex mesh of the bracket (bore, pipe only)" % what)
    else:
        mesh_b = path_bytes(what, "mesh", mesh)
    ctx = Context(threads, progress, what)
    so = ffi.new("cm_sweep_options *")
    lib.cm_sweep_options_init(so)
    model_c, mesh_c = ffi.new("char[]", model.encode()), ffi.new("char[]", mesh_b)
    so.model, so.mesh = model_c, mesh_c
    so.steps = integer(what, "steps", steps, 1, 1000)
    so.modes = _MODES[choice(what, "mode", mode, tuple(_MODES))]
    if size is not None:
        so.size = number(what, "size", size, 0, 1e6, lo_open=True)
    ms = None
    if methods is not None:
        ms, nm = _methods(ctx, methods, "", what)
        # the sweeps' table order (rbf-s, project, rbf-s-biharmonic, then as given), as the
        # CLI's plot and summary have them
        order = sorted(range(nm), key=lambda i: lib.cm_study_method_slot(ms + i, _MAX_METHODS))
        sorted_ms = ffi.new("cm_study_method[]", _MAX_METHODS)
        for k, i in enumerate(order):
            sorted_ms[k] = ms[i]
        ms = sorted_ms
        so.methods, so.n_methods = ms, nm
    so.adaptive = bool(adaptive)
    so.optimize = bool(optimize)
    so.write_step = bool(write_step)
    so.write_meshes = bool(write_meshes)
    with tempfile.TemporaryDirectory(prefix="cadmorph_sweep_") as tmp:
        d = path_bytes(what, "out_dir", tmp if out_dir is None else out_dir)
        os.makedirs(d, exist_ok=True)
        dir_c = ffi.new("char[]", d)
        so.out_dir = dir_c
        result = ctx.create(lib.cm_sweep_run, "cm_study_result", lib.cm_study_result_destroy, so)
    return StudyResult(result, lib.CM_STUDY_CSV_SWEEP)
