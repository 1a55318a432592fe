# Sourced by the drop-cutter benches: opencamlib in a virtualenv under $WORK, a release
# stylus-trace, and the four cutters both sides run (R 3 mm: flat, ball, bull-nose r 1, cone of
# half-angle 0.6 rad) as tool documents in $WORK. Sets BIN and PY.
mkdir -p "$WORK"
if [ ! -x "$WORK/venv/bin/python" ]; then
  python3 -m venv "$WORK/venv"
fi
"$WORK/venv/bin/pip" install -q opencamlib
cargo build -q --release -p stylus-trace
BIN=${CARGO_TARGET_DIR:-target}/release/stylus-trace
PY="$WORK/venv/bin/python"
echo '{"kind": "flat", "radius": 3}' > "$WORK/flat.json"
echo '{"kind": "ball", "radius": 3}' > "$WORK/ball.json"
echo '{"kind": "bull", "radius": 3, "corner_radius": 1}' > "$WORK/bull.json"
echo '{"kind": "cone", "radius": 3, "half_angle": 34.37746770784939}' > "$WORK/cone.json"
