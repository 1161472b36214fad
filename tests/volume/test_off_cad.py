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
    boundary component partly on G0 (a block mesh taller than the STEP's block: its top is off
    G0, its sides partly on).
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
rc, out, err = run("--from", path("g0.step"), "--to", path("g0.step"), "--mesh", path("tall.msh"),
                   "-o", path("tall_out.msh"), "--off-cad", "fixed")
check(rc == 2 and "is partly on the CAD model" in err,
      "partly matched component: exit 2 with the message, got %d (%s)" % (rc, err.strip()))
check(not os.path.exists(path("tall_out.msh")), "partly matched: nothing written")
gmsh.finalize()

if failures:
    print("%d failures" % len(failures))
    sys.exit(1)
print("all off-CAD checks passed")
