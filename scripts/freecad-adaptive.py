#!/usr/bin/env python3
"""FreeCAD's adaptive clearing (Path Adaptive, libarea's area.Adaptive2d) on a pocket given as a
toolpath table of closed contours (lines and arcs, e.g. data/medial-trochoid/box-die.csv), one
layer, headless: writes its path as a toolpath table CSV that `medial-trochoid --analyse` reads.

It drives area.Adaptive2d as FreeCAD 0.20's Mod/Path/PathScripts/PathAdaptive.py does (Execute:
stock = the stock's bounding box, ClearingInside; GenerateGCode: a helix of π/16 steps at the
helix angle down to the layer and one more circle at depth, Cutting moves at depth, LinkClear at
depth + lift distance, LinkNotClear at the clearance height), with FreeCAD's default operation
settings (tolerance 0.1, finishing profile, keep-tool-down ratio 3, helix angle 5°, lift 0)
except the step over, which is chosen by the caller.

Usage: freecad-adaptive.py CONTOURS.csv OUT.csv --diameter 10 --stepover 11.7
           --stock X0 Y0 X1 Y1 --top 60 [--tolerance 0.1]
LinkClear moves (FreeCAD: G0 at the layer's depth through cleared material) are written as feed
rows tagged `link` so that their engagement is simulated too; LinkNotClear as rapids.
Needs the Debian package freecad (area.so in /usr/lib/freecad-python3/lib).
"""
import argparse
import csv
import math
import sys
import time

sys.path.append("/usr/lib/freecad-python3/lib")
sys.path.append("/usr/lib/freecad/lib")
import FreeCAD  # noqa: E402,F401  (loads the libraries area.so links to)
import area  # noqa: E402

SAGITTA = 1e-3  # largest chord sagitta of arcs given to Adaptive2d (mm)


