#!/usr/bin/python3
"""`cadmorph morph --off-cad fixed` and `cadmorph study --off-cad fixed` with sliding patches
(docs/DESIGN.md, "Boundary motion by patch kind"): a block in a half wind tunnel whose
symmetry plane y = 0 cuts it (gmsh's OCC kernel: the box y >= 0 minus the block, tets,
physical surfaces "symmetry", "tunnel" and "body"); the block's STEP (the whole block) edited
longer and taller.

  * no --slide (a .msh has no patch types: nothing slides) and --no-slide: the morph of
    before, node for node (the tunnel and the symmetry plane unmoved bit for bit; one step,
    its inverted cells allowed: the fixed plane squeezes cells the sliding one frees);
  * --slide symmetry: the summary counts the sliding nodes; every node of the symmetry plane
    off the CAD stays exactly on y = 0 (normal motion 0, not round-off) and those near the
    block's end follow it along x; the tunnel's nodes unmoved bit for bit; the block's nodes
    on G1 (to 1e-9 of its diagonal); no inverted cell;
  * --slide with an unknown patch is refused naming the mesh's patches; --slide without
    --off-cad fixed is a usage error;
  * a 2-variant absolute study with --slide symmetry: both rows ok without inverted cells, the
    symmetry nodes off the CAD exactly on y = 0 in both meshes, and the variant equal to the
    one morphed above is the same mesh (to 1e-12 of the diagonal: the study shares the two
    warp passes' factorisations between its variants).
usage: test_off_cad_slide.py CADMORPH WORKDIR"""
import base64
import math
import os
import re
import struct
import subprocess
import sys
import zlib

import gmsh

CADMORPH, WORK = sys.argv[1], os.path.join(sys.argv[2], "off_cad_slide")
os.makedirs(WORK, exist_ok=True)
failures = []

L0, H0, W = 1.0, 0.4, 0.3  # the block [0, L] x [-W, W] x [0, H]


def check(cond, msg):
    if not cond:
        failures.append(msg)
        print("FAIL:", msg)


def path(name):
    return os.path.join(WORK, name)


def physical(dim, tags, tag, name):
    gmsh.model.addPhysicalGroup(dim, tags, tag)  # Debian's gmsh: no name argument yet
    gmsh.model.setPhysicalName(dim, tag, name)


def write_step(name, length, height):
    gmsh.model.add(name)
    gmsh.model.occ.addBox(0, -W, 0, length, 2 * W, height)
    gmsh.model.occ.synchronize()
    gmsh.write(path(name))
    gmsh.model.remove()


def write_half_tunnel(name):
    """The box [-1.5, 2.5] x [0, 1.2] x [-0.8, 1.2] minus the block: its face y = 0 is the
    symmetry plane (the block's section cut out of it)."""
    gmsh.model.add(name)
    occ = gmsh.model.occ
    box = occ.addBox(-1.5, 0, -0.8, 4, 1.2, 2)
    blk = occ.addBox(0, -W, 0, L0, 2 * W, H0)
    occ.cut([(3, box)], [(3, blk)])
    occ.synchronize()
    physical(3, [t for _, t in gmsh.model.getEntities(3)], 1, "fluid")
    sym, tunnel, body = [], [], []
    for _, t in gmsh.model.getEntities(2):
        xmin, ymin, zmin, xmax, ymax, zmax = gmsh.model.getBoundingBox(2, t)
        if ymax < 1e-6:
            sym.append(t)
        elif xmin < -1.4 or xmax > 2.4 or ymax > 1.1 or zmin < -0.7 or zmax > 1.1:
            tunnel.append(t)
        else:
            body.append(t)
    physical(2, sym, 2, "symmetry")
    physical(2, tunnel, 3, "tunnel")
    physical(2, body, 4, "body")
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.3)
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    near = [(0, t) for _, t in gmsh.model.getEntities(0)
            if -0.1 < gmsh.model.getValue(0, t, [])[0] < L0 + 0.1]
    gmsh.model.mesh.setSize(near, 0.1)
    gmsh.model.mesh.generate(3)
    gmsh.write(path(name))
    groups = {}
    for tag, gname in ((2, "symmetry"), (3, "tunnel"), (4, "body")):
        nt, _ = gmsh.model.mesh.getNodesForPhysicalGroup(2, tag)
        groups[gname] = set(int(t) for t in nt)
    gmsh.model.remove()
    return groups


def nodes(name):
    """{tag: (x, y, z)} of a .msh (gmsh parses the text: exact doubles)."""
    gmsh.open(path(name))
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    out = {int(t): (xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]) for i, t in enumerate(tags)}
    gmsh.model.remove()
    return out


