#!/usr/bin/env bash
# Side by side with ArcWelder on the shared G-code corpus: moves written, deviation measured by our
# own exact routine (on both programs), and throughput. ArcWelder's outputs and speeds come from
# the corpus (../shared/data/gcode-corpus/arcwelder/, its README says how they were made).
set -euo pipefail
cd "$(dirname "$0")/.."
corpus=${CORPUS:-../shared/data/gcode-corpus}
[ -d "$corpus" ] || { echo "corpus not found at $corpus (set CORPUS=...)" >&2; exit 2; }
cargo build --release -q -p curve-fit-arcs
exec target/release/curve-fit-arcs-bench "$corpus" 2>/dev/null || {
  echo "the side-by-side driver is not built yet" >&2; exit 1; }
