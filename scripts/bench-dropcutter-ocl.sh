#!/usr/bin/env bash
# stylus-trace --tool (fixed-axis drop-cutter) vs OpenCAMLib's BatchDropCutter (PyPI `opencamlib`)
# with CylCutter, BallCutter, BullCutter and ConeCutter on the same STL and the same grid, one
# core each (stylus-trace --threads 1, OpenCAMLib setThreads(1)): CL points per second of each
# and the largest difference of the tips. Installs opencamlib into a virtualenv under $WORK and
# makes its STL with scripts/dropcutter-ocl.py (the free-form height field of the committed test
# mesh, 20 × 20 mm, at CELLS × CELLS cells, two triangles each).
#
#   scripts/bench-dropcutter-ocl.sh
#   CELLS=40 PICK=0.5 scripts/bench-dropcutter-ocl.sh
set -euo pipefail
cd "$(dirname "$0")/.."
WORK=${WORK:-${CARGO_TARGET_DIR:-target}/bench-ocl}
CELLS=${CELLS:-100}     # 20 000 triangles
PICK=${PICK:-0.25}      # between lines (mm)
STEP=${STEP:-0.1}       # along a line (mm)
REGION=-3,23,-3,23
. scripts/ocl-env.sh
STL="$WORK/dropcut-$CELLS.stl"
"$PY" scripts/dropcutter-ocl.py stl "$STL" "$CELLS"
"$PY" scripts/dropcutter-ocl.py drop "$STL" "$REGION" "$PICK" "$STEP" "$WORK/ocl.csv" > "$WORK/ocl-times.txt"
for C in flat ball bull cone; do
  "$BIN" "$STL" --tool "$WORK/$C.json" --region=$REGION --pick "$PICK" --max-step "$STEP" --threads 1 \
    -o "$WORK/ours-$C.csv" --report "$WORK/ours-$C.json"
done
"$PY" - "$WORK" "$CELLS" <<'PYEOF'
import csv, json, sys
work, cells = sys.argv[1], int(sys.argv[2])
times = {l.split()[0]: (int(l.split()[1]), float(l.split()[2])) for l in open(f"{work}/ocl-times.txt")}
ocl = {}
for r in csv.DictReader(l for l in open(f"{work}/ocl.csv") if not l.startswith("#")):
    ocl[(r["cutter"], float(r["x"]) + 0.0, float(r["y"]) + 0.0)] = float(r["z"])
print(f"mesh {2 * cells * cells} triangles; one core each")
print("| cutter | stylus-trace CL points/s | OpenCAMLib CL points/s | ratio | largest difference | points differing > 1 µm (ours higher at) |")
print("|---|---|---|---|---|---|")
for c in ["flat", "ball", "bull", "cone"]:
    rep = json.load(open(f"{work}/ours-{c}.json"))
    n, dt = times[c]
    worst, over, higher = 0.0, 0, 0
    for r in csv.DictReader(open(f"{work}/ours-{c}.csv")):
        d = float(r["z"]) - ocl[(c, float(r["x"]) + 0.0, float(r["y"]) + 0.0)]
        worst = max(worst, abs(d))
        over += abs(d) > 1e-6
        higher += d > 1e-6
    ours = rep["points_per_second"]
    print(f"| {c} | {ours:.0f} ({rep['points']} in {rep['trace_seconds']:.3f} s) | {n / dt:.0f} ({n} in {dt:.2f} s) "
          f"| {ours / (n / dt):.0f}× | {worst:.2e} mm | {over} ({higher}) |")
PYEOF
