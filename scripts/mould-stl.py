#!/usr/bin/env python3
"""A mould for the 3-axis demo part (make demo-mould-3axis), as a binary STL.

    scripts/mould-stl.py OUT.stl [--step MM]

The solid: the block 0 <= x <= 120, 0 <= y <= 80, 0 <= z <= 40 with two cavities sunk into its top
(z = 40), each exactly described so that tests can compare with closed forms:

  - a spherical dish: the sphere of radius 40 centred at (40, 40, 68), 12 mm deep at (40, 40),
    its rim the circle of radius sqrt(40^2 - 28^2) = 28.566 about (40, 40) at z = 40;
  - a half-pipe with round ends: every point within 10 mm of the segment from (95, 20, 40) to
    (95, 60, 40), below z = 40 (a trough 10 deep and 20 wide along y, ended by quarter spheres).

The top is the height field z(x, y) = min(40, dish, trough) on a square grid of STEP mm (default
0.4: 300 x 200 cells, 120 000 triangles), the sides are strips on the same boundary vertices, the
bottom a fan: a closed surface with outward normals. A ball end mill of radius 3 reaches every
point of both cavities (their concave radii are 40 and 10); the rims are sharp. Python 3 standard
library only; the output is the same for the same arguments.
"""
import argparse
import math
import struct

X, Y, TOP = 120.0, 80.0, 40.0
DISH_C, DISH_R, DISH_DEPTH = (40.0, 40.0), 40.0, 12.0
PIPE_A, PIPE_B, PIPE_R = (95.0, 20.0), (95.0, 60.0), 10.0


def height(x, y):
    """The top of the solid at (x, y)."""
    z = TOP
    r2 = (x - DISH_C[0]) ** 2 + (y - DISH_C[1]) ** 2
    centre_z = TOP - DISH_DEPTH + DISH_R
    if r2 < DISH_R ** 2:
        z = min(z, centre_z - math.sqrt(DISH_R ** 2 - r2))
    # Distance from (x, y) to the pipe's axis segment (in plan: the axis lies at z = TOP).
    ax, ay = PIPE_A
    bx, by = PIPE_B
    dx, dy = bx - ax, by - ay
    t = max(0.0, min(1.0, ((x - ax) * dx + (y - ay) * dy) / (dx * dx + dy * dy)))
    d2 = (x - ax - t * dx) ** 2 + (y - ay - t * dy) ** 2
    if d2 < PIPE_R ** 2:
        z = min(z, TOP - math.sqrt(PIPE_R ** 2 - d2))
    return z


def triangles(step):
    nx, ny = round(X / step), round(Y / step)
    xs = [X * i / nx for i in range(nx + 1)]
    ys = [Y * j / ny for j in range(ny + 1)]
    top = [[height(x, y) for y in ys] for x in xs]
    p = lambda i, j: (xs[i], ys[j], top[i][j])
    out = []
    for i in range(nx):
        for j in range(ny):
            a, b, c, d = p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)
            out.append((a, b, c))  # counter-clockwise seen from above: normal up
            out.append((a, c, d))
    # The boundary of the top (all at z = TOP), counter-clockwise seen from above.
    ring = [(i, 0) for i in range(nx)] + [(nx, j) for j in range(ny)]
    ring += [(i, ny) for i in range(nx, 0, -1)] + [(0, j) for j in range(ny, 0, -1)]
    edge = [p(i, j) for i, j in ring]
    low = [(x, y, 0.0) for x, y, _ in edge]
    n = len(edge)
    for k in range(n):
        a, b = edge[k], edge[(k + 1) % n]
        a0, b0 = low[k], low[(k + 1) % n]
        out.append((a0, b0, b))  # outward: the ring runs counter-clockwise
        out.append((a0, b, a))
    centre = (X / 2, Y / 2, 0.0)
    for k in range(n):
        out.append((centre, low[(k + 1) % n], low[k]))  # normal down
    return out


def normal(t):
    (ax, ay, az), (bx, by, bz), (cx, cy, cz) = t
    ux, uy, uz = bx - ax, by - ay, bz - az
    vx, vy, vz = cx - ax, cy - ay, cz - az
    n = (uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx)
    length = math.sqrt(sum(c * c for c in n)) or 1.0
    return tuple(c / length for c in n)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--step", type=float, default=0.4)
    args = ap.parse_args()
    tris = triangles(args.step)
    with open(args.out, "wb") as f:
        header = b"mould: block 120x80x40, spherical dish R40 12 deep, half-pipe R10 (scripts/mould-stl.py)"
        f.write(header.ljust(80, b" ")[:80])
        f.write(struct.pack("<I", len(tris)))
        for t in tris:
            f.write(struct.pack("<3f", *normal(t)))
            for v in t:
                f.write(struct.pack("<3f", *v))
            f.write(b"\0\0")


if __name__ == "__main__":
    main()
