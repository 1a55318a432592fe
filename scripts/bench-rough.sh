#!/usr/bin/env bash
# rough-sim throughput and thread independence, on the paper 003 fig. 2 conditions (r 5 mm,
# 2 flutes, pick 0.5 mm, 0.5 mm per tooth, tilt 3°, shank to −x, 90° pass phase).
#
# For 1 and 2 threads it runs `rough-sim patch` on one cell at a 1 µm grid (251 001 nodes, every
# node computed by the exact envelope) and on a 2 × 2 mm patch at 1 µm (4 004 001 nodes: one
# period computed, then repeated), prints nodes, the simulation's seconds and nodes per second
# from the report (`simulate_seconds`, best of 3; figures and CSV writing are not timed), and
# checks that the outputs of both thread counts are byte-identical. The criterion bench
# (`cargo bench -p rough-sim`) measures the 10 × 10 mm patch at 1 µm in memory.
#
#   scripts/bench-rough.sh
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -q -p rough-sim
target=${CARGO_TARGET_DIR:-target}
bin=$target/release/rough-sim
tool=data/rough-sim/ball-r5-z2.json
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cond=(--pick 0.5 --feed-per-tooth 0.5 --tilt 3 --lean minus-x --pass-phase 90 --step 0.001)

printf '| case | threads | nodes | seconds (best of 3) | nodes/s | output identical 1 vs 2 threads |\n'
printf '|---|---|---|---|---|---|\n'
for case in cell size2; do
  extra=(); [ "$case" = size2 ] && extra=(--size 2)
  for threads in 1 2; do
    best=""
    for _ in 1 2 3; do
      RAYON_NUM_THREADS=$threads "$bin" patch "$tool" "${cond[@]}" "${extra[@]}" --report "$work/r.json" -o "$work/$case-$threads.csv"
      s=$(sed -n 's/.*"simulate_seconds": \([0-9.e-]*\).*/\1/p' "$work/r.json")
      if [ -z "$best" ] || awk -v a="$s" -v b="$best" 'BEGIN { exit !(a < b) }'; then best=$s; fi
    done
    nodes=$(sed -n 's/.*"nodes": \([0-9]*\).*/\1/p' "$work/r.json")
    same=""
    if [ "$threads" = 2 ]; then cmp -s "$work/$case-1.csv" "$work/$case-2.csv" && same=yes || same=NO; fi
    awk -v c="$case" -v t="$threads" -v n="$nodes" -v s="$best" -v same="$same" \
      'BEGIN { printf "| %s | %s | %d | %.3f | %.0f | %s |\n", c, t, n, s, n / s, same }'
  done
done
