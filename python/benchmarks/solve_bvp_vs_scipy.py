"""diffbvp.solve_bvp beside scipy.integrate.solve_bvp, in one run: whole-call wall time (the
median of N calls, alternating the contenders so that load changes hit all alike), same
problems, same tolerance, final nodes reported; plus sensitivities and adjoint gradients of
the expression path against closed forms.

    python python/benchmarks/solve_bvp_vs_scipy.py [N]        # default N = 21

Contenders per problem:
  scipy       scipy.integrate.solve_bvp, callables, finite-difference Jacobians
  scipy+jac   the same with the analytic fun_jac/bc_jac (where scipy's tests give them)
  expr        diffbvp.solve_bvp with expressions (Rust, exact Jacobians, GIL released)
  callable    diffbvp.solve_bvp with the same callables (scipy's collocation, wrapped)
  pounce      pounce.solve_bvp (pounce-solver on PyPI, the other Rust/PyO3 drop-in), the same
              callables; pounce+jac with the analytic Jacobians (only where it is installed)
"""

from __future__ import annotations

import statistics
import sys
import time

import numpy as np
from scipy.integrate import solve_bvp as scipy_solve_bvp

import diffbvp

try:  # the other Rust/PyO3 drop-in, where it installs (pip install pounce-solver)
    import pounce
except ImportError:  # pragma: no cover - optional peer
    pounce = None

sys.path.insert(0, __file__.rsplit("/", 2)[0] + "/tests")
import test_solve_bvp as T  # noqa: E402  (scipy's problems, written once)


def bratu_fun(x, y):
    return np.vstack((y[1], -np.exp(y[0])))


def bratu_bc(ya, yb):
    return np.array([ya[0], yb[0]])


PROBLEMS = [
    # name, callables (fun, bc, fun_jac, bc_jac), expressions (fun, bc, kwargs), x, y, p, tol
    ("exponential", (T.exp_fun, T.exp_bc, T.exp_fun_jac, T.exp_bc_jac), (*T.EXP, {}),
     np.linspace(0, 1, 5), np.zeros((2, 5)), None, 1e-3),
    ("exponential tol 1e-8", (T.exp_fun, T.exp_bc, T.exp_fun_jac, T.exp_bc_jac), (*T.EXP, {}),
     np.linspace(0, 1, 5), np.zeros((2, 5)), None, 1e-8),
    ("Sturm-Liouville (p)", (T.sl_fun, T.sl_bc, T.sl_fun_jac, T.sl_bc_jac), (*T.SL, {}),
     np.linspace(0, np.pi, 5), np.ones((2, 5)), [0.5], 1e-3),
    ("Bratu tol 1e-6", (bratu_fun, bratu_bc, None, None),
     (["y[1]", "-exp(y[0])"], ["ya[0]", "yb[0]"], {}),
     np.linspace(0, 1, 5), np.zeros((2, 5)), None, 1e-6),
    ("shock layer eps 1e-3", (T.shock_fun, T.shock_bc, None, None),
     (*T.SHOCK, {"constants": {"eps": 1e-3}}), np.linspace(-1, 1, 5), np.zeros((2, 5)), None,
     1e-3),
    ("nonlinear bc", (T.nonlin_bc_fun, T.nonlin_bc_bc, None, None),
     (*T.NONLIN_BC, {"constants": T.NONLIN_CONSTANTS}), np.linspace(0, 0.1, 5),
     np.zeros((2, 5)), None, 1e-3),
    ("big n=60 with p", (T.big_fun_with_parameters, T.big_bc_with_parameters,
                         T.big_fun_with_parameters_jac, T.big_bc_with_parameters_jac),
     (*T.big_with_parameters_expressions(60), {}), np.linspace(0, np.pi, 5), np.ones((60, 5)),
     [0.5, 0.5], 1e-3),
    ("Emden (S)", (T.emden_fun, T.emden_bc, T.emden_fun_jac, T.emden_bc_jac),
     (*T.EMDEN, {"S": np.array([[0, 0], [0, -2]])}), np.linspace(0, 1, 10),
     np.vstack((np.full(10, 0.75**0.5), np.full(10, 1e-4))), None, 1e-3),
]


