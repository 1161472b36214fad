#!/usr/bin/python3
"""The one runner of the CLI tests: runs a command and checks what a user or a script sees
(ctest alone checks either the exit code or one regex, not both).

  run_cli.py [checks] -- command args...

  --exit N            exit code (default 0)
  --stdout REGEX      must match somewhere in stdout (re.search, multiline); repeatable
  --stderr REGEX      the same for stderr; repeatable
  --output REGEX      must match stdout+stderr as one string, as CMake's MATCHES does
                      (^ is the start, . matches newlines too); repeatable
  --last-line REGEX   the last stdout line must match in full
  --stderr-lines N    exactly N stderr lines (error paths: one line saying what and where)
  --stderr-has TEXT   stderr contains TEXT literally (e.g. the path of the bad file); repeatable
  --csv PATH ROWS     PATH (removed before the run) exists afterwards with the quality header
                      cell,type,scaled_jacobian and ROWS data rows, no temporary file beside it
  --unchanged FILE    FILE has the same bytes after the run (an input never overwritten)
  --absent FILE       FILE does not exist after the run (nothing written on failure)
Prints the command, its exit code and output, and a FAIL: line per failed check.
"""
import glob
import os
import re
import subprocess
import sys

REPEATABLE = {"stdout", "stderr", "output", "stderr-has", "unchanged", "absent"}
SINGLE = {"exit", "last-line", "stderr-lines"}


def parse(opts):
    want = {k: [] for k in REPEATABLE}
    want.update({"exit": "0", "last-line": None, "stderr-lines": None, "csv": None})
    i = 0
    while i < len(opts):
        key = opts[i][2:] if opts[i].startswith("--") else None
        n = 2 if key == "csv" else 1
        if key not in REPEATABLE | SINGLE | {"csv"} or i + n >= len(opts):
            sys.exit("run_cli.py: bad option %s\n%s" % (opts[i], __doc__))
        if key in REPEATABLE:
            want[key].append(opts[i + 1])
        elif key == "csv":
            want[key] = (opts[i + 1], int(opts[i + 2]))
        else:
            want[key] = opts[i + 1]
        i += 1 + n
    return want


def main(argv):
    if "--" not in argv:
        sys.exit(__doc__)
    k = argv.index("--")
    want, cmd = parse(argv[:k]), argv[k + 1:]
    if want["csv"] and os.path.exists(want["csv"][0]):
        os.remove(want["csv"][0])
    before = {}
    for path in want["unchanged"]:
        with open(path, "rb") as f:
            before[path] = f.read()
    r = subprocess.run(cmd, capture_output=True, text=True)
    print("$ " + " ".join(cmd))
    print("exit %d\n--- stdout\n%s--- stderr\n%s---" % (r.returncode, r.stdout, r.stderr))
    ok = True

    def fail(msg):
        nonlocal ok
        print("FAIL: " + msg)
        ok = False

    if r.returncode != int(want["exit"]):
        fail("exit code %d, expected %s" % (r.returncode, want["exit"]))
    for stream, text in (("stdout", r.stdout), ("stderr", r.stderr)):
        for rx in want[stream]:
            if not re.search(rx, text, re.MULTILINE):
                fail("%s does not match /%s/" % (stream, rx))
    for rx in want["output"]:
        if not re.search(rx, r.stdout + r.stderr, re.DOTALL):
            fail("stdout+stderr does not match /%s/" % rx)
    for text in want["stderr-has"]:
        if text not in r.stderr:
            fail("stderr does not contain %r" % text)
    if want["last-line"] is not None:
        last = r.stdout.rstrip("\n").split("\n")[-1]
        if not re.fullmatch(want["last-line"], last):
            fail("last stdout line %r does not match /%s/" % (last, want["last-line"]))
    if want["stderr-lines"] is not None:
        n = len(r.stderr.splitlines())
        if n != int(want["stderr-lines"]):
            fail("%d stderr lines, expected %s" % (n, want["stderr-lines"]))
    if want["csv"]:
        path, rows = want["csv"]
        if not os.path.exists(path):
            fail(path + " missing")
        else:
            lines = open(path).read().splitlines()
            if not lines or lines[0] != "cell,type,scaled_jacobian" or len(lines) != rows + 1:
                fail("%s: header %r, %d lines, expected %d" %
                     (path, lines[0] if lines else "", len(lines), rows + 1))
            for line in lines[1:]:
                c, _, v = line.split(",")
                int(c), float(v)
        left = glob.glob(path + ".tmp*")
        if left:
            fail("temporary file left: " + ", ".join(left))
    for path, data in before.items():
        with open(path, "rb") as f:
            if f.read() != data:
                fail(path + " changed")
    for path in want["absent"]:
        if os.path.exists(path):
            fail(path + " exists")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
