#!/usr/bin/env python3
"""SciPy's least_squares on the same point files surf-probe-fit fitted: agreement and speed.

Usage: bench-fit-scipy.py POINTS.csv OURS_FRAME.json [OURS_REPORT.json]
Prints one JSON line: the largest difference (mm) of centre and radius between SciPy's
Levenberg-Marquardt sphere fit (analytic Jacobian, tolerances at the floating-point floor,
started from the same algebraic fit) and ours, SciPy's fit time and ours (fit only).

Usage: bench-fit-scipy.py --outliers POINTS.csv N CX,CY,CZ,R SEED > DIRTY.csv
Appends N gross outliers to a sphere's points: half pushed 0.5-5 mm out along the radius, half
anywhere in the box of 1.5 R about the centre at least 0.5 mm off the sphere.

Usage: bench-fit-scipy.py --robust DIRTY.csv OURS_FRAME.json OURS_REPORT.json CX,CY,CZ,R
Prints one JSON line per SciPy robust loss (least_squares method "trf", f_scale 0.01 mm): its
error against the true sphere and its time, beside ours (--robust ransac).
"""
import json
import sys
import time

import numpy as np
from scipy.optimize import least_squares


def fit_sphere(p, loss=None):
    m = p.mean(axis=0)
    y = p - m
    a = np.column_stack([2 * y, np.ones(len(y))])
    s, *_ = np.linalg.lstsq(a, (y * y).sum(axis=1), rcond=None)
    c0 = s[:3]
    x0 = np.concatenate([m + c0, [np.sqrt(s[3] + c0 @ c0)]])

    def res(x):
        return np.linalg.norm(p - x[:3], axis=1) - x[3]

    def jac(x):
        d = p - x[:3]
        n = np.linalg.norm(d, axis=1)[:, None]
        return np.column_stack([-d / n, -np.ones(len(p))])

    if loss is None:
        r = least_squares(res, x0, jac=jac, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15)
    else:
        r = least_squares(res, x0, jac=jac, method="trf", loss=loss, f_scale=0.01, xtol=1e-15, ftol=1e-15,
                          gtol=1e-15, max_nfev=1000)
    return r.x


def add_outliers(path, n, truth, seed):
    c, r = np.array(truth[:3]), truth[3]
    rng = np.random.default_rng(seed)
    sys.stdout.write(open(path).read())
    for k in range(n):
        if k % 2 == 0:
            u = rng.normal(size=3)
            p = c + u / np.linalg.norm(u) * (r + rng.uniform(0.5, 5.0))
        else:
            while True:
                p = c + rng.uniform(-1.5 * r, 1.5 * r, size=3)
                if abs(np.linalg.norm(p - c) - r) >= 0.5:
                    break
        print(",".join(repr(float(v)) for v in p))


def robust(path, frame, report, truth):
    pts = np.loadtxt(path, delimiter=",", skiprows=1, comments="#")
    c, r = np.array(truth[:3]), truth[3]
    err = lambda x: float(max(np.linalg.norm(np.array(x[:3]) - c), abs(x[3] - r)))
    ours = json.load(open(frame))["fit"]
    rep = json.load(open(report))
    print(json.dumps({"method": "ours ransac", "points": len(pts), "error_mm": err(ours["centre"] + [ours["radius"]]),
                      "seconds": rep["fit_seconds"], "outliers": rep["outliers"]}))
    for loss in ["linear", "soft_l1", "huber", "cauchy", "arctan"]:
        t = time.perf_counter()
        x = fit_sphere(pts, loss)
        s = time.perf_counter() - t
        print(json.dumps({"method": f"scipy trf {loss}", "error_mm": err(x), "seconds": s}))


def main():
    if sys.argv[1] == "--outliers":
        truth = [float(v) for v in sys.argv[4].split(",")]
        return add_outliers(sys.argv[2], int(sys.argv[3]), truth, int(sys.argv[5]))
    if sys.argv[1] == "--robust":
        return robust(sys.argv[2], sys.argv[3], sys.argv[4], [float(v) for v in sys.argv[5].split(",")])
    pts = np.loadtxt(sys.argv[1], delimiter=",", skiprows=1, comments="#")
    ours = json.load(open(sys.argv[2]))["fit"]
    t = time.perf_counter()
    x = fit_sphere(pts)
    scipy_s = time.perf_counter() - t
    d = max(np.abs(x[:3] - np.array(ours["centre"])).max(), abs(x[3] - ours["radius"]))
    out = {"points": len(pts), "max_diff_mm": float(d), "scipy_seconds": scipy_s}
    if len(sys.argv) > 3:
        out["ours_fit_seconds"] = json.load(open(sys.argv[3]))["fit_seconds"]
    print(json.dumps(out))


if __name__ == "__main__":
    main()
