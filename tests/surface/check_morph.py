#!/usr/bin/python3
"""Independent checks of `cadmorph morph` outputs (tools nobody here wrote: gmsh, meshio).
  check_morph.py ongeom M0.msh M1 G1.step REL   boundary nodes of M1 (those of M0's surface
      triangles) lie on G1 within REL x G1's bbox diagonal, measured by gmsh's closest point
      on every surface of G1; M1's 'displacement' field is M1 - M0 and 'scaled_jacobian' has
      no inverted cell (fields not checked for Medit .mesh, which has none)
  check_morph.py report R.csv K                 R.csv has the header and K step rows"""
import csv
import sys

import numpy as np


def ongeom(m0_path, m1_path, step, rel):
    import gmsh
    import meshio
    m0, m1 = meshio.read(m0_path), meshio.read(m1_path)
    assert m0.points.shape == m1.points.shape, "node counts differ"
    tri = np.concatenate([c.data.ravel() for c in m0.cells
                          if c.type.startswith("triangle") or c.type.startswith("quad")])
    nodes = np.unique(tri)
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.occ.importShapes(step)
    gmsh.model.occ.synchronize()
    lo = np.array(gmsh.model.getBoundingBox(-1, -1)[:3])
    hi = np.array(gmsh.model.getBoundingBox(-1, -1)[3:])
    diag = np.linalg.norm(hi - lo)
    best = np.full(len(nodes), np.inf)
    pts = m1.points[nodes].ravel().tolist()
    for dim, tag in gmsh.model.getEntities(2):
        cp, _ = gmsh.model.getClosestPoint(dim, tag, pts)
        d = np.linalg.norm(np.array(cp).reshape(-1, 3) - m1.points[nodes], axis=1)
        best = np.minimum(best, d)
    gmsh.finalize()
    worst = best.max()
    print("%d boundary nodes, largest distance to %s: %.3g (%.3g x diagonal)"
          % (len(nodes), step, worst, worst / diag))
    ok = worst <= rel * diag
    if m1_path.endswith(".mesh"):
        return ok  # Medit carries no fields
    disp = m1.point_data.get("displacement")
    if disp is None or np.abs(m0.points + disp - m1.points).max() > 1e-12 * diag:
        print("FAIL: displacement field missing or not M1 - M0")
        ok = False
    sj = [c for c in m1.cell_data.get("scaled_jacobian", [])]
    if not sj:
        print("FAIL: no scaled_jacobian cell field")
        ok = False
    else:
        vals = np.concatenate([np.asarray(a).ravel() for a in sj])
        vals = vals[np.isfinite(vals)]
        if len(vals) == 0 or vals.min() <= 0:
            print("FAIL: inverted cells in scaled_jacobian")
            ok = False
    return ok


def rejected(rows):
    """A refused morph's report: its last row rejected, with inverted cells that its note
    names; every accepted row before it valid."""
    last = rows[-1]
    if float(last[13]) != 0 or int(last[3]) < 1 or "inverted" not in last[15] or "SJ" not in last[15]:
        print("FAIL: the last row is not a rejected step naming its inverted cells: %s" % last)
        return False
    for r in rows[1:-1]:
        if float(r[13]) == 1 and int(r[3]) != 0:
            print("FAIL: accepted row with inverted cells %s" % r)
            return False
    return True


def report(path, k):
    """k rows (an integer), 'auto+N': any number with at least N accepted steps, or
    'rejected': a morph that reached no valid mesh (the last row says why)."""
    rows = list(csv.reader(open(path)))
    want = ["step", "min_scaled_jacobian", "mean_scaled_jacobian", "inverted",
            "max_distance_to_g1", "t_read", "t_sample", "t_classify", "t_surface_morph",
            "t_volume_solve", "t_evaluation", "t_write", "fraction", "accepted",
            "optimized_moves", "note"]
    if rows[0] != want:
        print("FAIL: header %s" % rows[0])
        return False
    n = len(rows) - 1
    if k == "rejected":
        return n >= 1 and rejected(rows)
    auto = k.startswith("auto+")
    if (not auto and n != int(k)) or n < 1 or [int(r[0]) for r in rows[1:]] != list(range(1, n + 1)):
        print("FAIL: %d rows, expected steps 1..%s" % (n, k))
        return False
    for r in rows[1:]:
        v = [float(x) for x in r[:15]]
        accepted = v[13] == 1
        if min(v[5:12]) < 0 or not (0 < v[12] <= 1):
            print("FAIL: row %s" % r)
            return False
        if accepted and (not (0 < v[1] <= v[2] <= 1) or v[3] != 0):
            print("FAIL: accepted row with inverted cells %s" % r)
            return False
        if not accepted and (v[1] > 0 or "SJ" not in r[15]):
            print("FAIL: rejected row without inverted cells or note %s" % r)
            return False
    if auto and sum(float(r[13]) == 1 for r in rows[1:]) < int(k[5:]):
        print("FAIL: fewer than %s accepted steps" % k[5:])
        return False
    last = rows[-1]
    if float(last[13]) != 1 or float(last[12]) != 1:
        print("FAIL: the last row is not an accepted full step: %s" % last)
        return False
    if float(last[4]) > 1e-9 or (float(rows[1][12]) < 1 and float(rows[1][4]) <= float(last[4])):
        print("FAIL: distance to G1 does not end at ~0: %s" % [r[4] for r in rows[1:]])
        return False
    return True


if __name__ == "__main__":
    a = sys.argv[1:]
    if a[:1] == ["ongeom"] and len(a) == 5:
        sys.exit(0 if ongeom(a[1], a[2], a[3], float(a[4])) else 1)
    if a[:1] == ["report"] and len(a) == 3:
        sys.exit(0 if report(a[1], a[2]) else 1)
    sys.exit(__doc__)
