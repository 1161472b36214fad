#!/usr/bin/python3
"""Hostile and broken input: each case writes its input (no large fixtures), runs
the cadmorph CLI in bounded time, and checks the exit code from the README's list, exactly one
stderr line that matches the case's pattern and names the file, and peak memory.

usage: hostile.py CADMORPH DATA_DIR WORK_DIR CASE       (CASE 'list' prints the cases)

The other tests/cli/hostile_*.py scripts share this frame: they import it, register their
cases with @case and end with `hostile.main()`; each lists only its own cases.
"""
import os
import re
import resource
import signal
import subprocess
import sys
import time
import zlib
import struct

CLI, DATA, WORK, CASE = sys.argv[1:5] if len(sys.argv) >= 5 else (None, None, None, "list")
BORE = os.path.join(DATA or "", "models", "bore_0.step")
# a hang guard, not a timing test: sanitizer builds (make check-asan) run several times slower
TIMEOUT = 120 * float(os.environ.get("CM_TIME_FACTOR", "1"))
cases = {}


def case(fn):
    cases[fn.__name__] = fn
    return fn


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def path(name):
    return os.path.join(WORK, name)


def write(name, data, mode="w"):
    p = path(name)
    with open(p, mode) as f:
        f.write(data)
    return p


def run(args, code, pattern, names=None, max_mb=None, lines=1, stdin=None):
    """Runs cadmorph args; checks exit code, stderr lines, pattern, the file named, memory."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    t0 = time.time()
    try:
        p = subprocess.run([CLI] + args, capture_output=True, text=True, errors="replace",
                           timeout=TIMEOUT, stdin=stdin)
    except subprocess.TimeoutExpired:
        fail(f"{args}: no exit after {TIMEOUT} s")
    dt = time.time() - t0
    err = [l for l in p.stderr.split("\n") if l.strip() and not l.startswith("warning: ")]
    print(f"$ cadmorph {' '.join(args)[:200]}\nexit {p.returncode} in {dt:.1f} s\nstderr: {p.stderr[:600]}")
    if p.returncode != code:
        fail(f"exit code {p.returncode}, expected {code}")
    if lines is not None and len(err) != lines:
        fail(f"{len(err)} stderr lines, expected {lines}")
    if pattern and not re.search(pattern, p.stderr):
        fail(f"stderr does not match {pattern!r}")
    for n in names or []:
        if n not in p.stderr:
            fail(f"stderr does not name {n}")
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    # sanitizer builds (make check-asan) carry shadow memory: the bound scales with them
    if max_mb:
        max_mb *= float(os.environ.get("CM_MEM_FACTOR", "1"))
    if max_mb and peak > before and peak / 1024 > max_mb:
        fail(f"peak memory {peak / 1024:.0f} MB > {max_mb} MB")
    return p


def bore_text():
    with open(BORE) as f:
        return f.read()


def add_entity(text, entity):
    """Adds an entity before the end of the DATA section."""
    i = text.rindex("ENDSEC;")
    return text[:i] + entity + "\n" + text[i:]


def gmsh_step(name, boxes):
    """STEP of separate (unfused) boxes, written by gmsh's OpenCASCADE."""
    p = path(name)
    code = ("import gmsh\ngmsh.initialize()\ngmsh.option.setNumber('General.Terminal', 0)\n" +
            "".join(f"gmsh.model.occ.addBox({','.join(map(str, b))})\n" for b in boxes) +
            f"gmsh.model.occ.synchronize()\ngmsh.write({p!r})\ngmsh.finalize()\n")
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True)
    return p


def bore_mesh():
    m = path("bore0.vtu")
    if not os.path.exists(m):
        subprocess.run([CLI, "mesh", BORE, "-o", m, "--size", "0.6"], check=True, capture_output=True)
    return m


# ---- 1. overlapping, identical, nested solids: refused before any mesher; touching solids
# are an assembly, meshed as one (tests/meshgen/test_assembly.py) ----
def solids(name, boxes):
    p = gmsh_step(name + ".step", boxes)
    run(["mesh", p, "-o", path(name + ".vtu")], 2, r"solids 0 and 1 \(of 2\) overlap", [name + ".step"])
    if os.path.exists(path(name + ".vtu")):
        fail("an output was written")


@case
def solids_touching():
    """Touching solids are an assembly: meshed, not refused."""
    p = gmsh_step("touching.step", [(0, 0, 0, 1, 1, 1), (1, 0, 0, 1, 1, 1)])
    run(["mesh", p, "-o", path("touching.vtu"), "--size", "0.5"], 0, None, lines=0)


