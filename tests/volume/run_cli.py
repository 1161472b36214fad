#!/usr/bin/python3
"""Runs a command and checks its exit code and output (ctest can only check one of them).

  run_cli.py [--exit N] [--stdout REGEX] [--stderr REGEX] [--stderr-lines N]
             [--unchanged FILE] [--absent FILE] -- command args...

--stdout/--stderr: a regex that must match somewhere (re.search, multiline);
--stderr-lines: exact number of non-empty stderr lines (the contract: one line per error);
--unchanged: FILE must have the same bytes after the run; --absent: FILE must not exist after.
"""
import re
import subprocess
import sys


def main(argv):
    if "--" not in argv:
        sys.exit(__doc__)
    k = argv.index("--")
    opts, cmd = argv[:k], argv[k + 1:]
    want = {"exit": "0", "stdout": [], "stderr": [], "stderr-lines": None, "unchanged": [],
            "absent": []}
    i = 0
    while i < len(opts):
        key = opts[i].lstrip("-")
        if key not in want or i + 1 >= len(opts):
            sys.exit("run_cli.py: bad option %s\n%s" % (opts[i], __doc__))
        if isinstance(want[key], list):
            want[key].append(opts[i + 1])
        else:
            want[key] = opts[i + 1]
        i += 2
    before = {}
    for path in want["unchanged"]:
        with open(path, "rb") as f:
            before[path] = f.read()
    r = subprocess.run(cmd, capture_output=True, text=True)
    ok = True
    print("$ " + " ".join(cmd))
    print("exit %d\n--- stdout\n%s--- stderr\n%s---" % (r.returncode, r.stdout, r.stderr))
    if r.returncode != int(want["exit"]):
        print("FAIL: exit code %d, expected %s" % (r.returncode, want["exit"]))
        ok = False
    for stream, text in (("stdout", r.stdout), ("stderr", r.stderr)):
        for rx in want[stream]:
            if not re.search(rx, text, re.MULTILINE):
                print("FAIL: %s does not match /%s/" % (stream, rx))
                ok = False
    if want["stderr-lines"] is not None:
        n = len([line for line in r.stderr.splitlines() if line.strip()])
        if n != int(want["stderr-lines"]):
            print("FAIL: %d stderr lines, expected %s" % (n, want["stderr-lines"]))
            ok = False
    for path, data in before.items():
        with open(path, "rb") as f:
            if f.read() != data:
                print("FAIL: %s changed" % path)
                ok = False
    for path in want["absent"]:
        try:
            open(path, "rb").close()
            print("FAIL: %s exists" % path)
            ok = False
        except FileNotFoundError:
            pass
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
