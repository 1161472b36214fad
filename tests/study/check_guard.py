"""Runs `cadmorph study` and checks how it treats morphs that reach no valid mesh.

  check_guard.py --dir DIR --exit N [--ok L,..] [--inverted L,..] [--failed L,..] -- COMMAND...

DIR (the study's -o) is removed first. Then: the exit code is N; study.csv has one absolute
row per label; --ok rows are complete without an inverted cell and their mesh is written;
--inverted rows are complete with inverted cells (kept on request) and their mesh is written;
--failed rows have status "result rejected" and a message naming inverted cells, and no mesh.
With exit 3 the last stderr line counts the failed rows.
"""
import argparse
import csv
import os
import shutil
import subprocess
import sys


def labels(v):
    return [x for x in v.split(",") if x]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--dir", required=True)
    ap.add_argument("--exit", type=int, required=True)
    ap.add_argument("--ok", type=labels, default=[])
    ap.add_argument("--inverted", type=labels, default=[])
    ap.add_argument("--failed", type=labels, default=[])
    ap.add_argument("command", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    cmd = a.command[1:] if a.command and a.command[0] == "--" else a.command
    shutil.rmtree(a.dir, ignore_errors=True)  # stale outputs must not pass the test
    p = subprocess.run(cmd, capture_output=True, text=True)
    sys.stdout.write(p.stdout)
    sys.stderr.write(p.stderr)
    failures = []

    def check(cond, msg):
        if not cond:
            failures.append(msg)
            print("FAIL:", msg)

    check(p.returncode == a.exit, "exit code %d, expected %d" % (p.returncode, a.exit))
    csv_path = os.path.join(a.dir, "study.csv")
    check(os.path.exists(csv_path), csv_path + " missing")
    if not os.path.exists(csv_path):
        return 1
    with open(csv_path, newline="") as f:
        rows = {r["variant"]: r for r in csv.DictReader(f)}
    want = a.ok + a.inverted + a.failed
    check(sorted(rows) == sorted(want), "rows %s, expected %s" % (sorted(rows), sorted(want)))
    for label in want:
        r = rows.get(label)
        if r is None:
            continue
        mesh = os.path.join(a.dir, "%s_%s_%s.vtu" % (r["method"], r["mode"], label))
        if label in a.failed:
            check(r["status"] == "result rejected" and "inverted" in r["message"],
                  "%s: status %r message %r" % (label, r["status"], r["message"]))
            check(not os.path.exists(mesh), mesh + " written for a failed row")
            continue
        check(r["status"] in ("ok", "warning"), "%s: status %r %r" % (label, r["status"], r["message"]))
        n = int(r["inverted"])
        check(n > 0 if label in a.inverted else n == 0, "%s: %d inverted cells" % (label, n))
        check(os.path.exists(mesh), mesh + " missing")
    if a.exit == 3:
        last = p.stderr.rstrip("\n").split("\n")[-1]
        check("%d of %d rows failed" % (len(a.failed), len(want)) in last,
              "last stderr line %r" % last)
    print("%d failed" % len(failures) if failures else "study guard OK")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
