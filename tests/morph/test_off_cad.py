#!/usr/bin/python3
"""`cadmorph morph --off-cad fixed`: a body in a box, the box not in the body's STEP (the
wind tunnel of a CFD mesh; `cadmorph mesh` cannot make such a mesh, gmsh's Python API does:
the box minus the body, tets, physical groups).

  * the default refuses it (exit 2, "boundary nodes are off the CAD model", naming the option);
  * --off-cad fixed onto the STEP with the body 10 % longer: exit 0, the summary says how many
    nodes were kept fixed and in how many components, and --verbose says it too; every body
    node is on G1 to 1e-9 x G1's diagonal (closest points by gmsh's OpenCASCADE on G1's
    faces), every box node has exactly its input coordinates, no inverted cell;
  * still refused with fixed: no node on G0 (the body's STEP moved away from the mesh), and a
    boundary component partly on G0 whose contact nodes the edit moves off the fixed surface
    (a block mesh taller than the STEP's block: its top is off G0, its sides partly on, and
    the edit makes the block longer);
  * a body touching the fixed surface (a block standing on the box's floor: one boundary
    component, partly on G0): the block 10 % taller morphs, the floor's nodes unmoved bit for
    bit, the block's nodes on G1, no inverted cell; the block lifted off the floor is refused
    (the contact nodes would leave the floor's plane).
usage: test_off_cad.py CADMORPH WORKDIR"""
import math
import os
import subprocess
import sys

import gmsh

CADMORPH, WORK = sys.argv[1], os.path.join(sys.argv[2], "off_cad")
os.makedirs(WORK, exist_ok=True)
failures = []


def check(cond, msg):
    if not cond:
        failures.append(msg)
        print("FAIL:", msg)


def path(name):
    return os.path.join(WORK, name)


def body(occ, length, dx=0.0):
    """A filleted block: length x 0.6 x 0.4 from (dx, 0, 0), edges rounded by 0.08."""
    b = occ.addBox(dx, 0, 0, length, 0.6, 0.4)
    occ.synchronize()
    occ.fillet([b], [e[1] for e in gmsh.model.getEntities(1)], [0.08])
    occ.synchronize()


def physical(dim, tags, tag, name):
    gmsh.model.addPhysicalGroup(dim, tags, tag)  # Debian's gmsh: no name argument yet
    gmsh.model.setPhysicalName(dim, tag, name)


def write_step(name, length, dx=0.0):
    gmsh.model.add(name)
    body(gmsh.model.occ, length, dx)
    gmsh.write(path(name))
    gmsh.model.remove()


def write_tunnel_mesh(name):
    """The box [-2, 3] x [-1.5, 2.1] x [-1.5, 1.9] minus the body (length 1)."""
    gmsh.model.add(name)
    occ = gmsh.model.occ
    box = occ.addBox(-2, -1.5, -1.5, 5, 3.6, 3.4)
    body(occ, 1.0)
    out, _ = occ.cut([(3, box)], [(3, t) for _, t in gmsh.model.getEntities(3) if t != box])
    occ.synchronize()
    vol = [t for _, t in gmsh.model.getEntities(3)]
    faces = [t for _, t in gmsh.model.getEntities(2)]
    physical(3, vol, 1, "fluid")
    tunnel = []
    for t in faces:
        xmin, ymin, zmin, xmax, ymax, zmax = gmsh.model.getBoundingBox(2, t)
        if min(xmin, ymin, zmin) < -1.4 or xmax > 2.9 or ymax > 2.0 or zmax > 1.8:
            tunnel.append(t)
    physical(2, tunnel, 2, "tunnel")
    physical(2, [t for t in faces if t not in tunnel], 3, "body")
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.05)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 10)
    gmsh.model.mesh.generate(3)
    gmsh.write(path(name))
    gmsh.model.remove()
    return len(tunnel)


def write_step_box(name, length, width, height, dz=0.0):
    gmsh.model.add(name)
    gmsh.model.occ.addBox(0, 0, dz, length, width, height)
    gmsh.model.occ.synchronize()
    gmsh.write(path(name))
    gmsh.model.remove()


