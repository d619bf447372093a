#!/usr/bin/env python3
"""Peer benchmark: scipy.integrate.solve_bvp with a singular term S (its `S=` argument) on
the singular problems of crates/diffbvp/benches/problem_classes.rs.

Run:
    python3 -m venv venv && venv/bin/pip install scipy
    venv/bin/python benches/peers/scipy_singular.py

Every solve uses tol=1e-6 (scipy's default bc_tol = tol), the guess of the Rust bench
(5 equally spaced nodes), and analytic Jacobians (fun_jac, bc_jac: scipy's best case) as well
as scipy's default finite differences. Each solve is repeated at least 30 times and for at
least 1 s; the median wall time of one solve is printed with the node count and the largest
error against the closed form.
"""

import statistics
import time

import numpy as np
import scipy
from scipy.integrate import solve_bvp

TOL = 1e-6
S = np.array([[0.0, 0.0], [0.0, -2.0]])
X0 = np.linspace(0.0, 1.0, 5)


def emden_fun(x, y):
    return np.vstack((y[1], -y[0] ** 5))


def emden_jac(x, y):
    j = np.zeros((2, 2, x.size))
    j[0, 1] = 1.0
    j[1, 0] = -5.0 * y[0] ** 4
    return j


def emden_bc(ya, yb):
    return np.array([ya[1], yb[0] - np.sqrt(0.75)])


def emden_bc_jac(ya, yb):
    return np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([[0.0, 0.0], [1.0, 0.0]])


def emden_exact(x):
    return (1.0 + x * x / 3.0) ** -0.5


PHI = 3.0


def pellet_fun(x, y):
    return np.vstack((y[1], PHI * PHI * y[0]))


def pellet_jac(x, y):
    j = np.zeros((2, 2, x.size))
    j[0, 1] = 1.0
    j[1, 0] = PHI * PHI
    return j


def pellet_bc(ya, yb):
    return np.array([ya[1], yb[0] - 1.0])


def pellet_bc_jac(ya, yb):
    return np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([[0.0, 0.0], [1.0, 0.0]])


def pellet_exact(x):
    x = np.where(x == 0.0, 1e-300, x)
    return np.sinh(PHI * x) / (x * np.sinh(PHI))


def median_time(run, min_reps=30, min_seconds=1.0):
    times = []
    start = time.perf_counter()
    while len(times) < min_reps or time.perf_counter() - start < min_seconds:
        t0 = time.perf_counter()
        run()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main():
    print(f"scipy {scipy.__version__}, numpy {np.__version__}, tol {TOL:g}")
    print("| problem | jacobians | median [ms] | nodes | max error |")
    print("|---|---|---|---|---|")
    xs = np.linspace(0.0, 1.0, 201)
    cases = [
        ("emden", emden_fun, emden_bc, emden_jac, emden_bc_jac, [1.0, 0.0], emden_exact),
        ("pellet phi=3", pellet_fun, pellet_bc, pellet_jac, pellet_bc_jac, [0.5, 0.0], pellet_exact),
    ]
    for name, fun, bc, jac, bc_jac, y0, exact in cases:
        y_guess = np.tile(np.array(y0)[:, None], (1, X0.size))
        for label, kw in [("analytic", dict(fun_jac=jac, bc_jac=bc_jac)), ("finite differences", {})]:
            def run():
                return solve_bvp(fun, bc, X0, y_guess, S=S, tol=TOL, **kw)

            sol = run()
            assert sol.success, sol.message
            err = np.max(np.abs(sol.sol(xs)[0] - exact(xs)))
            t = median_time(run)
            print(f"| {name} | {label} | {t * 1e3:.3f} | {sol.x.size} | {err:.1e} |")


if __name__ == "__main__":
    main()
