"""cadmorph: morph simulation meshes after a CAD edit, from Python.

A thin layer over libcadmorph's C API (through cffi, ABI mode): no algorithm is written in
Python, arrays are NumPy views onto the library's memory where its layout allows, and the
library's status becomes an exception carrying its message.

    import cadmorph
    mesh = cadmorph.read_mesh("M0.msh")
    print(cadmorph.quality(mesh).min_sj, mesh.points.shape)
"""
from ._capi import ffi as _ffi, lib as _lib
from .errors import (BadInputError, CadmorphWarning, Error, InterruptedCall, MismatchError,
                     RejectedError, ResourceError)
from .mesh import Mesh, mesh_formats, read_mesh, write_mesh
from .quality import FoamQuality, Quality, quality
from .geometry import Comparison, Counts, Edge, Face, Geometry, model, model_names, read_step
from .design import DesignRow, DesignTable
from .morph import Morpher, MorpherInfo, MorphStep, SurfaceStats, morph
from .warp import Warp, warp
from .deform import Deformer, deform
from .ffd import FFDStats, Lattice, ffd
from .optimize import OptimizeStats, optimize
from .meshgen import mesh_step
from .study import StudyResult, StudyRow, study, sweep
from .blas import BlasInfo, blas_info

__version__: str = _ffi.string(_lib.cm_version()).decode()

__all__ = [
    "Error", "BadInputError", "MismatchError", "RejectedError", "ResourceError",
    "InterruptedCall", "CadmorphWarning",
    "Mesh", "mesh_formats", "read_mesh", "write_mesh",
    "Quality", "FoamQuality", "quality",
    "Geometry", "Face", "Edge", "Counts", "Comparison", "read_step", "model", "model_names",
    "Morpher", "MorphStep", "MorpherInfo", "SurfaceStats", "morph",
    "DesignTable", "DesignRow",
    "Warp", "warp",
    "Deformer", "deform",
    "Lattice", "FFDStats", "ffd",
    "OptimizeStats", "optimize",
    "mesh_step",
    "StudyResult", "StudyRow", "study", "sweep",
    "BlasInfo", "blas_info",
    "__version__",
]
