#!/usr/bin/python3
"""A car-like body in a wind tunnel, meshed by OpenFOAM's snappyHexMesh with a boundary layer
([SMB14 §3.6.2]): a rounded box with four wheel arches and a sloped rear, built
with gmsh's OpenCASCADE kernel (STEP and STL), a blockMesh tunnel, snappyHexMesh (castellate,
snap, 2 layers on the body).  usage: make_case.py CASE_DIR [--base N] [--level L] [--height H] [--step-only PATH]
  --base N   background cells along the body length (default 10: ~50k cells; 20 ~ 300k)
  --level L  surface refinement level on the body (default 2)"""
import argparse
import os
import shutil
import subprocess
import sys

ap = argparse.ArgumentParser()
ap.add_argument("case")
ap.add_argument("--base", type=int, default=10)
ap.add_argument("--level", type=int, default=2)
ap.add_argument("--height", type=float, default=0.32, help="body height (default 0.32)")
ap.add_argument("--step-only", metavar="PATH", help="only write the body's STEP to PATH (a CAD edit)")
a = ap.parse_args()
case = a.case
if not a.step_only:
    shutil.rmtree(case, ignore_errors=True)
    for d in ("system", "constant/triSurface"):
        os.makedirs(os.path.join(case, d))

# body: length 1, width 0.45, height 0.32, ground clearance 0.05, at x in [0, 1]
L, W, H, C = 1.0, 0.45, a.height, 0.05
import gmsh  # noqa: E402  (Debian python3-gmsh)
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
occ = gmsh.model.occ
body = occ.addBox(0, -W / 2, C, L, W, H)
occ.synchronize()
occ.fillet([body], [e[1] for e in gmsh.model.getEntities(1)], [0.06])
occ.synchronize()
# sloped rear: a box rotated about y cuts the top rear
cut = occ.addBox(0.62, -W, C + 0.22 * H / 0.32, 1.0, 2 * W, 0.6)
occ.rotate([(3, cut)], 0.62, 0, C + 0.22 * H / 0.32, 0, 1, 0, -0.5)
arches = [occ.addCylinder(x, -W, C + 0.02, 0, 2 * W, 0, 0.075) for x in (0.2, 0.8)]
out, _ = occ.cut([(3, 1)], [(3, cut)] + [(3, t) for t in arches])
occ.synchronize()
if a.step_only:
    gmsh.write(a.step_only)
    gmsh.finalize()
    sys.exit(0)
gmsh.write(os.path.join(case, "constant", "body.step"))
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.02)
gmsh.option.setNumber("Mesh.MeshSizeMin", 0.004)
gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 12)
gmsh.model.mesh.generate(2)
gmsh.write(os.path.join(case, "constant", "triSurface", "body.stl"))
gmsh.finalize()

HEADER = "FoamFile { version 2.0; format ascii; class dictionary; object %s; }\n"
n = a.base
h = L / n
# tunnel: 2 L upstream, 4 L downstream, 1.5 L to each side, 1.5 L high; ground at z = 0
x0, x1, y0, y1, z0, z1 = -2 * L, 5 * L, -1.5 * L, 1.5 * L, 0.0, 1.5 * L
nx, ny, nz = round((x1 - x0) / h), round((y1 - y0) / h), round((z1 - z0) / h)
files = {
    "controlDict": "application snappyHexMesh; startFrom startTime; startTime 0; stopAt endTime;\n"
                   "endTime 1; deltaT 1; writeControl timeStep; writeInterval 1; writeFormat ascii;\n"
                   "writePrecision 6; writeCompression off; timeFormat general; timePrecision 6;\n",
    "fvSchemes": "ddtSchemes { default steadyState; } gradSchemes { default Gauss linear; }\n"
                 "divSchemes { default none; } laplacianSchemes { default Gauss linear corrected; }\n"
                 "interpolationSchemes { default linear; } snGradSchemes { default corrected; }\n",
    "fvSolution": "",
    "blockMeshDict": f"""
vertices ( ({x0} {y0} {z0}) ({x1} {y0} {z0}) ({x1} {y1} {z0}) ({x0} {y1} {z0})
           ({x0} {y0} {z1}) ({x1} {y0} {z1}) ({x1} {y1} {z1}) ({x0} {y1} {z1}) );
blocks ( hex (0 1 2 3 4 5 6 7) ({nx} {ny} {nz}) simpleGrading (1 1 1) );
boundary ( inlet {{ type patch; faces ((0 4 7 3)); }} outlet {{ type patch; faces ((1 2 6 5)); }}
  ground {{ type wall; faces ((0 3 2 1)); }}
  tunnel {{ type patch; faces ((0 1 5 4) (3 7 6 2) (4 5 6 7)); }} );
""",
    "snappyHexMeshDict": f"""
castellatedMesh true; snap true; addLayers true;
geometry {{ body.stl {{ type triSurfaceMesh; name body; }}
  near {{ type searchableBox; min (-0.3 -0.5 0); max (2.0 0.5 0.6); }} }}
castellatedMeshControls {{ maxLocalCells 5000000; maxGlobalCells 20000000; minRefinementCells 0;
  maxLoadUnbalance 0.1; nCellsBetweenLevels 2; features ( );
  refinementSurfaces {{ body {{ level ({a.level} {a.level}); }} }} resolveFeatureAngle 30;
  refinementRegions {{ near {{ mode inside; levels ((1e15 1)); }} }}
  locationInMesh ({x1 - 0.37 * h} {y1 - 0.41 * h} {z1 - 0.43 * h}); allowFreeStandingZoneFaces true; }}
snapControls {{ nSmoothPatch 3; tolerance 2.0; nSolveIter 50; nRelaxIter 5; nFeatureSnapIter 10;
  implicitFeatureSnap true; explicitFeatureSnap false; multiRegionFeatureSnap false; }}
addLayersControls {{ relativeSizes true; layers {{ body {{ nSurfaceLayers 2; }} }}
  expansionRatio 1.3; finalLayerThickness 0.4; minThickness 0.05; nGrow 0; featureAngle 130;
  slipFeatureAngle 30; nRelaxIter 5; nSmoothSurfaceNormals 1; nSmoothNormals 3; nSmoothThickness 10;
  maxFaceThicknessRatio 0.5; maxThicknessToMedialRatio 0.3; minMedialAxisAngle 90;
  nBufferCellsNoExtrude 0; nLayerIter 50; }}
meshQualityControls {{ maxNonOrtho 65; maxBoundarySkewness 20; maxInternalSkewness 4; maxConcave 80;
  minVol 1e-13; minTetQuality 1e-15; minArea -1; minTwist 0.02; minDeterminant 0.001;
  minFaceWeight 0.05; minVolRatio 0.01; minTriangleTwist -1; nSmoothScale 4; errorReduction 0.75; }}
mergeTolerance 1e-6;
""",
}
for name, text in files.items():
    with open(os.path.join(case, "system", name), "w") as f:
        f.write(HEADER % name + text)
env = dict(os.environ)
env.setdefault("WM_PROJECT_DIR", "/usr/share/openfoam")
for tool in (["blockMesh"], ["snappyHexMesh", "-overwrite"]):
    with open(os.path.join(case, "log." + tool[0]), "w") as log:
        if subprocess.run(tool + ["-case", case], env=env, stdout=log, stderr=subprocess.STDOUT).returncode:
            sys.exit("%s failed: see %s/log.%s" % (tool[0], case, tool[0]))
print("case written:", case)
