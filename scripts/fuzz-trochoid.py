#!/usr/bin/env python3
"""Fuzz `medial-trochoid` with random pockets: every run must exit 0 with a program that is checked
here, independently of the filter, or exit 2 with one stderr line naming the file and line (bad
input: islands crossing, a tool too large). Anything else (exit 1, a panic, a report without
threshold_held, more than one stderr line on refusal, a failed check below) is a defect and the
pocket is kept in --keep DIR (default /tmp/fuzz-trochoid-kept).

  scripts/fuzz-trochoid.py [SEEDS] [--family star|rect|slot|sharp|all] [--first N] [--jobs J] [--keep DIR]
                          [--minutes M]   (no pocket is started after M minutes; the summary covers those run)
                          [--radii 2,3,5] (the tool radii each pocket runs at)
                          [--strategy adaptive] (every run with this --strategy)
                          [--thresholds 40,30] (the thresholds a run picks from at random)
                                  (binary: $TROCHOID or $CARGO_TARGET_DIR/release/medial-trochoid)

Families: star (stars of lines and arcs, radii 15-24 mm, 0-2 round islands), rect (unions of grid cells, x-monotone,
some with a rectangular island), slot (thin L and U slots, straight or round ends, width 2R x
0.9-1.4 for an R of the runs), sharp (polygons with spikes of 4-25 degree inside corners).
Settings: R 2, 3, 5 or --radii (each pocket runs every R once with a random threshold 40/30 (or --thresholds), step default or
0.6 R, allowance 0 or 0.3) and one run with --layers 2 --layer-depth 5.
Checks of each exit-0 run (the written rows, every layer): the tool centre of every row (and the
middle of every arc row) at least R + allowance - 1e-6 from the input walls (exact point-segment and
point-arc distances, islands included) and inside the pocket; the report's largest_engagement_deg
<= threshold + 1e-5, threshold_held true, no_gouge true; the engagement column <= threshold + 1e-5
on trochoid and contour rows; every straight move (from the row before) R + allowance - 1e-6 or
more from the walls along its whole length (links across the pocket included); every uncut
stretch's from/to on the loop it names (1e-6 mm) and 0 <= uncut_area_mm2 < the pocket's area; and
`--analyse` of the written program gives the report's figures of it exactly (engagement of cuts,
links and entries, samples over the threshold, clearance, no_gouge, threshold_held); with
--strategy adaptive also `--analyse --sample 0.125` (a quarter of the default step) finds nothing
over the threshold.
"""
import csv, json, math, os, random, re, shutil, subprocess, sys, tempfile, time
from concurrent.futures import ThreadPoolExecutor

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fuzzkit import arc_centre, binary, inside, seg_dist  # noqa: E402

BIN = os.environ.get("TROCHOID", binary("medial-trochoid"))
# The finer referee's sample step for --strategy adaptive (mm): a quarter of the default 0.5.
FINE_SAMPLE = 0.125
CLEAR_TOL, ENG_TOL, ON_LOOP_TOL = 1e-6, 1e-5, 1e-6
STRATEGY = sys.argv[sys.argv.index("--strategy") + 1] if "--strategy" in sys.argv else None
THRESHOLDS = [float(t) for t in sys.argv[sys.argv.index("--thresholds") + 1].split(",")] if "--thresholds" in sys.argv else [40, 30]


# ---------------------------------------------------------------- geometry of the input loops
# A loop is a list of pieces (a, b, centre or None, ccw).

def sweep_of(a, b, c, ccw):
    a0, a1 = math.atan2(a[1] - c[1], a[0] - c[0]), math.atan2(b[1] - c[1], b[0] - c[0])
    return a0, ((a1 - a0) % (2 * math.pi) if ccw else -((a0 - a1) % (2 * math.pi)))


