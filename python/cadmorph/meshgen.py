"""mesh_step: a tet mesh of a CAD model's solids (cm_tetmesh_create), as `cadmorph mesh`:
gmsh's library (the default) or OpenCASCADE's surface triangulation filled by TetGen, the
mesher in a child process whose crash or hang is an error, never a signal here."""
import math
import os
import tempfile
from typing import Optional

from ._capi import ffi, lib
from ._context import Context, Progress
from ._inputs import choice, model_of, number
from .geometry import Geometry
from .mesh import _TOKEN, Mesh

_MESHERS = {"tetgen": lib.CM_MESHER_TETGEN, "gmsh": lib.CM_MESHER_GMSH}


def mesh_step(geometry: Geometry, size: Optional[float] = None, mesher: Optional[str] = None, *,
              quality: Optional[float] = None, min_dihedral: Optional[float] = None,
              preserve_surface: bool = False, optimize: bool = True, force: bool = False,
              time_limit: Optional[float] = None, threads: int = 0,
              progress: Progress = None) -> Mesh:
    """A tet mesh of geometry (a cadmorph.Geometry) as `cadmorph mesh G.step -o M`: the
    tets (group "solid"; solids that touch, an assembly: one conformal mesh, groups
    "solid_<k>") and the boundary triangles, each tagged with its CAD face (face index + 1,
    groups "face_<k>"), every boundary node on the CAD model, and the per-cell field
    "scaled_jacobian" the CLI writes with it.

    size: target edge length in model units (None: bbox diagonal / 20). mesher: "gmsh" or
    "tetgen"; None chooses as the CLI: "tetgen" when quality, min_dihedral or
    preserve_surface is given (TetGen's options), else "gmsh". quality (>= 1, default 1.4):
    TetGen's radius-edge bound; min_dihedral (0..20 degrees, default 12); preserve_surface:
    keep OpenCASCADE's surface triangulation (TetGen -Y). optimize: optimise the interior
    nodes after meshing (default True). force: lift the 1e7-tet limit. time_limit: seconds
    the meshing may take (default 600). With mesher None, when the first mesher fails (or its
    mesh has an inverted or flat tet after the optimisation) the other one is tried, with a
    warning; an explicit mesher is that mesher only.

    gmsh reads the geometry's STEP file; a Geometry whose file is gone is written to a
    temporary STEP file and read back for it (what the CLI's input goes through).
    Raises BadInputError when the mesher fails (the message says what was tried),
    RejectedError when its mesh keeps an inverted or flat tet, ResourceError beyond the tet
    limit.
    """
    what = "cadmorph.mesh_step"
    model = model_of(what, "geometry", geometry)
    opt = ffi.new("cm_tetmesh_options *")
    lib.cm_tetmesh_options_init(opt)
    tetgen_options = quality is not None or min_dihedral is not None or bool(preserve_surface)
    # as the CLI: an explicit mesher is that mesher only, without it the other one follows
    opt.fallback = 1 if mesher is None else 0
    if mesher is None:
        mesher = "tetgen" if tetgen_options else "gmsh"
    mesher = choice(what, "mesher", mesher, tuple(_MESHERS))
    if mesher == "gmsh" and tetgen_options:
        raise ValueError("%s: quality, min_dihedral and preserve_surface are TetGen's: not "
                         "with mesher='gmsh'" % what)
    opt.mesher = _MESHERS[mesher]
    if size is not None:
        opt.size = number(what, "size", size, 0, lo_open=True)
    if quality is not None:
        opt.quality = number(what, "quality", quality, 1)
    if min_dihedral is not None:
        opt.min_dihedral = number(what, "min_dihedral", min_dihedral, 0, 20)
    if preserve_surface:
        opt.preserve_surface = 1
    if not optimize:
        opt.optimize = 0
    if force:
        opt.max_tets = math.inf
    if time_limit is not None:
        opt.time_limit = number(what, "time_limit", time_limit, 0, lo_open=True)
    ctx = Context(threads, progress, what)
    path = ffi.string(lib.cm_cad_path(model)) if lib.cm_cad_path(model) != ffi.NULL else b""
    if mesher == "gmsh" and not os.path.isfile(path):
        with tempfile.TemporaryDirectory(prefix="cadmorph_") as d:
            step = os.path.join(os.fsencode(d), b"G.step")
            ctx.call(lib.cm_cad_write, model, step)
            ro = ffi.new("cm_cad_read_options *")
            lib.cm_cad_read_options_init(ro)
            unit = lib.cm_cad_unit(model)
            ro.unit = unit
            copy = ctx.create(lib.cm_cad_read, "cm_cad_model", lib.cm_cad_destroy, step, ro)
            m = ctx.create(lib.cm_tetmesh_create, "cm_mesh", lib.cm_mesh_destroy, copy, opt)
    else:
        m = ctx.create(lib.cm_tetmesh_create, "cm_mesh", lib.cm_mesh_destroy, model, opt)
    mesh = Mesh(m, _TOKEN)
    sj = ffi.new("double **")
    ctx.call(lib.cm_mesh_add_field, mesh._ptr, b"scaled_jacobian", lib.CM_FIELD_CELL, 1, sj)
    ctx.call(lib.cm_mesh_quality, mesh._ptr, sj[0])
    return mesh
