#!/usr/bin/python3
"""Outputs under hostile conditions: a full file system, SIGINT and a second writer during an
OpenFOAM case write, outputs that are inputs (hard and symbolic links, names of results), a
report that cannot be written, a converted mesh over a case with zones. The promises checked
are those of README.md ("Output guarantees") and docs/DESIGN.md ("Command line contract").

usage: hostile_outputs.py CADMORPH DATA_DIR WORK_DIR CASE
"""
import glob
import hashlib
import os
import shutil
import signal
import subprocess
import time

import hostile
from hostile import case, run, path, fail, DATA, CLI

BOX = os.path.join(DATA or "", "msh", "box_hole_41.msh")
CUBE = os.path.join(DATA or "", "warp", "cube.vtk")
FILES = ("boundary", "faces", "neighbour", "owner", "points")


def fresh():
    """An empty work directory (a ctest re-run finds the last run's files)."""
    for e in os.listdir(hostile.WORK):
        p = path(e)
        if os.path.isdir(p) and not os.path.islink(p):
            shutil.rmtree(p)
        else:
            os.unlink(p)


def zero_csv():
    p = path("zero.csv")
    with open(p, "w") as f:
        f.write("node,dx,dy,dz\n0,0,0,0\n")
    return p


def convert(mesh, out, check=True):
    """mesh written to out (a zero warp: the mesh converted as it is)."""
    p = subprocess.run([CLI, "warp", "--mesh", mesh, "--displacements", zero_csv(), "-o", out],
                       capture_output=True, text=True, timeout=120)
    if check and p.returncode != 0:
        fail(f"writing {out}: exit {p.returncode}: {p.stderr}")
    return p


def digest(case_dir):
    """The polyMesh's files, by content."""
    d = os.path.join(case_dir, "constant", "polyMesh")
    out = {}
    for n in FILES:
        with open(os.path.join(d, n), "rb") as f:
            out[n] = hashlib.sha1(f.read()).hexdigest()
    return out


def reads(case_dir):
    p = subprocess.run([CLI, "quality", case_dir], capture_output=True, text=True, timeout=60)
    if p.returncode != 0:
        fail(f"{case_dir} does not read after the write: {p.stderr.strip()}")


def file_bytes(p):
    with open(p, "rb") as f:
        return f.read()


def hex_mesh(name, scale=None):
    """A hex mesh of the built-in bore (model bore 0 --hex-mesh)."""
    args = [CLI, "model", "bore", "0", path(name + ".step"), "--hex-mesh", path(name + ".vtu")]
    if scale:
        args += ["--scale", str(scale)]
    p = subprocess.run(args, capture_output=True, text=True, timeout=120)
    if p.returncode != 0:
        fail(f"model bore: {p.stderr}")
    return path(name + ".vtu")


@case
def out_full_disk():
    """A converted mesh over an existing case on a file system with room for its faces only:
    the old case stays whole (a write of five separate renames left it mixed)."""
    fresh()
    mnt = path("fs")
    os.makedirs(mnt)
    script = (f'mount -t tmpfs -o size=44k tmpfs {mnt} || exit 99\n'
              f'{CLI} warp --mesh {CUBE} --displacements {zero_csv()} -o {mnt}/case/ >/dev/null || exit 98\n'
              f'cp -r {mnt}/case {path("old")}\n'
              f'{CLI} warp --mesh {BOX} --displacements {zero_csv()} -o {mnt}/case/ >/dev/null 2>{path("err")}\n'
              f'echo $? > {path("rc")}\n'
              f'ls -a {mnt} {mnt}/case/constant > {path("ls")}\n'
              f'cp -r {mnt}/case {path("after")}\n')
    try:
        p = subprocess.run(["unshare", "-rm", "sh", "-c", script], capture_output=True, text=True,
                           timeout=60)
    except FileNotFoundError:
        print("skipped: no unshare")
        return
    if p.returncode == 99 or p.returncode == 1 and "unshare" in p.stderr:
        print(f"skipped: cannot mount a tmpfs in a user namespace ({p.stderr.strip()})")
        return
    if p.returncode != 0:
        fail(f"setup: exit {p.returncode}: {p.stderr}")
    rc = int(open(path("rc")).read())
    err = open(path("err")).read()
    print(f"exit {rc}: {err}")
    if rc != 2 or "No space left" not in err:
        fail(f"exit {rc}, expected 2 naming the full disk")
    if digest(path("after")) != digest(path("old")):
        fail("the old case changed")
    reads(path("after"))
    if ".cm-" in open(path("ls")).read():
        fail("a temporary was left: " + open(path("ls")).read())


