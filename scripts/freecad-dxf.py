# Writes data/contours/freecad.dxf with FreeCAD's own DXF exporter (importDXF), run as
#     freecadcmd scripts/freecad-dxf.py            (FreeCAD 0.20.2 made the committed file)
# An 80 x 50 plate boundary of lines, a circle island, an ellipse island and a closed B-spline
# island: what a FreeCAD user's sketch of a pocket exports as (LINE, CIRCLE, ELLIPSE, SPLINE).
import os

import FreeCAD
import Part
import importDXF

V = FreeCAD.Vector
out = os.environ.get("OUT", "data/contours/freecad.dxf")
doc = FreeCAD.newDocument("pocket")
shapes = {
    "plate": Part.makePolygon([V(0, 0, 0), V(80, 0, 0), V(80, 50, 0), V(0, 50, 0), V(0, 0, 0)]),
    "hole": Part.Wire(Part.makeCircle(6, V(16, 25, 0))),
    "oval": Part.Wire(Part.Ellipse(V(40, 25, 0), 9, 5).toShape()),
}
spline = Part.BSplineCurve()
spline.interpolate([V(58, 15, 0), V(70, 18, 0), V(72, 32, 0), V(62, 38, 0), V(55, 28, 0)], PeriodicFlag=True)
shapes["blob"] = Part.Wire(spline.toShape())
objects = []
for name, shape in shapes.items():
    obj = doc.addObject("Part::Feature", name)
    obj.Shape = shape
    objects.append(obj)
doc.recompute()
importDXF.export(objects, out)
