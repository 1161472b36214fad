"""What the SU2 scripts of tests/mesh (su2_crosscheck.py, su2_cli.py, su2_cfd.py) share: the
tally of their checks and the reading of an .su2 file's markers and point lines as bytes."""

FAILED = []


def check(cond, what):
    """Prints "ok" or "FAIL" with what was checked; a failure is counted."""
    print(("ok   " if cond else "FAIL ") + what, flush=True)
    if not cond:
        FAILED.append(what)


def finish():
    """The script's exit code: 1 when a check failed."""
    if FAILED:
        print("%d checks failed" % len(FAILED))
        return 1
    return 0


def markers(path):
    """{name: node set} and {name: element lines} of an .su2 file."""
    nodes, elems, lines, i = {}, {}, open(path, "rb").read().split(b"\n"), 0
    while i < len(lines):
        if lines[i].startswith(b"MARKER_TAG="):
            name = lines[i].split(b"=", 1)[1].strip().decode()
            n = int(lines[i + 1].split(b"=")[1])
            elems[name] = lines[i + 2:i + 2 + n]
            nodes[name] = {int(t) for s in elems[name] for t in s.split()[1:]}
            i += 2 + n
        else:
            i += 1
    return nodes, elems


def point_lines(path):
    """The lines of an .su2 file up to NPOIN, its point lines, and the lines after them."""
    lines = open(path, "rb").read().split(b"\n")
    for i, s in enumerate(lines):
        if s.startswith(b"NPOIN"):
            n = int(s.split(b"=")[1].split()[0])
            return lines[:i + 1], lines[i + 1:i + 1 + n], lines[i + 1 + n:]
    return [], [], []
