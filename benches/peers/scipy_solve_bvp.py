#!/usr/bin/env python3
"""Peer benchmark: scipy.integrate.solve_bvp on the BVP problems used by the
Rust solver's benches.

Run:
    pip install scipy numpy
    python3 benches/peers/scipy_solve_bvp.py           # plain text table
    python3 benches/peers/scipy_solve_bvp.py --json    # JSON instead

Every solve uses tol=1e-6, scipy's default bc_tol (= tol), max_nodes=100000.
Jacobians come from scipy's default finite differences, except in the
"analytic jac" column (problems 1 and 2 only), where fun_jac and bc_jac are
given: that is scipy's best case.

Each solve is repeated at least --min-reps times (default 30) and until at
least --min-seconds (default 1.0) of wall time has been spent; the median
wall time of one solve is reported.
"""

import argparse
import json
import math
import platform
import statistics
import sys
import time

import numpy as np
import scipy
from scipy.integrate import solve_bvp
from scipy.optimize import brentq
from scipy.special import erf

TOL = 1e-6
MAX_NODES = 100000

# ---------------------------------------------------------------------------
# Problem 1: Bratu  y'' + k e^y = 0, y(0) = y(1) = 0, k = 1
# state Y = [y, y']
# ---------------------------------------------------------------------------
BRATU_K = 1.0
BRATU_Y_HALF = 0.1405392144004718  # lower branch, y(1/2)


def bratu_fun(x, y):
    return np.vstack((y[1], -BRATU_K * np.exp(y[0])))


def bratu_bc(ya, yb):
    return np.array([ya[0], yb[0]])


def bratu_fun_jac(x, y):
    n = y.shape[1]
    j = np.zeros((2, 2, n))
    j[0, 1, :] = 1.0
    j[1, 0, :] = -BRATU_K * np.exp(y[0])
    return j


def bratu_bc_jac(ya, yb):
    dya = np.array([[1.0, 0.0], [0.0, 0.0]])
    dyb = np.array([[0.0, 0.0], [1.0, 0.0]])
    return dya, dyb


def bratu_guess():
    x = np.linspace(0.0, 1.0, 5)
    return x, np.zeros((2, x.size))


def _bratu_theta():
    # Exact solution y = -2 ln( cosh((x - 1/2) th/2) / cosh(th/4) ),
    # th solves th = sqrt(2k) cosh(th/4); lower branch = smaller root.
    g = lambda t: t - math.sqrt(2.0 * BRATU_K) * math.cosh(t / 4.0)
    return brentq(g, 0.0, 4.0)  # smaller root lies in (0, 4) for k = 1


BRATU_THETA = _bratu_theta()


def bratu_exact(x):
    th = BRATU_THETA
    return -2.0 * np.log(np.cosh((x - 0.5) * th / 2.0) / np.cosh(th / 4.0))


def bratu_check(sol):
    xs = np.linspace(0.0, 1.0, 2001)
    err = float(np.max(np.abs(sol.sol(xs)[0] - bratu_exact(xs))))
    y_half = float(sol.sol(0.5)[0])
    return {
        "y(0.5)": y_half,
        "y(0.5)_err": abs(y_half - BRATU_Y_HALF),
        "max_abs_err": err,
    }


# ---------------------------------------------------------------------------
# Problem 2: shock layer
#   eps y'' + x y' = -eps pi^2 cos(pi x) - pi x sin(pi x),  x in [-1, 1]
#   y(-1) = -2, y(1) = 0, eps = 1e-3
#   exact y = cos(pi x) + erf(x / sqrt(2 eps)) / erf(1 / sqrt(2 eps))
# state Y = [y, y']
# ---------------------------------------------------------------------------
SHOCK_EPS = 1e-3


def shock_fun(x, y):
    e = SHOCK_EPS
    rhs = -e * np.pi**2 * np.cos(np.pi * x) - np.pi * x * np.sin(np.pi * x)
    return np.vstack((y[1], (rhs - x * y[1]) / e))


def shock_bc(ya, yb):
    return np.array([ya[0] + 2.0, yb[0]])


def shock_fun_jac(x, y):
    n = y.shape[1]
    j = np.zeros((2, 2, n))
    j[0, 1, :] = 1.0
    j[1, 1, :] = -x / SHOCK_EPS
    return j


def shock_bc_jac(ya, yb):
    dya = np.array([[1.0, 0.0], [0.0, 0.0]])
    dyb = np.array([[0.0, 0.0], [1.0, 0.0]])
    return dya, dyb


def shock_guess():
    x = np.linspace(-1.0, 1.0, 5)
    return x, np.zeros((2, x.size))


def shock_exact(x):
    s = math.sqrt(2.0 * SHOCK_EPS)
    return np.cos(np.pi * x) + erf(x / s) / erf(1.0 / s)


