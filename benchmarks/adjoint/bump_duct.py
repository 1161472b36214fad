#!/usr/bin/python3
"""A square duct with a bump on its floor, the geometry of the OpenFOAM adjoint example:
x in [0, 6] (flow direction), y in [0, 1], z in [0, 1]. The floor's profile is a cubic
B-spline in the x-z plane with control points (0,0) (1.5,0) (3-w,0) (3,h) (3+w,0) (4.5,0)
(6,0), extruded along y: h (the middle control point's height) and w (the half-spread of
the bump's control points) are the design parameters. Every (h, w) gives the same six faces
(inlet x=0, outlet x=6, the bump floor, three flat walls), so a mesh of one STEP can be
morphed onto another. Built with gmsh's OpenCASCADE kernel (Debian python3-gmsh).

usage: bump_duct.py step H W OUT.step
       bump_duct.py mesh STEP OUT.msh [--nx 60 --ny 16 --nz 16]
`mesh` writes a structured hex mesh of the STEP (transfinite, MSH 2.2) with the physical
groups inlet, outlet, bump and walls (2D) and fluid (3D), for gmshToFoam."""
import argparse

import gmsh

LENGTH, HEIGHT, WIDTH = 6.0, 1.0, 1.0


def write_step(h: float, w: float, path: str) -> None:
    """Writes the duct with bump parameters h, w as STEP to path."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    occ = gmsh.model.occ
    xs = [0.0, 1.5, 3.0 - w, 3.0, 3.0 + w, 4.5, LENGTH]
    zs = [0.0, 0.0, 0.0, h, 0.0, 0.0, 0.0]
    pts = [occ.addPoint(x, 0.0, z) for x, z in zip(xs, zs)]
    floor = occ.addBSpline(pts)
    p_out = occ.addPoint(LENGTH, 0.0, HEIGHT)
    p_in = occ.addPoint(0.0, 0.0, HEIGHT)
    loop = occ.addCurveLoop([floor, occ.addLine(pts[-1], p_out), occ.addLine(p_out, p_in),
                             occ.addLine(p_in, pts[0])])
    occ.extrude([(2, occ.addPlaneSurface([loop]))], 0.0, WIDTH, 0.0)
    occ.synchronize()
    gmsh.write(path)
    gmsh.finalize()


def write_mesh(step: str, path: str, nx: int, ny: int, nz: int) -> None:
    """Structured hex mesh of the duct's STEP: nx x ny x nz cells, physical groups by face."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    model = gmsh.model
    model.occ.importShapes(step)
    model.occ.synchronize()
    for _, tag in model.getEntities(1):
        b = model.getBoundingBox(1, tag)
        ext = [b[3] - b[0], b[4] - b[1], b[5] - b[2]]
        axis = max(range(3), key=lambda i: ext[i])
        model.mesh.setTransfiniteCurve(tag, [nx, ny, nz][axis] + 1)
    for _, tag in model.getEntities(2):
        model.mesh.setTransfiniteSurface(tag)
        model.mesh.setRecombine(2, tag)
    for _, tag in model.getEntities(3):
        model.mesh.setTransfiniteVolume(tag)
    groups = {"inlet": [], "outlet": [], "bump": [], "walls": []}
    for _, tag in model.getEntities(2):
        b = model.getBoundingBox(2, tag)
        if b[3] - b[0] < 1e-6:  # a face at constant x
            groups["inlet" if b[0] < 0.5 * LENGTH else "outlet"].append(tag)
        elif model.getType(2, tag) != "Plane":
            groups["bump"].append(tag)
        else:
            groups["walls"].append(tag)
    if any(len(v) != n for v, n in zip(groups.values(), (1, 1, 1, 3))):
        raise SystemExit("bump_duct.py: unexpected faces %r" % groups)
    for name, tags in groups.items():
        model.setPhysicalName(2, model.addPhysicalGroup(2, tags), name)
    model.setPhysicalName(3, model.addPhysicalGroup(3, [t for _, t in model.getEntities(3)]),
                          "fluid")
    model.mesh.generate(3)
    gmsh.option.setNumber("Mesh.MshFileVersion", 2.2)
    gmsh.write(path)
    gmsh.finalize()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("step")
    s.add_argument("h", type=float)
    s.add_argument("w", type=float)
    s.add_argument("out")
    m = sub.add_parser("mesh")
    m.add_argument("step")
    m.add_argument("out")
    m.add_argument("--nx", type=int, default=60)
    m.add_argument("--ny", type=int, default=16)
    m.add_argument("--nz", type=int, default=16)
    a = ap.parse_args()
    if a.cmd == "step":
        write_step(a.h, a.w, a.out)
    else:
        write_mesh(a.step, a.out, a.nx, a.ny, a.nz)


if __name__ == "__main__":
    main()
