#!/usr/bin/env python3
"""Fuzz `offset` with random star pockets of lines and arcs (round islands sometimes): every run
must give a verified result (exit 0) or refuse the input naming a crossing (exit 2). Anything
else (exit 1: no verified offset; a crash) is a defect and its input is kept as
$TMPDIR/fuzz-offset-defects/<family>-<seed>.csv (rerun it with the options the summary prints).

  scripts/fuzz-offset.py [SEEDS [FIRST]] [--spiky | --fine | --fillets | --far | --tiny | --open | --wiggle]
                                             (offset binary: $OFFSET or target/release/offset)

--spiky widens radii and bulges so that many stars fold across themselves (refusals expected).
--open offsets random walks of lines and arcs (open paths) on both sides, with and without
--allow-self-crossing (with it, every run must verify). --fine splits every piece into up to 30
shorter ones, the line pieces' joints moved off the line by up to 1e-4 mm (near-collinear runs). --fillets rounds every corner with a tangent arc (radius
0.2-3 mm), the tangency broken by up to 1e-6 rad at random joints. --far moves the star to
x = 1e5, y = -3e4 mm; --tiny scales the star and every radius and step by 1/100. --wiggle draws
a smooth closed curve r = 50 + a sin(m t + p) + b sin(M t + q) with 3 000-60 000 lines (issue 20,
D13), its tightest bends near the radii offset by (0.3-1 mm), both sides and a pocket's first levels.
"""
import math, os, random, shutil, subprocess, sys, tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fuzzkit import arc_centre, binary  # noqa: E402

def star_pieces(rnd, spiky):
    """The star's outer loop as pieces (a, b, centre or None, ccw)."""
    n = rnd.randint(5, 40)
    lo, hi, bmax = (12, 30, 0.4) if spiky else (22, 30, 0.15)
    pts = []
    for k in range(n):
        r, a = rnd.uniform(lo, hi), 2 * math.pi * k / n
        pts.append((50 + r * math.cos(a), 50 + r * math.sin(a)))
    pieces = []
    for k in range(n):
        a, b = pts[k], pts[(k + 1) % n]
        if rnd.random() < 0.4:
            bulge = rnd.choice([-1, 1]) * rnd.uniform(0.02, bmax)
            pieces.append((a, b, arc_centre(a, b, bulge), bulge > 0))
        else:
            pieces.append((a, b, None, True))
    return pieces

def finer(rnd, pieces):
    """Each piece split into up to 30, line joints moved off the line by up to 1e-4 mm."""
    out = []
    for a, b, c, ccw in pieces:
        k = rnd.randint(1, 30)
        if c is None:
            pts = [a]
            for j in range(1, k):
                t, off = j / k, rnd.uniform(-1e-4, 1e-4) * rnd.choice([0, 1e-3, 1])
                L = math.dist(a, b)
                nx, ny = -(b[1] - a[1]) / L, (b[0] - a[0]) / L
                pts.append((a[0] + t * (b[0] - a[0]) + off * nx, a[1] + t * (b[1] - a[1]) + off * ny))
            pts.append(b)
            out += [(p, q, None, True) for p, q in zip(pts, pts[1:])]
        else:
            r = math.dist(a, c)
            a0, a1 = math.atan2(a[1] - c[1], a[0] - c[0]), math.atan2(b[1] - c[1], b[0] - c[0])
            sweep = (a1 - a0) % (2 * math.pi) if ccw else -((a0 - a1) % (2 * math.pi))
            pts = [a] + [(c[0] + r * math.cos(a0 + sweep * j / k), c[1] + r * math.sin(a0 + sweep * j / k))
                         for j in range(1, k)] + [b]
            out += [(p, q, c, ccw) for p, q in zip(pts, pts[1:])]
    return out

