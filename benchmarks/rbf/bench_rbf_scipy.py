#!/usr/bin/python3
"""scipy side of the RBF benchmark: RBFInterpolator(kernel='cubic', degree=1) on the data that
bench_rbf wrote (raw float64: centres.f64, values.f64, points.f64, c_out.f64 in DIR).
Prints one line of key=value, including the max difference to cadmorph's results. With
REPS > 1 the best times of REPS runs are reported, as bench_rbf does.
usage: bench_rbf_scipy.py M DIR [REPS]"""
import os
import resource
import sys
import time

import numpy as np
from scipy.interpolate import RBFInterpolator


def main():
    m, d = int(sys.argv[1]), sys.argv[2]
    reps = int(sys.argv[3]) if len(sys.argv) > 3 else 1
    load = lambda name: np.fromfile(os.path.join(d, name), dtype=np.float64).reshape(-1, 3)
    centres, values, points, ours = (load(f) for f in
                                     ("centres.f64", "values.f64", "points.f64", "c_out.f64"))
    assert len(centres) == m
    fit = ev = float("inf")
    for _ in range(reps):
        interp = ref = None
        t0 = time.perf_counter()
        interp = RBFInterpolator(centres, values, kernel="cubic", degree=1)
        t1 = time.perf_counter()
        ref = interp(points)
        t2 = time.perf_counter()
        fit, ev = min(fit, t1 - t0), min(ev, t2 - t1)
    rng = values.max() - values.min()
    diff = np.abs(ref - ours).max() / rng
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    print(f"scipy m={m} n={len(points)} reps={reps} fit_s={fit:.3f} eval_s={ev:.3f} "
          f"maxrss_mb={rss:.0f} maxdiff_over_range={diff:.2g}")


if __name__ == "__main__":
    main()
