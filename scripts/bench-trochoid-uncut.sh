#!/bin/sh
# medial-trochoid, leaving uncut what the tool cannot reach under the threshold: the pockets of
# docs/benchmarks.md ("what is left uncut") planned with the default (opening) and with
# --no-leave-uncut (the refusal), alternating, best of N wall times; one table row per pocket.
# Usage: scripts/bench-trochoid-uncut.sh [BIN] [N]   (BIN default target/release/medial-trochoid)
set -eu
BIN=${1:-target/release/medial-trochoid}
N=${2:-3}
D=data/medial-trochoid
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
uptime
for case in "polygon12.csv --radius 5" "box-die.csv --radius 6" "box-die.csv --radius 8" "island.csv --radius 8"; do
  set -- $case
  file=$1; shift
  for i in $(seq "$N"); do
    /usr/bin/time -f %e -a -o "$T/u.t" "$BIN" "$D/$file" "$@" --report "$T/u.json" -o "$T/u.csv" 2>/dev/null
    /usr/bin/time -f %e -a -o "$T/n.t" "$BIN" "$D/$file" "$@" --no-leave-uncut --report "$T/n.json" -o "$T/n.csv" 2>/dev/null || true
  done
  python3 - "$file $*" "$T" <<'PY'
import json, sys
case, t = sys.argv[1], sys.argv[2]
u, n = (json.load(open(f"{t}/{k}.json")) for k in "un")
best = lambda k: min(float(x) for x in open(f"{t}/{k}.t").read().split() if x[0].isdigit())
thick = max(s["thickness_mm"] for s in u["uncut"])
print(f"| `{case}` | {u['uncut_radius_mm']:.2f} | {len(u['uncut'])} | {u['uncut_area_mm2']:.3f} | {thick:.3f} "
      f"| {n['largest_engagement_deg']:.1f}° ({n['samples_over_threshold']}) | {u['largest_engagement_deg']:.4f}° "
      f"| {u['smallest_wall_clearance_mm']:.6f} | {u['offset_only_minutes']:.3f} / {u['trochoidal_minutes']:.3f} = {u['time_ratio']:.2f} "
      f"| {u['time_ratio_chip_only']:.2f} | {best('n'):.2f} / {best('u'):.2f} s |")
PY
  rm -f "$T"/*.t
done
uptime