def filleted(rnd, n_min=5):
    """A star polygon with every corner rounded by a tangent arc, tangency broken at random joints."""
    while True:
        n = rnd.randint(n_min, 30)
        pts = []
        for k in range(n):
            r, a = rnd.uniform(18, 30), 2 * math.pi * k / n
            pts.append((50 + r * math.cos(a), 50 + r * math.sin(a)))
        pieces, ok = [], True
        corners = []
        for k in range(n):
            p, v, q = pts[k - 1], pts[k], pts[(k + 1) % n]
            u1 = ((v[0] - p[0]) / math.dist(p, v), (v[1] - p[1]) / math.dist(p, v))
            u2 = ((q[0] - v[0]) / math.dist(v, q), (q[1] - v[1]) / math.dist(v, q))
            turn = math.atan2(u1[0] * u2[1] - u1[1] * u2[0], u1[0] * u2[0] + u1[1] * u2[1])
            rf = rnd.uniform(0.2, 3)
            t = rf * math.tan(abs(turn) / 2)
            if t > 0.45 * min(math.dist(p, v), math.dist(v, q)):
                ok = False
                break
            e1 = (v[0] - u1[0] * t, v[1] - u1[1] * t)
            e2 = (v[0] + u2[0] * t, v[1] + u2[1] * t)
            s = 1 if turn > 0 else -1
            c = (e1[0] - s * u1[1] * rf, e1[1] + s * u1[0] * rf)
            if rnd.random() < 0.3:  # break the tangency by up to 1e-6 rad about the corner
                w = rnd.uniform(-1e-6, 1e-6)
                c = (v[0] + (c[0] - v[0]) * math.cos(w) - (c[1] - v[1]) * math.sin(w),
                     v[1] + (c[0] - v[0]) * math.sin(w) + (c[1] - v[1]) * math.cos(w))
                r2 = math.dist(c, e1)
                e2 = (c[0] + (e2[0] - c[0]) * r2 / math.dist(c, e2), c[1] + (e2[1] - c[1]) * r2 / math.dist(c, e2))
            corners.append((e1, e2, c, turn > 0))
        if not ok:
            continue
        for k in range(n):
            e1, e2, c, ccw = corners[k]
            pieces.append((e1, e2, c, ccw))
            pieces.append((e2, corners[(k + 1) % n][0], None, True))
        return pieces

def walk(seed):
    """An open path: a random walk of 3-26 lines and arcs (bulges up to 0.9), often crossing itself."""
    rnd = random.Random(seed)
    pts, ang = [(0.0, 0.0)], 0.0
    for _ in range(rnd.randint(2, 25)):
        ang += rnd.uniform(-2.0, 2.0)
        step = rnd.uniform(0.5, 15)
        pts.append((pts[-1][0] + step * math.cos(ang), pts[-1][1] + step * math.sin(ang)))
    rows = ["path,move,x,y,z,xc,yc", f"0,rapid,{pts[0][0]!r},{pts[0][1]!r},0,,"]
    for a, b in zip(pts, pts[1:]):
        if rnd.random() < 0.4:
            bulge = rnd.choice([-1, 1]) * rnd.uniform(0.02, 0.9)
            c = arc_centre(a, b, bulge)
            rows.append(f"0,{'ccw' if bulge > 0 else 'cw'},{b[0]!r},{b[1]!r},0,{c[0]!r},{c[1]!r}")
        else:
            rows.append(f"0,line,{b[0]!r},{b[1]!r},0,,")
    return "\n".join(rows) + "\n"

def wiggle(seed):
    """A smooth closed curve of many short lines whose tightest bends come near the offset radii."""
    rnd = random.Random(seed)
    n, m, big_m = rnd.randint(3000, 60000), rnd.randint(3, 9), rnd.randint(40, 150)
    a, p, q = rnd.uniform(0, 6), rnd.uniform(0, 6.3), rnd.uniform(0, 6.3)
    # The ripple's own bend radius (50 / M)^2 / b spread over 0.25-1.5 mm.
    b = (50 / big_m) ** 2 / rnd.uniform(0.25, 1.5)
    rows = ["path,move,x,y,z"]
    for i in range(n + 1):
        t = 2 * math.pi * (i % n) / n
        r = 50 + a * math.sin(m * t + p) + b * math.sin(big_m * t + q)
        rows.append(f"0,{'rapid' if i == 0 else 'line'},{r * math.cos(t):.9f},{r * math.sin(t):.9f},0")
    return "\n".join(rows) + "\n"