@case
def solids_overlapping():
    solids("overlapping", [(0, 0, 0, 1, 1, 1), (0.5, 0.2, 0.2, 1, 1, 1)])


@case
def solids_identical():
    solids("identical", [(0, 0, 0, 1, 1, 1), (0, 0, 0, 1, 1, 1)])


@case
def solids_nested():
    solids("nested", [(0, 0, 0, 3, 3, 3), (1, 1, 1, 1, 1, 1)])


@case
def solids_apart():
    """Separate solids are still meshed (the check must not refuse them)."""
    p = gmsh_step("apart.step", [(0, 0, 0, 1, 1, 1), (3, 0, 0, 1, 1, 1)])
    run(["mesh", p, "-o", path("apart.vtu"), "--size", "0.5"], 0, None, lines=0)


# ---- 2. deep nesting; 3. non-finite numbers: the STEP pre-scan, for every command ----
def step_commands(p, code, pattern, name):
    run(["info", p], code, pattern, [name])
    run(["mesh", p, "-o", path("x.vtu")], code, pattern, [name])
    run(["morph", "--from", p, "--to", BORE, "--mesh", bore_mesh(), "-o", path("x.vtu")], code, pattern, [name])


@case
def step_deep_nesting():
    n = 100000
    p = write("deep.step", add_entity(bore_text(), "#99999 = DEEP(" + "(" * n + ")" * n + ");"))
    step_commands(p, 2, r"deep\.step:\d+: parentheses nested deeper than 64", "deep.step")


@case
def step_nan():
    t = bore_text()
    t2 = re.sub(r"CARTESIAN_POINT\('',\(([^,]+),", r"CARTESIAN_POINT('',(nan,", t, count=1)
    if t2 == t:
        fail("no CARTESIAN_POINT to break")
    p = write("nan.step", t2)
    step_commands(p, 2, r"nan\.step:\d+: number 'nan' is not finite", "nan.step")


@case
def step_overflow():
    t = bore_text()
    p = write("inf.step", re.sub(r"CARTESIAN_POINT\('',\(([^,]+),", r"CARTESIAN_POINT('',(1.E999,", t, count=1))
    run(["info", p], 2, r"inf\.step:\d+: number '1\.E999' is not finite", ["inf.step"])


# ---- 4. FIFOs and other non-regular files ----
@case
def fifo_inputs():
    for name, args in [("f.msh", lambda p: ["quality", p]),
                       ("f.step", lambda p: ["info", p]),
                       ("g.step", lambda p: ["mesh", p, "-o", path("f.vtu")])]:
        p = path(name)
        if os.path.exists(p):
            os.remove(p)
        os.mkfifo(p)
        run(args(p), 2, r"not a regular file", [name])
    d = path("fd.csv")
    if os.path.exists(d):
        os.remove(d)
    os.mkfifo(d)
    run(["warp", "--mesh", bore_mesh(), "--displacements", d, "-o", path("fw.vtu")], 2,
        r"not a regular file", ["fd.csv"])
    z = path("zero.msh")
    if not os.path.lexists(z):
        os.symlink("/dev/zero", z)
    run(["quality", z], 2, r"zero\.msh: not a regular file", ["zero.msh"])


# ---- 6. zlib bomb, deep XML ----
def vtu_bomb(name, n_points, blocks, block_size):
    comp = zlib.compress(bytes(block_size), 9)
    hdr = struct.pack("<QQQ", blocks, block_size, block_size) + struct.pack("<Q", len(comp)) * blocks
    data = hdr + comp * blocks
    xml = (f'<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" '
           f'header_type="UInt64" compressor="vtkZLibDataCompressor">\n<UnstructuredGrid>\n'
           f'<Piece NumberOfPoints="{n_points}" NumberOfCells="0">\n<Points>\n'
           f'<DataArray type="Float64" NumberOfComponents="3" format="appended" offset="0"/>\n</Points>\n'
           f'</Piece>\n</UnstructuredGrid>\n<AppendedData encoding="raw">\n_').encode()
    return write(name, xml + data + b"\n</AppendedData>\n</VTKFile>\n", "wb")


@case
def vtu_zlib_bomb():
    # 2 GB of zeros in ~2 MB of zlib data, declared for 4 points
    p = vtu_bomb("bomb.vtu", 4, 1000, 2 << 20)
    run(["quality", p], 2, r"bomb\.vtu: byte offset \d+: DataArray '': header declares \d+ values, more than the 12 expected",
        ["bomb.vtu"], max_mb=150)


