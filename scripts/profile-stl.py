#!/usr/bin/env python3
"""A profile in the XZ plane as a solid, for the collision check of a profile job (make demo-sine).

    scripts/profile-stl.py PROFILE.csv OUT.stl [--width MM] [--bottom Z] [--sagitta MM]

PROFILE.csv is a toolpath table of one pass in the XZ plane, x increasing: `line` rows and `cw`/`ccw`
arcs with centres `xc, zc` and `plane` xz (camkit's convention: counter-clockwise in (z, x), G3 of
G18). The solid is the material under the profile down to z = BOTTOM, extruded across y from -WIDTH
to +WIDTH: a closed surface with outward normals, the arcs drawn by chords whose sagitta is at most
SAGITTA (default 1e-4 mm: the solid lies within that of the true profile). Python 3 standard library
only.
"""
import argparse
import csv
import math
import struct


def profile_points(path, sagitta):
    rows = list(csv.DictReader(open(path)))
    pts = []
    for r in rows:
        x, z = float(r["x"]), float(r["z"])
        move = (r.get("move") or "line").strip()
        if move in ("cw", "ccw") and pts:
            if (r.get("plane") or "xy").strip() != "xz":
                raise SystemExit(f"{path}: an arc outside the xz plane")
            xc, zc = float(r["xc"]), float(r["zc"])
            x0, z0 = pts[-1]
            # (u, v) = (z, x): counter-clockwise in (u, v) is ccw.
            a0 = math.atan2(x0 - xc, z0 - zc)
            a1 = math.atan2(x - xc, z - zc)
            radius = math.hypot(x0 - xc, z0 - zc)
            sweep = a1 - a0
            if move == "ccw" and sweep <= 0:
                sweep += 2 * math.pi
            if move == "cw" and sweep >= 0:
                sweep -= 2 * math.pi
            step = 2 * math.acos(max(-1.0, 1 - sagitta / radius)) if radius > sagitta else math.pi
            n = max(1, math.ceil(abs(sweep) / step))
            for k in range(1, n):
                a = a0 + sweep * k / n
                pts.append((xc + radius * math.sin(a), zc + radius * math.cos(a)))
        pts.append((x, z))
    for (xa, _), (xb, _) in zip(pts, pts[1:]):
        if not xb > xa:
            raise SystemExit(f"{path}: the profile must run with x increasing")
    return pts


def solid(pts, width, bottom):
    T = lambda i, s: (pts[i][0], s * width, pts[i][1])
    B = lambda i, s: (pts[i][0], s * width, bottom)
    tris = []
    n = len(pts)
    for i in range(n - 1):
        tris += [(T(i, -1), T(i + 1, -1), T(i + 1, 1)), (T(i, -1), T(i + 1, 1), T(i, 1))]  # top
        tris += [(T(i, -1), B(i, -1), B(i + 1, -1)), (T(i, -1), B(i + 1, -1), T(i + 1, -1))]  # y = -w
        tris += [(T(i, 1), T(i + 1, 1), B(i + 1, 1)), (T(i, 1), B(i + 1, 1), B(i, 1))]  # y = +w
        tris += [(B(i, -1), B(i, 1), B(i + 1, 1)), (B(i, -1), B(i + 1, 1), B(i + 1, -1))]  # bottom
    tris += [(T(0, -1), T(0, 1), B(0, 1)), (T(0, -1), B(0, 1), B(0, -1))]  # x = first
    m = n - 1
    tris += [(T(m, -1), B(m, -1), B(m, 1)), (T(m, -1), B(m, 1), T(m, 1))]  # x = last
    return tris


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("profile")
    ap.add_argument("out")
    ap.add_argument("--width", type=float, default=5.0)
    ap.add_argument("--bottom", type=float, default=-20.0)
    ap.add_argument("--sagitta", type=float, default=1e-4)
    a = ap.parse_args()
    pts = profile_points(a.profile, a.sagitta)
    if min(z for _, z in pts) <= a.bottom:
        raise SystemExit("--bottom must be below the profile")
    tris = solid(pts, a.width, a.bottom)
    with open(a.out, "wb") as f:
        f.write(b"profile extruded across y (scripts/profile-stl.py)".ljust(80, b" "))
        f.write(struct.pack("<I", len(tris)))
        for t in tris:
            (ax, ay, az), (bx, by, bz), (cx, cy, cz) = t
            u, v = (bx - ax, by - ay, bz - az), (cx - ax, cy - ay, cz - az)
            nrm = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
            length = math.sqrt(sum(c * c for c in nrm)) or 1.0
            f.write(struct.pack("<3f", *(c / length for c in nrm)))
            for p in t:
                f.write(struct.pack("<3f", *p))
            f.write(b"\0\0")


if __name__ == "__main__":
    main()
