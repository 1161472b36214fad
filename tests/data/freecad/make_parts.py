# FreeCAD 0.20 parts for tests/cad/freecad.cmake and benchmarks/freecad/run.sh
# (benchmarks/RESULTS.md, FreeCAD-made parts):
# run with `freecadcmd make_parts.py`
# and OUT_DIR in the environment variable CM_FREECAD_OUT (freecadcmd passes no argv to scripts).
# Each part is a Part-workbench document object recomputed at two or three values of one
# dimension and exported by FreeCAD's own STEP writer (Import.export), plus a re-export: the
# first file read back by FreeCAD (Import.insert) and written again unchanged.
import os
import FreeCAD as App
import Part
import Import
from FreeCAD import Vector as V

out = os.environ.get("CM_FREECAD_OUT", ".")
os.makedirs(out, exist_ok=True)


def shaft(flange_r):
    """A flanged shaft: a revolved profile whose flange rim and shaft shoulders share circles
    (cocircular rims at the same z), with a cross hole through the shaft."""
    r, L, t = 6.0, 40.0, 4.0
    pts = [V(0, 0, 0), V(r, 0, 0), V(r, 0, 10), V(flange_r, 0, 10), V(flange_r, 0, 10 + t),
           V(r, 0, 10 + t), V(r, 0, L), V(0, 0, L), V(0, 0, 0)]
    face = Part.Face(Part.makePolygon(pts))
    solid = face.revolve(V(0, 0, 0), V(0, 0, 1), 360)
    hole = Part.makeCylinder(2.0, 4 * r, V(-2 * r, 0, 28), V(1, 0, 0))
    return solid.cut(hole)


def plate(length):
    """A plate with four bolt holes and filleted vertical edges."""
    w, h = 50.0, 8.0
    box = Part.makeBox(length, w, h)
    vert = [e for e in box.Edges if abs(e.Vertexes[0].Point.z - e.Vertexes[1].Point.z) > 1e-9]
    box = box.makeFillet(5.0, vert)
    for x in (8.0, length - 8.0):
        for y in (8.0, w - 8.0):
            box = box.cut(Part.makeCylinder(3.0, 3 * h, V(x, y, -h)))
    return box


def bracket(shoulder_r):
    """An L bracket with a boss on its foot whose shoulder is an annulus between the boss
    radius and shoulder_r, and a bore through the boss."""
    foot = Part.makeBox(60, 40, 6)
    wall = Part.makeBox(6, 40, 40)
    s = foot.fuse(wall)
    shoulder = Part.makeCylinder(shoulder_r, 4, V(35, 20, 6))
    boss = Part.makeCylinder(6.0, 12, V(35, 20, 6))
    s = s.fuse(shoulder).fuse(boss)
    s = s.cut(Part.makeCylinder(3.0, 40, V(35, 20, -5)))
    return s.removeSplitter()


parts = {"shaft": (shaft, [20.0, 23.0, 16.0]),
         "plate": (plate, [80.0, 95.0]),
         "bracket": (bracket, [14.0, 11.0, 8.0])}

for name, (make, values) in parts.items():
    doc = App.newDocument(name)
    obj = doc.addObject("Part::Feature", name)
    for i, v in enumerate(values):
        obj.Shape = make(v)
        doc.recompute()
        path = os.path.join(out, "%s_%d.step" % (name, i))
        Import.export([obj], path)
        print("%s value %g: %d faces -> %s" % (name, v, len(obj.Shape.Faces), path))
    App.closeDocument(name)
    # the re-export: FreeCAD reads its own STEP file and writes it again, no edit
    doc = App.newDocument(name + "_re")
    Import.insert(os.path.join(out, "%s_0.step" % name), doc.Name)
    objs = [o for o in doc.Objects if hasattr(o, "Shape") and not o.Shape.isNull()]
    path = os.path.join(out, "%s_re.step" % name)
    Import.export(objs, path)
    print("%s re-export: %d objects -> %s" % (name, len(objs), path))
    App.closeDocument(doc.Name)