@case
def vtu_deep_xml():
    n = 5000000
    p = write("deep.vtu", '<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid">' + "<a>" * n)
    run(["quality", p], 2, r"deep\.vtu:2: XML: elements nested deeper than 64", ["deep.vtu"], max_mb=150)


# ---- 8. a size far below the model's ----
@case
def mesh_tiny_size():
    run(["mesh", BORE, "-o", path("tiny.vtu"), "--size", "0.001"], 4,
        r"bore_0\.step: size 0\.001 would make (about|at least) [0-9.e+]+ tets .*more than the limit", ["bore_0.step"], max_mb=300)


# ---- 9. what we write we read: hostile names, duplicate tags ----
def hostile_vtu():
    pts = "0 0 0 1 0 0 0 1 0 0 0 1"
    names = ["a&quot;b", "line&#10;two", "", "sp ace", "x%y", "new\nline"]
    arrays = "".join(f'<DataArray type="Float64" Name="{n}" format="ascii">{i}</DataArray>\n'
                     for i, n in enumerate(names))
    return write("src_names.vtu", f'''<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian">
<UnstructuredGrid><Piece NumberOfPoints="4" NumberOfCells="1">
<Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">{pts}</DataArray></Points>
<Cells>
<DataArray type="Int64" Name="connectivity" format="ascii">0 1 2 3</DataArray>
<DataArray type="Int64" Name="offsets" format="ascii">4</DataArray>
<DataArray type="UInt8" Name="types" format="ascii">10</DataArray>
</Cells>
<CellData>{arrays}</CellData>
</Piece></UnstructuredGrid></VTKFile>
''')


@case
def names_round_trip():
    src = hostile_vtu()
    csv = write("zero.csv", "node,dx,dy,dz\n")
    for out in ["names.msh", "names.vtk", "names.vtu", "names.mesh"]:
        # warp of a tet with no boundary motion: only the writer is under test
        p = subprocess.run([CLI, "warp", "--mesh", src, "--displacements", csv, "-o", path(out)],
                           capture_output=True, text=True, timeout=TIMEOUT)
        if p.returncode != 0:
            fail(f"warp to {out}: exit {p.returncode}: {p.stderr}")
        run(["quality", path(out)], 0, None, lines=0)


@case
def nastran_recursive_include():
    # a.bdf includes b.bdf which includes a.bdf: refused at the INCLUDE, not a loop
    write("nas_b.bdf", "GRID    2               1.      0.      0.\nINCLUDE 'nas_a.bdf'\n")
    a = write("nas_a.bdf", "BEGIN BULK\nGRID    1               0.      0.      0.\nINCLUDE 'nas_b.bdf'\nENDDATA\n")
    run(["quality", a], 2, r"nas_b\.bdf:2: INCLUDE of .*nas_a\.bdf includes itself", ["nas_b.bdf"], max_mb=200)


@case
def nastran_huge_ids():
    # ids near 10^17 are numbers, never sizes: read in little memory; an undefined one is named
    a = write("nas_ids.bdf", "GRID,99999999999999999,,0.,0.,0.\nGRID,88888888888888888,,1.,0.,0.\n"
                             "GRID,77777777777777777,,0.,1.,0.\nGRID,66666666666666666,,0.,0.,1.\n"
                             "CTETRA,5,1,99999999999999999,88888888888888888,77777777777777777,55555555555555555\n")
    run(["quality", a], 2, r"nas_ids\.bdf:5: CTETRA 5: GRID 55555555555555555 is not defined", ["nas_ids.bdf"], max_mb=200)


@case
def msh_duplicate_tags():
    p = write("dup.msh", """$MeshFormat
4.1 0 8
$EndMeshFormat
$Nodes
1 5 1 5
3 1 0 5
1
2
3
4
5
0 0 0
1 0 0
0 1 0
0 0 1
1 1 1
$EndNodes
$Elements
1 2 1 2
3 1 4 2
7 1 2 3 4
7 2 3 4 5
$EndElements
""")
    run(["quality", p], 2, r"dup\.msh:\d+: expected unique element tags, got tag 7 twice", ["dup.msh"])


