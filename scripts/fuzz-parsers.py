#!/usr/bin/env python3
"""Mutation fuzzing of every parser family (issue 20): tables (CSV), G-code, JSON documents
(tool, machine, setup, model, frame), STL (binary and ASCII), DXF, SVG and STEP. Each run takes a
seed file of the family, mutates it (bit flips, cut/duplicated/spliced chunks, numbers replaced by
extremes, control characters, BOMs, truncation, swapped lines) and feeds it to every filter that
reads that family. A run keeps its promises when it exits 0, 1 or 2 within 20 s of CPU under 4 GiB,
with no panic ("internal error") and, when it fails, one error line (warnings aside).

  scripts/fuzz-parsers.py [--minutes M | --runs N] [--seed S] [FAMILY...]   (default 1 minute per family)

`--runs N` runs exactly N mutants per family (the same ones for the same seed: make test's short
run); `--minutes` runs as many as fit.

Binaries: $CARGO_TARGET_DIR/release (or $OFFSET etc.). Prints per family: runs, exits 0/1/2,
defects, slowest run; keeps each defect's input under $TMPDIR/fuzz-parsers-defects/."""
import os, random, resource, shutil, struct, subprocess, sys, tempfile, time
sys.path.insert(0, os.path.dirname(__file__))
from fuzzkit import binary

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
DATA = os.path.join(ROOT, "data")

SQUARE = "path,move,x,y,z\n1,rapid,0,0,0\n1,line,60,0,0\n1,line,60,40,0\n1,line,0,40,0\n1,line,0,0,0\n"
ISLAND = SQUARE + "2,rapid,24,16,0\n2,line,24,24,0\n2,line,36,24,0\n2,line,36,16,0\n2,line,24,16,0\n"
ARCS = "path,move,x,y,z,xc,yc\n1,rapid,15,0,0,,\n1,ccw,-15,0,0,0,0\n1,ccw,15,0,0,0,0\n"
def cl(z):
    """A CL table of 40 rows at heights z … z + 0.2 over x 0 … 19.5."""
    return "path,move,x,y,z,i,j,k,f\n" + "".join(
        f"1,{'rapid' if k == 0 else 'line'},{k * 0.5},{(k % 5) * 0.3},{z + (k % 3) * 0.1},0,0,1,600\n" for k in range(40))


CL = cl(15)
GCODE = "G21 G90\nG0 X0 Y0 Z-1\nG1 X0.1 F300\n" + "".join(
    f"G1 X{k * 0.7:.3f} Y{(k % 9) * 0.4:.3f}\n" for k in range(60)) + "G1 X40 Y0\nG2 X50 Y0 I5 J0\nG3 X40 Y0 R5\nM30\n"
SQUARE_NC = "G21 G90\nG0 X0 Y0 Z-1\nG1 X60 F300\nG1 Y40\nG3 X50 Y50 I-10 J0\nG1 X0\nG1 Y0\nM30\n"
TOOL = '{"kind": "ball", "radius": 3, "flutes": 2, "length": 30, "number": 1, "spindle_speed": 8000, "feed": 600}'
FLAT = '{"kind": "flat", "radius": 5, "flutes": 4, "length": 40, "tilt_range": [0, 15]}'
SETUP = ('{"tool": "tool.json", "stock": {"min": [0, 0, -10], "max": [60, 40, 0]}, "part": {"contours": '
         '"part.csv", "floor": -10}, "clearance_height": 20, "safe_height": 5, "approach": 1, "plunge": {"feed": 200}}')
MODEL = '{"surfaces": [{"type": "sphere", "name": "dome", "centre": [0, 0, 0], "radius": 20}]}'


def read(rel):
    with open(os.path.join(DATA, rel), "rb") as f:
        return f.read()


def binary_stl(tris):
    out = bytearray(b"fuzz".ljust(80, b" ") + struct.pack("<I", len(tris)))
    for t in tris:
        out += struct.pack("<3f", 0, 0, 0)
        for p in t:
            out += struct.pack("<3f", *p)
        out += b"\0\0"
    return bytes(out)