def shock_check(sol):
    xs = np.linspace(-1.0, 1.0, 20001)
    err = float(np.max(np.abs(sol.sol(xs)[0] - shock_exact(xs))))
    err_nodes = float(np.max(np.abs(sol.y[0] - shock_exact(sol.x))))
    return {"max_abs_err": err, "max_abs_err_at_nodes": err_nodes}


# ---------------------------------------------------------------------------
# Problem 3: coupled Troesch (4 states), x in [0, 1]
#   y1' = y2
#   y2' = mu sinh(mu y1) + y3
#   y3' = y4
#   y4' = y3 - y1
#   y1(0) = 0, y1(1) = 1, y3(0) = 0, y3(1) = 0
# guess y1 = x, y2 = 1, y3 = y4 = 0 on 11 uniform nodes. No exact solution.
# mu = 5 is tried first; if scipy fails, 4 then 3.
# ---------------------------------------------------------------------------
TROESCH_MUS = (5.0, 4.0, 3.0)


def make_troesch(mu):
    def fun(x, y):
        return np.vstack((y[1], mu * np.sinh(mu * y[0]) + y[2], y[3], y[2] - y[0]))

    def bc(ya, yb):
        return np.array([ya[0], yb[0] - 1.0, ya[2], yb[2]])

    return fun, bc


def troesch_guess():
    x = np.linspace(0.0, 1.0, 11)
    y = np.zeros((4, x.size))
    y[0] = x
    y[1] = 1.0
    return x, y


def troesch_check(sol, mu):
    # No closed form: compare with a much tighter scipy solve (tol=1e-10).
    fun, bc = make_troesch(mu)
    ref = solve_bvp(fun, bc, sol.x, sol.y, tol=1e-10, max_nodes=MAX_NODES)
    out = {"mu": mu, "y2(0)": float(sol.y[1, 0])}
    if ref.success:
        xs = np.linspace(0.0, 1.0, 2001)
        out["ref_y2(0)_tol1e-10"] = float(ref.y[1, 0])
        out["y2(0)_err_vs_ref"] = abs(float(sol.y[1, 0]) - float(ref.y[1, 0]))
        out["max_abs_err_y1_vs_ref"] = float(
            np.max(np.abs(sol.sol(xs)[0] - ref.sol(xs)[0]))
        )
    return out


# ---------------------------------------------------------------------------
# Timing harness
# ---------------------------------------------------------------------------
def time_solve(make_call, min_reps, min_seconds):
    """Run make_call() repeatedly; return (median_ms, reps, last_result)."""
    times = []
    res = None
    start = time.perf_counter()
    while len(times) < min_reps or (time.perf_counter() - start) < min_seconds:
        t0 = time.perf_counter()
        res = make_call()
        times.append(time.perf_counter() - t0)
    return statistics.median(times) * 1e3, len(times), res


def run(min_reps, min_seconds):
    rows = []

    # --- 1. Bratu
    def p1_fd():
        x, y = bratu_guess()
        return solve_bvp(bratu_fun, bratu_bc, x, y, tol=TOL, max_nodes=MAX_NODES)

    def p1_jac():
        x, y = bratu_guess()
        return solve_bvp(bratu_fun, bratu_bc, x, y, tol=TOL, max_nodes=MAX_NODES,
                         fun_jac=bratu_fun_jac, bc_jac=bratu_bc_jac)

    ms, reps, sol = time_solve(p1_fd, min_reps, min_seconds)
    ms_j, reps_j, sol_j = time_solve(p1_jac, min_reps, min_seconds)
    rows.append({
        "problem": "bratu",
        "description": "y''+e^y=0, y(0)=y(1)=0, k=1, guess 0 on 5 nodes",
        "success": bool(sol.success), "status": int(sol.status),
        "median_ms_fd": ms, "reps_fd": reps, "nodes_fd": int(sol.x.size),
        "median_ms_jac": ms_j, "reps_jac": reps_j, "nodes_jac": int(sol_j.x.size),
        "success_jac": bool(sol_j.success),
        "max_rms_residual": float(np.max(sol.rms_residuals)),
        "check": bratu_check(sol),
    })

    # --- 2. Shock layer
    def p2_fd():
        x, y = shock_guess()
        return solve_bvp(shock_fun, shock_bc, x, y, tol=TOL, max_nodes=MAX_NODES)

    def p2_jac():
        x, y = shock_guess()
        return solve_bvp(shock_fun, shock_bc, x, y, tol=TOL, max_nodes=MAX_NODES,
                         fun_jac=shock_fun_jac, bc_jac=shock_bc_jac)

    ms, reps, sol = time_solve(p2_fd, min_reps, min_seconds)
    ms_j, reps_j, sol_j = time_solve(p2_jac, min_reps, min_seconds)
    rows.append({
        "problem": "shock",
        "description": "eps y''+x y'=..., [-1,1], eps=1e-3, guess 0 on 5 nodes",
        "success": bool(sol.success), "status": int(sol.status),
        "median_ms_fd": ms, "reps_fd": reps, "nodes_fd": int(sol.x.size),
        "median_ms_jac": ms_j, "reps_jac": reps_j, "nodes_jac": int(sol_j.x.size),
        "success_jac": bool(sol_j.success),
        "max_rms_residual": float(np.max(sol.rms_residuals)),
        "check": shock_check(sol),
    })

    # --- 3. Coupled Troesch: first mu in (5, 4, 3) that scipy solves
    attempts = []
    for mu in TROESCH_MUS:
        fun, bc = make_troesch(mu)
        x, y = troesch_guess()
        trial = solve_bvp(fun, bc, x, y, tol=TOL, max_nodes=MAX_NODES)
        attempts.append({"mu": mu, "success": bool(trial.success),
                         "status": int(trial.status), "message": trial.message})
        if trial.success:
            break
    mu = attempts[-1]["mu"]
    fun, bc = make_troesch(mu)

    def p3_fd():
        x, y = troesch_guess()
        return solve_bvp(fun, bc, x, y, tol=TOL, max_nodes=MAX_NODES)

    ms, reps, sol = time_solve(p3_fd, min_reps, min_seconds)
    rows.append({
        "problem": "coupled_troesch",
        "description": "4-state, mu=%g, guess y1=x,y2=1 on 11 nodes" % mu,
        "success": bool(sol.success), "status": int(sol.status),
        "median_ms_fd": ms, "reps_fd": reps, "nodes_fd": int(sol.x.size),
        "median_ms_jac": None, "reps_jac": None, "nodes_jac": None,
        "success_jac": None,
        "max_rms_residual": float(np.max(sol.rms_residuals)),
        "check": troesch_check(sol, mu),
        "mu_attempts": attempts,
    })
    return rows


