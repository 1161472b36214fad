"""Checks of the arguments of the one-shot functions (deform, ffd, optimize, mesh_step,
study) before the library sees them: shapes, dtypes, finite values, index ranges and option
values become ValueError or TypeError here, so that no call can hand the library an array it
would read out of bounds."""
import os
from typing import Any, Dict, Optional, Sequence, Tuple

import numpy as np

from ._capi import ffi
from .mesh import Mesh


def real_array(value: Any, shape: Tuple[Optional[int], ...], what: str) -> np.ndarray:
    """value as a C-contiguous float64 array of the given shape (None: any length), finite;
    no copy when it already is one."""
    a = np.asarray(value)
    if a.dtype.kind not in "fiu" or a.dtype == np.bool_:
        raise TypeError("%s: real numbers, not dtype %s" % (what, a.dtype))
    if a.ndim != len(shape) or any(s is not None and s != d for s, d in zip(shape, a.shape)):
        want = "(%s)" % ", ".join("n" if s is None else str(s) for s in shape)
        raise ValueError("%s: shape %s, not %s" % (what, want, a.shape))
    a = np.ascontiguousarray(a, dtype=np.float64)
    if not np.all(np.isfinite(a)):
        raise ValueError("%s: every value must be finite" % what)
    return a


def points_of(points: Any, what: str) -> Tuple[np.ndarray, Optional[Mesh]]:
    """The (n, 3) float64 coordinates of a Mesh (its view, no copy) or of an array-like, and
    the Mesh (None for an array)."""
    if isinstance(points, Mesh):
        xyz = points.points
        if not np.all(np.isfinite(xyz)):
            raise ValueError("%s: the mesh has non-finite coordinates" % what)
        return xyz, points
    return real_array(points, (None, 3), what), None


def index_array(value: Any, n: int, what: str, unique: bool = True) -> np.ndarray:
    """value as a 1-D int64 array of indices into 0..n-1 (a boolean mask of length n is
    taken as the indices of its True entries); duplicates refused when unique."""
    a = np.asarray(value)
    if a.dtype == np.bool_:
        if a.shape != (n,):
            raise ValueError("%s: a boolean mask of shape (%d,), not %s" % (what, n, a.shape))
        return np.flatnonzero(a).astype(np.int64)
    if a.size == 0:
        return np.zeros(0, np.int64)
    if a.dtype.kind not in "iu":
        raise TypeError("%s: integer node indices, not dtype %s" % (what, a.dtype))
    if a.ndim != 1:
        raise ValueError("%s: a 1-D array of node indices, not shape %s" % (what, a.shape))
    a = a.astype(np.int64, copy=False)
    bad = (a < 0) | (a >= n)
    if np.any(bad):
        raise ValueError("%s: index %d out of range 0..%d" % (what, a[np.argmax(bad)], n - 1))
    if unique and len(np.unique(a)) != len(a):
        raise ValueError("%s: an index is listed twice" % what)
    return a


def choice(value: Any, names: Sequence[str], what: str) -> str:
    """value, one of names (case-sensitive, as the CLI)."""
    if not isinstance(value, str):
        raise TypeError("%s: a str, one of %s, not %s" % (what, "|".join(names),
                                                         type(value).__name__))
    if value not in names:
        raise ValueError("%s: %r is not one of %s" % (what, value, "|".join(names)))
    return value


def number(value: Any, what: str, lo: float = -np.inf, hi: float = np.inf,
           open_lo: bool = False, open_hi: bool = False) -> float:
    """value as a finite float in [lo, hi] (open ends as asked)."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError("%s: a number, not %s" % (what, type(value).__name__))
    v = float(value)
    if not np.isfinite(v) or v < lo or v > hi or (open_lo and v == lo) or (open_hi and v == hi):
        raise ValueError("%s: %s%g, %g%s, not %r" % (what, "(" if open_lo else "[", lo, hi,
                                                      ")" if open_hi else "]", value))
    return v


def integer(value: Any, what: str, lo: int, hi: int) -> int:
    """value as an int in [lo, hi]."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError("%s: an int, not %s" % (what, type(value).__name__))
    if not lo <= value <= hi:
        raise ValueError("%s: %d..%d, not %d" % (what, lo, hi, value))
    return int(value)


def path_bytes(path: Any, what: str) -> bytes:
    """A path as bytes for the C API (no NUL byte, not empty)."""
    if not isinstance(path, (str, bytes, os.PathLike)):
        raise TypeError("%s: a path (str, bytes or os.PathLike), not %s"
                        % (what, type(path).__name__))
    b = os.fsencode(path)
    if not b or b"\0" in b:
        raise ValueError("%s: an empty path or one with a NUL byte: %r" % (what, path))
    return b


def struct_dict(value: Any) -> Any:
    """A cffi struct (by value or pointer) as a dict of Python numbers, nested structs as
    dicts, char arrays as str."""
    t = ffi.typeof(value)
    if t.kind == "pointer":
        value, t = value[0], t.item
    if t.kind == "array" and t.item.cname == "char":
        return ffi.string(value).decode("utf-8", "replace")
    if t.kind != "struct":
        return value
    out: Dict[str, Any] = {}
    for name, field in t.fields:
        v = getattr(value, name)
        ft = field.type
        if ft.kind == "struct" or (ft.kind == "array" and ft.item.cname == "char"):
            out[name] = struct_dict(v)
        elif ft.kind == "array":
            out[name] = [v[i] for i in range(ft.length)]
        elif ft.kind in ("primitive", "enum"):
            out[name] = v
    return out
