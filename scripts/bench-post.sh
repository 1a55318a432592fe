#!/usr/bin/env bash
# post-6axis speed, side by side with LinuxCNC's own G-code interpreter (rs274, Debian package
# linuxcnc-uspace, scripts/install-linuxcnc.sh) on the same program.
#
# Input: paper 000's smoothing of an R500 sphere: scan lines along X, 1 mm apart, a row every
# 0.2 mm (1000 rows a line), tool axis on the normal tilted −5° towards the feed, spindle
# orientation `s` facing the feed; ROWS rows (default 100000). Posted for the six-axis machine
# (data/post-6axis/paper000-sixaxis-b.json, spindle as the B address) and the A/C machine of paper
# 002 (paper002-ac.json, no `s`). post-6axis is single-threaded, so every figure is one core.
#
#  1. benches/cpu.rs: rows per CPU-second of one thread for the poses and the linearisation
#     check (the issue's "before linearisation inserts"), the NC text, and the whole post with its
#     read-back check; then the same stages in criterion (benches/post.rs, wall clock);
#  2. the binary end to end (read CSV, post, read the program back, write it), best of 3 in CPU
#     seconds (user + system: the machine is shared, wall-clock time would measure the others);
#  3. the written program through rs274 (parse and interpret, canonical calls to a file), best of
#     3, beside `post-6axis --reverse` (read NC, forward kinematics, write the table) and
#     `post-6axis --verify` (read NC, sample every block 32 times against the rows).
#
#   scripts/bench-post.sh [ROWS]          (SKIP_CRITERION=1 skips the criterion part of step 1)
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-target}
rows=${1:-100000}
command -v rs274 >/dev/null || { echo "rs274 not installed: run scripts/install-linuxcnc.sh" >&2; exit 2; }
cargo build --release -q -p post-6axis
bin=$CARGO_TARGET_DIR/release/post-6axis
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for t in $(seq 1 20); do echo "T$t P$t Z0 D10 ;"; done > "$work/tool.tbl"

# CL rows on the R500 sphere (centre 0, 0, −500); with_s=1 adds the spindle orientation column,
# the edge along the feed measured from camkit::kinematics::spindle_reference.
cl() {
  awk -v n="$rows" -v with_s="$1" 'BEGIN {
    R = 500; cz = -500; pi = atan2(0, -1); t = -5 * pi / 180
    printf "path,x,y,z,i,j,k,%sf\n", (with_s ? "s," : "")
    for (r = 0; r < n; r++) {
      line = int(r / 1000); x = -100 + (r % 1000) * 0.2; y = -50 + line * 1.0
      h = sqrt(R * R - x * x - y * y); z = cz + h
      nx = x / R; ny = y / R; nz = h / R
      tx = 1; ty = 0; tz = -x / h; d = tx * nx + ty * ny + tz * nz
      tx -= d * nx; ty -= d * ny; tz -= d * nz; l = sqrt(tx * tx + ty * ty + tz * tz); tx /= l; ty /= l; tz /= l
      u = nx * cos(t) + tx * sin(t); v = ny * cos(t) + ty * sin(t); w = nz * cos(t) + tz * sin(t)
      l = sqrt(u * u + v * v + w * w); u /= l; v /= l; w /= l
      printf "%d,%.6f,%.6f,%.6f,%.12f,%.12f,%.12f,", line, x, y, z, u, v, w
      if (with_s) {
        rx = w + v * v / (1 + w); ry = -u * v / (1 + w); rz = -u; l = sqrt(rx * rx + ry * ry + rz * rz)
        rx /= l; ry /= l; rz /= l
        yx = v * rz - w * ry; yy = w * rx - u * rz; yz = u * ry - v * rx
        printf "%.6f,", atan2(tx * yx + ty * yy + tz * yz, tx * rx + ty * ry + tz * rz) * 180 / pi
      }
      printf "1000\n"
    }
  }'
}
cl 1 > "$work/six.csv"
cl 0 > "$work/five.csv"

# Best CPU seconds (user + system, the machine is shared) of 3 runs of a command, output discarded.
best() {
  python3 - "$@" <<'PY'
import resource, subprocess, sys
def cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime
times = []
for _ in range(3):
    t0 = cpu()
    subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    times.append(cpu() - t0)
print(f"{min(times):.3f}")
PY
}

echo "== rows per CPU-second of one thread: crates/post-6axis/benches/cpu.rs"
cargo bench -q -p post-6axis --bench cpu 2>/dev/null | grep '^|'
if [ -z "${SKIP_CRITERION:-}" ]; then
  echo; echo "== criterion (wall clock): crates/post-6axis/benches/post.rs (100000 rows, six-axis machine)"
  cargo bench -q -p post-6axis --bench post 2>&1 | grep -E '^post-6axis|thrpt' || true
fi

printf '\n| machine | rows | blocks | post-6axis post + read-back (CPU s) | rows per CPU-s | rs274 on the program (CPU s) | post-6axis --reverse (CPU s) | post-6axis --verify (CPU s) | rs274 / post |\n'
printf '|---|---|---|---|---|---|---|---|---|\n'
for case in "paper000-sixaxis-b.json six" "paper002-ac.json five"; do
  set -- $case
  m=data/post-6axis/$1 in=$work/$2.csv
  "$bin" "$in" --machine "$m" -o "$work/p.ngc" --report "$work/r.json" 2> /dev/null
  # rs274 must read the program without error before it is timed.
  rs274 -t "$work/tool.tbl" -g "$work/p.ngc" > "$work/canon" 2> "$work/rs274.err" ||
    { echo "rs274 refused the program:" >&2; cat "$work/rs274.err" >&2; exit 1; }
  blocks=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['blocks'])" "$work/r.json")
  t_post=$(best "$bin" "$in" --machine "$m" -o "$work/p2.ngc")
  t_rs=$(best rs274 -t "$work/tool.tbl" -g "$work/p.ngc")
  t_rev=$(best "$bin" "$work/p.ngc" --machine "$m" --reverse -o "$work/back.csv")
  t_ver=$(best "$bin" "$in" --machine "$m" --verify "$work/p.ngc")
  python3 - "$1" "$rows" "$blocks" "$t_post" "$t_rs" "$t_rev" "$t_ver" <<'EOF'
import sys
m, rows, blocks, tp, tr, tv, tve = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), *map(float, sys.argv[4:])
print(f"| {m} | {rows} | {blocks} | {tp:.3f} | {rows / tp:,.0f} | {tr:.3f} | {tv:.3f} | {tve:.3f} | {tr / tp:.1f} |")
EOF
done