def interrupt_when_writing(args, case_dir):
    """Runs args and sends SIGINT as soon as the write has visibly begun: a faces file of
    the polyMesh replaced, or one complete in a temporary beside it."""
    pm = os.path.join(case_dir, "constant", "polyMesh")
    ino = os.stat(os.path.join(pm, "faces")).st_ino
    p = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    t0 = time.time()
    while p.poll() is None and time.time() - t0 < 60:
        try:
            replaced = os.stat(os.path.join(pm, "faces")).st_ino != ino
        except FileNotFoundError:
            replaced = True
        staged = glob.glob(os.path.join(case_dir, "constant", ".cm-*", "owner"))
        if replaced or staged:
            p.send_signal(signal.SIGINT)
            break
        time.sleep(0.0005)
    p.communicate(timeout=60)
    return p.returncode


@case
def out_sigint_case_write():
    """SIGINT while a converted mesh replaces a case: afterwards the case is the old one or
    the new one, whole, and no temporary is left."""
    fresh()
    big = hex_mesh("big")
    convert(big, path("new/"))
    convert(BOX, path("old/"))
    new, old = digest(path("new")), digest(path("old"))
    for k in range(3):
        c = path(f"case{k}/")
        convert(BOX, c)
        args = [CLI, "warp", "--mesh", big, "--displacements", zero_csv(), "-o", c]
        rc = interrupt_when_writing(args, c)
        got = digest(c)
        print(f"round {k}: exit {rc}, case {'old' if got == old else 'new' if got == new else 'MIXED'}")
        if got not in (old, new):
            fail(f"round {k}: the case is a mix of the old and the new mesh")
        reads(c)
        left = glob.glob(os.path.join(c, "constant", ".cm-*")) + glob.glob(os.path.join(c, "constant", "polyMesh", ".cm-*"))
        if left:
            fail(f"temporaries left: {left}")


