#!/usr/bin/env bash
# Load-independent view of offset's speed: instructions (callgrind, one rayon thread) of our
# verified offset against bare cavalier_contours on the dense stars of scripts/bench-offset.sh,
# and of our pocket to empty against bare cavalier's shape offsets of the same levels. Each
# figure is the run's total less that of the `none` mode (program start and the star alone).
#
#   scripts/callgrind-offset.sh            (needs valgrind; CARGO_TARGET_DIR as you build)
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build -q --release -p offset --example offset_phases
BIN=${CARGO_TARGET_DIR:-target}/release/examples/offset_phases
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
count() {
  RAYON_NUM_THREADS=1 valgrind --tool=callgrind --callgrind-out-file="$TMP/cg" "$BIN" "$@" 2>&1 |
    sed -n 's/.*Collected : \([0-9]*\).*/\1/p'
}
echo "== load before: $(uptime)"
echo "| input | offset | bare cavalier M | ours M | ratio ours/bare |"
echo "|---|---|---|---|---|"
for args in "1000 lines 2" "1000 lines 5" "1000 arcs 2" "10000 lines 5" "10000 arcs 2" "10000 arcs 5"; do
  set -- $args
  none=$(count "$1" "$2" "$3" none)
  bare=$(count "$1" "$2" "$3" bare)
  ours=$(count "$1" "$2" "$3")
  awk -v n="$1" -v k="$2" -v d="$3" -v z="$none" -v b="$bare" -v o="$ours" \
    'BEGIN { printf "| star-%s-%s | %+g | %.2f | %.2f | %.2f |\n", n, k, d, (b-z)/1e6, (o-z)/1e6, (o-z)/(b-z) }'
done
none=$(count 10000 lines 1.5 none)
bare=$(count 10000 lines 1.5 barepocket)
ours=$(count 10000 lines 1.5 pocket1)
awk -v z="$none" -v b="$bare" -v o="$ours" \
  'BEGIN { printf "| star-10000-lines pocket | R 1.5, step 2 | %.1f | %.1f | %.2f |\n", (b-z)/1e6, (o-z)/1e6, (o-z)/(b-z) }'
echo "== load after: $(uptime)"
