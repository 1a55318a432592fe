#!/usr/bin/env python3
"""OpenCAMLib's BatchDropCutter (PyPI `opencamlib`) on a grid, for stylus-trace --tool to be compared with.

  dropcutter-ocl.py stl PATH [N]             a free-form height field, 20 x 20 mm, N x N cells (binary STL)
  dropcutter-ocl.py drop STL X0,X1,Y0,Y1 PICK STEP OUT.csv
                                             tips of the four cutters (flat R3, ball R3, bull R3 r1, cone R3
                                             half-angle 0.6 rad) on the grid stylus-trace scans: lines
                                             y = Y0 + k*PICK, points evenly at most STEP apart from X0 to X1;
                                             one thread; writes cutter,x,y,z and prints the seconds per cutter.
  dropcutter-ocl.py at STL CUTTER IN.csv OUT.csv
                                             the tips of one of those cutters at the x,y of every row of
                                             IN.csv (stylus-trace's output), one thread; writes x,y,z and
                                             prints the cutter, the points and the seconds.
"""
import math
import struct
import sys
import time

CUTTERS = {
    "flat": lambda ocl: ocl.CylCutter(6.0, 50.0),
    "ball": lambda ocl: ocl.BallCutter(6.0, 50.0),
    "bull": lambda ocl: ocl.BullCutter(6.0, 1.0, 50.0),
    "cone": lambda ocl: ocl.ConeCutter(6.0, 0.6, 50.0),
}


def height(x, y):
    return 2.0 * math.sin(x / 3.0) * math.cos(y / 4.0) + 0.1 * x + 0.05 * x * y / 4.0


def make_stl(path, n):
    pts = [[(20.0 * i / n, 20.0 * j / n) for j in range(n + 1)] for i in range(n + 1)]
    tris = []
    for i in range(n):
        for j in range(n):
            a, b, c, d = pts[i][j], pts[i + 1][j], pts[i + 1][j + 1], pts[i][j + 1]
            p = lambda q: (q[0], q[1], height(*q))
            tris.append((p(a), p(b), p(c)))
            tris.append((p(a), p(c), p(d)))
    with open(path, "wb") as f:
        f.write(b"dropcut free-form height field".ljust(80, b" "))
        f.write(struct.pack("<I", len(tris)))
        for t in tris:
            f.write(struct.pack("<3f", 0.0, 0.0, 0.0))
            for q in t:
                f.write(struct.pack("<3f", *q))
            f.write(b"\0\0")
    print(f"{path}: {len(tris)} triangles")


def stations(s0, s1, step):
    n = max(1, math.ceil((s1 - s0) / step))
    return [s1 if k == n else s0 + (s1 - s0) * k / n for k in range(n + 1)]


def grid(region, pick, step):
    x0, x1, y0, y1 = region
    n = math.floor((y1 - y0) / pick + 1e-9)
    return [(x, y0 + k * pick) for k in range(n + 1) for x in stations(x0, x1, step)]


def batch(ocl, surf, name, points):
    """One cutter's BatchDropCutter over the points on one thread: its CL points and seconds."""
    bdc = ocl.BatchDropCutter()
    bdc.setSTL(surf)
    cutter = CUTTERS[name](ocl)  # held here: setCutter keeps only a pointer to it
    bdc.setCutter(cutter)
    bdc.setThreads(1)
    for x, y in points:
        bdc.appendPoint(ocl.CLPoint(x, y, -100.0))
    t0 = time.perf_counter()
    bdc.run()
    dt = time.perf_counter() - t0
    return bdc.getCLPoints(), dt


def drop(stl, region, pick, step, out):
    import opencamlib as ocl
    surf = ocl.STLSurf()
    ocl.STLReader(stl, surf)
    points = grid(region, pick, step)
    rows = []
    for name in CUTTERS:
        cl, dt = batch(ocl, surf, name, points)
        print(f"{name} {len(cl)} {dt:.6f}")
        rows += [(name, p.x, p.y, p.z) for p in cl]
    with open(out, "w") as f:
        f.write(f"# OpenCAMLib {ocl.version()} BatchDropCutter on {stl.split('/')[-1]}, one thread (scripts/dropcutter-ocl.py)\n")
        f.write("cutter,x,y,z\n")
        for name, x, y, z in rows:
            f.write(f"{name},{x!r},{y!r},{z!r}\n")


def drop_at(stl, name, points_csv, out):
    import csv

    import opencamlib as ocl
    surf = ocl.STLSurf()
    ocl.STLReader(stl, surf)
    points = [(float(r["x"]), float(r["y"])) for r in csv.DictReader(open(points_csv))]
    cl, dt = batch(ocl, surf, name, points)
    print(f"{name} {len(cl)} {dt:.6f}")
    with open(out, "w") as f:
        f.write("x,y,z\n")
        for p in cl:
            f.write(f"{p.x!r},{p.y!r},{p.z!r}\n")


if __name__ == "__main__":
    if sys.argv[1] == "stl":
        make_stl(sys.argv[2], int(sys.argv[3]) if len(sys.argv) > 3 else 16)
    elif sys.argv[1] == "drop":
        region = [float(v) for v in sys.argv[3].split(",")]
        drop(sys.argv[2], region, float(sys.argv[4]), float(sys.argv[5]), sys.argv[6])
    elif sys.argv[1] == "at":
        drop_at(sys.argv[2], sys.argv[3], sys.argv[4], sys.argv[5])
    else:
        sys.exit(__doc__)
