#!/usr/bin/env bash
# stylus-trace --tool on a STEP model's exact faces vs OpenCAMLib's BatchDropCutter on a fine
# tessellation of it (FreeCAD's mesher, scripts/step-stl.py, DEFLECTION mm from the faces), at the
# same points (the x,y of every tip stylus-trace writes), flat, ball, bull-nose and cone cutters
# R 3 mm, one core each (stylus-trace --threads 1, OpenCAMLib setThreads(1)): CL points per second
# of each and the largest difference of the tips (the STL's deflection bounds what the mesh
# adds: a tip on the mesh is within DEFLECTION / n_z of the exact one). Installs opencamlib
# into a virtualenv under $WORK; needs freecadcmd.
#
#   scripts/bench-dropcutter-step.sh
#   MODEL=data/step/block.step PICK=4 STEP=2 DEFLECTION=0.0005 scripts/bench-dropcutter-step.sh
set -euo pipefail
cd "$(dirname "$0")/.."
WORK=${WORK:-${CARGO_TARGET_DIR:-target}/bench-step}
MODEL=${MODEL:-data/step/block.step}
PICK=${PICK:-4}
STEP=${STEP:-2}
DEFLECTION=${DEFLECTION:-0.0005}
. scripts/ocl-env.sh
STL="$WORK/$(basename "$MODEL" .step).stl"
[ -s "$STL" ] || IN="$MODEL" OUT="$STL" DEFLECTION="$DEFLECTION" freecadcmd scripts/step-stl.py | tail -1
: > "$WORK/ocl-times.txt"
for C in flat ball bull cone; do
  "$BIN" "$MODEL" --tool "$WORK/$C.json" --pick "$PICK" --max-step "$STEP" --threads 1 -q \
    -o "$WORK/ours-$C.csv" --report "$WORK/ours-$C.json"
  "$PY" scripts/dropcutter-ocl.py at "$STL" "$C" "$WORK/ours-$C.csv" "$WORK/ocl-$C.csv" >> "$WORK/ocl-times.txt"
done
"$PY" - "$WORK" "$STL" <<'PYEOF'
import csv, json, struct, sys
work, stl = sys.argv[1], sys.argv[2]
n_tris = struct.unpack("<I", open(stl, "rb").read(84)[80:84])[0]
times = {l.split()[0]: (int(l.split()[1]), float(l.split()[2])) for l in open(f"{work}/ocl-times.txt")}
print(f"STL {n_tris} triangles; one core each")
print("| cutter | stylus-trace CL points/s (STEP faces) | OpenCAMLib CL points/s (STL) | ratio | largest difference | ours lower by > 0.1 µm |")
print("|---|---|---|---|---|---|")
for c in ["flat", "ball", "bull", "cone"]:
    rep = json.load(open(f"{work}/ours-{c}.json"))
    n, dt = times[c]
    ours_rows = list(csv.DictReader(open(f"{work}/ours-{c}.csv")))
    ocl_rows = list(csv.DictReader(open(f"{work}/ocl-{c}.csv")))
    worst, lower = 0.0, 0
    for a, b in zip(ours_rows, ocl_rows):
        d = float(a["z"]) - float(b["z"])
        worst = max(worst, abs(d))
        lower += d < -1e-4
    ours = rep["points_per_second"]
    print(f"| {c} | {ours:.0f} ({rep['points']} in {rep['trace_seconds']:.3f} s) | {n / dt:.1f} ({n} in {dt:.2f} s) "
          f"| {ours / (n / dt):.0f}× | {worst:.2e} mm | {lower} |")
PYEOF
