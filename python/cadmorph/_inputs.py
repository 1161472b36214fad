"""Checks of the arguments of every Python call before the library sees them: option values,
shapes, dtypes, finite values, index ranges and paths become ValueError or TypeError here, so
that no call can hand the library an array it would read out of bounds.

One calling convention: check(what, name, value, ...), what the Python function
("cadmorph.Morpher"), name the argument ("steps"); the messages read
"cadmorph.Morpher: steps must be in 1..4096, not 0". Each returns the value checked, in the
form the library takes (int, float, bytes, a C-contiguous array).
"""
import math
import os
import warnings
from typing import Any, Dict, Optional, Sequence, Tuple

import numpy as np

from ._capi import ffi

# NumPy < 1.24 warns on ragged nested sequences instead of raising
_RAGGED = getattr(np, "VisibleDeprecationWarning", None) or np.exceptions.VisibleDeprecationWarning


def choice(what: str, name: str, value: Any, allowed: Sequence[str]) -> str:
    """value, one of the strings allowed (case-sensitive, as the CLI)."""
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


def text(what: str, name: str, value: Any, empty: bool = False) -> bytes:
    """value, a str without NUL characters (empty only when allowed), as UTF-8 bytes for the
    C API."""
    if not isinstance(value, str):
        raise TypeError("%s: %s must be a str, not %s" % (what, name, type(value).__name__))
    if (not value and not empty) or "\0" in value:
        raise ValueError("%s: %s must be a %sstr without NUL characters, not %r"
                         % (what, name, "" if empty else "non-empty ", value))
    return value.encode("utf-8")


def path_bytes(what: str, name: str, value: Any) -> bytes:
    """A path (str, bytes, os.PathLike) as bytes for the C API: not empty, no NUL byte."""
    if not isinstance(value, (str, bytes, os.PathLike)):
        raise TypeError("%s: %s must be a path (str, bytes or os.PathLike), not %s"
                        % (what, name, type(value).__name__))
    b = os.fsencode(value)
    if not b or b"\0" in b:
        raise ValueError("%s: %s is an empty path or one with a NUL byte: %r"
                         % (what, name, value))
    return b


def mesh_of(what: str, name: str, value: Any) -> Any:
    """value, a cadmorph.Mesh."""
    from .mesh import Mesh  # mesh.py uses this module
    if not isinstance(value, Mesh):
        raise TypeError("%s: %s must be a cadmorph.Mesh, not %s"
                        % (what, name, type(value).__name__))
    return value


def model_of(what: str, name: str, value: Any) -> Any:
    """The cm_cad_model * of value, a cadmorph.Geometry."""
    from .geometry import Geometry  # geometry.py uses this module
    if not isinstance(value, Geometry):
        raise TypeError("%s: %s must be a cadmorph.Geometry (cadmorph.read_step or "
                        "cadmorph.model), not %s" % (what, name, type(value).__name__))
    return value._ptr


