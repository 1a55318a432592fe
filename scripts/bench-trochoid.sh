#!/usr/bin/env bash
# medial-trochoid peer benchmark: our medial axis (boostvoronoi, Rust port, plus the filtering
# and clearance of medial-trochoid) against Boost.Voronoi itself (pyvoronoi, C++) on the same
# integer segments (the builder's own input, `medial::builder_input`) of a wavy star pocket with
# 1k and 10k segments. Needs `pip install pyvoronoi`.
#
# Usage: scripts/bench-trochoid.sh [--callgrind] [RESOLUTION_MM]
#   ROUNDS rounds (default 3), ours and pyvoronoi alternating, each 7 runs (best and median);
#   the summary is the best of all rounds and the ratio ours / pyvoronoi. `uptime` before and
#   after. --callgrind: instead, instructions of one Voronoi build on each side under valgrind
#   (load-independent; ours `Builder::build`, 7 builds / 7; Boost's `construct_voronoi`, 1 build).
set -euo pipefail
cd "$(dirname "$0")/.."
TARGET=${CARGO_TARGET_DIR:-target}
callgrind=0
if [ "${1:-}" = "--callgrind" ]; then callgrind=1; shift; fi
RES=${1:-1e-6}
ROUNDS=${ROUNDS:-3}
cargo build --release -q -p medial-trochoid --example voronoi_bench
BENCH="$TARGET"/release/examples/voronoi_bench
PY=$(python3 -c 'import sys; print(sys.executable)')
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cat > "$tmp/pv.py" <<'PY'
import sys, time, pyvoronoi
segs = [tuple(map(int, l.split())) for l in open(sys.argv[1])]
runs = int(sys.argv[2])
times = []
for _ in range(runs):
    t0 = time.perf_counter()
    pv = pyvoronoi.Pyvoronoi(1)
    for s in segs:
        pv.AddSegment([[s[0], s[1]], [s[2], s[3]]])
    pv.Construct()
    edges = pv.CountEdges()
    times.append(time.perf_counter() - t0)
times.sort()
if len(sys.argv) < 5:
    print(f"pyvoronoi: segments {len(segs)} voronoi_edges {edges} best_ms {times[0] * 1e3:.3f} "
          f"median_ms {times[len(times) // 2] * 1e3:.3f}")
    sys.exit(0)
# Agreement: every end of our kept medial edges is a vertex of Boost's diagram (or an input
# point), within the stated error (the grid: RESOLUTION mm = 1 unit of the integer frame).
res = float(sys.argv[4])
verts = [(v.X, v.Y) for v in pv.GetVertices()] + [(s[0], s[1]) for s in segs]
grid = {}
for v in verts:
    grid.setdefault((round(v[0] / 100), round(v[1] / 100)), []).append(v)
worst = 0.0
for l in open(sys.argv[3]):
    x, y = map(float, l.split())
    k = (round(x / 100), round(y / 100))
    near = [v for dx in (-1, 0, 1) for dy in (-1, 0, 1) for v in grid.get((k[0] + dx, k[1] + dy), [])]
    worst = max(worst, min(((v[0] - x) ** 2 + (v[1] - y) ** 2) ** 0.5 for v in near) if near else float("inf"))
print(f"agreement: largest distance of our {sum(1 for _ in open(sys.argv[3]))} edge ends to Boost's "
      f"vertices {worst * res:.2e} mm (grid {res:g} mm)")
PY
count() { # callgrind output file -> total instructions
  callgrind_annotate "$1" 2>/dev/null | awk '/PROGRAM TOTALS/ && v == "" { gsub(",", "", $1); v = $1 } END { print v }'
}
echo "uptime before: $(uptime)"
for n in 1000 10000; do
  "$BENCH" "$n" "$tmp/seg$n.txt" "$RES" > "$tmp/ours$n.txt"
  "$PY" "$tmp/pv.py" "$tmp/seg$n.txt" 1 "$tmp/seg$n.txt.ends" "$RES"
  if [ "$callgrind" = 1 ]; then
    valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.ours" --toggle-collect='*Builder*build*' \
      "$BENCH" "$n" "$tmp/cg$n.txt" "$RES" > /dev/null 2>&1
    valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.boost" --toggle-collect='*construct_voronoi*' \
      "$PY" "$tmp/pv.py" "$tmp/seg$n.txt" 1 > /dev/null 2>&1
    ours=$(( $(count "$tmp/cg.ours") / 7 ))
    boost=$(count "$tmp/cg.boost")
    echo "callgrind $n segments (grid $RES mm): ours $ours instructions per build, Boost $boost," \
      "ratio $(awk -v a="$ours" -v b="$boost" 'BEGIN { printf "%.2f", a / b }')"
    continue
  fi
  for round in $(seq "$ROUNDS"); do
    echo "round $round ours:      $("$BENCH" "$n" "$tmp/seg$n.txt" "$RES" | tee -a "$tmp/all$n.txt")"
    echo "round $round $("$PY" "$tmp/pv.py" "$tmp/seg$n.txt" 7 | tee -a "$tmp/all$n.txt")"
  done
  awk -v n="$n" '
    /^segments/ { for (i = 1; i < NF; i++) if ($i == "best_ms") o = (o == "" || $(i + 1) < o) ? $(i + 1) : o }
    /^pyvoronoi/ { for (i = 1; i < NF; i++) if ($i == "best_ms") p = (p == "" || $(i + 1) < p) ? $(i + 1) : p }
    END { printf "summary %s segments: best ours %.1f ms, pyvoronoi %.1f ms, ratio ours / pyvoronoi %.2f\n", n, o, p, o / p }
  ' "$tmp/all$n.txt"
done
echo "uptime after: $(uptime)"
