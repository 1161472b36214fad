#!/usr/bin/python3
"""Two moved meshes of the same input agree: max |node difference| <= TOL x the range of the
first one's 'displacement' point data, or with SCALE = diagonal x the first one's bounding box
diagonal (for a morph that must leave the nodes where they are).
usage: compare_moved.py A B TOL [range|diagonal]"""
import sys

import meshio
import numpy as np


def main():
    a, b = meshio.read(sys.argv[1]), meshio.read(sys.argv[2])
    tol = float(sys.argv[3])
    by_diagonal = len(sys.argv) > 4 and sys.argv[4] == "diagonal"
    if by_diagonal:
        rng = np.linalg.norm(a.points.max(0) - a.points.min(0))
    else:
        d = np.asarray(a.point_data["displacement"])
        rng = d.max() - d.min()
    if a.points.shape != b.points.shape:
        sys.exit(f"{a.points.shape[0]} vs {b.points.shape[0]} nodes")
    diff = np.abs(a.points - b.points).max() / rng
    scale = "bounding box diagonal" if by_diagonal else "displacement range"
    print(f"max node difference {diff:.3g} of the {scale} (tolerance {tol:g})")
    sys.exit(0 if diff <= tol and rng > 0 else 1)


if __name__ == "__main__":
    main()