def median_time(f, n):
    ts = []
    for _ in range(n):
        t0 = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts)


def main(n: int) -> None:
    print(f"medians of {n} whole calls; ratio = scipy (finite differences) / contender")
    head = f"{'problem':<24}{'contender':<11}{'time':>11}{'ratio':>9}{'nodes':>7}  status"
    print(head)
    print("-" * len(head))
    if pounce is None:
        print("(pounce-solver not installed: its rows are left out)")
    for name, (f, g, fj, gj), (ef, eb, kw), x, y, p, tol in PROBLEMS:
        S = kw.get("S")
        kw_cb = {"S": S} if S is not None else {}
        runs = {
            "scipy": lambda: scipy_solve_bvp(f, g, x, y, p=p, tol=tol, **kw_cb),
            "expr": lambda: diffbvp.solve_bvp(ef, eb, x, y, p=p, tol=tol, **kw),
            "callable": lambda: diffbvp.solve_bvp(f, g, x, y, p=p, tol=tol, **kw_cb),
        }
        if fj is not None:
            runs["scipy+jac"] = lambda: scipy_solve_bvp(f, g, x, y, p=p, tol=tol, fun_jac=fj,
                                                        bc_jac=gj, **kw_cb)
        if pounce is not None:
            runs["pounce"] = lambda: pounce.solve_bvp(f, g, x, y, p=p, tol=tol, **kw_cb)
            if fj is not None:
                runs["pounce+jac"] = lambda: pounce.solve_bvp(f, g, x, y, p=p, tol=tol,
                                                              fun_jac=fj, bc_jac=gj, **kw_cb)
        results, refused = {}, {}
        for k, r in list(runs.items()):
            try:
                results[k] = r()
            except Exception as e:  # a peer that does not support the problem (pounce and S)
                refused[k] = f"{type(e).__name__}: {e}"
                del runs[k]
        times = {k: [] for k in runs}
        for _ in range(n):  # alternate the contenders
            for k, r in runs.items():
                t0 = time.perf_counter()
                r()
                times[k].append(time.perf_counter() - t0)
        base = statistics.median(times["scipy"])
        for k in ["scipy", "scipy+jac", "expr", "callable", "pounce", "pounce+jac"]:
            if k in refused:
                print(f"{name:<24}{k:<11}  refused: {refused[k][:70]}")
            if k not in runs:
                continue
            t = statistics.median(times[k])
            r = results[k]
            print(f"{name:<24}{k:<11}{t * 1e3:>9.3f}ms{base / t:>8.1f}x{r.x.size:>7}  {r.status}")
    print()
    derivatives(n)


def derivatives(n: int) -> None:
    """Sensitivity and adjoint-gradient cost and accuracy against closed forms."""
    k = 0.7
    x = np.linspace(0, 2, 5)
    r = diffbvp.solve_bvp(["-k*y[0]"], ["ya[0] - 1"], x, np.ones((1, 5)), params={"k": k},
                          tol=1e-8)
    xs = np.linspace(0, 2, 9)
    t_sens = median_time(lambda: r.sensitivities(xs), n)
    exact = -xs * np.exp(-k * xs)
    err_sens = np.max(np.abs(r.sensitivities(xs)["dy"][0, :, 0] - exact)) / np.max(np.abs(exact))
    t_grad = median_time(lambda: r.gradient("y[0]**2", [2.0]), n)
    v, g = r.gradient("y[0]**2", [2.0])
    err_grad = abs(g[0] + 4 * np.exp(-4 * k)) / (4 * np.exp(-4 * k))
    print("decay y' = -k y, y(0) = 1, tol 1e-8, "
          f"{r.x.size} nodes: forward sensitivities at 9 points {t_sens * 1e6:.0f} us "
          f"(error vs -x e^(-kx), relative to its maximum: {err_sens:.1e}); adjoint gradient of y(2)^2 "
          f"{t_grad * 1e6:.0f} us (rel. error vs -4 e^(-4k): {err_grad:.1e})")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 21)
