#!/usr/bin/env python3
"""Writes the contour test drawings of data/contours/ (see data/README.md).

DXF files are written by ezdxf (pip install ezdxf; 1.4.5 made the committed ones); the SVG and
CSV files are written here as text. pocket.* hold one two-island pocket in all three kinds, with
shapes each represents exactly (lines, full circles, half circles), so the contour filters give
byte-identical output on them (tests/contours.rs).

    python3 scripts/contour-files.py data/contours
"""
import os
import sys

import ezdxf
import ezdxf.math

OUT = sys.argv[1] if len(sys.argv) > 1 else "data/contours"
os.makedirs(OUT, exist_ok=True)

# The pocket in mm, y up: an 80 x 60 outer boundary, a circle island, a slot island (two lines and
# two half circles turning clockwise, as the SVG's y-down arcs become). Vertex order is the order
# each kind is read in: the SVG rect from its top-left corner, the circle from its rightmost point.
OUTER = [(10, 70), (90, 70), (90, 10), (10, 10)]
CIRCLE = ((30, 40), 8)
SLOT = [(55, 45, 0), (70, 45, -1), (70, 35, 0), (55, 35, -1)]  # x, y, bulge of the piece leaving


def pocket_dxf(path):
    doc = ezdxf.new("R2010")
    msp = doc.modelspace()
    msp.add_lwpolyline(OUTER, close=True)
    msp.add_circle(CIRCLE[0], CIRCLE[1])
    msp.add_lwpolyline([(x, y, b) for x, y, b in SLOT], format="xyb", close=True)
    doc.saveas(path)


def pocket_svg(path):
    # viewBox 0 0 100 80 at 100 mm x 80 mm: user units are mm, y measured down from the top.
    flip = lambda y: 80 - y
    (cx, cy), r = CIRCLE
    d = "M {} {} L {} {} A 5 5 0 0 1 {} {} L {} {} A 5 5 0 0 1 {} {} Z".format(
        SLOT[0][0], flip(SLOT[0][1]), SLOT[1][0], flip(SLOT[1][1]), SLOT[2][0], flip(SLOT[2][1]),
        SLOT[3][0], flip(SLOT[3][1]), SLOT[0][0], flip(SLOT[0][1]))
    with open(path, "w") as f:
        f.write('<?xml version="1.0" encoding="UTF-8"?>\n')
        f.write('<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="80mm" viewBox="0 0 100 80">\n')
        f.write(f'  <rect x="10" y="{flip(70)}" width="80" height="60" fill="none" stroke="black"/>\n')
        f.write(f'  <circle cx="{cx}" cy="{flip(cy)}" r="{r}" fill="none" stroke="black"/>\n')
        f.write(f'  <path d="{d}" fill="none" stroke="black"/>\n')
        f.write("</svg>\n")


def pocket_csv(path):
    rows = ["path,move,x,y,z,xc,yc"]
    ring = OUTER + [OUTER[0]]
    rows += [f"1,line,{x},{y},0,," for x, y in ring]
    (cx, cy), r = CIRCLE
    rows += [f"2,line,{cx + r},{cy},0,,", f"2,ccw,{cx - r},{cy},0,{cx},{cy}", f"2,ccw,{cx + r},{cy},0,{cx},{cy}"]
    rows.append(f"3,line,{SLOT[0][0]},{SLOT[0][1]},0,,")
    for k, (x, y, b) in enumerate(SLOT):
        nx, ny, _ = SLOT[(k + 1) % len(SLOT)]
        if b == 0:
            rows.append(f"3,line,{nx},{ny},0,,")
        else:
            rows.append(f"3,cw,{nx},{ny},0,{(x + nx) // 2},{(y + ny) // 2}")
    with open(path, "w") as f:
        f.write("\n".join(rows) + "\n")


