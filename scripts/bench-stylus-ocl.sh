#!/usr/bin/env bash
# stylus-trace vs OpenCAMLib (PyPI `opencamlib`) on the same STL files and the same raster:
# CL points per second for each, and the largest distance from our ball centres to OpenCAMLib's
# densely sampled CL curve on the same scan lines (both are exact on the mesh: they must agree to
# 1 µm). Installs opencamlib, numpy and numpy-stl into a virtualenv under $WORK and makes its own
# STL files: a 100 × 100 mm free-form height field of ≈20 k and ≈200 k triangles; last, the load
# time of the same field at ≈1 M triangles.
#
#   scripts/bench-stylus-ocl.sh            # both meshes
#   MESHES=20000 scripts/bench-stylus-ocl.sh
set -euo pipefail
cd "$(dirname "$0")/.."
WORK=${WORK:-${CARGO_TARGET_DIR:-target}/bench-ocl}
MESHES=${MESHES:-"20000 200000"}
R=5          # ball radius (mm)
PICK=1       # pick feed (mm)
STEP=0.5     # OpenCAMLib's sampling along the line (mm); our longest step
mkdir -p "$WORK"
if [ ! -x "$WORK/venv/bin/python" ]; then
  python3 -m venv "$WORK/venv"
fi
"$WORK/venv/bin/pip" install -q opencamlib numpy numpy-stl
cargo build -q --release -p stylus-trace
BIN=${CARGO_TARGET_DIR:-target}/release/stylus-trace
PY="$WORK/venv/bin/python"

# make_stl FILE TRIANGLES: the free-form height field as binary STL.
make_stl() {
  [ -f "$1" ] || "$PY" - "$1" "$2" <<'EOF'
import sys, math
import numpy as np
from stl import mesh
path, tris = sys.argv[1], int(sys.argv[2])
n = int(round(math.sqrt(tris / 2)))          # n × n cells, two triangles each
x = np.linspace(0.0, 100.0, n + 1)
X, Y = np.meshgrid(x, x, indexing="ij")
Z = 6 * np.sin(X / 17) * np.cos(Y / 23) + 3 * np.sin((X + 2 * Y) / 11) + 0.05 * X
P = np.stack([X, Y, Z], axis=-1)
a, b, c, d = P[:-1, :-1], P[1:, :-1], P[1:, 1:], P[:-1, 1:]
t = np.concatenate([np.stack([a, b, c], axis=-2).reshape(-1, 3, 3), np.stack([a, c, d], axis=-2).reshape(-1, 3, 3)])
m = mesh.Mesh(np.zeros(len(t), dtype=mesh.Mesh.dtype))
m.vectors[:] = t
m.save(path)
print(f"{path}: {len(t)} triangles")
EOF
}

for TRIS in $MESHES; do
  STL="$WORK/freeform-$TRIS.stl"
  make_stl "$STL" "$TRIS"

  # stylus-trace: the whole raster, lines y = 0.5 .. 99.5 every PICK, x 0 .. 100.
  "$BIN" "$STL" -r $R --pick $PICK --region 0,100,0.5,99.5 --max-step $STEP \
    -o "$WORK/ours-$TRIS.csv" --report "$WORK/ours-$TRIS.json"

  # OpenCAMLib: BatchDropCutter (OpenMP, all cores) on the same raster (every line on the small
  # mesh, every tenth on the large one: points per second is a rate), then dense sampling
  # (0.02 mm) of x 40 .. 60 on two lines for the agreement figure.
  "$PY" - "$STL" "$TRIS" "$WORK" $R $PICK $STEP <<'EOF'
import sys, time, json, csv, bisect
import opencamlib as ocl
path, tris, work, r, pick, step = sys.argv[1], int(sys.argv[2]), sys.argv[3], float(sys.argv[4]), float(sys.argv[5]), float(sys.argv[6])
surf = ocl.STLSurf()
ocl.STLReader(path, surf)
cutter = ocl.BallCutter(2 * r, 50)

def drop(points):
    bdc = ocl.BatchDropCutter()
    bdc.setSTL(surf)
    bdc.setCutter(cutter)
    for x, y in points:
        bdc.appendPoint(ocl.CLPoint(x, y, -100))
    t0 = time.perf_counter()
    bdc.run()
    dt = time.perf_counter() - t0
    cl = [(p.x, p.y, p.z + r) for p in bdc.getCLPoints()]   # tip + r = ball centre
    return cl, dt

every = 1 if tris < 100000 else 10
ys = [0.5 + k * pick for k in range(0, 100, every)]
xs = [i * step for i in range(int(100 / step) + 1)]
cl, dt = drop([(x, y) for y in ys for x in xs])
ocl_rate = len(cl) / dt

ours = json.load(open(f"{work}/ours-{tris}.json"))
rows = list(csv.DictReader(open(f"{work}/ours-{tris}.csv")))
worst = 0.0
for y in (30.5, 70.5):
    dense_x = [40 + i * 0.02 for i in range(1001)]
    dense, _ = drop([(x, y) for x in dense_x])
    dense.sort()
    px = [p[0] for p in dense]
    for row in rows:
        cx, cy, cz = float(row["x"]), float(row["y"]), float(row["z"])
        if abs(cy - y) > 1e-9 or not (40.5 <= cx <= 59.5):
            continue
        k = bisect.bisect_left(px, cx)
        best = float("inf")
        for j in range(max(0, k - 3), min(len(dense) - 1, k + 3)):
            (ax, _, az), (bx, _, bz) = dense[j], dense[j + 1]
            dx, dz = bx - ax, bz - az
            t = max(0.0, min(1.0, ((cx - ax) * dx + (cz - az) * dz) / (dx * dx + dz * dz)))
            best = min(best, ((cx - ax - t * dx) ** 2 + (cz - az - t * dz) ** 2) ** 0.5)
        worst = max(worst, best)

print(f"mesh {tris} triangles, ball r {r}, pick {pick}, step {step}")
print(f"  stylus-trace : {ours['points']} CL points in {ours['trace_seconds']:.3f} s "
      f"= {ours['points_per_second']:.0f} points/s ({ours['threads']} threads; load {ours['load_seconds']:.3f} s)")
print(f"  OpenCAMLib   : {len(cl)} CL points in {dt:.3f} s = {ocl_rate:.1f} points/s ({ocl.max_threads()} threads)")
print(f"  ratio        : {ours['points_per_second'] / ocl_rate:.0f}x")
print(f"  agreement    : largest distance from our centres to OpenCAMLib's dense CL curve "
      f"(y 30.5, 70.5; x 40.5..59.5) = {worst * 1000:.4f} µm")
EOF
done

# Loading: a 1 M-triangle STL (read, checked, indexed), traced over a 1 mm² patch only.
STL="$WORK/freeform-1000000.stl"
make_stl "$STL" 1000000
"$BIN" "$STL" -r $R --region 40,41,50,51 -o "$WORK/load.csv" --report "$WORK/load.json"
"$PY" -c "import json; r = json.load(open('$WORK/load.json')); print(f\"load: {r['triangles']} triangles in {r['load_seconds']:.2f} s\")"