# ---- 10. every VTK type name in legacy files ----
@case
def vtk_type_names():
    for t, pt in [("vtktypeint32", "vtktypefloat64"), ("vtktypeint8", "vtktypefloat32"),
                  ("vtktypeuint8", "double"), ("vtktypeint16", "float"), ("vtktypeuint16", "vtktypefloat64"),
                  ("vtktypeuint32", "float"), ("unsigned_char", "FLOAT")]:
        name = f"types_{t}.vtk"
        cells = "OFFSETS vtktypeint64\n0 4\nCONNECTIVITY vtktypeint64\n0 1 2 3\n"
        write(name, f"# vtk DataFile Version 5.1\nx\nASCII\nDATASET UNSTRUCTURED_GRID\n"
                    f"POINTS 4 {pt}\n0 0 0 1 0 0 0 1 0 0 0 1\nCELLS 2 4\n{cells}CELL_TYPES 1\n10\n"
                    f"CELL_DATA 1\nSCALARS v {t} 1\n"
                    f"LOOKUP_TABLE default\n1\n")
        run(["quality", path(name)], 0, None, lines=0)


# ---- 11. overflowing counts, echoed newlines, huge displacements ----
@case
def vtu_count_overflow():
    p = write("count.vtu", '''<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian">
<UnstructuredGrid><Piece NumberOfPoints="6148914691236517206" NumberOfCells="1">
<Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">0 0 0</DataArray></Points>
</Piece></UnstructuredGrid></VTKFile>
''')
    run(["quality", p], 2, r"count\.vtu:3: <Piece> NumberOfPoints=\"6148914691236517206\" is more than", ["count.vtu"])


@case
def vtu_newline_echoed():
    p = write("echo.vtu", '''<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian">
<UnstructuredGrid><Piece NumberOfPoints="1" NumberOfCells="0">
<Points><DataArray type="Float64
second line" NumberOfComponents="3" format="ascii">0 0 0</DataArray></Points>
</Piece></UnstructuredGrid></VTKFile>
''')
    run(["quality", p], 2, r"echo\.vtu:4: DataArray '': type 'Float64\\nsecond line' is not numeric", ["echo.vtu"])


@case
def displacement_huge():
    d = write("huge.csv", "node,dx,dy,dz\n0,1.7e308,0,0\n")
    run(["warp", "--mesh", bore_mesh(), "--displacements", d, "-o", path("huge.vtu")], 2,
        r"huge\.csv:2: dx of node 0 is 1\.7e308, beyond any mesh", ["huge.csv"])


# ---- 12. units ----
@case
def step_unknown_unit():
    t = bore_text().replace("SI_UNIT(.MILLI.,.METRE.)", "SI_UNIT(.KILO.,.PARSEC.)")
    p = write("parsec.step", t)
    run(["info", p], 2, r"parsec\.step:\d+: unknown SI unit 'KILO\.PARSEC'", ["parsec.step"])


@case
def step_unit_mismatch():
    t = bore_text().replace("SI_UNIT(.MILLI.,.METRE.)", "SI_UNIT($,.METRE.)")
    p = write("metres.step", t)
    run(["morph", "--from", BORE, "--to", p, "--mesh", bore_mesh(), "-o", path("m.vtu")], 2,
        r"G and G' differ in size by 1e\+03x .*file units millimetre and metre", ["metres.step"])


