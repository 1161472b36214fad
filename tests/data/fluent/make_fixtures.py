#!/usr/bin/python3
"""Regenerates the Fluent fixtures of this folder (written by OpenFOAM's foamMeshToFluent,
Debian package openfoam, from meshes other tools made; the binary variants by to_binary.py):

  box.msh          blockMesh: a skewed 3x2x2 hex block; zones inlet, outlet, walls
  mixed.msh        gmsh (python3-gmsh) meshes 4 hexes, 8 prisms, 4 pyramids and 105 tets,
                   gmshToFoam converts them; zones bottom, walls
  poly.msh         polyDualMesh of box (18 polyhedra, 9 hexes; polygon faces)
  box_double.msh   box with binary sections 3010/3012/3013 (double precision)
  mixed_single.msh mixed with binary sections 2010/2012/2013 (single precision)
  poly_double.msh  poly with binary sections, double precision

usage: make_fixtures.py [OUTDIR]   (default: this folder; needs OpenFOAM and gmsh)"""
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import to_binary  # noqa: E402

ENV = dict(os.environ)
ENV.setdefault("WM_PROJECT_DIR", "/usr/share/openfoam")  # Debian keeps OpenFOAM's etc/ there
HEADER = "FoamFile { version 2.0; format ascii; class dictionary; object %s; }\n"
SYSTEM = {
    "controlDict": "application blockMesh; startFrom startTime; startTime 0; stopAt endTime; endTime 1;\n"
                   "deltaT 1; writeControl timeStep; writeInterval 1; writeFormat ascii; writePrecision 10;\n"
                   "writeCompression off; timeFormat general; timePrecision 6;\n",
    "fvSchemes": "ddtSchemes { default steadyState; } gradSchemes { default Gauss linear; }\n"
                 "divSchemes { default none; } laplacianSchemes { default Gauss linear corrected; }\n"
                 "interpolationSchemes { default linear; } snGradSchemes { default corrected; }\n",
    "fvSolution": "",
}
BLOCK = """convertToMeters 1;
vertices ((0 0 0) (1.2 0.1 0) (1.3 1 0.1) (0 0.9 0) (0.1 0 1) (1 0.1 1.1) (1.2 1.1 1) (0 1 0.9));
blocks (hex (0 1 2 3 4 5 6 7) (3 2 2) simpleGrading (1 1 1));
edges ();
boundary ( inlet { type patch; faces ((0 4 7 3)); } outlet { type patch; faces ((1 2 6 5)); }
 walls { type wall; faces ((0 1 5 4) (3 7 6 2) (0 3 2 1) (4 5 6 7)); } );
"""


def run(cmd, case):
    p = subprocess.run(cmd + ["-case", case], env=ENV, capture_output=True, text=True, cwd=case)
    if p.returncode != 0:
        sys.exit("%s failed:\n%s%s" % (cmd[0], p.stdout[-2000:], p.stderr[-2000:]))


def make_case(path):
    os.makedirs(os.path.join(path, "system"))
    os.makedirs(os.path.join(path, "constant"))
    for name, text in SYSTEM.items():
        with open(os.path.join(path, "system", name), "w") as f:
            f.write(HEADER % name + text)


def fluent(case):
    run(["foamMeshToFluent"], case)
    name = os.path.basename(case)
    with open(os.path.join(case, "fluentInterface", name + ".msh")) as f:
        return f.read()


def gmsh_mixed(path):
    """4 hexes and 8 prisms extruded from a half-quad, half-triangle square; tets above them
    (pyramids where they stand on quads)."""
    import gmsh
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    g = gmsh.model.geo
    p = [g.addPoint(x, y, 0, 0.5) for x, y in [(0, 0), (0.5, 0), (1, 0), (1, 1), (0.5, 1), (0, 1)]]
    L = lambda a, b: g.addLine(p[a], p[b])  # noqa: E731
    l01, l12, l23, l34, l45, l50, l14 = L(0, 1), L(1, 2), L(2, 3), L(3, 4), L(4, 5), L(5, 0), L(1, 4)
    sq = g.addPlaneSurface([g.addCurveLoop([l01, l14, l45, l50])])
    tr = g.addPlaneSurface([g.addCurveLoop([l12, l23, l34, -l14])])
    for c in (l01, l14, l45, l50):
        g.mesh.setTransfiniteCurve(c, 3)
    g.mesh.setTransfiniteSurface(sq)
    g.mesh.setRecombine(2, sq)
    e1 = g.extrude([(2, sq), (2, tr)], 0, 0, 0.5, numElements=[1], recombine=True)
    g.extrude([(2, e1[0][1]), (2, e1[6][1])], 0, 0, 0.5)
    g.synchronize()
    vols = [t for _, t in gmsh.model.getEntities(3)]
    gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, vols), "fluid")
    bnd = gmsh.model.getBoundary([(3, v) for v in vols], oriented=False)
    gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, [sq, tr]), "bottom")
    gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, [t for _, t in bnd if t not in (sq, tr)]), "walls")
    gmsh.model.mesh.generate(3)
    gmsh.option.setNumber("Mesh.MshFileVersion", 2.2)
    gmsh.write(path)
    gmsh.finalize()


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else HERE
    tmp = tempfile.mkdtemp()
    try:
        texts = {}
        box = os.path.join(tmp, "box")
        make_case(box)
        with open(os.path.join(box, "system", "blockMeshDict"), "w") as f:
            f.write(HEADER % "blockMeshDict" + BLOCK)
        run(["blockMesh"], box)
        texts["box"] = fluent(box)
        poly = os.path.join(tmp, "poly")
        shutil.copytree(box, poly)
        shutil.rmtree(os.path.join(poly, "fluentInterface"))
        subprocess.run(["polyDualMesh", "-case", poly, "60", "-overwrite"], env=ENV, capture_output=True, check=True, cwd=tmp)
        texts["poly"] = fluent(poly)
        mixed = os.path.join(tmp, "mixed")
        make_case(mixed)
        gmsh_mixed(os.path.join(tmp, "mixed.msh"))
        subprocess.run(["gmshToFoam", "-case", mixed, os.path.join(tmp, "mixed.msh")], env=ENV, capture_output=True, check=True)
        texts["mixed"] = fluent(mixed)
        for name, text in texts.items():
            with open(os.path.join(out, name + ".msh"), "w") as f:
                f.write(text)
        for name, prec in [("box", "double"), ("mixed", "single"), ("poly", "double")]:
            with open(os.path.join(out, "%s_%s.msh" % (name, prec)), "wb") as f:
                f.write(to_binary.convert(texts[name], prec))
    finally:
        shutil.rmtree(tmp)


if __name__ == "__main__":
    main()