def curves_dxf(path):
    """Curves on layer Cut: an old-style POLYLINE with bulges (a 100 x 60 plate with round
    corners), an ELLIPSE island, a closed cubic SPLINE island and a rational one; on layer Notes
    a lone LINE (open: refused unless --layer Cut) and a TEXT."""
    doc = ezdxf.new("R2010")
    msp = doc.modelspace()
    doc.layers.add("Cut")
    doc.layers.add("Notes")
    cut = {"layer": "Cut"}
    t = 0.41421356237309503  # tan(22.5°): a quarter circle
    plate = [(10, 0, 0), (90, 0, t), (100, 10, 0), (100, 50, t), (90, 60, 0), (10, 60, t), (0, 50, 0), (0, 10, t)]
    pl = msp.add_polyline2d([(x, y) for x, y, _ in plate], close=True, dxfattribs=cut)
    for v, (_, _, b) in zip(pl.vertices, plate):
        v.dxf.bulge = b
    msp.add_ellipse((25, 30), major_axis=(12, 4), ratio=0.5, dxfattribs=cut)
    frame = [(55, 20), (70, 18), (80, 30), (70, 45), (55, 42), (50, 30)]
    msp.add_spline(dxfattribs=cut).apply_construction_tool(ezdxf.math.closed_uniform_bspline(frame, order=4))
    msp.add_rational_spline([(80, 8), (92, 8), (92, 20), (80, 20), (80, 8)], weights=[1, 0.7, 2.0, 0.7, 1],
                            degree=2, dxfattribs=cut)
    msp.add_line((0, 70), (40, 70), dxfattribs={"layer": "Notes"})
    msp.add_text("plate", dxfattribs={"layer": "Notes"}).set_placement((0, 75))
    doc.saveas(path)


def open_dxf(path):
    """A 50 x 30 rectangle of LINEs whose last side stops 0.05 mm short of the first corner."""
    doc = ezdxf.new("R2010")
    msp = doc.modelspace()
    msp.add_line((0, 0), (50, 0))
    msp.add_line((50, 0), (50, 30))
    msp.add_line((50, 30), (0, 30))
    msp.add_line((0, 30), (0, 0.05))
    doc.saveas(path)


def inkscape_svg(path):
    """An Inkscape-style drawing: a layer translated into place, a rect boundary, a circle
    island and a bezier blob island, plus hidden and non-drawing elements."""
    text = """<?xml version="1.0" encoding="UTF-8" standalone="no"?>
<svg
   width="120mm"
   height="90mm"
   viewBox="0 0 120 90"
   version="1.1"
   id="svg1"
   xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"
   xmlns:sodipodi="http://sodipodi.sourceforge.net/DTD/sodipodi-0.dtd"
   xmlns="http://www.w3.org/2000/svg"
   xmlns:svg="http://www.w3.org/2000/svg">
  <sodipodi:namedview id="namedview1" inkscape:document-units="mm" />
  <defs id="defs1" />
  <g
     inkscape:label="Pocket"
     inkscape:groupmode="layer"
     id="layer1"
     transform="translate(10,5)">
    <rect
       style="fill:none;stroke:#000000;stroke-width:0.264583"
       id="rect1"
       width="100"
       height="80"
       x="0"
       y="0" />
    <circle
       style="fill:none;stroke:#000000;stroke-width:0.264583"
       id="path2"
       cx="25"
       cy="40"
       r="10" />
    <path
       style="fill:none;stroke:#000000;stroke-width:0.264583"
       d="m 60,25 c 10,-8 25,-4 28,8 3,12 -6,22 -18,22 -12,0 -20,-10 -18,-18 0.8,-4 4,-8 8,-12 z"
       id="path3"
       sodipodi:nodetypes="ccccc" />
  </g>
  <g inkscape:label="Notes" inkscape:groupmode="layer" id="layer2" style="display:none">
    <path d="M 0 0 L 5 5" id="path4" />
  </g>
  <text x="5" y="88" id="text1">pocket</text>
</svg>
"""
    with open(path, "w") as f:
        f.write(text)


def no_paths_svg(path):
    with open(path, "w") as f:
        f.write('<?xml version="1.0"?>\n<svg xmlns="http://www.w3.org/2000/svg" width="50mm" height="50mm" '
                'viewBox="0 0 50 50">\n  <text x="5" y="25">no contour here</text>\n</svg>\n')


pocket_dxf(os.path.join(OUT, "pocket.dxf"))
pocket_svg(os.path.join(OUT, "pocket.svg"))
pocket_csv(os.path.join(OUT, "pocket.csv"))
curves_dxf(os.path.join(OUT, "curves.dxf"))
open_dxf(os.path.join(OUT, "open.dxf"))
inkscape_svg(os.path.join(OUT, "inkscape.svg"))
no_paths_svg(os.path.join(OUT, "no-paths.svg"))
