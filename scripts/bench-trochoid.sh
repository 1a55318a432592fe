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
print(f"pyvoronoi: segments {len(segs)} voronoi_edges {edges} median_ms {times[3] * 1e3:.3f}")
PY
done
