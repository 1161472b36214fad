#!/usr/bin/python3
"""Hostile input: the input rule of every reader (docs/DESIGN.md, "Reading input").

Inputs that are not regular files (FIFOs, devices, directories) are refused without blocking,
by the list readers as by the mesh, STEP and CSV readers, and for the files a list names; a
list or table line has a bound, so that a file without newlines costs little memory; a STEP
file or a binary file given as a list of variants is refused as such.

usage: hostile_inputs.py CADMORPH DATA_DIR WORK_DIR CASE       (CASE 'list' prints the cases)
"""
import os

import hostile
from hostile import case, run, path, write, fail, BORE

# the CLI's peak on these refusals is ~35 MB; the 50 MB line read whole (as it was) shows
# well above the bound
MAX_MB = 80


def fifo(name):
    p = path(name)
    if os.path.lexists(p):
        os.remove(p)
    os.mkfifo(p)
    return p


def study(variants, out="out"):
    """A study whose list is read before anything else: its mesh need not exist."""
    return ["study", "--from", BORE, "--mesh", path("none.vtu"), "--variants", variants,
            "-o", path(out)]


@case
def inputs_list_fifo():
    """A list that is a FIFO: refused at once (it blocked in open())."""
    p = fifo("variants.txt")
    run(study(p), 2, r"variants\.txt: not a regular file \(a FIFO\)", ["variants.txt"], MAX_MB)


@case
def inputs_list_names_fifo():
    """A list naming a FIFO, a directory, a device: the list's line and the entry's kind."""
    fifo("v1.step")
    os.makedirs(path("v2.step"), exist_ok=True)
    for entry, kind in [("v1.step", "a FIFO"), ("v2.step", "a directory"),
                        ("/dev/null", "a character device")]:
        p = write("list.txt", "# variants\n\n" + entry + "\n")
        run(study(p), 2, r"list\.txt:3: .*%s: not a regular file \(%s\)" % (entry, kind),
            ["list.txt", entry], MAX_MB)
    p = write("table.csv", "step,a\n" + BORE + ",1\nv1.step,2\n")
    run(study(p), 2, r"table\.csv:3: .*v1\.step: not a regular file \(a FIFO\)",
        ["table.csv", "v1.step"], MAX_MB)


@case
def inputs_list_dev_zero():
    """/dev/zero as the list (one endless line: it read 4 GB)."""
    run(study("/dev/zero"), 2, r"/dev/zero: not a regular file \(a character device\)",
        ["/dev/zero"], MAX_MB)
    z = path("zero.txt")
    if not os.path.lexists(z):
        os.symlink("/dev/zero", z)
    run(study(z), 2, r"zero\.txt: not a regular file \(a character device\)", ["zero.txt"], MAX_MB)


def endless(name, head):
    """head, then 50 MB without a newline, written in pieces (a forked child counts this
    process's resident memory until it execs)."""
    p = path(name)
    with open(p, "wb") as f:
        f.write(head)
        for _ in range(50):
            f.write(b"a" * (1 << 20))
    return p


@case
def inputs_list_endless_line():
    """Regular files without a newline: refused at the line's bound, not read whole."""
    p = endless("endless.txt", b"")
    run(study(p), 2, r"endless\.txt:1: longer than \d+ bytes: not a list of STEP paths",
        ["endless.txt"], MAX_MB)
    # a design table whose second line never ends
    p = endless("endless.csv", b"step,a\n")
    run(study(p), 2, r"endless\.csv:2: longer than \d+ bytes: not a design table",
        ["endless.csv"], MAX_MB)
    run(["sensitivity", "--from", BORE, "--mesh", path("none.vtu"), "--design-table", p,
         "-o", path("sens")], 2, r"endless\.csv:2: longer than \d+ bytes: not a design table",
        ["endless.csv"], MAX_MB)
    # a sparse file of NUL bytes (nothing to write): a binary file at its first byte
    z = path("sparse.txt")
    with open(z, "wb") as f:
        f.truncate(200 << 20)
    run(study(z), 2, r"sparse\.txt:1: a NUL byte \(a binary file\): not a list of STEP paths",
        ["sparse.txt"], MAX_MB)


@case
def inputs_step_as_variants():
    """A STEP file given as the list, and a binary file: said as such."""
    run(study(BORE), 2, r"bore_0\.step: a STEP file, not a list of variants", ["bore_0.step"],
        MAX_MB)
    p = write("variants.bin", b"\x1f\x8b\x08\x00" + bytes(range(256)) * 4, "wb")
    run(study(p), 2, r"variants\.bin:1: a NUL byte \(a binary file\): not a list of STEP paths",
        ["variants.bin"], MAX_MB)


@case
def inputs_directory_inputs():
    """Directories given as a mesh, a STEP file, a list: refused with their kind."""
    for name in ("d.vtu", "d.msh", "d.cgns", "d.exo", "d.step", "dlist.txt"):
        os.makedirs(path(name), exist_ok=True)
    kind = r"not a regular file \(a directory\)"
    for name in ("d.vtu", "d.msh", "d.cgns", "d.exo"):
        run(["quality", path(name)], 2, name.replace(".", r"\.") + ": " + kind, [name], MAX_MB)
    run(["info", path("d.step")], 2, r"d\.step: " + kind, ["d.step"], MAX_MB)
    run(study(path("dlist.txt")), 2, r"dlist\.txt: " + kind, ["dlist.txt"], MAX_MB)


@case
def inputs_fifo_inputs():
    """A FIFO as each command's input file: refused at once with its kind (the CGNS reader
    blocked in open())."""
    kind = r"not a regular file \(a FIFO\)"
    for name in ("f.cgns", "f.exo", "f.vtu", "f.msh"):
        run(["quality", fifo(name)], 2, name.replace(".", r"\.") + ": " + kind, [name], MAX_MB)
    m = hostile.bore_mesh()
    out = path("x.vtu")
    for name, args in [
            ("from.step", lambda p: ["morph", "--from", p, "--to", BORE, "--mesh", m, "-o", out]),
            ("to.step", lambda p: ["morph", "--from", BORE, "--to", p, "--mesh", m, "-o", out]),
            ("handles.csv", lambda p: ["deform", "--mesh", m, "--handles", p,
                                       "--fix-unlisted-boundary", "-o", out]),
            ("lattice.prm", lambda p: ["ffd", "--mesh", m, "--lattice", p, "-o", out]),
            ("disp.csv", lambda p: ["warp", "--mesh", m, "--displacements", p, "-o", out]),
            ("table.csv", lambda p: ["sensitivity", "--from", BORE, "--mesh", m,
                                     "--design-table", p, "-o", path("sens")])]:
        run(args(fifo(name)), 2, name.replace(".", r"\.") + ": " + kind, [name], MAX_MB)
    if os.path.exists(out):
        fail("an output was written")


if __name__ == "__main__":
    hostile.main()