def asarray(what: str, name: str, value: Any) -> np.ndarray:
    """np.asarray(value) (no copy of an array); a ragged or otherwise unconvertible value as
    ValueError/TypeError naming the argument."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", _RAGGED)
            return np.asarray(value)
    except (ValueError, _RAGGED) as e:
        raise ValueError("%s: %s is not a rectangular array (%s)" % (what, name, e)) from None
    except TypeError as e:
        raise TypeError("%s: %s is not an array (%s)" % (what, name, e)) from None


def _shape_text(shape: Sequence[Optional[int]]) -> str:
    dims = ["n" if s is None else str(s) for s in shape]
    return "(%s)" % (dims[0] + "," if len(dims) == 1 else ", ".join(dims))


def real_array(what: str, name: str, value: Any, shape: Tuple[Optional[int], ...],
               limit: float = math.inf, finite: bool = True) -> np.ndarray:
    """value as a C-contiguous float64 array of the given shape (None: any length), of finite
    numbers (unless finite=False) of magnitude at most limit; a copy only when it is not one
    already. Bad rows are named (for 2-D arrays: the row)."""
    a = asarray(what, name, value)
    if a.dtype.kind not in "fiu":
        raise TypeError("%s: %s must hold real numbers, not dtype %s" % (what, name, a.dtype))
    if a.ndim != len(shape) or any(s is not None and s != d for s, d in zip(shape, a.shape)):
        raise ValueError("%s: %s must have shape %s, not %s"
                         % (what, name, _shape_text(shape), a.shape))
    a = np.ascontiguousarray(a, dtype=np.float64)
    rows = a.reshape(a.shape[0], int(np.prod(a.shape[1:]))) if a.ndim > 1 else a.reshape(-1, 1)
    bad = ~np.isfinite(rows).all(axis=1) if finite else np.zeros(len(rows), bool)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise ValueError("%s: %s %s is not finite: %s" % (what, name, _row(a, k), a[k]))
    if a.size and limit < math.inf and np.abs(a).max() > limit:
        k = int(np.flatnonzero((np.abs(rows) > limit).any(axis=1))[0])
        raise ValueError("%s: %s %s is %s, beyond any mesh (|d| <= %g)"
                         % (what, name, _row(a, k), a[k], limit))
    return a


def _row(a: np.ndarray, k: int) -> str:
    return "row %d" % k if a.ndim > 1 else "[%d]" % k


def points(what: str, name: str, value: Any, n: Optional[int] = None,
           limit: float = math.inf, planar: bool = False) -> np.ndarray:
    """value as (n, 3) float64 coordinates (n None: any number), as real_array; planar: an
    (n, 2) array is taken too, as points with z = 0 (a copy)."""
    if planar:
        a = asarray(what, name, value)
        if a.ndim == 2 and a.shape[1] == 2 and (n is None or len(a) == n):
            value = np.concatenate((a, np.zeros((len(a), 1), a.dtype)), axis=1) \
                if a.dtype.kind in "fiu" else a
        elif not (a.ndim == 2 and a.shape[1] == 3):
            raise ValueError("%s: %s must have shape %s or (%s, 2), not %s"
                             % (what, name, _shape_text((n, 3)), "n" if n is None else n,
                                a.shape))
    return real_array(what, name, value, (n, 3), limit)


def points_of(what: str, name: str, value: Any) -> Tuple[np.ndarray, Any]:
    """The (n, 3) float64 coordinates of a Mesh (its view, no copy) or of an array-like, and
    the Mesh (None for an array)."""
    from .mesh import Mesh  # mesh.py uses this module
    if isinstance(value, Mesh):
        xyz = value.points
        if not np.all(np.isfinite(xyz)):
            raise ValueError("%s: %s: the mesh has non-finite coordinates" % (what, name))
        return xyz, value
    return points(what, name, value), None


def index_array(what: str, name: str, value: Any, n: Optional[int] = None, *,
                ndim: Optional[int] = 1, unique: bool = False, empty: bool = True,
                mask: bool = False) -> np.ndarray:
    """value as an int64 array of node indices in 0..n-1 (n None: not checked) with ndim
    dimensions (None: any); unique: no index twice; empty: [] allowed; mask: a boolean
    array of shape (n,) is taken as the indices of its True entries. No copy when value is
    already a C-contiguous int64 array."""
    a = asarray(what, name, value)
    if mask and a.dtype == np.bool_:
        if a.shape != (n,):
            raise ValueError("%s: %s as a boolean mask must have shape (%d,), not %s"
                             % (what, name, n, a.shape))
        a = np.flatnonzero(a).astype(np.int64)
    if a.dtype.kind not in "iu":
        if a.size == 0 and a.dtype.kind == "f":  # [] is float64 to numpy
            a = a.astype(np.int64)
        else:
            raise TypeError("%s: %s must be integer node indices, not dtype %s"
                            % (what, name, a.dtype))
    if ndim is not None and a.ndim != ndim:
        raise ValueError("%s: %s must be %d-D, not of shape %s" % (what, name, ndim, a.shape))
    if a.size == 0 and not empty:
        raise ValueError("%s: %s is empty: at least one node is needed" % (what, name))
    if n is not None and a.size:
        bad = (a < 0) | (a >= n)
        if bad.any():
            at = np.unravel_index(int(np.argmax(bad)), a.shape)
            where = "[%d]" % at[0] if a.ndim == 1 else " row %d" % at[0]
            raise ValueError("%s: %s%s: node index %d out of range [0, %d)"
                             % (what, name, where, int(a[at]), n))
    a = np.ascontiguousarray(a, dtype=np.int64)
    if unique:
        u, counts = np.unique(a, return_counts=True)
        if u.size != a.size:
            dup = int(u[counts > 1][0])
            raise ValueError("%s: %s lists node %d %d times" % (what, name, dup,
                                                                 int(counts[u == dup][0])))
    return a


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
