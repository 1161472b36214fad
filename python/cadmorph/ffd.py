"""Free-form deformation by a control lattice (deform.h, cm_ffd_*): Lattice and ffd, as
`cadmorph ffd`, with PyGeM's parameter files (.prm) read by the library.

Displacement form: d(x) = sum_p dc_p N_p(u(x)) over the control displacements dc (one row
per control point, flat index (i n1 + j) n2 + k as PyGeM's arrays), so zero control
displacements leave every point bit for bit where it was; points outside the lattice do not
move (counted in FFDStats.outside).
"""
import os
from dataclasses import dataclass
from typing import Any, Optional, Sequence, Tuple, Union

import numpy as np

from ._capi import ffi, lib
from ._context import Context, Progress, owned
from ._inputs import choice, integer, path_bytes, points_of, real_array
from .errors import BadInputError
from .mesh import Mesh, PathLike

_BASES = {"bspline": lib.CM_FFD_BSPLINE, "bernstein": lib.CM_FFD_BERNSTEIN}
_KNOTS = {"uniform": lib.CM_FFD_KNOTS_UNIFORM, "clamped": lib.CM_FFD_KNOTS_CLAMPED}
_LOCAL = {"auto": lib.CM_FFD_LOCAL_AUTO, "affine": lib.CM_FFD_LOCAL_AFFINE,
          "newton": lib.CM_FFD_LOCAL_NEWTON}


@dataclass(frozen=True)
class FFDStats:
    """What an FFD did with the points (cm_ffd_stats).

    Attributes:
        inside: points in the lattice (moved).
        outside: points outside it (not moved).
        failed: points Newton could not locate in a moved lattice (not moved).
        max_iterations: Newton steps of the worst point (0 on the affine path).
    """

    inside: int
    outside: int
    failed: int
    max_iterations: int


