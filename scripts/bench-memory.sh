#!/bin/bash
# Peak memory (maximum resident set size, /usr/bin/time -v) of the streaming filters per input
# size: curve-fit-arcs on G-code programs of 10, 50 and 105 MB (made here, runs of 2000 moves
# each, and one of 50 MB with runs of 50 000 moves: sampled arcs between rapids),
# surf-probe-fit raster writing about 20 and 200 MB, tool-attitude on the mould's stylus-centre
# stream repeated to about 50 MB (--axis, and the tilt mode of a ball), and post-6axis on the
# mould's cavity stream with its setup (linking, collision check against the stock and the mould)
# once and repeated 10 times. The mould's files come from `make demo-mould-3axis`
# (MOULD=out/mould-3axis by default; those rows are left out when it has not run).
# Outputs are compared byte for byte between the two builds.
# Usage: scripts/bench-memory.sh [BIN_DIR [BEFORE_DIR]] — BIN_DIR holds release binaries
# (default target/release); BEFORE_DIR, if given, older binaries measured side by side.
# Inputs go to ${TMPDIR:-/tmp}/bench-memory (never committed). Prints a Markdown table.
# PARTS (default "curve-fit-arcs surf-probe-fit mould") picks the groups of rows to run.
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

PARTS=${PARTS:-curve-fit-arcs surf-probe-fit mould}
has() { [[ " $PARTS " == *" $1 "* ]]; }

printf '| run | input | output | peak RSS before | peak RSS after |\n|---|---|---|---|---|\n'
has curve-fit-arcs && for spec in 10:2000 50:2000 105:2000 50:50000; do
  mb=${spec%:*} RUN=${spec#*:}
  f=$DIR/prog-${mb}mb-$RUN.nc
  [ -s "$f" ] || make_gcode "$mb" "$RUN"
  after=$(peak "$BIN/curve-fit-arcs" "$f" --tol 0.01)
  out=$(size_mb "$DIR/out")
  before=-; [ -n "$BEFORE" ] && { before=$(peak "$BEFORE/curve-fit-arcs" "$f" --tol 0.01); cmp -s "$DIR/out" <("$BIN/curve-fit-arcs" "$f" --tol 0.01) || before="$before (output differs!)"; }
  echo "| curve-fit-arcs G-code → G-code, runs of $RUN moves | $(size_mb "$f") MB | $out MB | $before | $after |"
done
# A table of about 50 MB: the same ripple arcs as points, one path per run.
if has curve-fit-arcs && [ ! -s "$DIR/pts-50mb.csv" ]; then
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
if has curve-fit-arcs; then
  f=$DIR/pts-50mb.csv
  after=$(peak "$BIN/curve-fit-arcs" "$f")
  out=$(size_mb "$DIR/out")
  before=-; [ -n "$BEFORE" ] && { before=$(peak "$BEFORE/curve-fit-arcs" "$f"); cmp -s "$DIR/out" <("$BIN/curve-fit-arcs" "$f") || before="$before (output differs!)"; }
  echo "| curve-fit-arcs table → table, runs of 2000 rows | $(size_mb "$f") MB | $out MB | $before | $after |"
fi
has surf-probe-fit && for spec in "0,670 0,670" "0,2080 0,2080"; do
  set -- $spec
  step=1
  args=(raster --x "$1" --y "$2" --step $step --z 10 --max-points 10000000)
  after=$(peak "$BIN/surf-probe-fit" "${args[@]}")
  out=$(size_mb "$DIR/out")
  before=-; [ -n "$BEFORE" ] && { before=$(peak "$BEFORE/surf-probe-fit" "${args[@]}"); cmp -s "$DIR/out" <("$BIN/surf-probe-fit" "${args[@]}") || before="$before (output differs!)"; }
  echo "| surf-probe-fit raster --x $1 --y $2 --step $step | – | $out MB | $before | $after |"
done
MOULD=${MOULD:-out/mould-3axis}
if has mould && [ -s "$MOULD/cl.csv" ] && [ -s "$MOULD/tip-cavity.csv" ]; then
  # A stream repeated N times, each copy's paths numbered after the last one's.
  repeat() {
    python3 - "$1" "$2" > "$3" <<'PY'
import sys
lines = open(sys.argv[1]).read().splitlines()
k = lines[0].split(",").index("path")
rows = [l.split(",") for l in lines[1:]]
step = max(int(r[k]) for r in rows) + 1
print(lines[0])
for n in range(int(sys.argv[2])):
    for r in rows:
        print(",".join(r[:k] + [str(int(r[k]) + n * step)] + r[k + 1:]))
PY
  }
  f=$DIR/mould-cl-x11.csv
  [ -s "$f" ] || repeat "$MOULD/cl.csv" 11 "$f"
  for mode in "--axis 0,0,1" ""; do
    # shellcheck disable=SC2086
    args=("$f" --tool "$MOULD/ball-r3.json" $mode)
    after=$(peak "$BIN/tool-attitude" "${args[@]}")
    out=$(size_mb "$DIR/out")
    before=-; [ -n "$BEFORE" ] && { before=$(peak "$BEFORE/tool-attitude" "${args[@]}"); cmp -s "$DIR/out" <("$BIN/tool-attitude" "${args[@]}") || before="$before (output differs!)"; }
    echo "| tool-attitude ${mode:-tilt mode (ball R3, ζ 0)}, the mould's stylus-centre stream ×11 | $(size_mb "$f") MB | $out MB | $before | $after |"
  done
  cp "$MOULD/setup.json" "$MOULD/ball-r3.json" "$MOULD/mould.stl" "$DIR/"
  f=$DIR/tip-cavity-x10.csv
  [ -s "$f" ] || repeat "$MOULD/tip-cavity.csv" 10 "$f"
  for src in "$MOULD/tip-cavity.csv" "$f"; do
    args=("$src" --machine data/post-6axis/three-axis.json --setup "$DIR/setup.json")
    after=$(peak "$BIN/post-6axis" "${args[@]}")
    out=$(size_mb "$DIR/out")
    rows=$(($(wc -l < "$src") - 1))
    before=-; [ -n "$BEFORE" ] && { before=$(peak "$BEFORE/post-6axis" "${args[@]}"); cmp -s "$DIR/out" <("$BIN/post-6axis" "${args[@]}") || before="$before (output differs!)"; }
    echo "| post-6axis --setup, the mould's cavity stream ($rows rows) | $(size_mb "$src") MB | $out MB | $before | $after |"
  done
fi
