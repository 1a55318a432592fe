#!/usr/bin/env python3
"""Fuzz `offset --profile` with random profiles of lines and arcs running left to right (0-60 mm,
heights -8..8), cut by ball and square end mills of radius 0.3, 1.5, 4 and 12 mm. Every run must
exit 0, and every tip path is checked independently of the filter (9 points a piece):
  square: the tip height at x is the profile's highest point over [x - R, x + R], found exactly
          from the window's ends, the vertices and the arcs' tops inside it;
  ball:   the ball's centre (x, tip + R) is exactly R from the profile (exact point-line and
          point-arc distances).
Deviations over 1e-6 mm are defects.

  scripts/fuzz-profile.py [SEEDS]        (offset binary: $OFFSET or target/release/offset)
"""
import csv, io, math, os, random, subprocess, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fuzzkit import arc_centre, binary, finish, scratch, seg_dist  # noqa: E402

B = binary("offset")

def arc_params(a, b, c, ccw):
    """Radius, start angle and signed sweep of the arc from a to b about c."""
    r = math.dist(a, c)
    a0, a1 = math.atan2(a[1] - c[1], a[0] - c[0]), math.atan2(b[1] - c[1], b[0] - c[0])
    sw = (a1 - a0) % (2 * math.pi) if ccw else -((a0 - a1) % (2 * math.pi))
    return r, a0, sw

def progress(a0, sw, phi):
    """Angle the arc turns from its start to direction phi."""
    return ((phi - a0) % (2 * math.pi)) if sw > 0 else ((a0 - phi) % (2 * math.pi))

def spans(a0, sw, phi):
    return progress(a0, sw, phi) <= abs(sw)

def monotone(a, b, c, ccw):
    """True if the arc runs left to right: no vertical tangent (direction 0 or pi) inside it."""
    _, a0, sw = arc_params(a, b, c, ccw)
    return not any(1e-9 < progress(a0, sw, phi) < abs(sw) - 1e-9 for phi in (0, math.pi))

def height(pieces, u):
    """The profile's height at u."""
    for a, b, c, ccw in pieces:
        if a[0] - 1e-12 <= u <= b[0] + 1e-12:
            if c is None:
                t = (u - a[0]) / (b[0] - a[0])
                return a[1] + t * (b[1] - a[1])
            r, a0, sw = arc_params(a, b, c, ccw)
            dy = math.sqrt(max(r * r - (u - c[0]) ** 2, 0))
            # Upper or lower half of the circle: the arc's middle decides.
            mid = c[1] + r * math.sin(a0 + sw / 2)
            return c[1] + dy if mid >= c[1] else c[1] - dy
    return None

def square_tip(pieces, x, R):
    """Highest profile point over [x - R, x + R]."""
    cands = [x - R, x + R]
    for a, b, c, ccw in pieces:
        cands += [a[0], b[0]]
        if c is not None:
            r, a0, sw = arc_params(a, b, c, ccw)
            if spans(a0, sw, math.pi / 2):
                cands.append(c[0])
    x0, x1 = pieces[0][0][0], pieces[-1][1][0]
    hs = [height(pieces, u) for u in cands if x - R - 1e-12 <= u <= x + R + 1e-12 and x0 <= u <= x1]
    return max(h for h in hs if h is not None)

def dist_piece(p, a, b, c, ccw):
    """Distance from p to a line (c None) or arc piece."""
    if c is None:
        return seg_dist(p, a, b)
    r, a0, sw = arc_params(a, b, c, ccw)
    phi = math.atan2(p[1] - c[1], p[0] - c[0])
    if spans(a0, sw, phi):
        return abs(math.dist(p, c) - r)
    return min(math.dist(p, a), math.dist(p, b))

def tip_points(text):
    """Nine points along each piece of the written tip path."""
    rows = list(csv.DictReader(io.StringIO(text)))
    pts, prev = [], None
    for r in rows:
        q = (float(r["x"]), float(r["y"]))
        if prev is not None and r["move"] != "rapid":
            if r["move"] == "line":
                pts += [(prev[0] + (q[0] - prev[0]) * k / 8, prev[1] + (q[1] - prev[1]) * k / 8) for k in range(9)]
            else:
                c = (float(r["xc"]), float(r["yc"]))
                rr, a0, sw = arc_params(prev, q, c, r["move"] == "ccw")
                pts += [(c[0] + rr * math.cos(a0 + sw * k / 8), c[1] + rr * math.sin(a0 + sw * k / 8)) for k in range(9)]
        prev = q
    return pts

counts, bad, worst = {}, [], {"ball": 0.0, "square": 0.0}
seeds = int(sys.argv[1]) if len(sys.argv) > 1 else 100
src, out = scratch("fuzz-profile")
for seed in range(1, seeds + 1):
    rnd = random.Random(seed)
    n = rnd.randint(2, 30)
    xs = sorted(rnd.uniform(0, 60) for _ in range(n - 1))
    pts = [(x, rnd.uniform(-8, 8) if rnd.random() < 0.7 else 0.0) for x in [0.0] + xs + [60.0]]
    pieces = []
    for a, b in zip(pts, pts[1:]):
        if b[0] - a[0] < 1e-3:
            continue
        a = pieces[-1][1] if pieces else a
        if rnd.random() < 0.4:
            bulge = rnd.choice([-1, 1]) * rnd.uniform(0.02, 0.4)
            c = arc_centre(a, b, bulge)
            if monotone(a, b, c, bulge > 0):
                pieces.append((a, b, c, bulge > 0))
                continue
        pieces.append((a, b, None, True))
    rows = ["path,move,x,y,xc,yc", f"0,rapid,{pieces[0][0][0]!r},{pieces[0][0][1]!r},,"]
    for a, b, c, ccw in pieces:
        rows.append(f"0,{'ccw' if ccw else 'cw'},{b[0]!r},{b[1]!r},{c[0]!r},{c[1]!r}" if c else f"0,line,{b[0]!r},{b[1]!r},,")
    open(src, "w").write("\n".join(rows) + "\n")
    for tool in ("ball", "square"):
        for R in (0.3, 1.5, 4, 12):
            p = subprocess.run([B, src, "--profile", tool, "--up", "y", "--radius", str(R), "-o", out], capture_output=True, text=True)
            counts[p.returncode] = counts.get(p.returncode, 0) + 1
            if p.returncode:
                bad.append(f"seed {seed} {tool} {R}: {p.returncode} {p.stderr.strip()[:250]}")
                continue
            for q in tip_points(open(out).read()):
                if tool == "square":
                    err = abs(q[1] - square_tip(pieces, q[0], R))
                else:
                    centre = (q[0], q[1] + R)
                    err = abs(min(dist_piece(centre, *pc) for pc in pieces) - R)
                worst[tool] = max(worst[tool], err)
                if err > 1e-6:
                    bad.append(f"seed {seed} {tool} {R}: tip at {q} off by {err:.3g}")
                    break
finish((src, out), f"{seeds} profiles, exit statuses {counts}, largest deviation "
       + ", ".join(f"{k} {v:.2e} mm" for k, v in worst.items()), bad)
