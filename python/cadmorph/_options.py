"""Checked keyword options and the arrays of Morpher and Warp: every value is validated here,
before the library sees it (ValueError naming the option and what it accepts, TypeError for
a value of the wrong kind), then written into the library's option structs.

The ranges are those of the CLI's options (cli/cmd_morph.c, cli/cmd_warp.c, cli/options.h),
so that a Python call and a command line accept the same values.
"""
import math
from typing import Any, Dict, Optional, Sequence

import numpy as np

from ._capi import ffi, lib

SOLVERS: Dict[str, int] = {"auto": lib.CM_RBF_SOLVER_AUTO, "dense": lib.CM_RBF_SOLVER_DENSE,
                           "iterative": lib.CM_RBF_SOLVER_ITERATIVE,
                           "petsc": lib.CM_RBF_SOLVER_PETSC}
KERNELS: Dict[str, str] = {"triharmonic": "rbf", "biharmonic": "rbf-biharmonic"}


def warp_methods() -> Sequence[str]:
    """The warp method names of the library's table ("rbf", "rbf-biharmonic", "femwarp", ...)."""
    return ffi.string(lib.cm_warp_method_list()).decode().split("|")


def choice(what: str, name: str, value: Any, allowed: Sequence[str]) -> str:
    """value, one of the strings allowed."""
    if not isinstance(value, str):
        raise TypeError("%s: %s must be a str (%s), not %s"
                        % (what, name, ", ".join(allowed), type(value).__name__))
    if value not in allowed:
        raise ValueError("%s: %s must be one of %s, not %r"
                         % (what, name, ", ".join(allowed), value))
    return value


def flag(what: str, name: str, value: Any) -> bool:
    """value, a bool (numpy's too)."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError("%s: %s must be a bool, not %s" % (what, name, type(value).__name__))
    return bool(value)


def integer(what: str, name: str, value: Any, lo: int, hi: int) -> int:
    """value, an int in lo..hi."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise TypeError("%s: %s must be an int, not %s" % (what, name, type(value).__name__))
    if not lo <= value <= hi:
        raise ValueError("%s: %s must be in %d..%d, not %d" % (what, name, lo, hi, value))
    return int(value)


def number(what: str, name: str, value: Any, lo: float = -math.inf, hi: float = math.inf,
           lo_open: bool = False, hi_open: bool = False) -> float:
    """value, a finite real number in the interval of lo, hi (open ends as said)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer,
                                                                     np.floating)):
        raise TypeError("%s: %s must be a real number, not %s"
                        % (what, name, type(value).__name__))
    x = float(value)
    ok = math.isfinite(x) and (x > lo if lo_open else x >= lo) and (x < hi if hi_open else x <= hi)
    if not ok:
        raise ValueError("%s: %s must be a finite number in %s%s, %s%s, not %r"
                         % (what, name, "(" if lo_open else "[", lo, hi, ")" if hi_open else "]",
                            value))
    return x


class WarpSettings:
    """The checked options of a warp (cm_warp_options): the method and its parameters, as
    Warp, Morpher and Morpher.apply take them."""

    NAMES = ("method", "kernel", "solver", "tolerance", "lattice", "clamp", "samples",
             "cubature", "cover", "stretch", "bend", "blend", "graded")

    def __init__(self, what: str, method: str = "rbf", kernel: Optional[str] = None,
                 solver: str = "auto", tolerance: float = 0.0, lattice: Optional[int] = None,
                 clamp: Optional[float] = None, samples: Optional[int] = None,
                 cubature: Optional[int] = None, cover: int = 5, stretch: float = 1.0,
                 bend: float = 1.0, blend: float = 1.5, graded: float = 0.0) -> None:
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


def points(what: str, name: str, value: Any, n: int, limit: float = math.inf) -> np.ndarray:
    """value as an (n, 3) C-contiguous float64 array of finite numbers of magnitude at most
    limit (a copy only when it is not one already)."""
    a = np.asarray(value)
    if a.dtype.kind not in "fiu" or a.dtype.kind == "b":
        raise TypeError("%s: %s must hold real numbers, not dtype %s" % (what, name, a.dtype))
    if a.shape != (n, 3):
        raise ValueError("%s: %s must have shape (%d, 3), not %s" % (what, name, n, a.shape))
    a = np.ascontiguousarray(a, dtype=np.float64)
    if not np.isfinite(a).all():
        bad = int(np.flatnonzero(~np.isfinite(a).all(axis=1))[0])
        raise ValueError("%s: %s row %d is not finite: %s" % (what, name, bad, a[bad]))
    if a.size and np.abs(a).max() > limit:
        bad = int(np.flatnonzero((np.abs(a) > limit).any(axis=1))[0])
        raise ValueError("%s: %s row %d is %s, beyond any mesh (|d| <= %g)"
                         % (what, name, bad, a[bad], limit))
    return a


def node_indices(what: str, name: str, value: Any, n: int) -> np.ndarray:
    """value as a 1-D int64 array of distinct node indices in 0..n-1 (at least one)."""
    a = np.asarray(value)
    if a.dtype.kind not in "iu":
        if a.size == 0 and a.dtype.kind == "f":  # [] is float64 to numpy
            a = a.astype(np.int64)
        else:
            raise TypeError("%s: %s must be integer node indices, not dtype %s"
                            % (what, name, a.dtype))
    if a.ndim != 1:
        raise ValueError("%s: %s must be 1-D, not of shape %s" % (what, name, a.shape))
    if a.size == 0:
        raise ValueError("%s: %s is empty: at least one node must be constrained" % (what, name))
    bad = np.flatnonzero((a < 0) | (a >= n))
    if bad.size:
        raise ValueError("%s: %s[%d] = %d is not a node index (0..%d)"
                         % (what, name, bad[0], a[bad[0]], n - 1))
    a = np.ascontiguousarray(a, dtype=np.int64)
    u, counts = np.unique(a, return_counts=True)
    if u.size != a.size:
        dup = int(u[counts > 1][0])
        raise ValueError("%s: %s lists node %d %d times" % (what, name, dup,
                                                             int(counts[u == dup][0])))
    return a
