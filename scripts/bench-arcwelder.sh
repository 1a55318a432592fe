#!/usr/bin/env bash
# curve-fit-arcs side by side with ArcWelder on the shared G-code corpus.
#
# For each file and each tolerance pair (ours --tol 0.025 vs ArcWelder -y, i.e. resolution
# 0.05 mm = a ±0.025 mm band; ours --tol 0.005 vs ArcWelder -y -r=0.01), it prints the feed moves
# (G1/G2/G3) each program writes, the largest deviation of each from the original measured by
# the same independent instrument (tests/paths.rs: dense sampling, exact distances), and our
# throughput (best of 5 runs, one core, read + fit + write). ArcWelder's outputs are the corpus's
# own (arcwelder/, made with ArcWelder 2.0 as its README says); its speed there was 7-21 MB/s.
#
#   scripts/bench-arcwelder.sh [CORPUS_DIR]     (default ../shared/data/gcode-corpus)
set -euo pipefail
cd "$(dirname "$0")/.."
corpus=${1:-../shared/data/gcode-corpus}
[ -d "$corpus/arcwelder" ] || { echo "corpus not found at $corpus" >&2; exit 2; }
cargo build --release -q -p curve-fit-arcs -p e2e --example deviation
rel=${CARGO_TARGET_DIR:-target}/release
fit=$rel/curve-fit-arcs
measure=$rel/examples/deviation
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# The explicit-G1 variant of the modal wheels file, as the corpus README describes it.
awk '{ line = $0; up = toupper(line)
       if (match(up, /G0*[0-3]([^0-9.]|$)/)) { mode = substr(up, RSTART, RLENGTH); gsub(/[^G0-9]/, "", mode); sub(/G0*/, "", mode) }
       else if (up ~ /^[ \t]*[XYZ]/ && mode != "") { line = "G" mode " " line }
       print line }' "$corpus/linuxcnc_wheels.ngc" > "$work/linuxcnc_wheels_explicitG1.ngc"

printf '| file | tol (mm) | input moves | ArcWelder moves | ours | ours vs AW | proved floor | AW deviation (mm) | our deviation (mm) | our MB/s |\n'
printf '|---|---|---|---|---|---|---|---|---|---|\n'
for f in cncjs_tball-pocket.gcode cncjs_jsdc-engrave.gcode linuxcnc_trochoidal.ngc linuxcnc_wheels_explicitG1.ngc \
         gcode-preview_benchy_prusaslicer261.gcode gcode-preview_vase_prusaslicer274.gcode \
         linuxcnc_wheels.ngc linuxcnc_3D_Chips_2006.ngc linuxcnc_circle_small_segments_ncd.ngc; do
  src=$corpus/$f
  [ -f "$src" ] || src=$work/$f
  stem=${f%.*}
  for pair in "0.025 aw_y" "0.005 aw_yr0.01"; do
    set -- $pair
    tol=$1 aw=$corpus/arcwelder/$stem.$2.gcode
    best=0
    for _ in 1 2 3 4 5; do
      "$fit" "$src" --tol "$tol" -o "$work/out" --report "$work/r.json"
      mbs=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['mb_per_second'])" "$work/r.json")
      best=$(python3 -c "print(max($best, $mbs))")
    done
    read -r n_in n_ours d_ours < <("$measure" "$src" "$work/out" "$tol")
    # The proved floor of any segmentation, in feed moves (rapids pass through unchanged).
    "$fit" "$src" --tol "$tol" -o "$work/out" --report "$work/r.json" --lower-bound
    floor=$(python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print(r['moves_lower_bound'] - (r['output_moves'] - $n_ours))" "$work/r.json")
    if [ -f "$aw" ]; then
      read -r _ n_aw d_aw < <("$measure" "$src" "$aw" "$tol")
      ratio=$(python3 -c "print(f'{($n_ours / $n_aw - 1) * 100:+.0f} %')")
      d_aw=$(printf '%.5f' "$d_aw")
    else
      n_aw="—" ratio="—" d_aw="—"
    fi
    printf '| %s | %s | %s | %s | %s | %s | %s | %s | %.5f | %.0f |\n' "$f" "$tol" "$n_in" "$n_aw" "$n_ours" "$ratio" "$floor" "$d_aw" "$d_ours" "$best"
  done
done
