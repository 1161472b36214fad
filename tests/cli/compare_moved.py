#!/usr/bin/python3
"""Two moved meshes of the same input agree: max |node difference| <= TOL x the range of the
first one's 'displacement' point data. usage: compare_moved.py A B TOL"""
import sys

import meshio
import numpy as np


def main():
    a, b = meshio.read(sys.argv[1]), meshio.read(sys.argv[2])
    tol = float(sys.argv[3])
    d = np.asarray(a.point_data["displacement"])
    rng = d.max() - d.min()
    if a.points.shape != b.points.shape:
        sys.exit(f"{a.points.shape[0]} vs {b.points.shape[0]} nodes")
    diff = np.abs(a.points - b.points).max() / rng
    print(f"max node difference {diff:.3g} of the displacement range (tolerance {tol:g})")
    sys.exit(0 if diff <= tol and rng > 0 else 1)


if __name__ == "__main__":
    main()
