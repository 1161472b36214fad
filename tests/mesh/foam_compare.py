"""The comparison of checkMesh's printed metrics with `cadmorph quality --foam`, shared by the
OpenFOAM cross-checks (test_foam_crosscheck.py, test_foam_car.py): one parser for both outputs
(cadmorph prints checkMesh's layout), every number string-equal to checkMesh's printed
precision; values that are round-off noise (|x| < 1e-10) only to 1e-12."""
import re
import subprocess
import time

NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


def metrics(text):
    """The numbers of checkMesh's mesh stats and geometry block, by name (same parser for
    checkMesh's output and cadmorph's, which prints the same layout)."""
    out = {}
    for key in ["points", "faces", "internal faces", "cells", "boundary patches"]:
        m = re.search(r"^\s+%s:\s+(%s)" % (key, NUM), text, re.M)
        if m:
            out[key] = m.group(1)
    geo = text[text.find("Checking geometry..."):]
    pats = {
        "bbox": r"bounding box \((%s) (%s) (%s)\) \((%s) (%s) (%s)\)" % ((NUM,) * 6),
        "boundary openness": r"Boundary openness \((%s) (%s) (%s)\)" % ((NUM,) * 3),
        "max cell openness": r"Max cell openness = (%s)" % NUM,
        "max aspect ratio": r"Max aspect ratio = (%s)" % NUM,
        "face area": r"Minimum face area = (%s)\. Maximum face area = (%s)\." % (NUM, NUM),
        "volume": r"Min volume = (%s)\. Max volume = (%s)\.  Total volume = (%s)\." % (NUM, NUM, NUM),
        "non-orthogonality": r"Mesh non-orthogonality Max: (%s) average: (%s)" % (NUM, NUM),
        "severe non-orthogonal faces": r"severely non-orthogonal \(> 70 degrees\) faces: (%s)" % NUM,
        "max skewness": r"Max skewness = (%s)" % NUM,
        "wrong pyramids": r"Error in face pyramids: (%s) faces" % NUM,
        "failed checks": r"Failed (%s) mesh checks" % NUM,
    }
    for k, p in pats.items():
        m = re.search(p, geo)
        if m:
            out[k] = m.groups()
    out["pyramids OK"] = "Face pyramids OK." in geo
    out["mesh OK"] = "\nMesh OK." in geo
    return out


def same_number(a, b):
    if a == b:
        return True
    x, y = float(a), float(b)
    if abs(x) < 1e-10 and abs(y) < 1e-10:  # round-off noise: summation order differs
        return abs(x - y) < 1e-12
    return False



class FoamCompare:
    """Failures collected by check(); run() times the OpenFOAM tools (foam=True) into
    foam_seconds, so that each test can hold its OpenFOAM runs to the budget."""

    def __init__(self, cadmorph, env):
        self.cadmorph, self.env = cadmorph, env
        self.failures = []
        self.foam_seconds = 0.0

    def check(self, cond, msg):
        if not cond:
            self.failures.append(msg)
            print("FAIL:", msg)

    def run(self, cmd, cwd=None, foam=False):
        t = time.time()
        p = subprocess.run(cmd, cwd=cwd, env=self.env, capture_output=True, text=True)
        if foam:
            self.foam_seconds += time.time() - t
        return p

    def compare(self, name, case):
        """checkMesh and `cadmorph quality --foam` on case: every printed value equal; (ref, ours)."""
        p = self.run(["checkMesh", "-case", case], foam=True)
        self.check(p.returncode == 0, "%s: checkMesh exit %d" % (name, p.returncode))
        q = self.run([self.cadmorph, "quality", case, "--foam"])
        self.check(q.returncode == 0, "%s: cadmorph quality --foam exit %d: %s" % (name, q.returncode, q.stderr))
        ref, ours = metrics(p.stdout), metrics(q.stdout)
        self.check(len(ref) >= 14, "%s: parsed only %s from checkMesh" % (name, sorted(ref)))
        n = 0
        for k, v in ref.items():
            if k not in ours:
                self.check(False, "%s: cadmorph lacks '%s' (checkMesh: %s)" % (name, k, v))
                continue
            w = ours[k]
            vs, ws = (v if isinstance(v, tuple) else (v,)), (w if isinstance(w, tuple) else (w,))
            for a, b in zip(vs, ws):
                if isinstance(a, bool):
                    self.check(a == b, "%s: %s: checkMesh %s, cadmorph %s" % (name, k, a, b))
                else:
                    self.check(same_number(a, b), "%s: %s: checkMesh %s, cadmorph %s" % (name, k, a, b))
                n += 1
        for k in ours:
            if k not in ref and k not in ("pyramids OK", "mesh OK"):
                self.check(False, "%s: cadmorph reports '%s' = %s, checkMesh does not" % (name, k, ours[k]))
        line = [l for l in q.stdout.splitlines() if l.startswith("max_aspect_ratio=")]
        self.check(len(line) == 1, "%s: no summary line" % name)
        print("%-10s %3d values equal to checkMesh's: non-orth max %s avg %s, skewness %s, aspect %s"
              % (name, n, ref.get("non-orthogonality", ("-", "-"))[0], ref.get("non-orthogonality", ("-", "-"))[1],
                 ref.get("max skewness", ("-",))[0], ref.get("max aspect ratio", ("-",))[0]))
        return ref, ours
