#!/usr/bin/python3
"""check_map.py MAP.csv FACES EDGES VERTICES: the --map of `cadmorph info --compare` has the
header, one row per face, edge and vertex of G, each kind a permutation of G''s indices, an
orientation of 'same' or 'reversed', and at least one entity numbered otherwise."""
import csv
import sys

path, want = sys.argv[1], dict(zip(("face", "edge", "vertex"), map(int, sys.argv[2:5])))
with open(path, newline="") as f:
    rows = list(csv.reader(f))
assert rows[0] == ["kind", "index_in_G", "index_in_G'", "orientation", "type_G", "type_G'"], rows[0]
moved = 0
for kind, n in want.items():
    r = [x for x in rows[1:] if x[0] == kind]
    assert len(r) == n, "%s: %d rows, expected %d" % (kind, len(r), n)
    assert sorted(int(x[1]) for x in r) == list(range(n)), kind
    assert sorted(int(x[2]) for x in r) == list(range(n)), kind + ": not a permutation"
    assert all(x[3] in ("same", "reversed") for x in r), kind
    moved += sum(x[1] != x[2] for x in r)
assert moved > 0, "nothing renumbered"
print("%s: %d rows, %d entities renumbered" % (path, len(rows) - 1, moved))
