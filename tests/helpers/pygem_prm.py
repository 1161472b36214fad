"""Writes a PyGeM FFD parameter file (.prm, the format `cadmorph ffd` reads and PyGeM's
FFD.read_parameters writes), for the tests of `cadmorph ffd` and cadmorph.ffd."""


def write_prm(path, n, origin, length, angle, mu):
    """path: the .prm of a lattice with n control points per axis, its box origin, lengths
    and rotation angles (degrees), and mu[a][i, j, k] the weights along axis a (in units of
    the box length)."""
    with open(path, "w") as f:
        f.write("[Box info]\n")
        for key, v in (("n control points", n), ("box length", length),
                       ("box origin", origin), ("rotation angle", angle)):
            for a, c in enumerate("xyz"):
                f.write("%s %s: %r\n" % (key, c, v[a]))
        f.write("\n[Parameters weights]\n")
        for a, c in enumerate("xyz"):
            lines = ["%d %d %d %r" % (i, j, k, mu[a][i, j, k])
                     for i in range(n[0]) for j in range(n[1]) for k in range(n[2])]
            f.write("parameter %s: %s\n" % (c, "\n    ".join(lines)))