def fmt_check(row):
    c = row["check"]
    if row["problem"] == "bratu":
        return "y(.5)=%.16f |err|=%.1e max|err|=%.1e" % (
            c["y(0.5)"], c["y(0.5)_err"], c["max_abs_err"])
    if row["problem"] == "shock":
        return "max|err| dense=%.1e nodes=%.1e" % (
            c["max_abs_err"], c["max_abs_err_at_nodes"])
    s = "mu=%g y2(0)=%.10f" % (c["mu"], c["y2(0)"])
    if "y2(0)_err_vs_ref" in c:
        s += " |y2(0)-ref|=%.1e (ref %.12f)" % (
            c["y2(0)_err_vs_ref"], c["ref_y2(0)_tol1e-10"])
    return s


def print_table(rows, meta):
    print("scipy %s, numpy %s, Python %s, %s" % (
        meta["scipy"], meta["numpy"], meta["python"], meta["machine"]))
    print("solve_bvp tol=%g bc_tol=default max_nodes=%d; median of >=%d reps "
          "and >=%.1f s per cell" % (TOL, MAX_NODES, meta["min_reps"],
                                     meta["min_seconds"]))
    print()
    hdr = "%-16s %-3s %12s %6s %14s %6s  %s" % (
        "problem", "ok", "FD jac [ms]", "nodes", "analytic [ms]", "nodes", "check")
    print(hdr)
    print("-" * len(hdr))
    for r in rows:
        jac_ms = "%14.3f" % r["median_ms_jac"] if r["median_ms_jac"] is not None else "%14s" % "-"
        jac_n = "%6d" % r["nodes_jac"] if r["nodes_jac"] is not None else "%6s" % "-"
        print("%-16s %-3s %12.3f %6d %s %s  %s" % (
            r["problem"], "yes" if r["success"] else "NO", r["median_ms_fd"],
            r["nodes_fd"], jac_ms, jac_n, fmt_check(r)))
    for r in rows:
        if "mu_attempts" in r:
            for a in r["mu_attempts"]:
                print("coupled_troesch attempt mu=%g: success=%s (%s)" % (
                    a["mu"], a["success"], a["message"]))


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--json", action="store_true", help="print JSON instead of a table")
    ap.add_argument("--min-reps", type=int, default=30)
    ap.add_argument("--min-seconds", type=float, default=1.0)
    args = ap.parse_args()

    rows = run(args.min_reps, args.min_seconds)
    meta = {
        "scipy": scipy.__version__,
        "numpy": np.__version__,
        "python": platform.python_version(),
        "machine": "%s, %s cores" % (platform.machine(), __import__("os").cpu_count()),
        "tol": TOL,
        "max_nodes": MAX_NODES,
        "min_reps": args.min_reps,
        "min_seconds": args.min_seconds,
    }
    if args.json:
        json.dump({"meta": meta, "results": rows}, sys.stdout, indent=2)
        print()
    else:
        print_table(rows, meta)
    return 0 if all(r["success"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