# ---- 13. signals during a write; long output names ----
@case
def signal_removes_temporary():
    d = path("sig")
    os.makedirs(d, exist_ok=True)
    for f in os.listdir(d):
        os.remove(os.path.join(d, f))
    # quality --csv of a mesh with many cells writes long enough to be caught in the act
    big = path("big.vtk")
    if not os.path.exists(big):
        n = 400000
        with open(big, "w") as f:
            f.write(f"# vtk DataFile Version 5.1\nbig\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS {n + 3} double\n")
            f.write("0 0 0\n1 0 0\n0 1 0\n" + "".join(f"0 0 {1 + i % 7}\n" for i in range(n)))
            f.write(f"CELLS {n + 1} {4 * n}\nOFFSETS vtktypeint64\n" + "\n".join(str(4 * i) for i in range(n + 1)))
            f.write("\nCONNECTIVITY vtktypeint64\n" + "".join(f"0 1 2 {3 + i}\n" for i in range(n)))
            f.write(f"CELL_TYPES {n}\n" + "10\n" * n)
    for sig in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP):
        caught = False
        for attempt in range(5):
            p = subprocess.Popen([CLI, "quality", big, "--csv", os.path.join(d, "q.csv")],
                                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            t0 = time.time()
            while p.poll() is None and time.time() - t0 < TIMEOUT:
                if any(f.startswith(".cm-") for f in os.listdir(d)):
                    p.send_signal(sig)
                    caught = True
                    break
                time.sleep(0.0005)
            p.wait(timeout=TIMEOUT)
            if caught:
                break
            if os.path.exists(os.path.join(d, "q.csv")):
                os.remove(os.path.join(d, "q.csv"))
        if not caught:
            fail(f"never saw the temporary of a {sig.name} run")
        left = os.listdir(d)
        print(f"{sig.name}: exit {p.returncode}, left {left}")
        if p.returncode != -sig:
            fail(f"exit {p.returncode}, expected death by {sig.name}")
        if left:
            fail(f"left behind after {sig.name}: {left}")


@case
def long_output_name():
    for n in (245, 250, 255):
        name = "o" * (n - 4) + ".vtu"
        run(["mesh", BORE, "-o", path(name), "--size", "1"], 0, None, lines=0)
        if not os.path.exists(path(name)):
            fail(f"{n}-character output not written")
        os.remove(path(name))


# ---- 14. many element blocks: read in linear time (a hang guard, not a timing test) ----
@case
def msh_many_blocks():
    n = 20000
    nodes = "".join(f"{i + 1}\n" for i in range(4)) + "0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
    blocks = "".join(f"3 {b + 1} 4 1\n{b + 1} 1 2 3 4\n" for b in range(n))
    ents = f"0 0 0 {n}\n" + "".join(f"{b + 1} 0 0 0 1 1 1 0 6 1 2 3 4 5 6\n" for b in range(n))
    p = write("blocks.msh", f"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n{ents}$EndEntities\n"
                            f"$Nodes\n1 4 1 4\n3 1 0 4\n{nodes}$EndNodes\n"
                            f"$Elements\n{n} {n} 1 {n}\n{blocks}$EndElements\n")
    run(["quality", p], 0, None, lines=0)


# ---- 15. Fluent files: huge declared counts, deep lists, missing cells (file:line named) ----
@case
def fluent_hostile():
    with open(os.path.join(DATA, "fluent", "box.msh")) as f:
        box = f.read()
    deep = "(64 " + "(" * 100000 + ")" * 100000 + ")\n"
    p = write("fl_deep.msh", deep + box)
    run(["quality", p], 0, None, lines=0)
    p = write("fl_open.msh", box + "(64 " + "(" * 100000)
    run(["quality", p], 2, r"fl_open\.msh:\d+: unterminated section", ["fl_open.msh"])
    p = write("fl_cells.cas", box.replace("(12 (0 1 c 0 0))", "(12 (0 1 3fffffffffffffff 0 0))"))
    run(["quality", p], 2, r"fl_cells\.cas: .* cells, but only \d+ faces", ["fl_cells.cas"], max_mb=200)
    p = write("fl_nodes.cas", box.replace("(10 (1 1 24 1 3)", "(10 (1 1 3fffffffffffffff 1 3)"))
    run(["quality", p], 2, r"fl_nodes\.cas:11: the node section holds more nodes", ["fl_nodes.cas"], max_mb=200)
    p = write("fl_c1.msh", box.replace(" 2 1\n", " 2 ff\n", 1))
    run(["quality", p], 2, r"fl_c1\.msh:53: face names a missing cell c1 ff", ["fl_c1.msh"])

# ---- 16. Abaqus decks: an include loop, a GENERATE range of 2^62 ids, many sets (linear) ----
@case
def inp_include_loop():
    write("loop_b.inp", "** b\n*INCLUDE, INPUT=loop.inp\n")
    p = write("loop.inp", "*NODE\n1, 0, 0, 0\n*INCLUDE, INPUT=loop_b.inp\n")
    run(["quality", p], 2, r"loop_b\.inp:2: the included file .*loop\.inp includes itself", ["loop_b.inp"], max_mb=150)


@case
def inp_huge_generate():
    p = write("generate.inp", "*NODE\n1, 0, 0, 0\n*NSET, NSET=ALL, GENERATE\n1, 4611686018427387904, 1\n")
    run(["quality", p], 2, r"generate\.inp:4: expected a GENERATE range", ["generate.inp"], max_mb=150)


@case
def inp_many_sets():
    n = 50000
    nodes = "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n"
    sets = "".join(f"*NSET, NSET=S{i}\n{i % 4 + 1}\n" for i in range(n))
    p = write("sets.inp", nodes + sets)
    run(["quality", p], 0, None, lines=0)


def main():
    """Lists the cases of the script being run, or runs the one named on the command line."""
    own = [n for n, fn in cases.items() if fn.__module__ == "__main__"]
    if CASE == "list":
        print("\n".join(own))
        sys.exit(0)
    if CASE not in own:
        fail(f"no case {CASE!r}")
    os.makedirs(WORK, exist_ok=True)
    cases[CASE]()
    print("ok")


if __name__ == "__main__":
    main()
