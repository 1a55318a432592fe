#!/bin/bash
# Peak memory (maximum resident set size, /usr/bin/time -v) of the streaming filters per input
# size: curve-fit-arcs on G-code programs of 10, 50 and 105 MB (made here, runs of 2000 moves
# each, and one of 50 MB with runs of 50 000 moves: sampled arcs between rapids), and
# surf-probe-fit raster writing about 20 and 200 MB.
# Outputs are compared byte for byte between the two builds.
# Usage: scripts/bench-memory.sh [BIN_DIR [BEFORE_DIR]] — BIN_DIR holds release binaries
# (default target/release); BEFORE_DIR, if given, older binaries measured side by side.
# Inputs go to ${TMPDIR:-/tmp}/bench-memory (never committed). Prints a Markdown table.
set -euo pipefail
BIN=${1:-target/release}
BEFORE=${2:-}
DIR=${TMPDIR:-/tmp}/bench-memory
mkdir -p "$DIR"

# A program of about $1 MB: runs of $2 G1 moves along arcs of radius 5..50 mm, 3 decimals, with
# a ripple of 0.03 mm every few moves (so that about a third of the moves survive the fit).
make_gcode() {
  python3 - "$1" "$2" > "$DIR/prog-$1mb-$2.nc" <<'PY'
import math, sys
target, run = int(sys.argv[1]) * 1_000_000, int(sys.argv[2])
out, size, k = sys.stdout, 0, 0
out.write("G21 G90 G17\nF1200\n")
while size < target:
    r = 5 + (k * 7) % 45
    cx, cy = (k % 50) * 100.0, (k // 50 % 50) * 100.0
    lines = [f"G0 X{cx + r:.3f} Y{cy:.3f} Z1.000\n", "G1 Z-0.500\n"]
    for i in range(1, run + 1):
        t, rr = i * 0.01, r + 0.03 * math.sin(i * 1.7)
        lines.append(f"G1 X{cx + rr * math.cos(t):.3f} Y{cy + rr * math.sin(t):.3f}\n")
    block = "".join(lines)
    out.write(block)
    size += len(block)
    k += 1
out.write("G0 Z5\nM2\n")
PY
}

# Maximum resident set size (MB) and seconds of a command, its output to a file.
peak() {
  /usr/bin/time -v "$@" > "$DIR/out" 2> "$DIR/time" || { cat "$DIR/time" >&2; exit 1; }
  local kb s
  kb=$(grep 'Maximum resident set size' "$DIR/time" | awk '{print $NF}')
  s=$(grep 'Elapsed (wall clock)' "$DIR/time" | awk '{print $NF}')
  printf '%.0f MB, %s s' "$(echo "$kb / 1024" | bc -l)" "$s"
}

size_mb() { printf '%.0f' "$(echo "$(stat -c %s "$1") / 1000000" | bc -l)"; }

printf '| run | input | output | peak RSS before | peak RSS after |\n|---|---|---|---|---|\n'
for spec in 10:2000 50:2000 105:2000 50:50000; do
  mb=${spec%:*} RUN=${spec#*:}
  f=$DIR/prog-${mb}mb-$RUN.nc
  [ -s "$f" ] || make_gcode "$mb" "$RUN"
  after=$(peak "$BIN/curve-fit-arcs" "$f" --tol 0.01)
  out=$(size_mb "$DIR/out")
  before=-; [ -n "$BEFORE" ] && { before=$(peak "$BEFORE/curve-fit-arcs" "$f" --tol 0.01); cmp -s "$DIR/out" <("$BIN/curve-fit-arcs" "$f" --tol 0.01) || before="$before (output differs!)"; }
  echo "| curve-fit-arcs G-code → G-code, runs of $RUN moves | $(size_mb "$f") MB | $out MB | $before | $after |"
done
# A table of about 50 MB: the same ripple arcs as points, one path per run.
if [ ! -s "$DIR/pts-50mb.csv" ]; then
  python3 - > "$DIR/pts-50mb.csv" <<'PY'
import math, sys
out, size, k = sys.stdout, 0, 0
out.write("path,x,y\n")
while size < 50_000_000:
    r, cx, cy = 5 + (k * 7) % 45, (k % 50) * 100.0, (k // 50 % 50) * 100.0
    rows = []
    for i in range(2001):
        t, rr = i * 0.01, r + 0.03 * math.sin(i * 1.7)
        rows.append(f"{k},{cx + rr * math.cos(t):.3f},{cy + rr * math.sin(t):.3f}\n")
    block = "".join(rows)
    out.write(block)
    size += len(block)
    k += 1
PY
fi
f=$DIR/pts-50mb.csv
after=$(peak "$BIN/curve-fit-arcs" "$f")
out=$(size_mb "$DIR/out")
before=-; [ -n "$BEFORE" ] && { before=$(peak "$BEFORE/curve-fit-arcs" "$f"); cmp -s "$DIR/out" <("$BIN/curve-fit-arcs" "$f") || before="$before (output differs!)"; }
echo "| curve-fit-arcs table → table, runs of 2000 rows | $(size_mb "$f") MB | $out MB | $before | $after |"
for spec in "0,670 0,670" "0,2080 0,2080"; do
  set -- $spec
  step=1
  args=(raster --x "$1" --y "$2" --step $step --z 10 --max-points 10000000)
  after=$(peak "$BIN/surf-probe-fit" "${args[@]}")
  out=$(size_mb "$DIR/out")
  before=-; [ -n "$BEFORE" ] && { before=$(peak "$BEFORE/surf-probe-fit" "${args[@]}"); cmp -s "$DIR/out" <("$BIN/surf-probe-fit" "${args[@]}") || before="$before (output differs!)"; }
  echo "| surf-probe-fit raster --x $1 --y $2 --step $step | – | $out MB | $before | $after |"
done