def write_floor_mesh(name):
    """The box [-1.5, 2.5] x [-1.2, 1.8] x [0, 1.5] minus a block 1 x 0.6 x 0.4 standing on its
    floor (z = 0): the block's faces and the floor meet along the block's bottom edges."""
    gmsh.model.add(name)
    occ = gmsh.model.occ
    box = occ.addBox(-1.5, -1.2, 0, 4, 3, 1.5)
    blk = occ.addBox(0, 0, 0, 1, 0.6, 0.4)
    occ.cut([(3, box)], [(3, blk)])
    occ.synchronize()
    physical(3, [t for _, t in gmsh.model.getEntities(3)], 1, "fluid")
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.3)
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.model.mesh.setSize([(0, t) for _, t in gmsh.model.getEntities(0)
                             if max(abs(c) for c in gmsh.model.getValue(0, t, [])[:2]) < 1.2], 0.08)
    gmsh.model.mesh.generate(3)
    gmsh.write(path(name))
    gmsh.model.remove()


def write_block_mesh(name, height):
    gmsh.model.add(name)
    gmsh.model.occ.addBox(0, 0, 0, 1, 0.6, height)
    gmsh.model.occ.synchronize()
    physical(3, [1], 1, "block")
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.15)
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.model.mesh.generate(3)
    gmsh.write(path(name))
    gmsh.model.remove()


def nodes(name):
    """{tag: (x, y, z)} of a .msh (gmsh parses the text: exact doubles)."""
    gmsh.open(path(name))
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    out = {int(t): (xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]) for i, t in enumerate(tags)}
    gmsh.model.remove()
    return out


