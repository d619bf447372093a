#!/usr/bin/env python3
"""Peer figures: scipy.integrate.solve_bvp on an oscillatory family with tens of periods.

Run:
    pip install scipy numpy
    python3 benches/peers/scipy_oscillatory.py          # plain text table
    python3 benches/peers/scipy_oscillatory.py --json   # JSON instead

Problems (state Y = [y, y'], x in [0, 1], eps in EPS, tol in TOLS):

* linear:    eps^2 y'' + y = 0,            y(0) = 1, y(1) = 0
             exact y = cos(x/eps) - cot(1/eps) sin(x/eps)
* pendulum:  eps^2 y'' + sin(y) = 0,       y(0) = 0.5, y(1) = 0 (nonlinear)
* airy:      eps^2 y'' + (1 + x) y = 0,    y(0) = 1, y(1) = 0   (frequency rising
             by sqrt(2) across the interval)

1/eps is the angular frequency: eps = 0.01 gives 16 periods on [0, 1].
Initial guess: y = y' = 0 on 5 uniform nodes. Every solve uses scipy's default
bc_tol (= tol) and max_nodes = 10000 (diffbvp's default max_nodes). The table
prints success, final node count, and for the linear problem the max |error|
on 20001 points of sol.sol. tests/oscillatory_mesh.rs records these node
counts as constants.
"""

import argparse
import json
import platform
import sys

import numpy as np
import scipy
from scipy.integrate import solve_bvp

EPS = (0.01, 0.015, 0.02, 0.03, 0.04)
TOLS = (1e-3, 1e-6)
MAX_NODES = 10000
PENDULUM_AMPLITUDE = 0.5


def make(problem, eps):
    e2 = eps * eps
    if problem == "linear":
        def fun(x, y):
            return np.vstack((y[1], -y[0] / e2))
    elif problem == "pendulum":
        def fun(x, y):
            return np.vstack((y[1], -np.sin(y[0]) / e2))
    elif problem == "airy":
        def fun(x, y):
            return np.vstack((y[1], -(1.0 + x) * y[0] / e2))
    else:
        raise ValueError(problem)

    left = PENDULUM_AMPLITUDE if problem == "pendulum" else 1.0

    def bc(ya, yb):
        return np.array([ya[0] - left, yb[0]])

    return fun, bc


def linear_exact(eps, x):
    w = 1.0 / eps
    return np.cos(w * x) - np.sin(w * x) / np.tan(w)


def run():
    rows = []
    for problem in ("linear", "pendulum", "airy"):
        for eps in EPS:
            for tol in TOLS:
                fun, bc = make(problem, eps)
                x = np.linspace(0.0, 1.0, 5)
                y = np.zeros((2, x.size))
                sol = solve_bvp(fun, bc, x, y, tol=tol, max_nodes=MAX_NODES)
                row = {
                    "problem": problem,
                    "eps": eps,
                    "tol": tol,
                    "success": bool(sol.success),
                    "status": int(sol.status),
                    "nodes": int(sol.x.size),
                    "niter": int(sol.niter),
                    "message": sol.message,
                    "y_half": float(sol.sol(0.5)[0]),
                }
                if problem == "linear":
                    xs = np.linspace(0.0, 1.0, 20001)
                    row["max_abs_err"] = float(
                        np.max(np.abs(sol.sol(xs)[0] - linear_exact(eps, xs))))
                rows.append(row)
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--json", action="store_true", help="print JSON instead of a table")
    args = ap.parse_args()
    rows = run()
    meta = {
        "scipy": scipy.__version__,
        "numpy": np.__version__,
        "python": platform.python_version(),
        "max_nodes": MAX_NODES,
    }
    if args.json:
        json.dump({"meta": meta, "results": rows}, sys.stdout, indent=2)
        print()
        return 0
    print("scipy %s, numpy %s, Python %s; solve_bvp bc_tol=default max_nodes=%d, "
          "guess 0 on 5 nodes" % (meta["scipy"], meta["numpy"], meta["python"], MAX_NODES))
    hdr = "%-9s %6s %6s %-3s %6s %5s %12s  %s" % (
        "problem", "eps", "tol", "ok", "nodes", "iter", "y(0.5)", "max|err| (linear)")
    print(hdr)
    print("-" * len(hdr))
    for r in rows:
        err = "%.1e" % r["max_abs_err"] if "max_abs_err" in r else "-"
        print("%-9s %6g %6g %-3s %6d %5d %12.8f  %s" % (
            r["problem"], r["eps"], r["tol"], "yes" if r["success"] else "NO",
            r["nodes"], r["niter"], r["y_half"], err))
    return 0


if __name__ == "__main__":
    sys.exit(main())
