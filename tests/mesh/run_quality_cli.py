"""Runs one `cadmorph quality` command line and checks what a user or a script sees.

usage: run_quality_cli.py --exit CODE [--last-line REGEX] [--stderr-lines N]
                          [--csv PATH ROWS] [--unchanged PATH] -- COMMAND...
  --exit        expected exit code
  --last-line   regex the last stdout line must match in full
  --stderr-lines exact number of stderr lines (error paths: one line saying what and where)
  --csv         PATH must exist with header cell,type,scaled_jacobian and ROWS data rows,
                no temporary files left beside it
  --unchanged   PATH must have the same bytes after the run (an input never overwritten)
"""
import argparse
import glob
import os
import re
import subprocess
import sys


def main():
    sep = sys.argv.index("--")
    ap = argparse.ArgumentParser()
    ap.add_argument("--exit", type=int, required=True)
    ap.add_argument("--last-line")
    ap.add_argument("--stderr-lines", type=int)
    ap.add_argument("--csv", nargs=2)
    ap.add_argument("--unchanged")
    a = ap.parse_args(sys.argv[1:sep])
    cmd = sys.argv[sep + 1:]
    if a.csv and os.path.exists(a.csv[0]):
        os.remove(a.csv[0])
    before = open(a.unchanged, "rb").read() if a.unchanged else None
    p = subprocess.run(cmd, capture_output=True, text=True)
    sys.stdout.write(p.stdout)
    sys.stderr.write(p.stderr)
    ok = True

    def fail(msg):
        nonlocal ok
        print("FAIL: " + msg)
        ok = False

    if p.returncode != a.exit:
        fail(f"exit code {p.returncode}, expected {a.exit}")
    if a.last_line is not None:
        lines = p.stdout.rstrip("\n").split("\n")
        if not re.fullmatch(a.last_line, lines[-1]):
            fail(f"last stdout line {lines[-1]!r} does not match {a.last_line!r}")
    if a.stderr_lines is not None:
        n = len(p.stderr.splitlines())
        if n != a.stderr_lines:
            fail(f"{n} stderr lines, expected {a.stderr_lines}")
    if a.csv:
        path, rows = a.csv[0], int(a.csv[1])
        if not os.path.exists(path):
            fail(f"{path} missing")
        else:
            lines = open(path).read().splitlines()
            if lines[0] != "cell,type,scaled_jacobian" or len(lines) != rows + 1:
                fail(f"{path}: header {lines[0]!r}, {len(lines)} lines, expected {rows + 1}")
            for line in lines[1:]:
                c, t, v = line.split(",")
                int(c), float(v)
        if glob.glob(path + ".tmp*"):
            fail("temporary file left: " + ", ".join(glob.glob(path + ".tmp*")))
    if before is not None and open(a.unchanged, "rb").read() != before:
        fail(f"{a.unchanged} was modified")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
