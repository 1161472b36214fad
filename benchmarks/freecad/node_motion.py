"""Largest node displacement between two meshes with the same nodes, relative to the bbox
diagonal of the first: usage node_motion.py M0 M1."""
import sys
import meshio
import numpy as np

a = meshio.read(sys.argv[1]).points
b = meshio.read(sys.argv[2]).points
diag = np.linalg.norm(a.max(0) - a.min(0))
d = np.linalg.norm(a - b, axis=1).max() if a.shape == b.shape else float("nan")
print("nodes %d, max |x1 - x0| = %.3g (%.3g x diagonal)" % (len(a), d, d / diag))
