#!/usr/bin/env bash
# Checks every NC program the demo parts wrote (out/<part>/*.ngc), as `make test` runs it after
# `make demo`:
#   - LinuxCNC's interpreter reads it and agrees with our reader block by block
#     (scripts/linuxcnc-check.sh; skipped with a note where rs274 is not installed);
#   - its post report (<name>.json beside it) shows the collision check ran and found 0 rapids
#     into material and 0 moves nearer the part than allowed (programs the post wrote with a
#     setup), and prints the smallest clearances.
# Exit 1 if any program fails.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out}
shopt -s nullglob
programs=("$out"/*/*.ngc)
[ ${#programs[@]} -gt 0 ] || { echo "no programs under $out/: run make demo first" >&2; exit 1; }
have_rs274=1
command -v rs274 >/dev/null || { have_rs274=0; echo "rs274 not installed (scripts/install-linuxcnc.sh): LinuxCNC checks skipped"; }
failed=0
for prog in "${programs[@]}"; do
  line="$prog:"
  if [ $have_rs274 = 1 ]; then
    if msg=$(scripts/linuxcnc-check.sh "$prog" 2>&1); then
      line+=" rs274 ok (${msg##*read })"
    else
      line+=" rs274 FAILED: $msg"; failed=1
    fi
  fi
  report=${prog%.ngc}.json
  if [ -f "$report" ] && grep -q '"collision_checked"' "$report"; then
    summary=$(python3 - "$report" <<'EOF'
import json, sys
r = json.load(open(sys.argv[1]))
bad = r["rapids_into_material"] != 0 or r["part_collisions"] != 0
fmt = lambda v: "none" if v is None else f"{v:.6f} mm"
print(("FAILED " if bad else "") + f"collisions: {r['rapids_into_material']} rapids into material, "
      f"{r['part_collisions']} moves too near the part; smallest rapid clearance {fmt(r['smallest_rapid_clearance_mm'])}, "
      f"smallest feed clearance {fmt(r['smallest_feed_clearance_mm'])} ({r['part_checked']})")
sys.exit(1 if bad else 0)
EOF
) || failed=1
    line+="; $summary"
  else
    line+="; no collision report (not posted with a setup)"
  fi
  echo "$line"
done
exit $failed
