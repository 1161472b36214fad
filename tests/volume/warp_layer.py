"""The warp's tolerance from the mesh on a boundary-layer mesh that gmsh writes (docs/DESIGN.md,
"The warp's tolerance"): a 1 x 1 x 0.5 box of prisms extruded from a triangulated square,
its first layer 1e-4 thick (a CFD wall layer), the wall z = 0 moved by a bump of 0.1, the rest
of the boundary held. `cadmorph warp --solver iterative -v` must name the tolerance of the
rule (1e-3 x the shortest wall-to-free spacing of a cell over the boundary's diagonal, here
found by brute force over the prisms' node pairs with numpy), and its mesh must stretch or
turn no cell's edges by more than 1e-3 of their length against the same warp at
--rbf-tol 1e-12 (max |de| / |dx| over the node pairs of each prism; measured 1.1e-5). The
iterative solve overshoots its tolerance here (at 1e-6 or 1e-5 it stops at the same iterate,
1.2e-4), so the strain bound is a check of the whole path; tests/volume/
test_warp_tolerance.c is the one that fails for a looser rule.
usage: warp_layer.py CADMORPH WORK
"""
import os
import re
import subprocess
import sys

import meshio
import numpy as np

GEO = """
Point(1) = {0, 0, 0, 0.125}; Point(2) = {1, 0, 0, 0.125};
Point(3) = {1, 1, 0, 0.125}; Point(4) = {0, 1, 0, 0.125};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
// the first layer 1e-4 / 0.5 of the height, then 4 layers up to the top
Extrude {0, 0, 0.5} { Surface{1}; Layers{{1, 4}, {2e-4, 1}}; Recombine; }
"""


def boundary_nodes(prisms):
    """Nodes on faces that belong to one prism only."""
    tri = np.sort(np.concatenate([prisms[:, [0, 1, 2]], prisms[:, [3, 4, 5]]]), axis=1)
    quad = np.sort(np.concatenate([prisms[:, [0, 1, 4, 3]], prisms[:, [1, 2, 5, 4]],
                                   prisms[:, [2, 0, 3, 5]]]), axis=1)
    nodes = []
    for faces in (tri, quad):
        u, c = np.unique(faces, axis=0, return_counts=True)
        nodes.append(u[c == 1].ravel())
    return np.unique(np.concatenate(nodes))


def pairs(prisms):
    """Every pair of nodes of a prism, as two index arrays."""
    i, j = np.triu_indices(6, 1)
    return prisms[:, i].ravel(), prisms[:, j].ravel()


def warp(cli, mesh, csv, out, extra):
    """`cadmorph warp` with the iterative solver; its moved points and its -v log."""
    p = subprocess.run([cli, "warp", "--mesh", mesh, "--displacements", csv, "-o", out,
                        "--solver", "iterative", "--threads", "2", "-v"] + extra,
                       capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"cadmorph warp {' '.join(extra)} failed ({p.returncode}):\n{p.stderr}")
    return meshio.read(out).points, p.stderr


def main():
    cli, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    geo, msh = os.path.join(work, "layer.geo"), os.path.join(work, "layer.msh")
    with open(geo, "w") as f:
        f.write(GEO)
    subprocess.run(["gmsh", "-3", geo, "-o", msh, "-format", "msh22"], check=True,
                   capture_output=True)
    m = meshio.read(msh)
    x = m.points
    prisms = m.cells_dict["wedge"]
    assert len(prisms) > 0 and all(c.type in ("wedge", "triangle", "quad", "line", "vertex")
                                   for c in m.cells), [c.type for c in m.cells]
    # the motion: the wall z = 0 bumps up, every other boundary node stays (not listed)
    wall = np.where(np.abs(x[:, 2]) < 1e-12)[0]
    csv = os.path.join(work, "bump.csv")
    with open(csv, "w") as f:
        f.write("node,dx,dy,dz\n")
        for n in wall:
            bump = 0.1 * np.sin(np.pi * x[n, 0]) * np.sin(np.pi * x[n, 1])
            f.write(f"{n},0,0,{bump:.17g}\n")
    # the rule by brute force: constrained = the boundary (listed or held)
    con = np.zeros(len(x), bool)
    con[boundary_nodes(prisms)] = True
    i, j = pairs(prisms)
    mixed = con[i] != con[j]
    h = np.linalg.norm(x[i[mixed]] - x[j[mixed]], axis=1).min()
    b = x[con]
    diag = np.linalg.norm(b.max(axis=0) - b.min(axis=0))
    want = max(1e-10, min(1e-6, 1e-3 * h / diag))
    got, log = warp(cli, msh, csv, os.path.join(work, "default.vtu"), [])
    ref, _ = warp(cli, msh, csv, os.path.join(work, "tight.vtu"), ["--rbf-tol", "1e-12"])
    said = re.search(r"cm_warp_create: .* tolerance ([0-9.e+-]+) \(from the mesh: wall spacing "
                     r"([0-9.e+-]+)", log)
    failures = []
    if not said:
        failures.append("no 'tolerance ... (from the mesh' in the -v log")
    else:
        tol = float(said.group(1))
        print(f"wall spacing {h:.4g} (cadmorph {said.group(2)}), diagonal {diag:.4g}: "
              f"tolerance {tol:.3g}, the rule {want:.3g}")
        if abs(tol - want) > 1e-3 * want:  # the log prints 3 digits
            failures.append(f"tolerance {tol:g}, the rule gives {want:g}")
    e = got - ref
    dx = np.linalg.norm(x[i] - x[j], axis=1)
    strain = (np.linalg.norm(e[i] - e[j], axis=1) / dx).max()
    print(f"the default's mesh against --rbf-tol 1e-12: nodes within {np.abs(e).max():.3g}, "
          f"cell edges within {strain:.3g} of their length (wall layer {h:.3g})")
    if not strain <= 1e-3:
        failures.append(f"strain {strain:g} above 1e-3")
    if np.abs(got[wall, 2] - x[wall, 2]).max() < 0.05:
        failures.append("the wall did not move")
    for f in failures:
        print("FAIL:", f)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