class Lattice:
    """An FFD control lattice (a cm_ffd): the parallelepiped origin + A u, u in [0, 1]^3,
    with n[0] x n[1] x n[2] control points.

    n: control points per axis (B-spline: >= 4, Bernstein: >= 2). origin: the corner u = 0.
    axes: (3, 3), column j the domain edge a_j (deform.h's row-major layout); default the
    unit cube. basis: "bspline" (uniform cubic B-splines, local support) or "bernstein"
    (degree n-1, PyGeM's). knots (B-spline): "uniform", "clamped", or three arrays of
    n[a] + 4 knots (non-decreasing, t_3 = 0, t_n = 1). local: how points find their local
    coordinates, "auto" (affine for the reference lattice, Newton once moved), "affine" or
    "newton".

    Lattice.box (PyGeM's box and angles) and Lattice.from_prm (a PyGeM .prm file) make the
    lattices of `cadmorph ffd`. A lattice may be used by several threads at once except
    while set_control_points or set_local runs.
    """

    def __init__(self, n: Sequence[int] = (4, 4, 4), origin: Any = (0.0, 0.0, 0.0),
                 axes: Any = None, basis: str = "bspline",
                 knots: Union[str, Sequence[Any]] = "uniform", local: str = "auto") -> None:
        what = "cadmorph.Lattice"
        desc = ffi.new("cm_ffd_desc *")
        lib.cm_ffd_desc_init(desc)
        if isinstance(n, (str, bytes)) or len(n) != 3:
            raise ValueError("%s: n is three counts of control points, not %r" % (what, n))
        desc.n = [integer(what, "n", v, 2, 1 << 20) for v in n]
        desc.basis = _BASES[choice(what, "basis", basis, tuple(_BASES))]
        desc.origin = list(real_array(what, "origin", origin, (3,)))
        if axes is not None:
            desc.axes = list(real_array(what, "axes", axes, (3, 3)).ravel())
        keep = []
        if isinstance(knots, str):
            desc.knots = _KNOTS[choice(what, "knots", knots, tuple(_KNOTS))]
        else:
            if len(knots) != 3:
                raise ValueError("%s: knots: three arrays (one per axis)" % what)
            desc.knots = lib.CM_FFD_KNOTS_CUSTOM
            for a in range(3):
                k = real_array(what, "knots[%d]" % a, knots[a], (desc.n[a] + 4,))
                keep.append(k)
                desc.knot[a] = ffi.from_buffer("double[]", k)
        self._create(desc, what)
        self.set_local(local)

    def _create(self, desc, what: str, path: Optional[bytes] = None) -> None:
        ctx = Context(0, False, what)
        p = ffi.new("cm_ffd *[1]")
        status = lib.cm_ffd_create(ctx.ptr, desc, p)
        if status == lib.CM_ERR_ARGUMENT and path is not None:
            # a lattice that came from a file: bad input naming the file, as `cadmorph ffd`
            raise BadInputError(lib.CM_ERR_FORMAT, "%s: %s" % (path.decode("utf-8", "replace"),
                                                               ctx.message()))
        ctx.check(status)
        self._ptr = owned(p[0], lib.cm_ffd_destroy)
        self.n: Tuple[int, int, int] = (int(desc.n[0]), int(desc.n[1]), int(desc.n[2]))
        """Control points per axis."""
        self.basis: str = "bspline" if desc.basis == lib.CM_FFD_BSPLINE else "bernstein"
        """"bspline" or "bernstein"."""
        self.weights: Optional[np.ndarray] = None
        """The control displacements of the .prm file it came from ((n_control, 3),
        physical, world frame: R diag(length) mu), else None."""

    @classmethod
    def box(cls, n: Sequence[int], length: Any, origin: Any = (0.0, 0.0, 0.0),
            angles: Any = (0.0, 0.0, 0.0), basis: str = "bernstein") -> "Lattice":
        """PyGeM's box: origin + R diag(length) [0,1]^3, R = Rx Ry Rz of the angles in
        degrees about the origin (cm_ffd_box_axes)."""
        what = "cadmorph.Lattice.box"
        L = real_array(what, "length", length, (3,))
        A = real_array(what, "angles", angles, (3,))
        axes = np.empty(9)
        lib.cm_ffd_box_axes(ffi.from_buffer("double[]", L), ffi.from_buffer("double[]", A),
                            ffi.from_buffer("double[]", axes))
        return cls(n, origin, axes.reshape(3, 3), basis)

    @classmethod
    def from_prm(cls, path: PathLike, basis: str = "bernstein") -> "Lattice":
        """The lattice of a PyGeM parameter file (cm_ffd_prm_read, cm_ffd_prm_desc): its box,
        its n and basis ("bernstein", PyGeM's, the default as in `cadmorph ffd`; or
        "bspline" on the box as the valid domain); the file's weights in .weights.
        BadInputError naming path:line for a malformed file, a missing one, or a lattice
        the library refuses."""
        what = "cadmorph.Lattice.from_prm"
        p = path_bytes(what, "path", path)
        b = _BASES[choice(what, "basis", basis, tuple(_BASES))]
        ctx = Context(0, False, what)
        prm = ffi.new("cm_ffd_prm *")
        ctx.call(lib.cm_ffd_prm_read, p, prm)
        try:
            nc = prm.n[0] * prm.n[1] * prm.n[2]
            dc = np.empty((nc, 3))
            desc = ffi.new("cm_ffd_desc *")
            lib.cm_ffd_prm_desc(prm, b, desc, ffi.from_buffer("double[]", dc))
        finally:
            lib.cm_ffd_prm_free(prm)
        self = cls.__new__(cls)
        self._create(desc, what, p)
        self.weights = dc
        return self

    @property
    def n_control(self) -> int:
        """Number of control points, n[0] n[1] n[2]."""
        return int(lib.cm_ffd_control_count(self._ptr))

    @property
    def control_points(self) -> np.ndarray:
        """(n_control, 3) control positions (a copy): the reference ones, or those given to
        set_control_points."""
        xyz = np.empty((self.n_control, 3))
        lib.cm_ffd_control_points(self._ptr, ffi.from_buffer("double[]", xyz))
        return xyz

    def set_control_points(self, xyz: Any) -> None:
        """Moves the lattice (a pre-deformed lattice: points then find their local
        coordinates by Newton's method); None restores the reference."""
        what = "cadmorph.Lattice.set_control_points"
        ctx = Context(0, False, what)
        if xyz is None:
            ctx.call(lib.cm_ffd_set_control_points, self._ptr, ffi.NULL)
            return
        a = real_array(what, "xyz", xyz, (self.n_control, 3))
        ctx.call(lib.cm_ffd_set_control_points, self._ptr, ffi.from_buffer("double[]", a))

    def set_local(self, mode: str) -> None:
        """How points find their local coordinates: "auto", "affine" or "newton"."""
        mode = choice("cadmorph.Lattice.set_local", "mode", mode, tuple(_LOCAL))
        lib.cm_ffd_set_local(self._ptr, _LOCAL[mode])

    def read_displacements(self, path: PathLike) -> np.ndarray:
        """The (n_control, 3) control displacements of a CSV `i,j,k,dx,dy,dz` (physical,
        world frame; unlisted points 0), as `cadmorph ffd --displacements`
        (cm_ffd_read_displacements)."""
        what = "cadmorph.Lattice.read_displacements"
        p = path_bytes(what, "path", path)
        dc = np.zeros((self.n_control, 3))
        Context(0, False, what).call(lib.cm_ffd_read_displacements, p, list(self.n),
                                     ffi.from_buffer("double[]", dc), ffi.NULL)
        return dc

    def local_coords(self, points: Union[Mesh, np.ndarray], threads: int = 0,
                     progress: Progress = None) -> Tuple[np.ndarray, np.ndarray]:
        """Local coordinates u ((n, 3)) of the points and a flag per point: 1 inside, 0
        outside, 2 not located by Newton (cm_ffd_local_coords)."""
        what = "cadmorph.Lattice.local_coords"
        x, _ = points_of(what, "points", points)
        n = x.shape[0]
        u = np.zeros((max(n, 1), 3))
        flags = np.zeros(max(n, 1), np.uint8)
        Context(threads, progress, what).call(
            lib.cm_ffd_local_coords, self._ptr, n, ffi.from_buffer("double[]", x) if n else
            ffi.NULL, ffi.from_buffer("double[]", u), ffi.from_buffer("unsigned char[]", flags),
            ffi.NULL)
        return u[:n], flags[:n]

    def displacement(self, points: Union[Mesh, np.ndarray], dc: Any = None, threads: int = 0,
                     progress: Progress = None) -> Tuple[np.ndarray, FFDStats]:
        """The (n, 3) FFD displacement of the points (a Mesh or an (n, 3) array) for the
        control displacements dc ((n_control, 3); None: .weights) and the counts
        (cm_ffd_deform)."""
        what = "cadmorph.Lattice.displacement"
        x, _ = points_of(what, "points", points)
        if dc is None:
            if self.weights is None:
                raise ValueError("%s: dc is needed (the lattice has no .prm weights)" % what)
            dc = self.weights
        c = real_array(what, "dc", dc, (self.n_control, 3))
        n = x.shape[0]
        d = np.zeros((max(n, 1), 3))
        st = ffi.new("cm_ffd_stats *")
        Context(threads, progress, what).call(
            lib.cm_ffd_deform, self._ptr, ffi.from_buffer("double[]", c), n,
            ffi.from_buffer("double[]", x) if n else ffi.NULL, ffi.from_buffer("double[]", d), st)
        return d[:n], FFDStats(int(st.inside), int(st.outside), int(st.failed),
                               int(st.max_iterations))

    def __repr__(self) -> str:
        return "<cadmorph.Lattice %s %dx%dx%d>" % ((self.basis,) + self.n)


def ffd(points: Union[Mesh, np.ndarray], lattice: Union[Lattice, PathLike],
        displacements: Union[None, PathLike, np.ndarray] = None, basis: str = "bernstein",
        *, threads: int = 0, progress: Progress = None) -> np.ndarray:
    """The (n, 3) new coordinates of points (a Mesh's nodes or an (n, 3) array) after the
    FFD of lattice, as `cadmorph ffd --lattice L.prm [--displacements C.csv] [--basis B]`.

    lattice: a Lattice, or the path of a PyGeM .prm file (read with basis, default
    "bernstein" as the CLI; basis is ignored for a Lattice). displacements: None for the
    .prm's weights, an (n_control, 3) array of control displacements, or the path of a CSV
    `i,j,k,dx,dy,dz` (physical units, world frame). The mesh itself is not changed."""
    if not isinstance(lattice, Lattice):
        lattice = Lattice.from_prm(lattice, basis)
    if isinstance(displacements, (str, bytes, os.PathLike)):
        displacements = lattice.read_displacements(displacements)
    x, _ = points_of("cadmorph.ffd", "points", points)
    d, _ = lattice.displacement(x, displacements, threads, progress)
    return x + d