def vtu_points(p):
    """The points of a .vtu as written by cadmorph (ascii, or base64 with a UInt64 header,
    optionally zlib blocks)."""
    text = open(p, "rb").read().decode("latin-1")
    m = re.search(r"<Points>\s*<DataArray([^>]*)>([^<]*)</DataArray>", text)
    attrs, body = m.group(1), m.group(2)
    if 'format="ascii"' in attrs:
        vals = [float(v) for v in body.split()]
    else:
        b64 = "".join(body.split())
        if "vtkZLibDataCompressor" in text:
            # VTK's inline compressed form: the header and the blocks encoded separately
            nb = struct.unpack_from("<Q", base64.b64decode(b64[:32]), 0)[0]
            hchars = 4 * ((8 * (3 + nb) + 2) // 3)
            sizes = struct.unpack_from("<%dQ" % nb, base64.b64decode(b64[:hchars]), 24)
            raw, off, data = base64.b64decode(b64[hchars:]), 0, b""
            for s in sizes:
                data += zlib.decompress(raw[off:off + s])
                off += s
        else:
            raw = base64.b64decode(b64)
            n = struct.unpack_from("<Q", raw, 0)[0]
            data = raw[8:8 + n]
        vals = list(struct.unpack("<%dd" % (len(data) // 8), data))
    return [tuple(vals[3 * i:3 * i + 3]) for i in range(len(vals) // 3)]


def run(cmd, *args):
    p = subprocess.run([CADMORPH, cmd] + list(args), capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


def on_g1(p, length, height, tol):
    """Distance of p to the surface of the block [0, length] x [-W, W] x [0, height]."""
    x, y, z = p
    inside = -tol <= x <= length + tol and -W - tol <= y <= W + tol and -tol <= z <= height + tol
    d = min(abs(x), abs(x - length), abs(y + W), abs(y - W), abs(z), abs(z - height))
    return d if inside else math.inf


gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
L1, H1 = 1.15, 0.45
write_step("g0.step", L0, H0)
write_step("g1.step", L1, H1)
write_step("g2.step", 1.08, 0.42)
groups = write_half_tunnel("half.msh")
m0 = nodes("half.msh")
sym, tunnel, body = groups["symmetry"], groups["tunnel"], groups["body"]
sym_off = sym - body  # the body's nodes on the plane are on the CAD (and prescribed)
sliding = sym_off - tunnel  # those on the tunnel's walls too are fixed (fixed beats slide)
tunnel_only = tunnel - sym
check(len(sym_off) > 100 and len(body) > 100 and len(tunnel_only) > 50,
      "fixture: %d symmetry nodes off the CAD, %d body, %d tunnel nodes" %
      (len(sym_off), len(body), len(tunnel_only)))
check(all(m0[t][1] == 0.0 for t in sym), "fixture: the symmetry plane is y = 0 exactly")
diag = math.dist((0, -W, 0), (L1, W, H1))
common = ["--from", path("g0.step"), "--to", path("g1.step"), "--mesh", path("half.msh"),
          "--off-cad", "fixed"]

# nothing slides: the morph of before (one step; the block pushes cells against the fixed
# plane until they invert, kept here: what is checked is where the nodes off G0 stay)
one = ["--steps", "1", "--allow-inverted"]
rc, out, err = run("morph", *common, "-o", path("fixed.msh"), *one)
check(rc == 0, "fixed: exit 0, got %d (%s)" % (rc, err.strip()[-600:]))
check(re.search(r"\d+ off G0 kept fixed \(\d+ boundary components\)", out) is not None,
      "fixed: the summary says the nodes off G0 are kept fixed: %s" % out)
rc, out, err = run("morph", *common, "-o", path("noslide.msh"), "--no-slide", *one)
check(rc == 0, "--no-slide: exit 0, got %d (%s)" % (rc, err.strip()[-600:]))
if os.path.exists(path("fixed.msh")) and os.path.exists(path("noslide.msh")):
    mf, mn = nodes("fixed.msh"), nodes("noslide.msh")
    check(mf == mn, "--no-slide: the same mesh as without --slide")
    moved = [t for t in sym | tunnel if t not in body and mf[t] != m0[t]]
    check(not moved, "fixed: %d symmetry/tunnel nodes moved" % len(moved))

# the symmetry plane slides
rc, out, err = run("morph", *common, "-o", path("slide.msh"), "--slide", "symmetry")
print(out)
check(rc == 0, "slide: exit 0, got %d (%s)" % (rc, err.strip()[-600:]))
m = re.search(r"(\d+) off G0 \(\d+ boundary components; (\d+) of them slide", out)
check(m is not None and int(m.group(2)) == len(sliding),
      "slide: the summary counts the %d sliding nodes: %s" % (len(sliding), out))
check(" inverted=0 " in out, "slide: no inverted cell: %s" % out)
if rc == 0:
    m1 = nodes("slide.msh")
    off_plane = [t for t in sym_off if m1[t][1] != 0.0]
    check(not off_plane, "slide: %d symmetry nodes left y = 0 (first %r)" %
          (len(off_plane), m1[off_plane[0]] if off_plane else None))
    # the plane's nodes beyond the block's end follow it (the block grows by 0.15 along x)
    ahead = [t for t in sym_off if L0 < m0[t][0] < L0 + 0.25 and m0[t][2] < H0]
    dx = max((m1[t][0] - m0[t][0] for t in ahead), default=0.0)
    check(ahead and dx > 0.05, "slide: the plane's nodes ahead of the block move along x "
          "(largest %.3g over %d nodes)" % (dx, len(ahead)))
    moved = [t for t in tunnel_only if m1[t] != m0[t]]
    check(not moved, "slide: %d tunnel nodes moved" % len(moved))
    worst = max(on_g1(m1[t], L1, H1, 1e-9 * diag) for t in body)
    check(worst <= 1e-9 * diag, "slide: the body's nodes on G1 (worst %.3g)" % worst)

# refusals
rc, out, err = run("morph", *common, "-o", path("bad.msh"), "--slide", "nosuch")
check(rc in (1, 2) and "nosuch" in err and "symmetry" in err,
      "unknown patch: refused naming the patches, got %d (%s)" % (rc, err.strip()))
rc, out, err = run("morph", "--from", path("g0.step"), "--to", path("g1.step"), "--mesh",
                   path("half.msh"), "-o", path("bad.msh"), "--slide", "symmetry")
check(rc == 1 and "--off-cad fixed" in err,
      "--slide without --off-cad fixed: usage error, got %d (%s)" % (rc, err.strip()))

# a study of two variants, sharing the factorisations
with open(path("variants.txt"), "w") as f:
    f.write("g1.step\ng2.step\n")
rc, out, err = run("study", "--from", path("g0.step"), "--mesh", path("half.msh"), "--variants",
                   path("variants.txt"), "-o", path("study"), "--off-cad", "fixed", "--slide",
                   "symmetry")
print(out)
check(rc == 0, "study: exit 0, got %d (%s)" % (rc, err.strip()[-600:]))
if rc == 0:
    rows = [l.split() for l in out.splitlines() if l.startswith(("g1 ", "g2 "))]
    check(len(rows) == 2 and all(r[5] == "0" and r[-1] == "ok" for r in rows),
          "study: two rows, no inverted cell: %s" % out)
    import csv
    with open(path(os.path.join("study", "study.csv"))) as f:
        solve = [float(r["t_volume_solve"]) for r in csv.DictReader(f)]
    check(len(solve) == 2 and solve[0] > 0 and solve[1] == 0,
          "study: the second variant reuses the first's factorisations (t_volume_solve %r)"
          % solve)
    order = sorted(m0)  # the .msh's node tags 1..n in file order
    for v in ("g1", "g2"):
        vp = path(os.path.join("study", "rbf-s_absolute_%s.vtu" % v))
        if not os.path.exists(vp):
            check(False, "study: %s written" % vp)
            continue
        pts = vtu_points(vp)
        check(len(pts) == len(order), "study %s: %d points" % (v, len(pts)))
        if len(pts) != len(order):
            continue
        at = {t: pts[i] for i, t in enumerate(order)}
        off_plane = [t for t in sym_off if at[t][1] != 0.0]
        check(not off_plane, "study %s: %d symmetry nodes left y = 0" % (v, len(off_plane)))
        moved = [t for t in tunnel_only if at[t] != m0[t]]
        check(not moved, "study %s: %d tunnel nodes moved" % (v, len(moved)))
        if v == "g1" and os.path.exists(path("slide.msh")):
            m1 = nodes("slide.msh")
            d = max(math.dist(at[t], m1[t]) for t in order)
            check(d <= 1e-12 * diag, "study g1 = morph g1 (largest difference %.3g)" % d)

gmsh.finalize()
if failures:
    print("%d failures" % len(failures))
    sys.exit(1)
print("ok")
