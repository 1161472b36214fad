#!/usr/bin/python3
"""Cross-check of the RBF core against scipy.interpolate.RBFInterpolator (code nobody here
wrote): same centres, values and kernel with a degree-1 polynomial give the same interpolant,
so cadmorph's results at random points must match scipy's to 1e-8 x the data range.
scipy's 'linear' kernel is -r: the same interpolant as phi = r (the weights change sign).
usage: rbf_scipy_check.py WORK_DIR"""
import os
import sys

import numpy as np
from scipy.interpolate import RBFInterpolator

TOL = 1e-8


def compare(work, case):
    d = os.path.join(work, "rbf_scipy")
    load = lambda what: np.loadtxt(os.path.join(d, f"{case}_{what}.txt"), ndmin=2)
    centres, values, points, ours = (load(w) for w in ("centres", "values", "points", "result"))
    ref = RBFInterpolator(centres, values, kernel=case, degree=1)(points)
    data_range = values.max() - values.min()
    return np.abs(ours - ref).max() / data_range, ours, ref, data_range


def main():
    work = sys.argv[1]
    failed = 0
    for case in ("cubic", "linear", "thin_plate_spline"):
        err, ours, ref, data_range = compare(work, case)
        ok = err <= TOL
        print(f"{case}: max |cadmorph - scipy| / data range = {err:.3g} (tol {TOL}) "
              f"{'ok' if ok else 'FAIL'}")
        failed += not ok
        # The comparison must be able to fail: a perturbation of 10 x TOL of the range at
        # one point is caught.
        bad = ours.copy()
        bad[len(bad) // 2, 0] += 10 * TOL * data_range
        if np.abs(bad - ref).max() / data_range <= TOL:
            print(f"{case}: the check does not see a perturbation of 10 x tol: FAIL")
            failed += 1
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