def run(*args):
    p = subprocess.run([CADMORPH, "morph"] + list(args), capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
write_step("g0.step", 1.0)
write_step("g1.step", 1.1)
write_step("away.step", 1.0, dx=20.0)

n_tunnel_faces = write_tunnel_mesh("tunnel.msh")
check(n_tunnel_faces == 6, "the tunnel box has 6 faces, found %d" % n_tunnel_faces)

# the default refuses
rc, out, err = run("--from", path("g0.step"), "--to", path("g1.step"), "--mesh", path("tunnel.msh"),
                   "-o", path("refused.msh"))
check(rc == 2, "default: exit 2, got %d (%s)" % (rc, err.strip()))
check("boundary nodes are off the CAD model" in err and "--off-cad fixed" in err,
      "default: the message names the off nodes and the option: %s" % err.strip())
check(not os.path.exists(path("refused.msh")), "default: nothing written")

# --off-cad fixed
rc, out, err = run("--from", path("g0.step"), "--to", path("g1.step"), "--mesh", path("tunnel.msh"),
                   "-o", path("morphed.msh"), "--off-cad", "fixed", "--verbose")
check(rc == 0, "fixed: exit 0, got %d (%s)" % (rc, err.strip()[-600:]))
print(out)
m0 = nodes("tunnel.msh")
# the box nodes: on the tunnel's planes
def on_tunnel(p):
    x, y, z = p
    return min(abs(x + 2), abs(x - 3), abs(y + 1.5), abs(y - 2.1), abs(z + 1.5), abs(z - 1.9)) < 1e-12
tunnel = [t for t, p in m0.items() if on_tunnel(p)]
# the body nodes: within the body's box grown a little (the mesh is coarse far from it)
body_nodes = [t for t, p in m0.items()
              if -1e-9 <= p[0] <= 1 + 1e-9 and -1e-9 <= p[1] <= 0.6 + 1e-9 and -1e-9 <= p[2] <= 0.4 + 1e-9]
check(len(tunnel) > 100 and len(body_nodes) > 100,
      "fixture: %d tunnel and %d body nodes" % (len(tunnel), len(body_nodes)))
import re
m = re.search(r"(\d+) off G0 kept fixed \((\d+) boundary components\)", out)
check(m is not None and int(m.group(1)) == len(tunnel) and m.group(2) == "1",
      "fixed: the summary says %d tunnel nodes kept fixed in 1 component: %s" % (len(tunnel), out))
check(re.search(r"%d of \d+ boundary nodes are off the CAD model, in 1 boundary components"
                % len(tunnel), err) is not None, "fixed: --verbose says it: %s" % err[-800:])
check(" inverted=0 " in out, "fixed: no inverted cell: %s" % out)
if rc == 0:
    m1 = nodes("morphed.msh")
    check(set(m1) == set(m0), "fixed: the same node tags")
    moved = [t for t in tunnel if m1[t] != m0[t]]
    check(not moved, "fixed: %d tunnel nodes moved (first %s: %r -> %r)" %
          (len(moved), moved[:1], m0[moved[0]] if moved else None, m1[moved[0]] if moved else None))
    gmsh.open(path("g1.step"))
    lo, hi = gmsh.model.getBoundingBox(-1, -1)[:3], gmsh.model.getBoundingBox(-1, -1)[3:]
    diag = math.dist(lo, hi)
    faces = [t for _, t in gmsh.model.getEntities(2)]
    worst = 0.0
    for t in body_nodes:
        p = m1[t]
        d = min(math.dist(p, gmsh.model.getClosestPoint(2, f, list(p))[0]) for f in faces)
        worst = max(worst, d)
    gmsh.model.remove()
    print("body nodes: %d, largest distance to G1 %.3g (%.3g x diagonal); tunnel nodes %d unmoved"
          % (len(body_nodes), worst, worst / diag, len(tunnel)))
    check(worst <= 1e-9 * diag, "fixed: body nodes on G1: worst %.3g > 1e-9 x %.3g" % (worst, diag))
    # the morph did something: the body's far end moved by the 0.1 of the edit
    far = max(body_nodes, key=lambda t: m0[t][0])
    check(abs(m1[far][0] - 1.1) < 1e-9, "fixed: the body's far end at x = 1.1: %r" % (m1[far],))

# --keep-offset (for meshes snapped near G0, with a loose --cad-tol): the body nodes pushed off
# G0 by up to 4e-4 (a snapped mesh's error); G0 -> G0 then moves nothing beyond round-off with
# it, and puts the body nodes back on G0 (moves of about that size) without it
gmsh.open(path("tunnel.msh"))
for t in body_nodes:
    p = m0[t]
    d = ((t * 7919) % 9 - 4) * 1e-4
    gmsh.model.mesh.setNode(t, [p[0] + d, p[1] - 0.5 * d, p[2] + 0.75 * d], [])
gmsh.write(path("snapped.msh"))
gmsh.model.remove()
ms = nodes("snapped.msh")
for flag, want in (("--keep-offset", "nothing"), (None, "back on G0")):
    args = ["--from", path("g0.step"), "--to", path("g0.step"), "--mesh", path("snapped.msh"),
            "-o", path("identity.msh"), "--off-cad", "fixed", "--cad-tol", "0.3"]
    rc, out, err = run(*(args + ([flag] if flag else [])))
    check(rc == 0, "snapped, %s: exit 0, got %d (%s)" % (flag, rc, err.strip()[-600:]))
    if rc != 0:
        continue
    mi = nodes("identity.msh")
    worst = max(math.dist(mi[t], ms[t]) for t in ms)
    print("snapped mesh, G0 -> G0, %s: largest node move %.3g" % (flag, worst))
    if flag:
        check(worst < 1e-12, "keep-offset identity: a node moved by %.3g" % worst)
    else:
        check(worst > 1e-4, "without --keep-offset the nodes go back on G0: largest move %.3g" % worst)
rc, out, err = run("--from", path("g0.step"), "--to", path("g1.step"), "--mesh", path("tunnel.msh"),
                   "-o", path("offset.msh"), "--off-cad", "fixed", "--keep-offset")
check(rc == 0 and re.search(r"largest distance to G1: [0-9.e+-]+ \(([0-9.e+-]+) x diagonal", out)
      and float(re.search(r"\(([0-9.e+-]+) x diagonal", out).group(1)) < 1e-9,
      "keep-offset G0 -> G1: on G1 to 1e-9 x diagonal: %s %s" % (out, err.strip()[-300:]))

# no node on G0: refused, also with fixed
rc, out, err = run("--from", path("away.step"), "--to", path("away.step"), "--mesh", path("tunnel.msh"),
                   "-o", path("away.msh"), "--off-cad", "fixed")
check(rc == 2 and "boundary nodes are off the CAD model" in err,
      "no node on G0: exit 2 with the message, got %d (%s)" % (rc, err.strip()))

# a component partly on G0: a block 0.5 high against the STEP's filleted block 0.4 high
write_block_mesh("tall.msh", 0.5)
rc, out, err = run("--from", path("g0.step"), "--to", path("g1.step"), "--mesh", path("tall.msh"),
                   "-o", path("tall_out.msh"), "--off-cad", "fixed")
check(rc == 2 and "touches the fixed surface off it" in err,
      "partly matched component: exit 2 with the message, got %d (%s)" % (rc, err.strip()))
check(not os.path.exists(path("tall_out.msh")), "partly matched: nothing written")

# a body standing on the fixed floor: the block 10 % taller follows the CAD, the floor stays
write_step_box("b0.step", 1, 0.6, 0.4)
write_step_box("b1.step", 1, 0.6, 0.44)
write_step_box("lifted.step", 1, 0.6, 0.4, dz=0.02)
write_floor_mesh("floor.msh")
rc, out, err = run("--from", path("b0.step"), "--to", path("b1.step"), "--mesh", path("floor.msh"),
                   "-o", path("floor_out.msh"), "--off-cad", "fixed", "--verbose")
check(rc == 0, "block on the floor: exit 0, got %d (%s)" % (rc, err.strip()[-600:]))
check(re.search(r"1 boundary components partly on the CAD model: \d+ nodes on it touch", err) is not None,
      "block on the floor: --verbose names the contact nodes: %s" % err[-600:])
check(" inverted=0 " in out, "block on the floor: no inverted cell: %s" % out)
if rc == 0:
    f0, f1 = nodes("floor.msh"), nodes("floor_out.msh")
    blk = [t for t, p in f0.items() if -1e-12 <= p[0] <= 1 + 1e-12 and -1e-12 <= p[1] <= 0.6 + 1e-12
           and p[2] <= 0.4 + 1e-12 and (min(p[0], 1 - p[0], p[1], 0.6 - p[1], 0.4 - p[2]) < 1e-12)]
    box = [t for t, p in f0.items() if t not in blk and (min(p[0] + 1.5, 2.5 - p[0], p[1] + 1.2, 1.8 - p[1],
                                                        p[2], 1.5 - p[2]) < 1e-12)]
    moved = [t for t in box if f1[t] != f0[t]]
    check(len(box) > 100 and not moved, "block on the floor: %d of %d box nodes moved" % (len(moved), len(box)))
    contact = [t for t in blk if abs(f0[t][2]) < 1e-12]
    off = max(abs(f1[t][2] - 0.44 * f0[t][2] / 0.4) for t in blk)
    same = max(math.dist(f1[t], f0[t]) for t in contact)
    print("block on the floor: %d block nodes (%d on the floor), largest miss of z' = 1.1 z %.3g, "
          "contact nodes moved by %.3g; %d box nodes unmoved" % (len(blk), len(contact), off, same, len(box)))
    check(len(contact) > 10 and same < 1e-12, "block on the floor: contact nodes stay: %.3g" % same)
    check(off < 1e-9, "block on the floor: the block's nodes at z' = 1.1 z (G1): %.3g" % off)
rc, out, err = run("--from", path("b0.step"), "--to", path("lifted.step"), "--mesh", path("floor.msh"),
                   "-o", path("lifted_out.msh"), "--off-cad", "fixed")
check(rc == 2 and "touches the fixed surface off it" in err and "off that surface's plane" in err,
      "block lifted off the floor: exit 2 with the message, got %d (%s)" % (rc, err.strip()))
check(not os.path.exists(path("lifted_out.msh")), "lifted: nothing written")
gmsh.finalize()

if failures:
    print("%d failures" % len(failures))
    sys.exit(1)
print("all off-CAD checks passed")
