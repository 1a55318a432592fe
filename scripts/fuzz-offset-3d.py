#!/usr/bin/env python3
"""Fuzz `offset --3d` with random star polygons (4-30 vertices at radii 15-30 mm) on random tilted
planes, the tool axis on the plane's normal, R 0.5, 2 and 5 mm on both sides. Every run must exit
0, and every written point is checked independently of the filter: in the plane (1e-6 mm), at
distance R to R + 1 um (the chord tolerance) from the polygon in that plane, on the requested side.

  scripts/fuzz-offset-3d.py [SEEDS]      (offset binary: $OFFSET or target/release/offset)
"""
import csv, math, os, random, subprocess, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fuzzkit import binary, finish, inside, scratch, seg_dist  # noqa: E402

B = binary("offset")

def main():
    seeds = int(sys.argv[1]) if len(sys.argv) > 1 else 100
    src, out = scratch("fuzz3d")
    counts, bad, worst = {}, [], 0.0
    for seed in range(1, seeds + 1):
        rnd = random.Random(seed)
        n = rnd.randint(4, 30)
        poly = []
        for k in range(n):
            r, a = rnd.uniform(15, 30), 2 * math.pi * k / n
            poly.append((r * math.cos(a), r * math.sin(a)))
        # A frame: the normal up to 81° from z, e1 and e2 in the plane.
        th, ph = rnd.uniform(0, math.pi * 0.45), rnd.uniform(0, 2 * math.pi)
        nrm = (math.sin(th) * math.cos(ph), math.sin(th) * math.sin(ph), math.cos(th))
        e1 = (math.cos(th) * math.cos(ph), math.cos(th) * math.sin(ph), -math.sin(th))
        e2 = (nrm[1] * e1[2] - nrm[2] * e1[1], nrm[2] * e1[0] - nrm[0] * e1[2], nrm[0] * e1[1] - nrm[1] * e1[0])
        o = (rnd.uniform(-50, 50), rnd.uniform(-50, 50), rnd.uniform(-20, 20))
        rows = ["path,move,x,y,z,i,j,k"]
        for k, (u, v) in enumerate(poly + poly[:1]):
            x, y, z = (o[i] + u * e1[i] + v * e2[i] for i in range(3))
            rows.append(f"0,{'rapid' if k == 0 else 'line'},{x!r},{y!r},{z!r},{nrm[0]!r},{nrm[1]!r},{nrm[2]!r}")
        with open(src, "w") as f:
            f.write("\n".join(rows) + "\n")
        for side in ("left", "right"):
            for R in (0.5, 2, 5):
                p = subprocess.run([B, src, "--3d", "--radius", str(R), "--side", side, "-o", out],
                                   capture_output=True, text=True)
                counts[p.returncode] = counts.get(p.returncode, 0) + 1
                if p.returncode:
                    bad.append(f"seed {seed} {side} R {R}: {p.stderr.strip()[:200]}")
                    continue
                for r in csv.DictReader(open(out)):
                    q = (float(r["x"]) - o[0], float(r["y"]) - o[1], float(r["z"]) - o[2])
                    off = sum(q[i] * nrm[i] for i in range(3))
                    u, v = sum(q[i] * e1[i] for i in range(3)), sum(q[i] * e2[i] for i in range(3))
                    d = min(seg_dist((u, v), a, b) for a, b in zip(poly, poly[1:] + poly[:1]))
                    wrong = (side == "left") != inside((u, v), poly)  # counter-clockwise: left is inside
                    err = max(abs(off), R - d, d - R - 0.001, 0)
                    worst = max(worst, err)
                    if err > 1e-6 or wrong:
                        bad.append(f"seed {seed} {side} R {R}: ({u:.4f}, {v:.4f}) at {d}, {off:.2e} off the plane, "
                                   f"wrong side {wrong}")
                        break
    finish((src, out), f"{seeds} stars, exit statuses {counts}, largest deviation {worst:.2e} mm", bad)

main()