@case
def out_concurrent_writers():
    """Two writers of different meshes onto one case at once: the case is one of the two,
    whole; a writer that finds the case locked exits 4 with one line saying so."""
    fresh()
    a, b = hex_mesh("a"), hex_mesh("b", 0.97)
    convert(a, path("ref_a/"))
    convert(b, path("ref_b/"))
    refs = (digest(path("ref_a")), digest(path("ref_b")))
    for k in range(4):
        c = path(f"case{k}/")
        convert(BOX, c)
        ps = [subprocess.Popen([CLI, "warp", "--mesh", m, "--displacements", zero_csv(), "-o", c],
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
              for m in (a, b)]
        res = [(p.wait(timeout=120), p.stderr.read()) for p in ps]
        print(f"round {k}: {[r[0] for r in res]} {[r[1].strip() for r in res]}")
        for rc, err in res:
            if rc == 4:
                lines = [l for l in err.split("\n") if l.strip()]
                if len(lines) != 1 or "another process is writing it" not in err:
                    fail(f"the refused writer said {err!r}")
            elif rc != 0:
                fail(f"exit {rc}: {err}")
        if all(r[0] != 0 for r in res):
            fail("neither writer wrote")
        if digest(c) not in refs:
            fail(f"round {k}: the case is a mix of the two writers' meshes")
        reads(c)


def morph_inputs():
    """G0, G1 and a small hex mesh of G0 for morph and study."""
    m0 = hex_mesh("G0", 0.3)
    g1 = path("G1.step")
    p = subprocess.run([CLI, "model", "bore", "0.5", g1], capture_output=True, timeout=120)
    if p.returncode != 0:
        fail("model bore 0.5 failed")
    return path("G0.step"), g1, m0


@case
def out_morph_output_is_input():
    """morph -o naming M0 through a hard link and through a symbolic link: refused (exit 1),
    M0 intact byte for byte."""
    fresh()
    g0, g1, m0 = morph_inputs()
    before = file_bytes(m0)
    os.link(m0, path("hard.vtu"))
    os.symlink(m0, path("soft.vtu"))
    for out in ("hard.vtu", "soft.vtu"):
        run(["morph", "--from", g0, "--to", g1, "--mesh", m0, "-o", path(out)], 1,
            "is an input", lines=2)
        if file_bytes(m0) != before:
            fail(f"M0 changed by -o {out}")


@case
def out_morph_report_unwritable():
    """morph --report into a place that cannot hold it: exit 2 naming it, and no mesh
    written (the mesh used to be written before the report failed)."""
    fresh()
    g0, g1, m0 = morph_inputs()
    with open(path("plain"), "w") as f:
        f.write("a file, not a directory\n")
    report = path("plain") + "/report.csv"
    run(["morph", "--from", g0, "--to", g1, "--mesh", m0, "-o", path("M1.vtu"), "--report", report],
        2, "report.csv", names=[report])
    if os.path.exists(path("M1.vtu")):
        fail("the mesh was written although the report could not be")
    if [e for e in os.listdir(hostile.WORK) if e.startswith(".cm-")]:
        fail("a temporary was left")


def study_setup():
    g0, g1, m0 = morph_inputs()
    lst = path("list.txt")
    with open(lst, "w") as f:
        f.write(g1 + "\n")
    return g0, g1, m0, lst


@case
def out_study_m0_named_like_a_result():
    """study whose M0 is DIR/<result>.vtu (the file itself, a hard link, a symbolic link):
    refused with exit 1 and one line, M0 intact byte for byte, no result written."""
    fresh()
    g0, g1, m0, lst = study_setup()
    before = file_bytes(m0)
    for kind in ("same", "hard", "soft"):
        d = path("out_" + kind)
        os.makedirs(d)
        res = os.path.join(d, "rbf_absolute_G1.vtu")
        if kind == "same":
            shutil.copy(m0, res)
            mesh = res
        else:
            (os.link if kind == "hard" else os.symlink)(m0, res)
            mesh = m0
        # the one-step morph with its inverted cells kept: a result to write (and refuse)
        run(["study", "--from", g0, "--mesh", mesh, "--variants", lst, "-o", d, "--methods", "rbf",
             "--write-meshes", "all", "--steps", "1", "--allow-inverted"], 1,
            "refusing to overwrite", names=["rbf_absolute_G1.vtu"])
        if file_bytes(mesh) != before or file_bytes(m0) != before:
            fail(f"{kind}: M0 changed")
        if kind == "soft" and not os.path.islink(res):
            fail("the symbolic link was replaced")
        if os.path.exists(os.path.join(d, "study.csv")):
            fail(f"{kind}: results were written")


@case
def out_study_list_named_study_csv():
    """study whose variants list is DIR/study.csv (itself, or linked there): refused before
    the run, exit 1, the list intact."""
    fresh()
    g0, g1, m0, lst = study_setup()
    d = path("out")
    os.makedirs(d)
    inside = os.path.join(d, "study.csv")
    shutil.copy(lst, inside)
    before = file_bytes(inside)
    run(["study", "--from", g0, "--mesh", m0, "--variants", inside, "-o", d, "--methods", "rbf"], 1,
        "refusing to overwrite", names=[inside])
    if file_bytes(inside) != before:
        fail("the list changed")
    os.unlink(inside)
    os.link(lst, inside)
    run(["study", "--from", g0, "--mesh", m0, "--variants", lst, "-o", d, "--methods", "rbf"], 1,
        "refusing to overwrite", names=[inside])
    if file_bytes(lst) != before:
        fail("the list changed")


@case
def out_study_new_dir_whole():
    """A study into a new DIR: DIR appears with all its results and nothing beside it; one
    interrupted (SIGINT) leaves no DIR and no temporary (it used to leave DIR begun)."""
    fresh()
    g0, g1, m0, lst = study_setup()
    d = path("sub/new")
    args = ["study", "--from", g0, "--mesh", m0, "--variants", lst, "--methods", "rbf",
            "--write-meshes", "all", "--steps", "1", "--allow-inverted", "-o"]
    run(args + [d], 0, None, lines=0)
    got = sorted(os.listdir(d))
    if got != ["rbf_absolute_G1.vtu", "study.csv", "study.svg"]:
        fail(f"DIR holds {got}")
    if [e for e in os.listdir(path("sub")) if e != "new"]:
        fail(f"left beside DIR: {os.listdir(path('sub'))}")
    d2 = path("sub/cut")
    p = subprocess.Popen([CLI] + args + [d2], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    t0 = time.time()
    while p.poll() is None and time.time() - t0 < 60:
        if os.path.exists(d2) or glob.glob(path("sub/.cm-*")):
            p.send_signal(signal.SIGINT)
            break
        time.sleep(0.001)
    p.communicate(timeout=60)
    print(f"interrupted study: exit {p.returncode}; beside DIR: {sorted(os.listdir(path('sub')))}")
    if p.returncode != -signal.SIGINT:
        fail(f"the study was not interrupted (exit {p.returncode})")
    if os.path.exists(d2) or glob.glob(path("sub/.cm-*")):
        fail("an interrupted study left DIR or its temporary")


@case
def out_sweep_mesh_named_like_a_result():
    """sweep --mesh DIR/<result>.vtu (the file itself, a symbolic link): refused, exit 1,
    the mesh intact byte for byte."""
    fresh()
    m0 = hex_mesh("G0", 0.3)
    before = file_bytes(m0)
    for kind in ("same", "soft"):
        d = path("sw_" + kind)
        os.makedirs(d)
        res = os.path.join(d, "rbf_absolute_100.vtu")
        if kind == "same":
            shutil.copy(m0, res)
        else:
            os.symlink(m0, res)
        run(["sweep", "bore", "--mesh", res, "--steps", "1", "-o", d, "--methods", "rbf",
             "--mode", "absolute"], 1, "refusing to overwrite", names=["rbf_absolute_100.vtu"])
        if file_bytes(res) != before or file_bytes(m0) != before:
            fail(f"{kind}: the mesh changed")
        if kind == "soft" and not os.path.islink(res):
            fail("the symbolic link was replaced")


ZONES = """FoamFile
{
    version     2.0;
    format      ascii;
    class       regIOobject;
    location    "constant/polyMesh";
    object      cellZones;
}
1
(
inner
{
    type cellZone;
cellLabels      List<label> 2(500 700);
}
)
"""


@case
def out_converted_over_zones():
    """A converted mesh written into a case whose polyMesh has zones and sets of the old mesh
    (cells the new one does not have): the case reads afterwards, the old zones are gone, the
    user's files elsewhere in the case stay."""
    fresh()
    c = path("case/")
    convert(BOX, c)
    pm = os.path.join(c, "constant", "polyMesh")
    with open(os.path.join(pm, "cellZones"), "w") as f:
        f.write(ZONES)
    os.makedirs(os.path.join(pm, "sets"))
    with open(os.path.join(pm, "sets", "inner"), "w") as f:
        f.write("x\n")
    reads(c)
    os.makedirs(os.path.join(c, "system"))
    with open(os.path.join(c, "system", "controlDict"), "w") as f:
        f.write("// the user's\n")
    convert(CUBE, c)
    reads(c)
    print(f"polyMesh after the write: {sorted(os.listdir(pm))}")
    if os.path.exists(os.path.join(pm, "cellZones")) or os.path.exists(os.path.join(pm, "sets")):
        fail("the old mesh's zones or sets are still there")
    if file_bytes(os.path.join(c, "system", "controlDict")) != b"// the user's\n":
        fail("a user file of the case changed")


if __name__ == "__main__":
    hostile.main()
