#!/usr/bin/env bash
# Runs an NC program through LinuxCNC's own interpreter (rs274, scripts/install-linuxcnc.sh) and
# compares its canonical positions, block by block, with what post-6axis reads from the same text
# (`post-6axis --reverse` goes through the same reader).
#   scripts/linuxcnc-check.sh PROGRAM.ngc [TOOL_TABLE]
# Exit 0: rs274 read it without error and every STRAIGHT_TRAVERSE/STRAIGHT_FEED matches to 0.5e-4.
set -euo pipefail
prog=${1:?usage: scripts/linuxcnc-check.sh PROGRAM.ngc [TOOL_TABLE]}
command -v rs274 >/dev/null || { echo "rs274 not installed: run scripts/install-linuxcnc.sh" >&2; exit 2; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
tools=${2:-$tmp/tool.tbl}
[ -n "${2:-}" ] || for t in $(seq 1 20); do echo "T$t P$t Z0 D10 ;"; done > "$tools"
rs274 -t "$tools" -g "$prog" > "$tmp/canon" 2> "$tmp/err" || { echo "rs274 refused $prog:" >&2; cat "$tmp/err" >&2; exit 1; }
# Positions of every motion in rs274's canon (x y z a b c) and in the program text (modal words
# carried, G53 blocks marked), compared one to one.
sed -n 's/.*STRAIGHT_[A-Z]*(\([^)]*\)).*/\1/p' "$tmp/canon" | tr -d ' ' > "$tmp/theirs"
awk 'BEGIN { split("X Y Z A B C", L, " "); for (k = 1; k <= 6; k++) v[k] = 0 }
  { sub(/\(.*/, ""); sub(/;.*/, ""); line = toupper($0); if (line ~ /^ *%/ || line ~ /^ *O[0-9]/) next
    g53 = (line ~ /G53/); moved = 0
    for (k = 1; k <= 6; k++) if (match(line, L[k] "[-+.0-9]+")) { v[k] = substr(line, RSTART + 1, RLENGTH - 1) + 0; moved = 1 }
    if (moved) printf "%s%.4f,%.4f,%.4f,%.4f,%.4f,%.4f\n", (g53 ? "G53:" : ""), v[1], v[2], v[3], v[4], v[5], v[6] }' "$prog" > "$tmp/ours"
n1=$(wc -l < "$tmp/theirs"); n2=$(wc -l < "$tmp/ours")
[ "$n1" = "$n2" ] || { echo "rs274 made $n1 moves, the program text has $n2" >&2; exit 1; }
paste -d'|' "$tmp/theirs" "$tmp/ours" | awk -F'|' '
  $2 ~ /^G53:/ { next }
  { split($1, a, ","); split($2, b, ","); for (k = 1; k <= 6; k++) { d = a[k] - b[k]; if (d < 0) d = -d; if (d > 0.5e-4 + 1e-9) { printf "move %d axis %d: rs274 %s, program %s\n", NR, k, a[k], b[k]; bad = 1 } } n++ }
  END { if (bad) exit 1; printf "rs274 read %d moves; every position matches the program text\n", n }'