def dome_triangles(n=8):
    """A small closed-ish dome: a height field over a square, as triangles."""
    import math
    z = lambda x, y: 5 + 3 * math.cos(x / 6) * math.cos(y / 6)
    tris = []
    for i in range(n):
        for j in range(n):
            x0, y0, x1, y1 = i * 4 - 16, j * 4 - 16, i * 4 - 12, j * 4 - 12
            a, b, c, d = (x0, y0, z(x0, y0)), (x1, y0, z(x1, y0)), (x1, y1, z(x1, y1)), (x0, y1, z(x0, y1))
            tris += [(a, b, c), (a, c, d)]
    return tris


def ascii_stl(tris):
    lines = ["solid fuzz"]
    for t in tris:
        lines += ["facet normal 0 0 1", " outer loop"] + [f"  vertex {p[0]} {p[1]} {p[2]}" for p in t]
        lines += [" endloop", "endfacet"]
    return ("\n".join(lines + ["endsolid fuzz"]) + "\n").encode()


# family -> (seed files: name -> bytes, runs: list of (filter, args with {in} for the mutant))
def families():
    three = os.path.join(DATA, "post-6axis", "three-axis.json")
    head = os.path.join(DATA, "post-6axis", "head-ab.json")
    tris = dome_triangles()
    return {
        "table": ({"square.csv": SQUARE.encode(), "island.csv": ISLAND.encode(), "arcs.csv": ARCS.encode(),
                   "cl.csv": CL.encode(), "lshape.csv": read("medial-trochoid/lshape.csv")}, [
            ("offset", ["{in}", "--radius", "2", "--side", "left"]),
            ("offset", ["{in}", "--radius", "2", "--until-empty"]),
            ("medial-trochoid", ["{in}", "--radius", "3", "--sample", "2", "--max-work", "1e5"]),
            ("curve-fit-arcs", ["{in}"]),
            ("tool-attitude", ["{in}", "--tool", "tool.json", "--axis", "0,0,1"]),
            ("post-6axis", ["{in}", "--machine", three]),
            ("rough-sim", ["zmap", "{in}", "--tool", "tool.json", "--spindle", "8000", "--step", "0.2", "--max-work", "1e7"]),
        ]),
        "gcode": ({"prog.ngc": GCODE.encode(), "square.ngc": SQUARE_NC.encode(), "engrave.gcode": read("gcode/cncjs_jsdc-engrave.gcode")[:6000]}, [
            ("curve-fit-arcs", ["{in}", "--from", "gcode"]),
            ("curve-fit-arcs", ["{in}", "--from", "gcode", "--to", "table"]),
            ("offset", ["{in}", "--from", "gcode", "--radius", "1", "--side", "left"]),
            ("post-6axis", ["{in}", "--machine", three, "--reverse"]),
        ]),
        "json": ({"tool.json": TOOL.encode(), "flat.json": FLAT.encode(), "setup.json": SETUP.encode(),
                  "model.json": MODEL.encode(), "machine.json": read("post-6axis/head-ab.json"),
                  "frame.json": read("post-6axis/frame-example.json")}, [
            ("tool-attitude", ["cl.csv", "--tool", "{in}", "--axis", "0,0,1"]),
            ("post-6axis", ["cl.csv", "--machine", "{in}"]),
            ("post-6axis", ["square.csv", "--machine", three, "--setup", "{in}"]),
            ("post-6axis", ["cl.csv", "--machine", head, "--frame", "{in}"]),
            ("stylus-trace", ["{in}", "-r", "3", "--pick", "4", "--region", "-20,20,-20,20"]),
            ("medial-trochoid", ["square.csv", "--setup", "{in}"]),
        ]),
        "stl": ({"dome.stl": binary_stl(tris), "dome-ascii.stl": ascii_stl(tris)}, [
            # A bound of about 14 s at the measured 14 µs a unit (the default's 1e8 is minutes).
            ("stylus-trace", ["{in}", "-r", "3", "--pick", "4", "--max-points", "1e6"]),
            ("tool-attitude", ["cl.csv", "--tool", "tool.json", "--axis", "0,0,1", "--model", "{in}"]),
        ]),
        "dxf": ({"box-die.dxf": read("medial-trochoid/box-die.dxf"),
                 "islands.dxf": read("post-6axis/pocket-islands.dxf")}, [
            # A bound of about 6 to 19 s at the measured 60 to 190 µs a sample (the default is minutes).
            ("medial-trochoid", ["{in}", "--radius", "4", "--sample", "2", "--max-work", "1e5"]),
            ("offset", ["{in}", "--radius", "2", "--side", "left"]),
        ]),
        "svg": ({"pocket.svg": read("contours/pocket.svg"), "inkscape.svg": read("contours/inkscape.svg")}, [
            ("medial-trochoid", ["{in}", "--radius", "3", "--sample", "2", "--max-work", "1e5"]),
            ("offset", ["{in}", "--radius", "2", "--side", "left"]),
            ("offset", ["{in}", "--radius", "2", "--until-empty"]),
        ]),
        "step": ({"faces.step": read("step/faces.step"), "bspline.step": read("step/bspline.step"),
                  "revolve.step": read("step/revolve.step")}, [
            ("stylus-trace", ["{in}", "--tool", "tool.json", "--pick", "6", "--max-step", "3"]),
            ("stylus-trace", ["{in}", "-r", "3", "--pick", "10", "--region=-20,20,-20,20"]),
            # Above the models, and a coarser solid: the gouge check's tessellation is not the parser.
            ("tool-attitude", ["high.csv", "--tool", "tool.json", "--axis", "0,0,1", "--model", "{in}", "--gouge-tol", "0.02"]),
        ]),
    }


