#!/usr/bin/python3
"""A snappyHexMesh case for the CFD benchmark: a sphere body (snappyHexMesh's own
searchableSphere: no STL needed) in a tunnel, castellated, snapped and with 2 boundary layers
on the body, then made a runnable simpleFoam (laminar) case like tests/helpers/foam_cases.py's
(patches inlet outlet walls body). usage: snappy_case.py CASE_DIR [--base N]
  --base N   background cells across the tunnel's height (default 24: ~150k cells)"""
import argparse
import os
import shutil
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "tests", "helpers"))
import foam_cases as fc  # noqa: E402


def make_snappy_case(case, base=24):
    """Writes and meshes the case; returns case."""
    shutil.rmtree(case, ignore_errors=True)
    os.makedirs(case)
    # tunnel x in [-1.5, 3], y and z in [-1, 1]; the body a sphere of radius 0.35 at 0
    nx, ny = int(round(base * 4.5 / 2)), base
    fc._write_system(case, False, False, None)
    fc._dict(case, "system/blockMeshDict", """convertToMeters 1;
vertices ( (-1.5 -1 -1) (3 -1 -1) (3 1 -1) (-1.5 1 -1) (-1.5 -1 1) (3 -1 1) (3 1 1) (-1.5 1 1) );
blocks ( hex (0 1 2 3 4 5 6 7) (%d %d %d) simpleGrading (1 1 1) );
edges ();
boundary ( inlet { type patch; faces ((0 4 7 3)); } outlet { type patch; faces ((1 2 6 5)); }
  walls { type wall; faces ((0 1 5 4) (3 7 6 2) (0 3 2 1) (4 5 6 7)); } );
mergePatchPairs ();
""" % (nx, ny, ny))
    fc._dict(case, "system/snappyHexMeshDict", """
castellatedMesh true; snap true; addLayers true;
geometry { body { type searchableSphere; centre (0 0 0); radius 0.35; } }
castellatedMeshControls { maxLocalCells 10000000; maxGlobalCells 20000000; minRefinementCells 0;
  maxLoadUnbalance 0.1; nCellsBetweenLevels 3; features ( );
  refinementSurfaces { body { level (2 2); patchInfo { type wall; } } }
  resolveFeatureAngle 30;
  refinementRegions { body { mode distance; levels ((0.25 1)); } }
  locationInMesh (2.71 0.831 0.771); allowFreeStandingZoneFaces true; }
snapControls { nSmoothPatch 3; tolerance 2.0; nSolveIter 30; nRelaxIter 5; nFeatureSnapIter 10;
  implicitFeatureSnap false; explicitFeatureSnap false; multiRegionFeatureSnap false; }
addLayersControls { relativeSizes true; layers { body { nSurfaceLayers 2; } }
  expansionRatio 1.2; finalLayerThickness 0.4; minThickness 0.05; nGrow 0; featureAngle 120;
  slipFeatureAngle 30; nRelaxIter 3; nSmoothSurfaceNormals 1; nSmoothNormals 3; nSmoothThickness 10;
  maxFaceThicknessRatio 0.5; maxThicknessToMedialRatio 0.3; minMedialAxisAngle 90;
  nBufferCellsNoExtrude 0; nLayerIter 50; }
meshQualityControls { maxNonOrtho 65; maxBoundarySkewness 20; maxInternalSkewness 4; maxConcave 80;
  minVol 1e-13; minTetQuality 1e-15; minArea -1; minTwist 0.02; minDeterminant 0.001;
  minFaceWeight 0.05; minVolRatio 0.01; minTriangleTwist -1; nSmoothScale 4; errorReduction 0.75; }
mergeTolerance 1e-6;
""")
    fc.run_foam("blockMesh", case)
    fc.run_foam("snappyHexMesh", case, "-overwrite")
    # the fields after meshing (snappyHexMesh would map fields it found in 0/)
    fc._write_fields(case, {"inlet": "patch", "outlet": "patch", "walls": "wall", "body": "wall"})
    return case


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("case")
    ap.add_argument("--base", type=int, default=24)
    a = ap.parse_args()
    make_snappy_case(a.case, a.base)
