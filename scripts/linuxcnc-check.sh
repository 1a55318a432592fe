#!/usr/bin/env bash
# Runs an NC program through LinuxCNC's own interpreter (rs274, scripts/install-linuxcnc.sh) and
# compares its canonical moves, block by block, with the program text as our readers take it
# (`post-6axis --reverse` goes through the same reading): every STRAIGHT_TRAVERSE, STRAIGHT_FEED
# and ARC_FEED's end position (x y z a b c), and for arcs the centre (in the selected plane's
# first and second axes, G17: X Y, G18: Z X, G19: Y Z) and the signed turn count.
#   scripts/linuxcnc-check.sh PROGRAM.ngc [TOOL_TABLE]
# Exit 0: rs274 read it without error and every move matches to 0.5e-4 (centres to 1e-4).
set -euo pipefail
prog=${1:?usage: scripts/linuxcnc-check.sh PROGRAM.ngc [TOOL_TABLE]}
command -v rs274 >/dev/null || { echo "rs274 not installed: run scripts/install-linuxcnc.sh" >&2; exit 2; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
tools=${2:-$tmp/tool.tbl}
[ -n "${2:-}" ] || for t in $(seq 1 20); do echo "T$t P$t Z0 D10 ;"; done > "$tools"
rs274 -t "$tools" -g "$prog" > "$tmp/canon" 2> "$tmp/err" || { echo "rs274 refused $prog:" >&2; cat "$tmp/err" >&2; exit 1; }
# Every motion of rs274's canon as "x,y,z,a,b,c" (arcs: "...|first,second,turns"), in order.
awk 'function arg(i) { return args[i] + 0 }
  /SELECT_PLANE/ { plane = /XY/ ? "XY" : (/XZ/ ? "XZ" : "YZ"); next }
  /STRAIGHT_(TRAVERSE|FEED)\(|ARC_FEED\(/ {
    s = $0; sub(/^[^(]*\(/, "", s); sub(/\).*$/, "", s); gsub(/ /, "", s); n = split(s, args, ",")
    if ($0 ~ /ARC_FEED/) {
      # first_end, second_end, first_axis, second_axis, rotation, axis_end, a, b, c
      if (plane == "XY") { x = arg(1); y = arg(2); z = arg(6) }
      else if (plane == "XZ") { z = arg(1); x = arg(2); y = arg(6) }
      else { y = arg(1); z = arg(2); x = arg(6) }
      printf "%.4f,%.4f,%.4f,%.4f,%.4f,%.4f|%.4f,%.4f,%d\n", x, y, z, arg(7), arg(8), arg(9), arg(3), arg(4), arg(5)
    } else printf "%.4f,%.4f,%.4f,%.4f,%.4f,%.4f\n", arg(1), arg(2), arg(3), arg(4), arg(5), arg(6)
  }' plane=XY "$tmp/canon" > "$tmp/theirs"
# The same from the program text: modal words carried, G53 blocks marked, arcs from their
# centre words (incremental I J K from the start, or R) and P turns.
awk 'function word(l,   v) { if (match(line, l "[-+.0-9]+")) { v = substr(line, RSTART + 1, RLENGTH - 1) + 0; has = 1; return v } has = 0; return 0 }
  BEGIN { split("X Y Z A B C", L, " "); for (k = 1; k <= 6; k++) v[k] = 0; plane = 17; motion = 0 }
  { sub(/\(.*/, ""); sub(/;.*/, ""); line = toupper($0); if (line ~ /^ *%/ || line ~ /^ *O[0-9]/) next
    if (line ~ /G17([^0-9.]|$)/) plane = 17; if (line ~ /G18([^0-9.]|$)/) plane = 18; if (line ~ /G19([^0-9.]|$)/) plane = 19
    if (match(line, /G0*[0-3]([^0-9.]|$)/)) { m = substr(line, RSTART + 1, RLENGTH - 1); gsub(/[^0-9]/, "", m); motion = m + 0 }
    g53 = (line ~ /G53/); moved = 0
    for (k = 1; k <= 6; k++) { old[k] = v[k]; val = word(L[k]); if (has) { v[k] = val; moved = 1 } }
    oi = word("I"); hi = has; oj = word("J"); hj = has; ok = word("K"); hk = has; r = word("R"); hr = has
    turns = word("P"); if (!has) turns = 1
    arc = (motion == 2 || motion == 3) && (moved || hi || hj || hk) && !(line ~ /M19/)
    if (!moved && !arc) next
    pos = sprintf("%s%.4f,%.4f,%.4f,%.4f,%.4f,%.4f", (g53 ? "G53:" : ""), v[1], v[2], v[3], v[4], v[5], v[6])
    if (!arc) { print pos; next }
    # In-plane (first, second) of start, end and centre offsets.
    if (plane == 17) { s1 = old[1]; s2 = old[2]; e1 = v[1]; e2 = v[2]; o1 = oi; o2 = oj }
    else if (plane == 18) { s1 = old[3]; s2 = old[1]; e1 = v[3]; e2 = v[1]; o1 = ok; o2 = oi }
    else { s1 = old[2]; s2 = old[3]; e1 = v[2]; e2 = v[3]; o1 = oj; o2 = ok }
    if (hr) {
      d1 = e1 - s1; d2 = e2 - s2; d = sqrt(d1 * d1 + d2 * d2); h = sqrt(r * r - d * d / 4 > 0 ? r * r - d * d / 4 : 0)
      side = ((motion == 3) == (r > 0)) ? 1 : -1
      c1 = (s1 + e1) / 2 - side * h * d2 / d; c2 = (s2 + e2) / 2 + side * h * d1 / d
    } else { c1 = s1 + o1; c2 = s2 + o2 }
    printf "%s|%.4f,%.4f,%d\n", pos, c1, c2, (motion == 3 ? 1 : -1) * turns }' "$prog" > "$tmp/ours"
n1=$(wc -l < "$tmp/theirs"); n2=$(wc -l < "$tmp/ours")
[ "$n1" = "$n2" ] || { echo "rs274 made $n1 moves, the program text has $n2" >&2; exit 1; }
paste -d'#' "$tmp/theirs" "$tmp/ours" | awk -F'#' '
  $2 ~ /^G53:/ { next }
  { split($1, t, "|"); split($2, o, "|"); split(t[1], a, ","); split(o[1], b, ",")
    for (k = 1; k <= 6; k++) { d = a[k] - b[k]; if (d < 0) d = -d; if (d > 0.5e-4 + 1e-9) { printf "move %d axis %d: rs274 %s, program %s\n", NR, k, a[k], b[k]; bad = 1 } }
    if ((t[2] != "") != (o[2] != "")) { printf "move %d: rs274 %s, program %s (arc or not)\n", NR, $1, $2; bad = 1 }
    else if (t[2] != "") {
      split(t[2], ca, ","); split(o[2], cb, ",")
      for (k = 1; k <= 2; k++) { d = ca[k] - cb[k]; if (d < 0) d = -d; if (d > 1e-4 + 1e-9) { printf "move %d centre %d: rs274 %s, program %s\n", NR, k, ca[k], cb[k]; bad = 1 } }
      if (ca[3] != cb[3]) { printf "move %d: rs274 turns %s, program %s\n", NR, ca[3], cb[3]; bad = 1 }
      arcs++
    }
    n++ }
  END { if (bad) exit 1; printf "rs274 read %d moves (%d arcs); every position matches the program text\n", n, arcs }'