def star(seed, family):
    rnd = random.Random(seed)
    pieces = filleted(rnd) if family == "fillets" else star_pieces(rnd, family == "spiky")
    if family == "fine":
        pieces = finer(rnd, pieces)
    islands = []
    for i in range(rnd.randint(0, 2)):
        islands.append((rnd.uniform(1, 4), 50 + rnd.uniform(-6, 6), 50 + rnd.uniform(-6, 6)))
    k, (dx, dy) = (0.01, (0, 0)) if family == "tiny" else (1, (1e5, -3e4) if family == "far" else (0, 0))
    def f(p):
        return f"{p[0] * k + dx:.9f},{p[1] * k + dy:.9f}"
    rows = ["path,move,x,y,z,xc,yc", f"0,rapid,{f(pieces[0][0])},0,,"]
    for a, b, c, ccw in pieces:
        rows.append(f"0,{'ccw' if ccw else 'cw'},{f(b)},0,{f(c)}" if c else f"0,line,{f(b)},0,,")
    for i, (r, cx, cy) in enumerate(islands):
        rows += [f"{i + 1},rapid,{f((cx + r, cy))},0,,", f"{i + 1},cw,{f((cx - r, cy))},0,{f((cx, cy))}",
                 f"{i + 1},cw,{f((cx + r, cy))},0,{f((cx, cy))}"]
    return "\n".join(rows) + "\n"

def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    seeds = int(args[0]) if args else 100
    first = int(args[1]) if len(args) > 1 else 1
    families = [f for f in ("spiky", "fine", "fillets", "far", "tiny", "open", "wiggle") if f"--{f}" in sys.argv]
    family = families[0] if families else "smooth"
    k = 0.01 if family == "tiny" else 1
    offset = binary("offset")
    g = lambda v: f"{v * k:g}"
    runs = [["--until-empty", "--radius", g(r), "--step", g(s)] for r in (0.7, 1.5, 3, 5) for s in (0.6, 1.9, 4)]
    runs += [["--side", side, "--radius", g(r)] for side in ("left", "right") for r in (0.5, 2, 6)]
    if family == "open":
        # Open paths: both sides, with and without accepting a crossing (then it must verify).
        runs = [["--side", side, "--radius", str(r), *extra]
                for side in ("left", "right") for r in (0.3, 2, 7) for extra in ([], ["--allow-self-crossing"])]
    if family == "wiggle":
        runs = [["--side", side, "--radius", str(r)] for side in ("left", "right") for r in (0.3, 0.5, 1)]
        runs += [["--radius", "0.5", "--step", "0.5", "--repeat", "2"]]
    counts, kept = {"ok": 0, "refused": 0, "defect": 0}, []
    keep = os.path.join(os.environ.get("TMPDIR", "/tmp"), "fuzz-offset-defects")
    with tempfile.TemporaryDirectory() as tmp:
        src, out = os.path.join(tmp, "star.csv"), os.path.join(tmp, "out.csv")
        for seed in range(first, first + seeds):
            with open(src, "w") as f:
                f.write(walk(seed) if family == "open" else wiggle(seed) if family == "wiggle" else star(seed, family))
            for run in runs:
                p = subprocess.run([offset, src, *run, "-o", out], capture_output=True, text=True)
                if p.returncode == 0:
                    counts["ok"] += 1
                elif p.returncode == 2 and "cross" in p.stderr and "--allow-self-crossing" not in run:
                    counts["refused"] += 1
                else:
                    counts["defect"] += 1
                    os.makedirs(keep, exist_ok=True)
                    saved = shutil.copy(src, os.path.join(keep, f"{family}-{seed}.csv"))
                    kept.append(f"seed {seed} {' '.join(run)} (input kept as {saved}): exit {p.returncode}: "
                                f"{p.stderr.strip()[:200]}")
    print(f"{seeds} stars ({family}), {sum(counts.values())} runs: {counts}")
    for k in kept[:20]:
        print(k)
    sys.exit(1 if kept else 0)

main()
