#!/usr/bin/env python3
"""SciPy's least_squares on the same point files surf-probe-fit fitted: agreement and speed.

Usage: bench-fit-scipy.py POINTS.csv OURS_FRAME.json [OURS_REPORT.json]
Prints one JSON line: the largest difference (mm) of centre and radius between SciPy's
Levenberg-Marquardt sphere fit (analytic Jacobian, tolerances at the floating-point floor,
started from the same algebraic fit) and ours, SciPy's fit time and ours (fit only).
"""
import json
import sys
import time

import numpy as np
from scipy.optimize import least_squares


def fit_sphere(p):
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

    r = least_squares(res, x0, jac=jac, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15)
    return r.x


def main():
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