EXTREMES = [b"0.5", b"-3", b"12345.678", b"1e-6", b"7", b"-0.001", b"100", b"NaN", b"inf", b"-inf", b"1e999", b"-1e999", b"1e308", b"1e-320", b"0", b"-0", b"1e9", b"-1e12",
            b"99999999999999999999999999999999999999", b"0x10", b"", b" ", b"1,2", b"\"", b"-"]
INSERTS = [b"\r", b"\0", b"\xef\xbb\xbf", b"\xff\xfe", b"\n\n", b"\t", b",", b"{", b"}", b"[", b"]", b"\"",
           b"\x1b[2J", b"\xc3", b"%", b"(", b";", b"G2", b"I", b"0\nSECTION\n", b"\nEOF\n"]


def mutate(data, rng):
    """1-4 random edits of `data`."""
    b = bytearray(data)
    for _ in range(rng.randint(1, 4)):
        kind = rng.randrange(12)
        n = len(b)
        if n == 0:
            b += rng.choice(INSERTS)
            continue
        i = rng.randrange(n)
        if kind == 0:  # bit flip
            b[i] ^= 1 << rng.randrange(8)
        elif kind == 1:  # cut a chunk
            del b[i:i + rng.randint(1, 64)]
        elif kind == 2:  # duplicate a chunk elsewhere
            chunk = b[i:i + rng.randint(1, 256)]
            j = rng.randrange(len(b) + 1)
            b[j:j] = chunk * rng.randint(1, 4)
        elif kind == 3 or kind > 8:  # a number replaced by another or an extreme
            digits = [k for k in range(n) if chr(b[k]) in "0123456789"]
            if digits:
                k = rng.choice(digits)
                s = e = k
                while s > 0 and chr(b[s - 1]) in "0123456789.-+e":
                    s -= 1
                while e < n and chr(b[e]) in "0123456789.-+e":
                    e += 1
                b[s:e] = rng.choice(EXTREMES)
        elif kind == 4:  # an odd byte sequence inserted
            b[i:i] = rng.choice(INSERTS)
        elif kind == 5:  # truncated
            del b[i:]
        elif kind == 6:  # two lines swapped
            lines = bytes(b).split(b"\n")
            if len(lines) > 2:
                x, y = rng.randrange(len(lines)), rng.randrange(len(lines))
                lines[x], lines[y] = lines[y], lines[x]
                b = bytearray(b"\n".join(lines))
        elif kind == 7:  # random bytes
            b[i:i] = bytes(rng.randrange(256) for _ in range(rng.randint(1, 16)))
        elif kind == 8:  # a line repeated many times
            lines = bytes(b).split(b"\n")
            k = rng.randrange(len(lines))
            lines[k:k] = [lines[k]] * rng.randint(2, 200)
            b = bytearray(b"\n".join(lines))
    return bytes(b)


def limit():
    """4 GiB of address space and 20 s of CPU (SIGXCPU past it: a defect): CPU time, so that a
    loaded machine does not turn a quick run into a time-out."""
    resource.setrlimit(resource.RLIMIT_AS, (4 << 30, 4 << 30))
    resource.setrlimit(resource.RLIMIT_CPU, (20, 21))


