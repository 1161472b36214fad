"""quality(mesh): the scaled Jacobian of every cell and its summary, as `cadmorph quality`."""
from dataclasses import dataclass

import numpy as np

from ._capi import ffi, lib
from ._context import Context
from .mesh import Mesh


@dataclass(frozen=True)
class Quality:
    """Verdict's scaled Jacobian of a mesh.

    Attributes:
        min_sj: the smallest over volume cells (collapsed cells count as 0).
        mean_sj: the mean over volume cells.
        p01_sj: the 1st percentile.
        inverted: volume cells with a scaled Jacobian <= 0.
        cells: number of volume cells (the CLI's `cells=`).
        per_cell: (n_cells,) float64 over every element in file order, NaN for elements of
            dimension < 3.
    """

    min_sj: float
    mean_sj: float
    p01_sj: float
    inverted: int
    cells: int
    per_cell: np.ndarray


def quality(mesh: Mesh, threads: int = 0) -> Quality:
    """The scaled Jacobian of every cell of mesh and the summary that `cadmorph quality`
    prints on its last line (cm_mesh_quality, cm_quality_summarize)."""
    if not isinstance(mesh, Mesh):
        raise TypeError("cadmorph.quality: mesh must be a cadmorph.Mesh, not %s"
                        % type(mesh).__name__)
    m = mesh._ptr
    sj = np.empty(max(int(m.n_cells), 1), np.float64)
    ctx = Context(threads, False, "cadmorph.quality")
    buf = ffi.from_buffer("double[]", sj)
    ctx.call(lib.cm_mesh_quality, m, buf)
    all_ = ffi.new("cm_quality_stats *")
    ctx.call(lib.cm_quality_summarize, m, buf, ffi.NULL, all_)
    return Quality(min_sj=float(all_.min), mean_sj=float(all_.mean), p01_sj=float(all_.p01),
                   inverted=int(all_.inverted), cells=int(all_.count),
                   per_cell=sj[:int(m.n_cells)])