def arc_dist(p, a, b, c, ccw):
    """Exact distance from p to the arc a -> b about c."""
    r = math.dist(a, c)
    a0, sw = sweep_of(a, b, c, ccw)
    if math.dist(p, c) > 0:
        ang = math.atan2(p[1] - c[1], p[0] - c[0])
        rel = (ang - a0) % (2 * math.pi) if sw > 0 else (a0 - ang) % (2 * math.pi)
        if rel <= abs(sw):
            return abs(math.dist(p, c) - r)
    return min(math.dist(p, a), math.dist(p, b))


def piece_dist(p, piece):
    a, b, c, ccw = piece
    return seg_dist(p, a, b) if c is None else arc_dist(p, a, b, c, ccw)


def move_dist(p, q, piece):
    """Distance from the straight move p -> q to a wall piece: exact for a line (segments that
    do not cross are nearest at an end of one), the move sampled every 0.05 mm for an arc."""
    a, b, c, _ = piece
    if c is None:
        cross = lambda u, v, w: (v[0] - u[0]) * (w[1] - u[1]) - (v[1] - u[1]) * (w[0] - u[0])
        if cross(p, q, a) * cross(p, q, b) < 0 and cross(a, b, p) * cross(a, b, q) < 0:
            return 0.0
        return min(seg_dist(p, a, b), seg_dist(q, a, b), seg_dist(a, p, q), seg_dist(b, p, q))
    n = max(1, int(math.ceil(math.dist(p, q) / 0.05)))
    return min(piece_dist((p[0] + (q[0] - p[0]) * k / n, p[1] + (q[1] - p[1]) * k / n), piece) for k in range(n + 1))


def flatten(loop, sag=1e-3):
    """The loop as a polygon (arcs within `sag`): only for inside tests of points far from it."""
    pts = []
    for a, b, c, ccw in loop:
        pts.append(a)
        if c is not None:
            r = math.dist(a, c)
            a0, sw = sweep_of(a, b, c, ccw)
            n = max(2, int(abs(sw) / (2 * math.acos(max(-1, 1 - sag / r)))) + 1)
            pts += [(c[0] + r * math.cos(a0 + sw * k / n), c[1] + r * math.sin(a0 + sw * k / n)) for k in range(1, n)]
    return pts


def loop_area(loop):
    """Signed area with arcs exact (shoelace of the chords plus each arc's segment)."""
    s = 0.0
    for a, b, c, ccw in loop:
        s += (a[0] * b[1] - b[0] * a[1]) / 2
        if c is not None:
            r = math.dist(a, c)
            _, sw = sweep_of(a, b, c, ccw)
            s += r * r / 2 * (sw - math.sin(sw))
    return s


def circle(r, cx, cy):
    return [((cx + r, cy), (cx - r, cy), (cx, cy), False), ((cx - r, cy), (cx + r, cy), (cx, cy), False)]


def polygon(pts):
    return [(a, b, None, True) for a, b in zip(pts, pts[1:] + pts[:1])]


def transform(loops, rnd):
    """Rotate by a random angle about (50, 50); arcs' sense kept."""
    t = rnd.uniform(0, 2 * math.pi)
    co, si = math.cos(t), math.sin(t)
    f = lambda p: (50 + (p[0] - 50) * co - (p[1] - 50) * si, 50 + (p[0] - 50) * si + (p[1] - 50) * co)
    return [[(f(a), f(b), f(c) if c else None, ccw) for a, b, c, ccw in lp] for lp in loops]


# ---------------------------------------------------------------- families

def star(rnd):
    n = rnd.randint(5, 30)
    pts = [(50 + rnd.uniform(15, 24) * math.cos(2 * math.pi * k / n), 50 + rnd.uniform(15, 24) * math.sin(2 * math.pi * k / n))
           for k in range(n)]
    outer = []
    for a, b in zip(pts, pts[1:] + pts[:1]):
        if rnd.random() < 0.4:
            bulge = rnd.choice([-1, 1]) * rnd.uniform(0.02, 0.15)
            outer.append((a, b, arc_centre(a, b, bulge), bulge > 0))
        else:
            outer.append((a, b, None, True))
    loops = [outer]
    for _ in range(rnd.randint(0, 2)):
        loops.append(circle(rnd.uniform(1, 3), 50 + rnd.uniform(-6, 6), 50 + rnd.uniform(-6, 6)))
    return loops


