#!/usr/bin/env bash
# surf-probe-fit's sphere fit side by side with SciPy's least_squares (method "lm") on the same
# reference sets (ISO 10360-6 style, `surf-probe-fit reference`): agreement of centre and radius
# on 20 random sets (centres up to 1 m off the origin, caps 20°..180°), and fit time on 1 M points
# (ours with one thread, fit alone; SciPy's least_squares alone, numpy vectorised, analytic
# Jacobian). Then robust fitting: 100 k points of which 35 % gross outliers, our --robust ransac
# against SciPy's robust losses (method "trf"), error against the true sphere and time.
# Installs scipy into a virtual environment under target/ (not part of `make test`).
#
#   scripts/bench-fit-scipy.sh [--robust-only]
set -euo pipefail
cd "$(dirname "$0")/.."
target=${CARGO_TARGET_DIR:-target}
venv=$target/bench-venv
[ -x "$venv/bin/python" ] || { python3 -m venv "$venv" && "$venv/bin/pip" install -q scipy numpy; }
py=$venv/bin/python
cargo build --release -q -p surf-probe-fit
bin=$target/release/surf-probe-fit
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

robust_only=${1:-}
if [ "$robust_only" != --robust-only ]; then
for seed in $(seq 1 20); do
  cx=$(( (seed * 7919) % 2000 - 1000 )); cy=$(( (seed * 104729) % 1600 - 800 )); cz=$(( (seed * 31) % 600 ))
  cap=$(( 20 + (seed * 37) % 161 )); r=$(( 5 + (seed * 13) % 200 ))
  "$bin" reference --centre "$cx,$cy,$cz" --radius "$r" --extent "$cap" --points 500 --seed "$seed" \
    --amplitude 0.02 -o "$work/p.csv"
  "$bin" fit "$work/p.csv" -o "$work/f.json" 2>/dev/null
  line=$("$py" scripts/bench-fit-scipy.py "$work/p.csv" "$work/f.json")
  echo "seed $seed centre ($cx,$cy,$cz) r $r cap $cap°: $line"
done

"$bin" reference --centre 120,-85,64 --radius 25 --extent 90 --points 1000000 --seed 1 -o "$work/big.csv"
RAYON_NUM_THREADS=1 "$bin" fit "$work/big.csv" -o "$work/big.json" --report "$work/big-report.json"
echo "1M points, one thread: $("$py" scripts/bench-fit-scipy.py "$work/big.csv" "$work/big.json" "$work/big-report.json")"
"$bin" fit "$work/big.csv" -o "$work/big.json" --report "$work/big-report.json"
echo "1M points, all cores: $("$py" scripts/bench-fit-scipy.py "$work/big.csv" "$work/big.json" "$work/big-report.json")"
fi

# Robust: an R25 sphere's 65 000 points (90° cap, residuals ±0.002 mm with the true sphere as
# their least-squares solution) and 35 000 gross outliers.
truth=120,-85,64,25
"$bin" reference --centre 120,-85,64 --radius 25 --extent 90 --points 65000 --amplitude 0.002 --seed 3 \
  -o "$work/in.csv"
"$py" scripts/bench-fit-scipy.py --outliers "$work/in.csv" 35000 "$truth" 1 > "$work/dirty.csv"
for threads in 1 2; do
  echo "100k points, 35 % outliers, RAYON_NUM_THREADS=$threads:"
  RAYON_NUM_THREADS=$threads "$bin" fit "$work/dirty.csv" --robust ransac -o "$work/r.json" --report "$work/rr.json"
  "$py" scripts/bench-fit-scipy.py --robust "$work/dirty.csv" "$work/r.json" "$work/rr.json" "$truth"
done
