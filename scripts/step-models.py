# Writes the STEP test models under data/step/ with FreeCAD's own STEP writer (OpenCASCADE), run as
#     freecadcmd scripts/step-models.py          (FreeCAD 0.20.2, Debian bookworm, made the files)
# block.step:   a 100 x 100 x 40 block (0..100, 0..100, 0..40) with a spherical dish R40 (centre
#               50,50,70: 10 mm deep), its vertical edges filleted R8 (cylinders), its top edges
#               R5 (cylinders, spheres at the corners) and the dish rim R3 (a torus).
# faces.step:   three separate faces: the upper half of a sphere R20 at the origin, the upper half
#               of a cylinder R10 along x (x 40..100) and the upper half of a torus (major 10,
#               minor 6) at (0, 60, 0); faces.json, the same surfaces as a camkit model document.
# bspline.step: one face on a bicubic B-spline surface (natural boundary) and bspline.json, the
#               same surface as a camkit model document (same control points and knots).
# revolve.step: a knob turned about z: the disc z = 0 (r <= 30), a cubic B-spline profile from
#               (30, 0) to (25, 15) (poles (30,0) (33,5) (22,10) (25,15) in (r, z)), an exact rational
#               quarter circle of radius 5 about (20, 15) up to (20, 20), and the disc z = 20: FreeCAD
#               writes both curved faces as SURFACE_OF_REVOLUTION of their B-spline profiles (the
#               second is a torus exactly), each face's seam edge used twice.
# tube.step:    one face on a closed periodic rational B-spline surface (u periodic: the exact circle
#               of eight poles, weights 1 and 1/sqrt(2); v linear) from radius 10 at z = 0 to radius 15
#               at z = 30: exactly the cone r = 10 + z / 6, its seam edge used twice.
# void.step:    a 60 x 60 x 40 block with a spherical void R10 about (30, 30, 20): a BREP_WITH_VOIDS
#               whose void is an ORIENTED_CLOSED_SHELL .F. (the sphere face turned over).
# The control points are on a 0.5 mm grid and the knots are integers, so both files hold the
# same numbers exactly.
import json
import os

import FreeCAD
import Part

V = FreeCAD.Vector
out = os.environ.get("OUT", "data/step")

block = Part.makeBox(100, 100, 40)
block = block.makeFillet(8, [e for e in block.Edges if abs(e.Vertexes[0].Point.z - e.Vertexes[1].Point.z) > 1])
block = block.cut(Part.makeSphere(40, V(50, 50, 70)))
block = block.cut(Part.makeCylinder(6, 20, V(85, 85, 25)))
rim = [e for e in block.Edges if abs(e.Length - 12 * 3.141592653589793) < 1e-6 and e.Vertexes[0].Point.z > 39]
block = block.makeFillet(2, rim)
block.exportStep(os.path.join(out, "block.step"))

dome = [f for f in Part.makeSphere(20, V(0, 0, 0), V(0, 0, 1), 0, 90).Faces if f.Surface.TypeId == "Part::GeomSphere"]
roof = [f for f in Part.makeCylinder(10, 60, V(40, 0, 0), V(1, 0, 0), 180).Faces if f.Surface.TypeId == "Part::GeomCylinder"]
roof[0].rotate(V(40, 0, 0), V(1, 0, 0), -90)  # the half from +z through -y to -z, turned to z >= 0
ring = [f for f in Part.makeTorus(10, 6, V(0, 60, 0), V(0, 0, 1), 0, 180).Faces if f.Surface.TypeId == "Part::GeomToroid"]
Part.makeCompound(dome + roof + ring).exportStep(os.path.join(out, "faces.step"))
faces = {"surfaces": [
    {"type": "sphere", "name": "dome", "centre": [0, 0, 0], "radius": 20},
    {"type": "cylinder", "name": "roof", "point": [40, 0, 0], "axis": [1, 0, 0], "radius": 10, "length": [0, 60]},
    {"type": "torus", "name": "ring", "centre": [0, 60, 0], "axis": [0, 0, 1], "major_radius": 10, "minor_radius": 6},
]}
with open(os.path.join(out, "faces.json"), "w") as f:
    json.dump(faces, f)
    f.write("\n")

# A bicubic surface over 0..60 x 0..40, 5 x 4 control points, knots 0 0 0 0 1 2 2 2 2 / 0 0 0 0 1 1 1 1.
grid = [[[15.0 * i, 40.0 / 3.0 * j, 0.0] for j in range(4)] for i in range(5)]
heights = [[0, 2, 3.5, 1], [1.5, 6, 8, 2.5], [2, 9, 10.5, 4], [1, 5.5, 7, 3], [0, 1.5, 2.5, 0.5]]
for i in range(5):
    for j in range(4):
        grid[i][j] = [round(grid[i][j][0] * 2) / 2, round(grid[i][j][1] * 2) / 2, heights[i][j]]
surface = Part.BSplineSurface()
surface.buildFromPolesMultsKnots(
    [[V(*p) for p in row] for row in grid], [4, 1, 4], [4, 4], [0.0, 1.0, 2.0], [0.0, 1.0], False, False, 3, 3
)
surface.toShape().exportStep(os.path.join(out, "bspline.step"))
doc = {"surfaces": [{"type": "bspline", "name": "free-form", "degree": [3, 3], "control_points": grid,
                     "knots_u": [0, 0, 0, 0, 1, 2, 2, 2, 2], "knots_v": [0, 0, 0, 0, 1, 1, 1, 1]}]}
with open(os.path.join(out, "bspline.json"), "w") as f:
    json.dump(doc, f)
    f.write("\n")

h = 0.5 ** 0.5
cubic = Part.BSplineCurve()
cubic.buildFromPolesMultsKnots([V(30, 0, 0), V(33, 0, 5), V(22, 0, 10), V(25, 0, 15)], [4, 4], [0.0, 1.0], False, 3)
quarter = Part.BSplineCurve()
quarter.buildFromPolesMultsKnots([V(25, 0, 15), V(25, 0, 20), V(20, 0, 20)], [3, 3], [0.0, 1.0], False, 2, [1.0, h, 1.0])
profile = [Part.LineSegment(V(0, 0, 0), V(30, 0, 0)), cubic, quarter,
           Part.LineSegment(V(20, 0, 20), V(0, 0, 20)), Part.LineSegment(V(0, 0, 20), V(0, 0, 0))]
knob = Part.Face(Part.Wire([c.toShape() for c in profile])).revolve(V(0, 0, 0), V(0, 0, 1), 360)
knob.exportStep(os.path.join(out, "revolve.step"))

ring = [(1, 0), (1, 1), (0, 1), (-1, 1), (-1, 0), (-1, -1), (0, -1), (1, -1)]
tube = Part.BSplineSurface()
tube.buildFromPolesMultsKnots([[V(r * x, r * y, z) for (r, z) in [(10, 0), (15, 30)]] for (x, y) in ring],
                              [2, 2, 2, 2, 2], [2, 2], [0.0, 1.0, 2.0, 3.0, 4.0], [0.0, 1.0], True, False, 2, 1,
                              [[w, w] for w in [1, h] * 4])
tube.toShape().exportStep(os.path.join(out, "tube.step"))

Part.makeBox(60, 60, 40).cut(Part.makeSphere(10, V(30, 30, 20))).exportStep(os.path.join(out, "void.step"))
