#!/usr/bin/env bash
# medial-trochoid peer benchmark: our medial axis (boostvoronoi, Rust port, plus the filtering
# and clearance of medial-trochoid) against Boost.Voronoi itself (pyvoronoi, C++) on the same
# integer segments of a wavy star pocket with 1k and 10k segments. Needs `pip install pyvoronoi`.
set -euo pipefail
cd "$(dirname "$0")/.."
TARGET=${CARGO_TARGET_DIR:-target}
cargo build --release -q -p medial-trochoid --example voronoi_bench
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for n in 1000 10000; do
  echo "ours:      $("$TARGET"/release/examples/voronoi_bench "$n" "$tmp/seg$n.txt")"
  python3 - "$tmp/seg$n.txt" <<'PY'
import sys, time, pyvoronoi
segs = [tuple(map(int, l.split())) for l in open(sys.argv[1])]
times = []
for _ in range(7):
    t0 = time.perf_counter()
    pv = pyvoronoi.Pyvoronoi(1)
    for s in segs:
        pv.AddSegment([[s[0], s[1]], [s[2], s[3]]])
    pv.Construct()
    edges = pv.CountEdges()
    times.append(time.perf_counter() - t0)
times.sort()
# Agreement: every end of our kept medial edges is a vertex of Boost's diagram (or an input
# point), within the stated error (1e-6 mm = 1 unit of the integer grid).
verts = [(v.X, v.Y) for v in pv.GetVertices()] + [(s[0], s[1]) for s in segs]
grid = {}
for v in verts:
    grid.setdefault((round(v[0] / 100), round(v[1] / 100)), []).append(v)
worst = 0.0
for l in open(sys.argv[1] + ".ends"):
    x, y = map(float, l.split())
    k = (round(x / 100), round(y / 100))
    near = [v for dx in (-1, 0, 1) for dy in (-1, 0, 1) for v in grid.get((k[0] + dx, k[1] + dy), [])]
    worst = max(worst, min(((v[0] - x) ** 2 + (v[1] - y) ** 2) ** 0.5 for v in near) if near else float("inf"))
print(f"pyvoronoi: segments {len(segs)} voronoi_edges {edges} median_ms {times[3] * 1e3:.3f}; "
      f"largest distance of our edge ends to its vertices {worst * 1e-6:.2e} mm")
PY
done