def read_contours(path):
    """Closed contours (list of [x, y] points, arcs flattened) and their z."""
    rows = [r for r in csv.DictReader(l for l in open(path) if not l.startswith("#"))]
    loops, cur, last, z, pid = [], [], None, None, None
    for r in rows:
        x, y = float(r["x"]), float(r["y"])
        z = float(r["z"])
        if r["move"] == "rapid" or r["path"] != pid:
            if cur:
                loops.append(cur)
            cur, last, pid = [[x, y]], (x, y), r["path"]
            continue
        if r["move"] in ("cw", "ccw"):
            cx, cy = float(r["xc"]), float(r["yc"])
            rad = math.hypot(last[0] - cx, last[1] - cy)
            a0 = math.atan2(last[1] - cy, last[0] - cx)
            a1 = math.atan2(y - cy, x - cx)
            sweep = a1 - a0
            if r["move"] == "ccw":
                while sweep <= 1e-12:
                    sweep += 2 * math.pi
            else:
                while sweep >= -1e-12:
                    sweep -= 2 * math.pi
            step = 2 * math.acos(max(-1.0, 1 - SAGITTA / rad))
            n = max(1, math.ceil(abs(sweep) / step))
            for k in range(1, n + 1):
                a = a0 + sweep * k / n
                cur.append([cx + rad * math.cos(a), cy + rad * math.sin(a)])
            cur[-1] = [x, y]
        else:
            cur.append([x, y])
        last = (x, y)
    if cur:
        loops.append(cur)
    return loops, z


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("contours")
    ap.add_argument("out")
    ap.add_argument("--diameter", type=float, required=True)
    ap.add_argument("--stepover", type=float, required=True, help="percent of the diameter")
    ap.add_argument("--stock", type=float, nargs=4, required=True)
    ap.add_argument("--top", type=float, required=True, help="z of the layer's top (the helix starts here)")
    ap.add_argument("--tolerance", type=float, default=0.1)
    ap.add_argument("--helix-angle", type=float, default=5.0)
    ap.add_argument("--clearance", type=float, default=5.0, help="clearance height above --top")
    a = ap.parse_args()
    loops, depth = read_contours(a.contours)
    x0, y0, x1, y1 = a.stock
    stock = [[[x0, y0], [x1, y0], [x1, y1], [x0, y1], [x0, y0]]]
    paths = [l + [l[0]] if l[0] != l[-1] else l for l in loops]

    a2d = area.Adaptive2d()
    a2d.stepOverFactor = 0.01 * a.stepover
    a2d.toolDiameter = a.diameter
    a2d.helixRampDiameter = 0.0
    a2d.keepToolDownDistRatio = 3.0
    a2d.stockToLeave = 0.0
    a2d.tolerance = a.tolerance
    a2d.forceInsideOut = False
    a2d.finishingProfile = True
    a2d.opType = area.AdaptiveOperationType.ClearingInside
    t0 = time.perf_counter()
    results = a2d.Execute(stock, paths, lambda tp: False)
    seconds = time.perf_counter() - t0

    clear_z = a.top + a.clearance
    out = [("path", "move", "x", "y", "z", "tag")]
    pid = 0
    cutting = link = 0.0
    for res in results:
        cx, cy = res.HelixCenterPoint
        sx, sy = res.StartPoint
        pid += 1
        helix_r = math.hypot(sx - cx, sy - cy)
        if helix_r > 0.01:
            # PathAdaptive.GenerateGCode, helix without arcs, cone angle 0.
            r = helix_r - 0.01
            per_circle = 2 * math.pi * helix_r * math.tan(math.radians(a.helix_angle))
            maxfi = (a.top - depth) / per_circle * 2 * math.pi
            off = -maxfi + math.atan2(sy - cy, sx - cx) - math.pi / 16
            hx, hy = cx + r * math.cos(off), cy + r * math.sin(off)
            out.append((pid, "rapid", hx, hy, clear_z, "entry"))
            out.append((pid, "line", hx, hy, a.top, "entry"))
            fi = 0.0
            while fi < maxfi:
                z = a.top - fi / maxfi * (a.top - depth)
                out.append((pid, "line", cx + r * math.cos(fi + off), cy + r * math.sin(fi + off), z, "entry"))
                fi += math.pi / 16
            maxfi += 2 * math.pi
            while fi < maxfi:
                out.append((pid, "line", cx + r * math.cos(fi + off), cy + r * math.sin(fi + off), depth, "circle"))
                fi += math.pi / 16
        else:
            out.append((pid, "rapid", sx, sy, clear_z, "entry"))
            out.append((pid, "line", sx, sy, depth, "entry"))
        last, lz = None, depth
        for kind, pts in res.AdaptivePaths:
            for x, y in pts:
                if kind == area.AdaptiveMotionType.Cutting:
                    if lz != depth:
                        out.append((pid, "line", last[0], last[1], depth, "plunge"))
                    if last is not None:
                        cutting += math.hypot(x - last[0], y - last[1])
                    out.append((pid, "line", x, y, depth, "cutting"))
                    lz = depth
                elif kind == area.AdaptiveMotionType.LinkClear:
                    if last is not None:
                        link += math.hypot(x - last[0], y - last[1])
                    out.append((pid, "line", x, y, depth, "link"))
                    lz = depth
                else:
                    if lz != clear_z:
                        pid += 1
                        out.append((pid, "rapid", last[0], last[1], clear_z, "air"))
                    out.append((pid, "rapid", x, y, clear_z, "air"))
                    lz = clear_z
                last = (x, y)
    with open(a.out, "w", newline="") as f:
        w = csv.writer(f)
        for r in out:
            w.writerow([r[0], r[1]] + [f"{v:.6f}" for v in r[2:5]] + [r[5]] if r[0] != "path" else r)
    print(
        f"freecad adaptive: regions {len(results)} rows {len(out) - 1} cutting_mm {cutting:.1f} link_mm {link:.1f} "
        f"seconds {seconds:.2f}"
    )


if __name__ == "__main__":
    main()
