# Tessellates a STEP file to a binary STL with FreeCAD's mesher (OpenCASCADE's BRepMesh), for
# OpenCAMLib to drop onto (scripts/bench-dropcutter-step.sh); run as
#     IN=data/step/block.step OUT=block.stl DEFLECTION=0.0005 freecadcmd scripts/step-stl.py
# DEFLECTION is the largest distance (mm) from a triangle to the surface it stands for.
import os

import MeshPart
import Part

shape = Part.read(os.environ["IN"])
d = float(os.environ.get("DEFLECTION", "0.0005"))
mesh = MeshPart.meshFromShape(Shape=shape, LinearDeflection=d, AngularDeflection=0.05, Relative=False)
mesh.write(os.environ["OUT"])
print(f"{os.environ['OUT']}: {mesh.CountFacets} triangles, deflection {d} mm")
