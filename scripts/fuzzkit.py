"""Shared parts of the fuzzers in scripts/: the binary under test, scratch files, exact 2D
distances, arcs from bulges, and the closing summary (exit status 1 if any defect was kept)."""
import math, os, sys

def binary(name):
    """The release binary `name`: $NAME (upper case, dashes as underscores) or the target dir's."""
    env = name.upper().replace("-", "_")
    return os.environ.get(env, os.path.join(os.environ.get("CARGO_TARGET_DIR", "target"), "release", name))

def scratch(tag):
    """An input and an output path for this run in $TMPDIR."""
    tmp = os.environ.get("TMPDIR", "/tmp")
    return tuple(os.path.join(tmp, f"{tag}-{os.getpid()}{end}") for end in (".csv", "-out.csv"))

def arc_centre(a, b, bulge):
    """Centre of the arc from a to b with this bulge (positive: counter-clockwise)."""
    c = math.dist(a, b)
    theta = 4 * math.atan(abs(bulge))
    h = math.sqrt(max((c / (2 * math.sin(theta / 2))) ** 2 - c * c / 4, 0))
    s = 1 if bulge > 0 else -1  # a minor ccw arc has its centre on the chord's left
    return ((a[0] + b[0]) / 2 - s * (b[1] - a[1]) / c * h, (a[1] + b[1]) / 2 + s * (b[0] - a[0]) / c * h)

def seg_dist(p, a, b):
    """Distance from point p to the segment a-b."""
    d = (b[0] - a[0], b[1] - a[1])
    L2 = d[0] ** 2 + d[1] ** 2
    t = max(0, min(1, ((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / L2)) if L2 else 0
    return math.dist(p, (a[0] + t * d[0], a[1] + t * d[1]))

def inside(p, poly):
    """True if point p is inside the polygon poly (a list of points, closed implicitly)."""
    c = False
    for (x1, y1), (x2, y2) in zip(poly, poly[1:] + poly[:1]):
        if (y1 > p[1]) != (y2 > p[1]) and p[0] < x1 + (p[1] - y1) * (x2 - x1) / (y2 - y1):
            c = not c
    return c

def finish(files, summary, bad):
    """Removes the scratch files, prints the summary and the first defects, exits 1 if any."""
    for f in files:
        if os.path.exists(f):
            os.remove(f)
    print(summary)
    for b in bad[:15]:
        print(b)
    sys.exit(1 if bad else 0)