def rect(rnd):
    """An x-monotone union of grid cells: column i spans [lo_i, hi_i) cells, adjacent columns overlap."""
    cell = rnd.choice([4, 5, 6, 8])
    n = rnd.randint(3, 9)
    lo, hi = [], []
    for i in range(n):
        while True:
            a, b = rnd.randint(0, 6), rnd.randint(2, 10)
            if b - a >= 2 and (i == 0 or (a < hi[-1] - 1 and b > lo[-1] + 1)):
                break
        lo.append(a)
        hi.append(b)
    pts = []
    for i in range(n):  # the bottom, left to right
        pts += [(i * cell, lo[i] * cell), ((i + 1) * cell, lo[i] * cell)]
    for i in reversed(range(n)):  # the top, right to left
        pts += [((i + 1) * cell, hi[i] * cell), (i * cell, hi[i] * cell)]
    clean = []
    for p in pts:  # drop repeated and collinear points
        if clean and p == clean[-1]:
            continue
        clean.append(p)
    if clean[0] == clean[-1]:
        clean.pop()
    k = 0
    while k < len(clean) and len(clean) > 3:
        a, b, c = clean[k - 1], clean[k], clean[(k + 1) % len(clean)]
        if (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0]) == 0:
            clean.pop(k)
            k = 0
        else:
            k += 1
    loops = [polygon(clean)]
    if rnd.random() < 0.5:  # a rectangular island over columns i0..i1 clear of the walls by 1 cell
        for _ in range(20):
            i0 = rnd.randint(1, n - 2) if n > 2 else 0
            i1 = rnd.randint(i0, min(n - 2, i0 + 2))
            b, t = max(lo[i0 - 1:i1 + 2]) + 1, min(hi[i0 - 1:i1 + 2]) - 1
            if t > b and i0 >= 1:
                y0, y1 = b * cell + rnd.uniform(0, cell / 2), t * cell - rnd.uniform(0, cell / 2)
                x0, x1 = i0 * cell + rnd.uniform(0, cell / 2), (i1 + 1) * cell - rnd.uniform(0, cell / 2)
                if y1 - y0 > 1 and x1 - x0 > 1:
                    loops.append(polygon([(x0, y0), (x0, y1), (x1, y1), (x1, y0)]))
                    break
    loops = [[((a[0] + 20, a[1] + 20), (b[0] + 20, b[1] + 20), c, ccw) for a, b, c, ccw in lp] for lp in loops]
    return transform(loops, rnd) if rnd.random() < 0.5 else loops


def slot(rnd):
    """A thin L or U slot of width near 2R for one of the runs' radii, straight or round ends."""
    R = rnd.choice([2, 3, 5])
    h = R * rnd.uniform(0.9, 1.4)
    A, B = rnd.uniform(20, 45), rnd.uniform(4 * h + 2, 40)
    x0, y0 = 30, 30
    if rnd.random() < 0.5:  # L: legs along x then y
        pts = [(x0, y0 - h), (x0 + A + h, y0 - h), (x0 + A + h, y0 + B), (x0 + A - h, y0 + B), (x0 + A - h, y0 + h),
               (x0, y0 + h)]
        ends = [(2, (x0 + A, y0 + B)), (5, (x0, y0))]  # (index of the end edge, its centre)
    else:  # U: legs along x, y, back along -x
        pts = [(x0, y0 - h), (x0 + A + h, y0 - h), (x0 + A + h, y0 + B + h), (x0, y0 + B + h), (x0, y0 + B - h),
               (x0 + A - h, y0 + B - h), (x0 + A - h, y0 + h), (x0, y0 + h)]
        ends = [(3, (x0, y0 + B)), (7, (x0, y0))]
    loop = polygon(pts)
    if rnd.random() < 0.5:  # round ends: the end edges become half circles bulging outward
        for i, c in ends:
            a, b, _, _ = loop[i]
            loop[i] = (a, b, c, True)  # ccw outer loop: the cap turns left about the end's centre
    return transform([loop], rnd)


