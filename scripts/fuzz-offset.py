#!/usr/bin/env python3
"""Fuzz `offset` with random star pockets of lines and arcs (round islands sometimes): every run
must give a verified result (exit 0) or refuse the input naming a crossing (exit 2). Anything
else (exit 1: no verified offset; a crash) is a defect and its input is kept.

  scripts/fuzz-offset.py [SEEDS] [--spiky]    (offset binary: $OFFSET or target/release/offset)

--spiky widens radii and bulges so that many stars fold across themselves (refusals expected).
"""
import math, os, random, subprocess, sys, tempfile

def star(seed, spiky):
    rnd = random.Random(seed)
    n = rnd.randint(5, 40)
    lo, hi, bmax = (12, 30, 0.4) if spiky else (22, 30, 0.15)
    pts = []
    for k in range(n):
        r, a = rnd.uniform(lo, hi), 2 * math.pi * k / n
        pts.append((50 + r * math.cos(a), 50 + r * math.sin(a)))
    rows = ["path,move,x,y,z,xc,yc", f"0,rapid,{pts[0][0]:.6f},{pts[0][1]:.6f},0,,"]
    for k in range(n):
        a, b = pts[k], pts[(k + 1) % n]
        if rnd.random() < 0.4:
            bulge = rnd.choice([-1, 1]) * rnd.uniform(0.02, bmax)
            c = math.dist(a, b)
            theta = 4 * math.atan(abs(bulge))
            h = math.sqrt(max((c / (2 * math.sin(theta / 2))) ** 2 - c * c / 4, 0))
            s = 1 if bulge > 0 else -1  # a minor ccw arc has its centre on the chord's left
            ox = (a[0] + b[0]) / 2 - s * (b[1] - a[1]) / c * h
            oy = (a[1] + b[1]) / 2 + s * (b[0] - a[0]) / c * h
            rows.append(f"0,{'ccw' if bulge > 0 else 'cw'},{b[0]:.6f},{b[1]:.6f},0,{ox:.9f},{oy:.9f}")
        else:
            rows.append(f"0,line,{b[0]:.6f},{b[1]:.6f},0,,")
    for i in range(rnd.randint(0, 2)):
        r, cx, cy = rnd.uniform(1, 4), 50 + rnd.uniform(-6, 6), 50 + rnd.uniform(-6, 6)
        rows += [f"{i + 1},rapid,{cx + r:.6f},{cy:.6f},0,,", f"{i + 1},cw,{cx - r:.6f},{cy:.6f},0,{cx:.6f},{cy:.6f}",
                 f"{i + 1},cw,{cx + r:.6f},{cy:.6f},0,{cx:.6f},{cy:.6f}"]
    return "\n".join(rows) + "\n"

def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    seeds, spiky = int(args[0]) if args else 100, "--spiky" in sys.argv
    binary = os.environ.get("OFFSET", os.path.join(os.environ.get("CARGO_TARGET_DIR", "target"), "release", "offset"))
    runs = [["--until-empty", "--radius", r, "--step", s] for r in ("0.7", "1.5", "3", "5") for s in ("0.6", "1.9", "4")]
    runs += [["--side", side, "--radius", r] for side in ("left", "right") for r in ("0.5", "2", "6")]
    counts, kept = {"ok": 0, "refused": 0, "defect": 0}, []
    with tempfile.TemporaryDirectory() as tmp:
        src, out = os.path.join(tmp, "star.csv"), os.path.join(tmp, "out.csv")
        for seed in range(1, seeds + 1):
            with open(src, "w") as f:
                f.write(star(seed, spiky))
            for run in runs:
                p = subprocess.run([binary, src, *run, "-o", out], capture_output=True, text=True)
                if p.returncode == 0:
                    counts["ok"] += 1
                elif p.returncode == 2 and "cross" in p.stderr:
                    counts["refused"] += 1
                else:
                    counts["defect"] += 1
                    kept.append(f"seed {seed} {' '.join(run)}: exit {p.returncode}: {p.stderr.strip()[:200]}")
    print(f"{seeds} stars ({'spiky' if spiky else 'smooth'}), {sum(counts.values())} runs: {counts}")
    for k in kept[:20]:
        print(k)
    sys.exit(1 if kept else 0)

main()