def run(cmd, cwd):
    start = time.time()
    p = subprocess.Popen(cmd, cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                         stderr=subprocess.PIPE, preexec_fn=limit)
    try:
        _, err = p.communicate(timeout=300)
    except subprocess.TimeoutExpired:
        p.kill()
        _, err = p.communicate()
        return "timeout", time.time() - start, err.decode(errors="replace")
    return p.returncode, time.time() - start, err.decode(errors="replace")


def main():
    args = sys.argv[1:]
    minutes, seed, count = 1.0, 20261127, None
    while args and args[0].startswith("--"):
        if args[0] == "--minutes":
            minutes = float(args[1])
        elif args[0] == "--runs":
            count = int(args[1])
        elif args[0] == "--seed":
            seed = int(args[1])
        else:
            sys.exit(f"unknown option {args[0]}")
        args = args[2:]
    fams = families()
    chosen = args or list(fams)
    keep = os.path.join(os.environ.get("TMPDIR", "/tmp"), "fuzz-parsers-defects")
    total_bad = 0
    with tempfile.TemporaryDirectory() as tmp:
        # Fixed companions the runs name: a CL table, a contour, a tool.
        for name, text in (("cl.csv", CL), ("high.csv", cl(45)), ("square.csv", SQUARE),
                           ("tool.json", TOOL), ("part.csv", SQUARE)):
            open(os.path.join(tmp, name), "w").write(text)
        for fam in chosen:
            seeds, runs = fams[fam]
            # Each run must accept some unmutated seed, or the mutants only meet its first check.
            for filt, fargs in runs:
                ok = False
                for name in sorted(seeds):
                    path = os.path.join(tmp, "seed" + os.path.splitext(name)[1])
                    with open(path, "wb") as f:
                        f.write(seeds[name])
                    ok = ok or run([binary(filt)] + [path if a == "{in}" else a for a in fargs], tmp)[0] == 0
                if not ok:
                    print(f"{fam}: no seed passes {filt} {' '.join(fargs)}", flush=True)
                    total_bad += 1
            rng = random.Random(f"{seed}-{fam}")
            counts, bad, slowest, n = {0: 0, 1: 0, 2: 0}, [], (0.0, ""), 0
            deadline = time.time() + minutes * 60
            while (n < count) if count is not None else (time.time() < deadline):
                name = rng.choice(sorted(seeds))
                mutant = mutate(seeds[name], rng)
                path = os.path.join(tmp, "mutant" + os.path.splitext(name)[1])
                with open(path, "wb") as f:
                    f.write(mutant)
                filt, fargs = rng.choice(runs)
                cmd = [binary(filt)] + [path if a == "{in}" else a for a in fargs]
                status, secs, err = run(cmd, tmp)
                n += 1
                label = f"{filt} {' '.join(fargs)} on a mutant of {name}"
                slowest = max(slowest, (secs, label))
                lines = [l for l in err.splitlines() if l.strip()]
                errors = [l for l in lines if "warning:" not in l]
                broken = None
                if status not in (0, 1, 2):
                    broken = f"status {status}"
                elif any("internal error" in l or "panicked" in l for l in lines):
                    broken = "panic"
                elif status != 0 and len(errors) != 1:
                    broken = f"{len(errors)} error lines"
                if status in counts:
                    counts[status] += 1
                if broken:
                    os.makedirs(keep, exist_ok=True)
                    kept = os.path.join(keep, f"{fam}-{n}{os.path.splitext(name)[1]}")
                    shutil.copy(path, kept)
                    bad.append(f"  {broken}: {label} (kept as {kept}): {errors[:2]}")
            total_bad += len(bad)
            spent = (time.time() - deadline) / 60 + minutes
            print(f"{fam}: {n} runs in {spent:.1f} min, exits 0/1/2 = {counts[0]}/{counts[1]}/{counts[2]}, "
                  f"{len(bad)} defects, slowest {slowest[0]:.2f} s ({slowest[1]})", flush=True)
            for b in bad[:10]:
                print(b, flush=True)
    sys.exit(1 if total_bad else 0)


if __name__ == "__main__":
    main()