def sharp(rnd):
    """A round-ish polygon with 1-4 spikes whose tips are inside corners of 4-25 degrees."""
    n = rnd.randint(8, 24)
    base = [(50 + rnd.uniform(15, 22) * math.cos(2 * math.pi * k / n), 50 + rnd.uniform(15, 22) * math.sin(2 * math.pi * k / n))
            for k in range(n)]
    spikes = rnd.sample(range(n), rnd.randint(1, min(4, n // 3)))
    pts = []
    for k in range(n):
        pts.append(base[k])
        if k in spikes:  # a spike between vertex k and k+1
            a, b = base[k], base[(k + 1) % n]
            m = ((a[0] + b[0]) / 2, (a[1] + b[1]) / 2)
            d = math.dist(a, b)
            ang = math.radians(rnd.uniform(4, 25))
            L = (d / 2) / math.tan(ang / 2)
            out = ((m[0] - 50), (m[1] - 50))
            no = math.hypot(*out)
            pts.append((m[0] + out[0] / no * L, m[1] + out[1] / no * L))
    loops = [polygon(pts)]
    if rnd.random() < 0.4:
        loops.append(circle(rnd.uniform(1, 3), 50 + rnd.uniform(-4, 4), 50 + rnd.uniform(-4, 4)))
    return loops


FAMILIES = {"star": star, "rect": rect, "slot": slot, "sharp": sharp}


def table(loops):
    rows = ["path,move,x,y,z,xc,yc"]
    f = lambda p: f"{p[0]:.9f},{p[1]:.9f}"
    for i, lp in enumerate(loops):
        rows.append(f"{i + 1},rapid,{f(lp[0][0])},0,,")
        for a, b, c, ccw in lp:
            rows.append(f"{i + 1},{'ccw' if ccw else 'cw'},{f(b)},0,{f(c)}" if c else f"{i + 1},line,{f(b)},0,,")
    return "\n".join(rows) + "\n"


def reread(text):
    """The loops as the filter reads them (the printed, rounded coordinates)."""
    loops, prev = {}, None
    for r in csv.DictReader(text.splitlines()):
        p, q = int(r["path"]), (float(r["x"]), float(r["y"]))
        if r["move"] == "rapid":
            loops[p] = []
        else:
            c = (float(r["xc"]), float(r["yc"])) if r["xc"] else None
            loops[p].append((prev, q, c, r["move"] != "cw"))
        prev = q
    return loops


# ---------------------------------------------------------------- one run and its checks

def settings(rnd, radii=(2, 3, 5)):
    runs = []
    for R in radii:
        runs.append((R, rnd.choice(THRESHOLDS), rnd.choice([None, 0.6 * R]), rnd.choice([0, 0.3]), 1))
    R = rnd.choice(list(radii))
    runs.append((R, rnd.choice(THRESHOLDS), rnd.choice([None, 0.6 * R]), rnd.choice([0, 0.3]), 2))
    return runs


def check(loops, run, out_csv, rep, stats):
    """The independent checks of an exit-0 run: a list of failures."""
    R, thr, step, allow, layers = run
    fails = []
    if "threshold_held" not in rep:
        return ["report without threshold_held"]
    if rep["threshold_held"] is not True:
        fails.append("threshold_held false")
    if not rep["largest_engagement_deg"] <= thr + ENG_TOL:
        fails.append(f"largest_engagement_deg {rep['largest_engagement_deg']}")
    if rep.get("no_gouge") is not True:
        fails.append(f"no_gouge {rep.get('no_gouge')} (smallest_wall_clearance_mm {rep.get('smallest_wall_clearance_mm')})")
    pieces = [pc for lp in loops.values() for pc in lp]
    polys = {k: flatten(lp) for k, lp in loops.items()}
    outer_keys = [k for k in loops if not any(k != j and inside(polys[k][0], polys[j]) for j in loops)]
    area = sum(abs(loop_area(loops[k])) for k in outer_keys) - sum(abs(loop_area(loops[k])) for k in loops if k not in outer_keys)
    wall = R + allow
    worst_short, worst_eng, prev = -1e9, 0.0, None
    with open(out_csv) as f:
        rows = list(csv.DictReader(f))
    zs = sorted({float(r["z"]) for r in rows if r["move"] != "rapid" and r["tag"] != "entry"})
    if len(zs) != layers:
        fails.append(f"{len(zs)} cutting z levels for {layers} layers")
    for r in rows:
        p = (float(r["x"]), float(r["y"]))
        if r["move"] == "line" and prev is not None:
            # The whole move keeps the wall distance (a link across the pocket, not only its ends).
            d = min(move_dist(prev, p, pc) for pc in pieces)
            worst_short = max(worst_short, wall - d)
            if d < wall - CLEAR_TOL:
                fails.append(f"line {rows.index(r) + 2} {r['tag']} move from {prev}: {d:.9f} mm from the walls < {wall}")
        pts = [p]
        if r["move"] in ("cw", "ccw") and prev is not None:
            c = (float(r["xc"]), float(r["yc"]))
            a0, sw = sweep_of(prev, p, c, r["move"] == "ccw")
            rr = math.dist(p, c)
            pts.append((c[0] + rr * math.cos(a0 + sw / 2), c[1] + rr * math.sin(a0 + sw / 2)))
        for q in pts:
            d = min(piece_dist(q, pc) for pc in pieces)
            worst_short = max(worst_short, wall - d)
            if d < wall - CLEAR_TOL:
                fails.append(f"line {rows.index(r) + 2} ({q[0]:.6f}, {q[1]:.6f}) {r['tag']}: {d:.9f} mm from the walls < {wall}")
            # inside: in an odd number of loops (outer minus islands)
            elif sum(inside(q, polys[k]) for k in loops) % 2 != 1:
                fails.append(f"line {rows.index(r) + 2} ({q[0]:.6f}, {q[1]:.6f}) {r['tag']}: outside the pocket")
        if r["tag"] in ("trochoid", "contour") and r.get("engagement"):
            e = float(r["engagement"])
            worst_eng = max(worst_eng, e - thr)
            if e > thr + ENG_TOL:
                fails.append(f"line {rows.index(r) + 2} {r['tag']}: engagement {e} > {thr}")
        prev = p
    stats["shortfall"] = max(stats["shortfall"], worst_short)
    for st in rep.get("uncut") or []:
        lp = loops.get(st["loop"])
        if lp is None:
            fails.append(f"uncut names loop {st['loop']}, not an input path")
            continue
        for key in ("from", "to"):
            d = min(piece_dist(tuple(st[key]), pc) for pc in lp)
            stats["on_loop"] = max(stats["on_loop"], d)
            if d > ON_LOOP_TOL:
                fails.append(f"uncut {key} {st[key]} is {d:.3g} mm off loop {st['loop']}")
    ua = rep.get("uncut_area_mm2", 0.0)
    if not (0 <= ua < area):
        fails.append(f"uncut_area_mm2 {ua} not in [0, pocket area {area:.3f})")
    if rep.get("uncut"):
        stats["uncut_runs"] += 1
    return fails[:5]


# Figures of the written program that its own --analyse must give exactly as the plan's report.
AGREE = ["largest_engagement_deg", "link_engagement_deg", "entry_engagement_deg", "smallest_wall_clearance_mm",
         "no_gouge", "threshold_held", "samples_over_threshold", "link_samples_over_threshold", "samples"]


def agree(binary, src, run, out, rep, stats):
    """--analyse of the written program against the plan's report: a list of disagreements."""
    R, thr, _, allow, _ = run
    an = out + ".an.json"
    p = subprocess.run([binary, src, "--radius", str(R), "--threshold", str(thr), "--allowance", str(allow),
                        "--analyse", out, "--report", an, "-o", os.devnull], capture_output=True, text=True)
    if p.returncode != 0:
        return [f"--analyse exit {p.returncode}: {p.stderr.strip()[-200:]}"]
    with open(an) as fh:
        given = json.load(fh)
    os.remove(an)
    stats["analysed"] += 1
    stats["link_deg"] = max(stats["link_deg"], given["link_engagement_deg"])
    stats["largest_deg"] = max(stats["largest_deg"], given["largest_engagement_deg"])
    fails = [f"--analyse {k} {given.get(k)} vs the report's {rep.get(k)}" for k in AGREE if given.get(k) != rep.get(k)]
    if STRATEGY == "adaptive":
        # The planner holds each step's end, middle and quarters: a referee sampling every
        # quarter of the default 0.5 mm step finds nothing over the threshold either.
        p = subprocess.run([binary, src, "--radius", str(R), "--threshold", str(thr), "--allowance", str(allow),
                            "--sample", str(FINE_SAMPLE), "--analyse", out, "--report", an, "-o", os.devnull],
                           capture_output=True, text=True)
        if p.returncode != 0:
            return fails + [f"--analyse --sample {FINE_SAMPLE} exit {p.returncode}: {p.stderr.strip()[-200:]}"]
        with open(an) as fh:
            fine = json.load(fh)["largest_engagement_deg"]
        os.remove(an)
        stats["fine_over"] = max(stats["fine_over"], fine - thr)
        if fine > thr + ENG_TOL:
            fails.append(f"--analyse --sample {FINE_SAMPLE}: largest engagement {fine} over {thr}")
    stats["agreed"] += not fails
    return fails


def one(binary, src, loops, run, tmp, tag):
    R, thr, step, allow, layers = run
    out, repf = os.path.join(tmp, f"{tag}.csv"), os.path.join(tmp, f"{tag}.json")
    for f in (out, repf):
        if os.path.exists(f):
            os.remove(f)
    args = [binary, src, "--radius", str(R), "--threshold", str(thr), "--allowance", str(allow), "-o", out,
            "--report", repf]
    if step is not None:
        args += ["--step", f"{step:g}"]
    if layers > 1:
        args += ["--layers", str(layers), "--layer-depth", "5"]
    if STRATEGY:
        args += ["--strategy", STRATEGY]
    p = subprocess.run(args, capture_output=True, text=True)
    err = p.stderr.strip().splitlines()
    shown = [a for i, a in enumerate(args[2:]) if a not in ("-o", "--report") and args[2:][i - 1] not in ("-o", "--report")]
    return p.returncode, err, shown, out, repf


def main():
    argv = sys.argv[1:]
    opt = lambda k, d: argv[argv.index(k) + 1] if k in argv else d
    pos = [a for i, a in enumerate(argv) if not a.startswith("--") and (i == 0 or argv[i - 1] not in
                                                                         ("--family", "--first", "--jobs", "--keep", "--minutes", "--radii", "--strategy", "--thresholds"))]
    seeds = int(pos[0]) if pos else 40
    fam = opt("--family", "all")
    first = int(opt("--first", "1"))
    jobs = int(opt("--jobs", "1"))
    keep = opt("--keep", "/tmp/fuzz-trochoid-kept")
    deadline = time.time() + 60 * float(opt("--minutes", "1e9"))
    fams = list(FAMILIES) if fam == "all" else [fam]
    radii = tuple(float(r) if "." in r else int(r) for r in opt("--radii", "2,3,5").split(","))
    counts, kept = {"exit0": 0, "exit2": 0, "defect": 0}, []
    stats = {"shortfall": -1e9, "on_loop": 0.0, "uncut_runs": 0, "analysed": 0, "agreed": 0, "link_deg": 0.0, "largest_deg": 0.0,
             "fine_over": -1e9}
    per_family = {f: [0, 0, 0] for f in fams}
    causes = {"exit 1, --step side-cuts over the threshold": 0, "exit 1, other": 0, "other": 0}
    os.makedirs(keep, exist_ok=True)
    tmp = tempfile.mkdtemp(prefix="fuzz-trochoid-")
    cases = [(f, s) for s in range(first, first + seeds) for f in fams]

    def do(case):
        f, seed = case
        if time.time() > deadline:
            return f, seed, None, []
        rnd = random.Random(f"{f}-{seed}")
        text = table(FAMILIES[f](rnd))
        src = os.path.join(tmp, f"{f}-{seed}.csv")
        with open(src, "w") as fh:
            fh.write(text)
        loops = reread(text)
        res = []
        for k, run in enumerate(settings(rnd, radii)):
            code, err, args, out, repf = one(BIN, src, loops, run, tmp, f"{f}-{seed}-{k}")
            why = None
            if code == 0:
                try:
                    with open(repf) as fh:
                        rep = json.load(fh)
                    fails = check(loops, run, out, rep, stats) or agree(BIN, src, run, out, rep, stats)
                except Exception as e:  # a missing or unreadable output is a defect too
                    fails = [f"unreadable output: {e!r}"]
                why = "; ".join(fails) if fails else None
            elif code == 2:
                if len(err) != 1 or not re.search(re.escape(src) + r":\d+", err[0]):
                    why = f"exit 2 with stderr {err[:3]}"
            else:
                why = f"exit {code}: {' | '.join(err[-3:])}"
            res.append((run, code, why, args))
            for fname in (out, repf):
                if os.path.exists(fname):
                    os.remove(fname)
        return f, seed, text, res

    with ThreadPoolExecutor(max_workers=jobs) as ex:
        done = 0
        for f, seed, text, res in ex.map(do, cases):
            done += text is not None
            for run, code, why, args in res:
                if why:
                    counts["defect"] += 1
                    if code == 1:  # why the program was refused: the step's own side cut, or not
                        causes["exit 1, --step side-cuts over the threshold" if "side-cuts" in why else "exit 1, other"] += 1
                    else:
                        causes["other"] += 1
                    per_family[f][2] += 1
                    name = os.path.join(keep, f"{f}-{seed}.csv")
                    with open(name, "w") as fh:
                        fh.write(text)
                    kept.append(f"{name} {' '.join(args)}: {why}")
                    print(kept[-1], flush=True)
                elif code == 0:
                    counts["exit0"] += 1
                    per_family[f][0] += 1
                else:
                    counts["exit2"] += 1
                    per_family[f][1] += 1
            if text is not None:
                print(f"{f} {seed}: " + " ".join(str(c) if not w else f"{c}!" for _, c, w, _ in res) +
                      f" (shortfall so far {stats['shortfall']:.3g} mm)", file=sys.stderr, flush=True)
    shutil.rmtree(tmp)
    print(f"{done} pockets ({', '.join(fams)}), {sum(counts.values())} runs: {counts}")
    print(f"defects by cause: {causes}")
    print("per family (exit0, exit2, defect): " + ", ".join(f"{f} {v}" for f, v in per_family.items()))
    print(f"largest wall-clearance shortfall (R + allowance - distance, negative = clear): {stats['shortfall']:.3g} mm;"
          f" uncut from/to off their loop by at most {stats['on_loop']:.3g} mm over {stats['uncut_runs']} runs leaving uncut")
    print(f"--analyse of {stats['agreed']} of {stats['analysed']} written programs (those that passed the checks above)"
          f" agreed with their reports on {', '.join(AGREE)};"
          f" largest engagement analysed {stats['largest_deg']:.6f} deg, on links {stats['link_deg']:.6f} deg")
    if STRATEGY == "adaptive":
        print(f"largest engagement over the threshold at the {FINE_SAMPLE} mm referee: {stats['fine_over']:.3g} deg")
    sys.exit(1 if kept else 0)


main()
