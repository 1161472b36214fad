#!/usr/bin/python3
"""Two study.csv of the same study (serial and over MPI ranks) have the same rows in the same
order: variant, mode, method, status equal; min/mean scaled Jacobian within TOL.
usage: same_study.py A.csv B.csv TOL"""
import csv
import sys


def main():
    a, b = (list(csv.DictReader(open(p))) for p in sys.argv[1:3])
    tol = float(sys.argv[3])
    if len(a) != len(b):
        sys.exit(f"{len(a)} vs {len(b)} rows")
    for i, (x, y) in enumerate(zip(a, b)):
        for k in ("variant", "mode", "method", "status", "inverted"):
            if x[k] != y[k]:
                sys.exit(f"row {i + 1}: {k} {x[k]!r} vs {y[k]!r}")
        for k in ("min_scaled_jacobian", "mean_scaled_jacobian"):
            if x[k] and abs(float(x[k]) - float(y[k])) > tol:
                sys.exit(f"row {i + 1}: {k} {x[k]} vs {y[k]}")
    print(f"{len(a)} rows agree")


if __name__ == "__main__":
    main()
