#!/usr/bin/env bash
# medial-trochoid on many-sided pockets: regular N-gons (radius 40 mm about (50, 50)) and a
# wavy N-gon with a round island, planned with a φ10 tool and default options; prints the wall
# time (best of RUNS) and the report's engagement figures. Usage:
#   scripts/bench-trochoid-ngon.sh [N ...]        (default 100 400 1000; N~ for the wavy one)
# Needs the release binary in ${CARGO_TARGET_DIR:-target}/release.
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${CARGO_TARGET_DIR:-target}/release/medial-trochoid
RUNS=${RUNS:-1}
CAP=${CAP:-600}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# ngon N WAVY: the N-gon's table on stdout (WAVY=1: radius 40 + 3 sin(6θ), and an R8 island).
ngon() {
  awk -v n="$1" -v wavy="$2" 'BEGIN {
    pi = atan2(0, -1); print "path,move,x,y,z,xc,yc"
    for (k = 0; k <= n; k++) {
      a = 2 * pi * (k % n) / n; r = 40 + (wavy ? 3 * sin(6 * a) : 0)
      printf "1,%s,%.9f,%.9f,0,,\n", (k ? "line" : "rapid"), 50 + r * cos(a), 50 + r * sin(a)
    }
    if (wavy) { print "2,rapid,58,50,0,,"; print "2,cw,42,50,0,50,50"; print "2,cw,58,50,0,50,50" }
  }'
}

for arg in "${@:-100 400 1000}"; do
  for spec in $arg; do
    n=${spec%\~}; wavy=0; [ "$spec" != "$n" ] && wavy=1
    ngon "$n" "$wavy" > "$tmp/in.csv"
    best=""
    for _ in $(seq "$RUNS"); do
      t0=$(date +%s.%N)
      if ! timeout "$CAP" "$BIN" "$tmp/in.csv" --radius 5 --report "$tmp/report.json" -o "$tmp/out.csv"; then
        echo "$spec: failed or over ${CAP} s"; continue 2
      fi
      t=$(echo "$(date +%s.%N) - $t0" | bc)
      if [ -z "$best" ] || [ "$(echo "$t < $best" | bc)" = 1 ]; then best=$t; fi
    done
    python3 - "$spec" "$best" "$tmp/report.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[3]))
def find(d, key):
    if isinstance(d, dict):
        for k, v in d.items():
            if k == key:
                return v
            f = find(v, key)
            if f is not None:
                return f
    return None
keys = ["largest_engagement_deg", "samples_over_threshold", "threshold_held", "repair_rounds", "link_samples_over_threshold", "no_gouge", "uncleared_stretches", "trochoid_runs", "corner_rests", "samples"]
print(f"{sys.argv[1]}-gon: {float(sys.argv[2]):.2f} s", {k: find(r, k) for k in keys})
PY
  done
done
