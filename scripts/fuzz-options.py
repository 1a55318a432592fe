#!/usr/bin/env python3
"""Every numeric option of offset, medial-trochoid and curve-fit-arcs at extreme values (0,
negative, NaN, ±inf, 1e-300, 1e300, tiny, huge) on small inputs: no panic, exit 0/1/2 only,
one stderr line on a failure, under 20 s and 4 GiB each (issue 20). Usage:
  scripts/fuzz-options.py [FILTER...]   (binaries: $CARGO_TARGET_DIR/release or $OFFSET etc.)
Prints one line per run that broke a promise and a summary (runs, slowest, largest memory)."""
import os, resource, subprocess, sys, tempfile, time
sys.path.insert(0, os.path.dirname(__file__))
from fuzzkit import binary

SQUARE = "path,move,x,y,z\n1,rapid,0,0,0\n1,line,60,0,0\n1,line,60,40,0\n1,line,0,40,0\n1,line,0,0,0\n"
ISLAND = SQUARE + "2,rapid,24,16,0\n2,line,24,24,0\n2,line,36,24,0\n2,line,36,16,0\n2,line,24,16,0\n"
ARCS = "path,move,x,y,z,xc,yc\n1,rapid,15,0,0,,\n1,ccw,-15,0,0,0,0\n1,ccw,15,0,0,0,0\n"
RING = "path,move,x,y,z,i,j,k\n" + "".join(
    f"0,{'rapid' if k == 0 else 'line'},{20 * __import__('math').cos(k * 0.157):.6f},{20 * __import__('math').sin(k * 0.157):.6f},0,0,0,1\n"
    for k in range(41))
POINTS = "x,y\n" + "".join(f"{k * 0.5},{__import__('math').sin(k * 0.05) * 10:.6f}\n" for k in range(200))
VALUES = ["0", "-1", "NaN", "inf", "-inf", "1e-300", "1e300", "1e-9", "1e9"]

# (filter, input, base arguments, numeric options)
CASES = [
    ("offset", ISLAND, ["--radius", "2", "--side", "left"], ["--radius", "--feed", "--decimals"]),
    ("offset", ISLAND, ["--radius", "2", "--until-empty"], ["--radius", "--step", "--repeat"]),
    ("offset", RING, ["--3d", "--radius", "1", "--side", "left"], ["--radius", "--window", "--chord-tol"]),
    ("offset", SQUARE, ["--radius", "1", "--profile", "ball"], ["--radius", "--gouge-tol"]),
    ("medial-trochoid", SQUARE, ["--radius", "5", "--sample", "2"],
     ["--radius", "--step", "--threshold", "--trochoid-radius", "--pitch", "--allowance", "--corner-radius",
      "--sample", "--layers", "--layer-depth", "--resolution", "--sagitta", "--spindle", "--teeth", "--chip",
      "--fz-max", "--force-at", "--decimals", "--max-memory"]),
    ("medial-trochoid", ARCS, ["--radius", "5", "--sample", "2"], ["--sagitta", "--resolution"]),
    ("curve-fit-arcs", POINTS, [],
     ["--tol", "--min-radius", "--max-radius", "--max-sweep", "--tangent", "--corner", "--curvature-threshold",
      "--e-rate-tol", "--decimals"]),
]

def limit():
    resource.setrlimit(resource.RLIMIT_AS, (4 << 30, 4 << 30))

def run(cmd):
    """Runs cmd under 4 GiB for at most 20 s: (status or "timeout", seconds, 0, stderr)."""
    start = time.time()
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, preexec_fn=limit)
    try:
        _, err = p.communicate(timeout=20)
    except subprocess.TimeoutExpired:
        p.kill()
        _, err = p.communicate()
        return "timeout", time.time() - start, 0, err.decode(errors="replace")
    return p.returncode, time.time() - start, 0, err.decode(errors="replace")

def main():
    only = set(sys.argv[1:])
    bad, runs, slowest, peak = [], 0, (0, ""), (0, "")
    with tempfile.TemporaryDirectory() as tmp:
        for name, text, base, options in CASES:
            if only and name not in only:
                continue
            src = os.path.join(tmp, f"{name}.csv")
            open(src, "w").write(text)
            for opt in options:
                for v in VALUES:
                    args = [a for a in base]
                    if opt in args:
                        i = args.index(opt)
                        del args[i:i + 2]
                    cmd = [binary(name), src] + args + [f"{opt}={v}"]
                    status, secs, _, err = run(cmd)
                    # The largest resident size of any run so far: this run's when it grew.
                    mb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
                    runs += 1
                    label = " ".join(cmd[2:])
                    slowest = max(slowest, (secs, f"{name} {label}"))
                    if mb > peak[0]:
                        peak = (mb, f"{name} {label}")
                    lines = [l for l in err.splitlines() if l.strip()]
                    failed_lines = [l for l in lines if "warning:" not in l]
                    if status not in (0, 1, 2):
                        bad.append(f"{name} {label}: status {status}: {lines[:1]}")
                    elif status != 0 and len(failed_lines) != 1:
                        bad.append(f"{name} {label}: status {status} with {len(failed_lines)} error lines: {failed_lines[:2]}")
                    elif "internal error" in err or "panicked" in err:
                        bad.append(f"{name} {label}: panic: {failed_lines[:1]}")
    print(f"{runs} runs, {len(bad)} broke a promise; slowest {slowest[0]:.2f} s ({slowest[1]}); "
          f"largest resident size {peak[0]:.0f} MB ({peak[1]})")
    for b in bad:
        print(b)
    sys.exit(1 if bad else 0)

main()
