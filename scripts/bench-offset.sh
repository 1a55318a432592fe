#!/usr/bin/env bash
# offset's kernel side by side with its peers on the same inputs: dense stars (1 k and 10 k
# vertices, lines and arcs, r = 50 + 15 cos 8θ) offset by 2 and 5 mm inward and 2 mm outward,
# and a pocket of the 10 k line star to empty (R 1.5, step 2).
#   1. bare cavalier_contours (default options) against our verified offset
#      (`crates/offset/examples/offset_peers.rs`: runs interleaved bare/ours, median and best
#      times, bare results run through our check);
#   2. pyclipper (PyPI, Clipper 1, integer polygons: arcs become chords) on the same vertices.
#
#   scripts/bench-offset.sh                  (SKIP_PYCLIPPER=1: the first part only)
set -euo pipefail
cd "$(dirname "$0")/.."
WORK=${WORK:-target/bench-offset}
mkdir -p "$WORK"
cargo build -q --release -p offset --example offset_peers
echo "== load before: $(uptime)"
echo "== cavalier_contours (bare) vs offset's verified kernel"
cargo run -q --release -p offset --example offset_peers -- "$WORK"
echo "== load after: $(uptime)"
[ -n "${SKIP_PYCLIPPER:-}" ] && exit 0

if [ ! -x "$WORK/venv/bin/python" ]; then
  python3 -m venv "$WORK/venv"
fi
"$WORK/venv/bin/pip" install -q pyclipper
echo
echo "== pyclipper (polygons only: the arc stars' arcs are lost, their vertices offset as a polygon)"
"$WORK/venv/bin/python" - "$WORK" <<'EOF'
import sys, time, statistics
import pyclipper
work = sys.argv[1]
SCALE = 1e6            # Clipper works on integers: 1 unit = 1 nm
ARC_TOL = 0.001 * SCALE  # round joins within 1 µm

def load(name):
    rows = open(f"{work}/{name}.csv").read().split()[1:]
    return [(round(float(x) * SCALE), round(float(y) * SCALE)) for x, y in (r.split(",") for r in rows)]

def offset(poly, d):
    pco = pyclipper.PyclipperOffset(2.0, ARC_TOL)
    pco.AddPath(poly, pyclipper.JT_ROUND, pyclipper.ET_CLOSEDPOLYGON)
    return pco.Execute(d * SCALE)

def median_ms(f, runs):
    t = []
    for _ in range(runs):
        s = time.perf_counter()
        out = f()
        t.append(time.perf_counter() - s)
    return statistics.median(t) * 1e3, out

print("| input | offset | pyclipper ms | loops | vertices out |")
print("|---|---|---|---|---|")
for n in (1000, 10000):
    for kind in ("lines", "arcs"):
        name = f"star-{n}-{kind}"
        poly = load(name)
        for d in (2.0, 5.0, -2.0):
            # Our +d is the left of a counter-clockwise star (inward); Clipper's positive delta grows.
            ms, out = median_ms(lambda: offset(poly, -d), 7 if n > 5000 else 21)
            print(f"| {name} | {d:+} | {ms:.2f} | {len(out)} | {sum(len(p) for p in out)} |")
poly = load("star-10000-lines")
def pocket():
    k = 0
    while offset(poly, -(1.5 + 2.0 * k)):
        k += 1
    return k
ms, levels = median_ms(pocket, 5)
print(f"| star-10000-lines pocket | r 1.5 step 2 | {ms:.2f} | {levels} levels | |")
EOF
