"""The warp options of Morpher and Warp: checked by _inputs' checks before the library sees
them (ValueError naming the option and what it accepts, TypeError for a value of the wrong
kind), then written into the library's option structs.

The ranges are those of the CLI's options (cli/cmd_morph.c, cli/cmd_warp.c, cli/options.h),
so that a Python call and a command line accept the same values.
"""
from typing import Any, Dict, Optional, Sequence

from ._capi import ffi, lib
from ._inputs import choice, integer, number

SOLVERS: Dict[str, int] = {"auto": lib.CM_RBF_SOLVER_AUTO, "dense": lib.CM_RBF_SOLVER_DENSE,
                           "iterative": lib.CM_RBF_SOLVER_ITERATIVE,
                           "petsc": lib.CM_RBF_SOLVER_PETSC}
KERNELS: Dict[str, str] = {"triharmonic": "rbf", "biharmonic": "rbf-biharmonic"}


def warp_methods() -> Sequence[str]:
    """The warp method names of the library's table ("rbf", "rbf-biharmonic", "femwarp", ...)."""
    return ffi.string(lib.cm_warp_method_list()).decode().split("|")


class WarpSettings:
    """The checked options of a warp (cm_warp_options): the method and its parameters, as
    Warp, Morpher and Morpher.apply take them."""

    NAMES = ("method", "kernel", "solver", "tolerance", "lattice", "clamp", "samples",
             "cubature", "cover", "stretch", "bend", "blend", "graded", "solves")

    def __init__(self, what: str, method: str = "rbf", kernel: Optional[str] = None,
                 solver: str = "auto", tolerance: float = 0.0, lattice: Optional[int] = None,
                 clamp: Optional[float] = None, samples: Optional[int] = None,
                 cubature: Optional[int] = None, cover: int = 5, stretch: float = 1.0,
                 bend: float = 1.0, blend: float = 1.5, graded: float = 0.0,
                 solves: int = 1) -> None:
        self.method = choice(what, "method", method, warp_methods())
        if kernel is not None:
            # --kernel of the CLI: another name for the two RBF methods
            alias = KERNELS[choice(what, "kernel", kernel, list(KERNELS))]
            if method != "rbf" and method != alias:
                raise ValueError("%s: kernel=%r is method=%r, not method=%r"
                                 % (what, kernel, alias, method))
            self.method = alias
        self.solver = choice(what, "solver", solver, list(SOLVERS))
        if self.solver == "petsc" and not lib.cm_parallel_available():
            raise ValueError("%s: solver='petsc': this libcadmorph was built without PETSc"
                             % what)
        self.tolerance = number(what, "tolerance", tolerance, 0.0, 0.5)
        # the fields the caller expects to apply with one warp (cm_warp_options.solves)
        self.solves = integer(what, "solves", solves, 1, 2 ** 31 - 1)
        # None: the library's default (a lattice of 10, clamp 1e-10), passed as its 0
        self.lattice = None if lattice is None else integer(what, "lattice", lattice, 4, 200)
        self.clamp = None if clamp is None else number(what, "clamp", clamp, 0.0, 1.0,
                                                       lo_open=True, hi_open=True)
        self.samples = None if samples is None else integer(what, "samples", samples, 1,
                                                            100000000)
        self.cubature = None if cubature is None else integer(what, "cubature", cubature, 1,
                                                              100000000)
        self.cover = integer(what, "cover", cover, 1, 64)
        self.stretch = number(what, "stretch", stretch, 0.0)
        self.bend = number(what, "bend", bend, 0.0)
        self.blend = number(what, "blend", blend, 0.0)
        self.graded = number(what, "graded", graded, 0.0, 1.0)

    def replaced(self, what: str, **changes: Any) -> "WarpSettings":
        """These settings with some replaced (checked again); method= alone keeps the rest."""
        values = {k: getattr(self, k) for k in self.NAMES if k != "kernel"}
        if "kernel" in changes and "method" not in changes:
            values["method"] = "rbf"  # kernel= names the method by itself
        values.update(changes)
        return WarpSettings(what, **values)

    def fill(self, w) -> None:
        """Writes the settings into a cm_warp_options (initialised here first)."""
        lib.cm_warp_options_init(w)
        w.method = lib.cm_warp_method_from_name(self.method.encode())
        w.solver = SOLVERS[self.solver]
        w.tolerance = self.tolerance
        # 1 is the library's 0 (one apply), so that the options match those of the CLI bytewise
        w.solves = self.solves if self.solves > 1 else 0
        if self.lattice is not None:
            w.lattice = self.lattice
        if self.clamp is not None:
            w.clamp = self.clamp
        if self.samples is not None:
            w.mls.samples = self.samples
        if self.cubature is not None:
            w.mls.cubature = self.cubature
        w.mls.cover = self.cover
        w.mls.stretch = self.stretch
        w.mls.bend = self.bend
        w.mls.blend = self.blend
        w.mls.graded = self.graded


# The largest displacement component `cadmorph warp` reads from a table: beyond it, squares
# in the warp overflow (volume/displacement_csv.c, CM_WARP_MAX_DISPLACEMENT)
MAX_DISPLACEMENT = 1e150
