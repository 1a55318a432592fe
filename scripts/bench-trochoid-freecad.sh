#!/usr/bin/env bash
# medial-trochoid against FreeCAD's adaptive clearing on the box-die cavity, one layer, φ10:
# our trochoids-first and offset-only programs, and FreeCAD 0.20's Adaptive2d (driven by
# scripts/freecad-adaptive.py) at the step over whose straight side cut is our 40° threshold
# (11.82 % of the diameter: Adaptive2d keeps the cut area per mm of travel at
# 2·f·A_ref/R, A_ref the crescent a disk sweeps advancing R/2 = 0.98948 R², so a side cut of
# width a = 1.97897 f R; R(1 − cos 40°) gives f = 0.11822) and at 4 % (a third of it). Every
# program is re-simulated by `medial-trochoid --analyse` (same exact engagement at the same 1 mm
# sample step, same feed model and gouge check); our own program is analysed too as a
# cross-check of the mode against the planner's figures. Needs `apt-get install freecad`.
set -euo pipefail
cd "$(dirname "$0")/.."
TARGET=${CARGO_TARGET_DIR:-target}
cargo build --release -q -p medial-trochoid --bins
B="$TARGET/release/medial-trochoid"
SRC=data/medial-trochoid/box-die.csv
COMMON=(--radius 5 --sample 1 --trochoid-radius 2.5)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
uptime
field() { python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print(' '.join(f'{k}={r[k]:.6g}' if isinstance(r[k], float) else f'{k}={r[k]}' for k in sys.argv[2:]))" "$@"; }
"$B" "$SRC" "${COMMON[@]}" --report "$tmp/ours.json" -o "$tmp/ours.csv"
echo "ours (plan, both programs): $(field "$tmp/ours.json" largest_engagement_deg samples_over_threshold link_samples_over_threshold trochoid_length_mm contour_length_mm trochoidal_minutes trochoidal_chip_only_minutes trochoidal_constant_feed_minutes offset_only_largest_engagement_deg offset_only_samples_over_threshold offset_only_length_mm offset_only_minutes offset_only_chip_only_minutes offset_only_variable_feed_minutes no_gouge seconds)"
"$B" "$SRC" "${COMMON[@]}" --analyse "$tmp/ours.csv" --report "$tmp/ours-a.json" -o "$tmp/ours-a.csv"
echo "ours trochoids first, analysed: $(field "$tmp/ours-a.json" largest_engagement_deg samples_over_threshold link_samples_over_threshold length_mm minutes chip_only_minutes constant_feed_minutes constant_feed_chip_only_minutes smallest_wall_clearance_mm seconds)"
"$B" "$SRC" "${COMMON[@]}" --program offset --report "$tmp/off.json" -o "$tmp/off.csv"
"$B" "$SRC" "${COMMON[@]}" --analyse "$tmp/off.csv" --report "$tmp/off-a.json" -o "$tmp/off-a.csv"
echo "ours offset only, analysed: $(field "$tmp/off-a.json" largest_engagement_deg samples_over_threshold length_mm minutes chip_only_minutes constant_feed_minutes constant_feed_chip_only_minutes smallest_wall_clearance_mm)"
for step in 11.82 4; do
  python3 scripts/freecad-adaptive.py "$SRC" "$tmp/fc.csv" --diameter 10 --stepover "$step" --stock 0 0 100 100 --top 60
  "$B" "$SRC" "${COMMON[@]}" --analyse "$tmp/fc.csv" --report "$tmp/fc.json" -o "$tmp/fc-a.csv"
  echo "freecad adaptive $step %, analysed: $(field "$tmp/fc.json" largest_engagement_deg samples_over_threshold length_mm entry_length_mm minutes chip_only_minutes constant_feed_minutes constant_feed_chip_only_minutes smallest_wall_clearance_mm seconds)"
  python3 - "$tmp/fc-a.csv" <<'PY'
import csv, sys
e = sorted(float(r["engagement"]) for r in csv.DictReader(open(sys.argv[1])) if r["engagement"] and r["tag"] != "entry")
n = len(e)
print("  engagement percentiles 50/90/99/100:", [round(e[int(q * (n - 1))], 1) for q in (0.5, 0.9, 0.99, 1.0)])
PY
done

# Adaptive strategy (issue 22) against FreeCAD's adaptive at 11.82 % on box-die and three more
# pockets (islands, a narrow neck, a round one): FreeCAD's program analysed first (its largest
# engagement is the bound for our target), then ours planned on one core (RAYON_NUM_THREADS=1,
# the plan's own time in plan_seconds) at each target of ADAPTIVE_TARGETS (default "40 freecad":
# 40° and FreeCAD's largest engagement on that pocket rounded down to the degree) and analysed
# by the same referee; all at the same feed model (force limit of the 40° side cut, --force-at 40).
# Each pocket is 10 mm deep under FreeCAD's --top, which FreeCAD enters by a 5° helix: ours is
# planned as one 10 mm layer at the same default 5° (--layers 1 --layer-depth 10), so both pay
# their entry. REFEREE (default 1) is the referee's sample step in mm: 0.25 finds what falls
# between a program's 1 mm samples (the 1 mm referee also times each stretch at its slower end's
# feed, 3-5 % pessimistic on these programs).
TARGETS=${ADAPTIVE_TARGETS:-40 freecad}
REFEREE=${REFEREE:-1}
DEPTH=(--layers 1 --layer-depth 10)
TOOL=(--radius 5 --trochoid-radius 2.5)
echo "pocket | FreeCAD: largest, length, min (feed following / one feed per kind), Execute s | ours adaptive: largest, length (links), min (feed following / one feed per kind), plan s | ratios"
for spec in "box-die 0 0 100 100 60" "islands2 0 0 100 60 10" "dumbbell 0 0 94 40 10" "circle40 10 10 90 90 10"; do
  set -- $spec
  P=$1
  SRCP=data/medial-trochoid/$P.csv
  fcout=$(python3 scripts/freecad-adaptive.py "$SRCP" "$tmp/fc-$P.csv" --diameter 10 --stepover 11.82 --stock "$2" "$3" "$4" "$5" --top "$6")
  fcsec=$(echo "$fcout" | sed -n 's/.*seconds \([0-9.]*\).*/\1/p')
  "$B" "$SRCP" "${TOOL[@]}" --sample "$REFEREE" --threshold 40 --force-at 40 --analyse "$tmp/fc-$P.csv" --report "$tmp/fc-$P.json" -o "$tmp/fca-$P.csv"
  for TARGET_DEG in $TARGETS; do
  # "freecad": FreeCAD's measured largest engagement rounded down to the degree (the issue's bound).
  [ "$TARGET_DEG" = freecad ] && TARGET_DEG=$(python3 -c "import json,sys,math; print(math.floor(json.load(open(sys.argv[1]))['largest_engagement_deg']))" "$tmp/fc-$P.json")
  RAYON_NUM_THREADS=1 "$B" "$SRCP" "${COMMON[@]}" "${DEPTH[@]}" --strategy adaptive --threshold "$TARGET_DEG" --force-at 40 --report "$tmp/ad-$P.json" -o "$tmp/ad-$P.csv" 2>/dev/null
  "$B" "$SRCP" "${TOOL[@]}" --sample "$REFEREE" --threshold "$TARGET_DEG" --force-at 40 --analyse "$tmp/ad-$P.csv" --report "$tmp/ada-$P.json" -o "$tmp/adaa-$P.csv"
  python3 - "$P@$TARGET_DEG°" "$fcsec" "$tmp/fc-$P.json" "$tmp/ad-$P.json" "$tmp/ada-$P.json" <<'PY'
import json, sys
p, fcsec = sys.argv[1], float(sys.argv[2])
fc, ad, ada = (json.load(open(f)) for f in sys.argv[3:6])
print(f"{p} | {fc['largest_engagement_deg']:.1f}°, {fc['length_mm']:.0f} mm, {fc['minutes']:.2f} / {fc['constant_feed_minutes']:.2f} min, {fcsec:.2f} s, gouge-free {fc['no_gouge']}"
      f" | {ada['largest_engagement_deg']:.4f}°, {ada['length_mm']:.0f} mm ({ad['link_length_mm']:.0f}), {ada['minutes']:.2f} / {ada['constant_feed_minutes']:.2f} min, {ad['plan_seconds']:.2f} s, gouge-free {ada['no_gouge']}, uncut {ad['uncut_area_mm2']:.1f} mm²"
      f" | {ada['minutes'] / fc['minutes']:.2f}x / {ada['constant_feed_minutes'] / fc['constant_feed_minutes']:.2f}x, plan {ad['plan_seconds'] / fcsec:.2f}x")
# Where the time goes (feed following; minutes / mm per kind; retracts: count / mm, not timed).
kinds = lambda t: ", ".join(f"{k} {v['minutes']:.2f} min / {v['mm']:.0f} mm" if 'minutes' in v else f"{k} {v['count']:.0f} / {v['mm']:.0f} mm" for k, v in t.items())
print(f"  FreeCAD by kind: {kinds(fc['time_by_kind'])}; chains {fc['chains']}, air above the layer {fc['air_length_mm']:.0f} mm")
print(f"  ours by kind:    {kinds(ada['time_by_kind'])}")
PY
  # Passes by length (a pass: a run of cutting rows; with it the links and air rows before it),
  # minutes as each row's length over its analysed feed: where short passes cost the time.
  for prog in "FreeCAD:$tmp/fca-$P.csv" "ours:$tmp/adaa-$P.csv"; do
  python3 - "${prog%%:*}" "${prog#*:}" <<'PY'
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[2])))
passes, prev, link, cutting_before = [], None, [0.0, 0.0], False
for r in rows:
    p = (float(r["x"]), float(r["y"]))
    d = math.dist(prev, p) if prev and r["move"] in ("line", "cw", "ccw") and r["f"] else 0.0
    t = d / float(r["f"]) if d else 0.0
    prev = p
    cutting = r["tag"] in ("contour", "cutting")
    if cutting and not cutting_before:
        passes.append({"mm": 0.0, "min": 0.0, "link_min": link[1]})
        link = [0.0, 0.0]
    cutting_before = cutting
    if cutting:
        passes[-1]["mm"] += d
        passes[-1]["min"] += t
    elif r["tag"] != "entry":
        link = [link[0] + d, link[1] + t]
passes = [g for g in passes if g["mm"] > 0]
out = []
for lo, hi in ((0, 5), (5, 15), (15, 50), (50, math.inf)):
    g = [x for x in passes if lo <= x["mm"] < hi]
    out.append(f"{lo}-{hi} mm: {len(g)}, {sum(x['min'] for x in g):.2f} + links {sum(x['link_min'] for x in g):.2f} min")
print(f"  {sys.argv[1]} passes ({len(passes)}) by length: " + "; ".join(out))
PY
  done
  done
done
