"""diffbvp.solve_bvp: scipy's own solve_bvp tests (scipy/integrate/tests/test_bvp.py, with
scipy's assertions and tolerances) by both paths — expressions (Rust, exact Jacobians) and
callables (scipy's collocation, checked and wrapped) —, sensitivities and adjoint gradients
against closed forms, a fit, and a hostile-input suite (each failure a diffbvp exception that
names what and where)."""

from __future__ import annotations

import pickle
import sys
import time
from io import StringIO

import numpy as np
import pytest
from numpy.testing import assert_, assert_allclose, assert_equal

import diffbvp
from diffbvp import EvaluationError, InputError, fit_bvp, solve_bvp

scipy = pytest.importorskip("scipy")
from scipy.special import erf  # noqa: E402

# ------------------------------------------------------------------ scipy's problems


def exp_fun(x, y):
    return np.vstack((y[1], y[0]))


def exp_fun_jac(x, y):
    df_dy = np.empty((2, 2, x.shape[0]))
    df_dy[0, 0] = 0
    df_dy[0, 1] = 1
    df_dy[1, 0] = 1
    df_dy[1, 1] = 0
    return df_dy


def exp_bc(ya, yb):
    return np.hstack((ya[0] - 1, yb[0]))


def exp_bc_jac(ya, yb):
    return np.array([[1, 0], [0, 0]]), np.array([[0, 0], [1, 0]])


def exp_sol(x):
    return (np.exp(-x) - np.exp(x - 2)) / (1 - np.exp(-2))


EXP = (["y[1]", "y[0]"], ["ya[0] - 1", "yb[0]"])


def sl_fun(x, y, p):
    return np.vstack((y[1], -p[0] ** 2 * y[0]))


def sl_fun_jac(x, y, p):
    n, m = y.shape
    df_dy = np.empty((n, 2, m))
    df_dy[0, 0] = 0
    df_dy[0, 1] = 1
    df_dy[1, 0] = -p[0] ** 2
    df_dy[1, 1] = 0
    df_dp = np.empty((n, 1, m))
    df_dp[0, 0] = 0
    df_dp[1, 0] = -2 * p[0] * y[0]
    return df_dy, df_dp


def sl_bc(ya, yb, p):
    return np.hstack((ya[0], yb[0], ya[1] - p[0]))


def sl_bc_jac(ya, yb, p):
    dbc_dya = np.zeros((3, 2))
    dbc_dya[0, 0] = 1
    dbc_dya[2, 1] = 1
    dbc_dyb = np.zeros((3, 2))
    dbc_dyb[1, 0] = 1
    dbc_dp = np.zeros((3, 1))
    dbc_dp[2, 0] = -1
    return dbc_dya, dbc_dyb, dbc_dp


def sl_sol(x, p):
    return np.sin(p[0] * x)


SL = (["y[1]", "-p[0]**2*y[0]"], ["ya[0]", "yb[0]", "ya[1] - p[0]"])


def emden_fun(x, y):
    return np.vstack((y[1], -y[0] ** 5))


def emden_fun_jac(x, y):
    df_dy = np.empty((2, 2, x.shape[0]))
    df_dy[0, 0] = 0
    df_dy[0, 1] = 1
    df_dy[1, 0] = -5 * y[0] ** 4
    df_dy[1, 1] = 0
    return df_dy


def emden_bc(ya, yb):
    return np.array([ya[1], yb[0] - (3 / 4) ** 0.5])


def emden_bc_jac(ya, yb):
    return np.array([[0, 1], [0, 0]]), np.array([[0, 0], [1, 0]])


def emden_sol(x):
    return (1 + x**2 / 3) ** -0.5


EMDEN = (["y[1]", "-y[0]**5"], ["ya[1]", "yb[0] - sqrt(3/4)"])


def undefined_fun(x, y):
    return np.zeros_like(y)


def undefined_bc(ya, yb):
    return np.array([ya[0], yb[0] - 1])


UNDEFINED = (["0", "0"], ["ya[0]", "yb[0] - 1"])


def big_fun(x, y):
    f = np.zeros_like(y)
    f[::2] = y[1::2]
    return f


def big_bc(ya, yb):
    return np.hstack((ya[::2], yb[::2] - 1))


def big_sol(x, n):
    y = np.ones((2 * n, x.size))
    y[::2] = x
    return x


def big_expressions(n):
    fun = []
    for i in range(2 * n):
        fun.append(f"y[{i + 1}]" if i % 2 == 0 else "0")
    bc = [f"ya[{i}]" for i in range(0, 2 * n, 2)] + [f"yb[{i}] - 1" for i in range(0, 2 * n, 2)]
    return fun, bc


def big_fun_with_parameters(x, y, p):
    f = np.zeros_like(y)
    f[::2] = y[1::2]
    f[1::4] = -p[0] ** 2 * y[::4]
    f[3::4] = -p[1] ** 2 * y[2::4]
    return f


def big_fun_with_parameters_jac(x, y, p):
    n, m = y.shape
    df_dy = np.zeros((n, n, m))
    df_dy[range(0, n, 2), range(1, n, 2)] = 1
    df_dy[range(1, n, 4), range(0, n, 4)] = -p[0] ** 2
    df_dy[range(3, n, 4), range(2, n, 4)] = -p[1] ** 2
    df_dp = np.zeros((n, 2, m))
    df_dp[range(1, n, 4), 0] = -2 * p[0] * y[range(0, n, 4)]
    df_dp[range(3, n, 4), 1] = -2 * p[1] * y[range(2, n, 4)]
    return df_dy, df_dp


def big_bc_with_parameters(ya, yb, p):
    return np.hstack((ya[::2], yb[::2], ya[1] - p[0], ya[3] - p[1]))


def big_bc_with_parameters_jac(ya, yb, p):
    n = ya.shape[0]
    dbc_dya = np.zeros((n + 2, n))
    dbc_dyb = np.zeros((n + 2, n))
    dbc_dya[range(n // 2), range(0, n, 2)] = 1
    dbc_dyb[range(n // 2, n), range(0, n, 2)] = 1
    dbc_dp = np.zeros((n + 2, 2))
    dbc_dp[n, 0] = -1
    dbc_dya[n, 1] = 1
    dbc_dp[n + 1, 1] = -1
    dbc_dya[n + 1, 3] = 1
    return dbc_dya, dbc_dyb, dbc_dp


def big_sol_with_parameters(x, p):
    return np.vstack((np.sin(p[0] * x), np.sin(p[1] * x)))


def big_with_parameters_expressions(n):
    fun = []
    for i in range(n):
        if i % 2 == 0:
            fun.append(f"y[{i + 1}]")
        elif i % 4 == 1:
            fun.append(f"-p[0]**2*y[{i - 1}]")
        else:
            fun.append(f"-p[1]**2*y[{i - 1}]")
    bc = [f"ya[{i}]" for i in range(0, n, 2)] + [f"yb[{i}]" for i in range(0, n, 2)]
    bc += ["ya[1] - p[0]", "ya[3] - p[1]"]
    return fun, bc


def shock_fun(x, y):
    eps = 1e-3
    return np.vstack(
        (
            y[1],
            -(x * y[1] + eps * np.pi**2 * np.cos(np.pi * x) + np.pi * x * np.sin(np.pi * x))
            / eps,
        )
    )


def shock_bc(ya, yb):
    return np.array([ya[0] + 2, yb[0]])


def shock_sol(x):
    eps = 1e-3
    k = np.sqrt(2 * eps)
    return np.cos(np.pi * x) + erf(x / k) / erf(1 / k)


SHOCK = (
    ["y[1]", "-(x*y[1] + eps*pi**2*cos(pi*x) + pi*x*sin(pi*x))/eps"],
    ["ya[0] + 2", "yb[0]"],
)


def nonlin_bc_fun(x, y):
    return np.stack([y[1], np.zeros_like(x)])


def nonlin_bc_bc(ya, yb):
    phiA, phipA = ya
    phiC, phipC = yb
    kappa, ioA, ioC, V, f = 1.64, 0.01, 1.0e-4, 0.5, 38.9
    hA = 0.0 - phiA - 0.0
    iA = ioA * (np.exp(f * hA) - np.exp(-f * hA))
    res0 = iA + kappa * phipA
    hC = V - phiC - 1.0
    iC = ioC * (np.exp(f * hC) - np.exp(-f * hC))
    res1 = iC - kappa * phipC
    return np.array([res0, res1])


def nonlin_bc_sol(x):
    return -0.13426436116763119 - 1.1308709 * x


NONLIN_BC = (
    ["y[1]", "0"],
    [
        "ioA*(exp(f*(-ya[0])) - exp(-f*(-ya[0]))) + kappa*ya[1]",
        "ioC*(exp(f*(V - yb[0] - 1)) - exp(-f*(V - yb[0] - 1))) - kappa*yb[1]",
    ],
)
NONLIN_CONSTANTS = dict(kappa=1.64, ioA=0.01, ioC=1.0e-4, V=0.5, f=38.9)

PATHS = ["expressions", "callables"]


def _jacs(path, fun_jac, bc_jac):
    """scipy's four Jacobian combinations on the callable path; one (exact) on expressions."""
    if path == "expressions":
        return [(None, None)]
    return [(fj, bj) for fj in (None, fun_jac) for bj in (None, bc_jac)]


def _check_residuals(sol, fun, x_test, p=None, S=None):
    sol_test = sol.sol(x_test)
    f_test = fun(x_test, sol_test) if p is None else fun(x_test, sol_test, p)
    if S is not None:
        f_test = f_test + S.dot(sol_test) / x_test
    r = sol.sol(x_test, 1) - f_test
    rel_res = r / (1 + np.abs(f_test))
    norm_res = np.sum(np.real(rel_res * np.conj(rel_res)), axis=0) ** 0.5
    assert_(np.all(norm_res < 1e-3))
    assert_allclose(sol.sol(sol.x), sol.y, rtol=1e-10, atol=1e-10)
    assert_allclose(sol.sol(sol.x, 1), sol.yp, rtol=1e-10, atol=1e-10)


@pytest.mark.parametrize("path", PATHS)
def test_no_params(path):
    x = np.linspace(0, 1, 5)
    x_test = np.linspace(0, 1, 100)
    y = np.zeros((2, x.shape[0]))
    for fun_jac, bc_jac in _jacs(path, exp_fun_jac, exp_bc_jac):
        if path == "expressions":
            sol = solve_bvp(*EXP, x, y)
            assert sol.jacobian == "exact (expressions)"
        else:
            sol = solve_bvp(exp_fun, exp_bc, x, y, fun_jac=fun_jac, bc_jac=bc_jac)
        assert_equal(sol.status, 0)
        assert_(sol.success)
        assert_equal(sol.x.size, 5)
        sol_test = sol.sol(x_test)
        assert_allclose(sol_test[0], exp_sol(x_test), atol=1e-5)
        assert_(np.all(sol.rms_residuals < 1e-3))
        _check_residuals(sol, exp_fun, x_test)


@pytest.mark.parametrize("path", PATHS)
def test_with_params(path):
    x = np.linspace(0, np.pi, 5)
    x_test = np.linspace(0, np.pi, 100)
    y = np.ones((2, x.shape[0]))
    for fun_jac, bc_jac in _jacs(path, sl_fun_jac, sl_bc_jac):
        if path == "expressions":
            sol = solve_bvp(*SL, x, y, p=[0.5])
        else:
            sol = solve_bvp(sl_fun, sl_bc, x, y, p=[0.5], fun_jac=fun_jac, bc_jac=bc_jac)
        assert_equal(sol.status, 0)
        assert_(sol.success)
        assert_(sol.x.size < 10)
        assert_allclose(sol.p, [1], rtol=1e-4)
        sol_test = sol.sol(x_test)
        assert_allclose(sol_test[0], sl_sol(x_test, [1]), rtol=1e-4, atol=1e-4)
        assert_(np.all(sol.rms_residuals < 1e-3))
        _check_residuals(sol, sl_fun, x_test, p=[1])


@pytest.mark.parametrize("path", PATHS)
def test_singular_term(path):
    x = np.linspace(0, 1, 10)
    x_test = np.linspace(0.05, 1, 100)
    y = np.empty((2, 10))
    y[0] = (3 / 4) ** 0.5
    y[1] = 1e-4
    S = np.array([[0, 0], [0, -2]])
    for fun_jac, bc_jac in _jacs(path, emden_fun_jac, emden_bc_jac):
        if path == "expressions":
            sol = solve_bvp(*EMDEN, x, y, S=S)
        else:
            sol = solve_bvp(emden_fun, emden_bc, x, y, S=S, fun_jac=fun_jac, bc_jac=bc_jac)
        assert_equal(sol.status, 0)
        assert_(sol.success)
        assert_equal(sol.x.size, 10)
        sol_test = sol.sol(x_test)
        assert_allclose(sol_test[0], emden_sol(x_test), atol=1e-5)
        _check_residuals(sol, emden_fun, x_test, S=S)


def test_complex_on_callables_and_refused_on_expressions():
    x = np.linspace(0, 1, 5)
    x_test = np.linspace(0, 1, 100)
    y = np.zeros((2, x.shape[0]), dtype=complex)
    sol = solve_bvp(exp_fun, lambda ya, yb: np.hstack((ya[0] - 1 - 1j, yb[0])), x, y)
    assert_equal(sol.status, 0)
    assert_allclose(sol.sol(x_test)[0].real, exp_sol(x_test), atol=1e-5)
    assert_allclose(sol.sol(x_test)[0].imag, exp_sol(x_test), atol=1e-5)
    with pytest.raises(InputError, match="complex"):
        solve_bvp(*EXP, x, y)


@pytest.mark.parametrize("path", PATHS)
def test_failures(path):
    x = np.linspace(0, 1, 2)
    y = np.zeros((2, x.size))
    if path == "expressions":
        res = solve_bvp(*EXP, x, y, tol=1e-5, max_nodes=5)
    else:
        res = solve_bvp(exp_fun, exp_bc, x, y, tol=1e-5, max_nodes=5)
    assert_equal(res.status, 1)
    assert_(not res.success)
    if path == "expressions":
        # the message gives the numbers
        assert "max_nodes = 5" in res.message and "tol 1.0e-5" in res.message, res.message

    x = np.linspace(0, 1, 5)
    y = np.zeros((2, x.size))
    if path == "expressions":
        res = solve_bvp(*UNDEFINED, x, y)
        assert "singular" in res.message.lower(), res.message
    else:
        res = solve_bvp(undefined_fun, undefined_bc, x, y)
    assert_equal(res.status, 2)
    assert_(not res.success)


@pytest.mark.parametrize("path", PATHS)
def test_big_problem(path):
    n = 30
    x = np.linspace(0, 1, 5)
    y = np.zeros((2 * n, x.size))
    if path == "expressions":
        sol = solve_bvp(*big_expressions(n), x, y)
    else:
        sol = solve_bvp(big_fun, big_bc, x, y)
    assert_equal(sol.status, 0)
    assert_(sol.success)
    sol_test = sol.sol(x)
    assert_allclose(sol_test[0], big_sol(x, n))
    assert_(np.all(sol.rms_residuals < 1e-3))
    _check_residuals(sol, big_fun, x)


@pytest.mark.parametrize("path", PATHS)
def test_big_problem_with_parameters(path):
    n = 30
    x = np.linspace(0, np.pi, 5)
    x_test = np.linspace(0, np.pi, 100)
    y = np.ones((2 * n, x.size))
    for fun_jac, bc_jac in _jacs(path, big_fun_with_parameters_jac, big_bc_with_parameters_jac):
        if path == "expressions":
            sol = solve_bvp(*big_with_parameters_expressions(2 * n), x, y, p=[0.5, 0.5])
        else:
            sol = solve_bvp(big_fun_with_parameters, big_bc_with_parameters, x, y,
                            p=[0.5, 0.5], fun_jac=fun_jac, bc_jac=bc_jac)
        assert_equal(sol.status, 0)
        assert_(sol.success)
        assert_allclose(sol.p, [1, 1], rtol=1e-4)
        sol_test = sol.sol(x_test)
        for isol in range(0, n, 4):
            assert_allclose(sol_test[isol], big_sol_with_parameters(x_test, [1, 1])[0],
                            rtol=1e-4, atol=1e-4)
            assert_allclose(sol_test[isol + 2], big_sol_with_parameters(x_test, [1, 1])[1],
                            rtol=1e-4, atol=1e-4)
        assert_(np.all(sol.rms_residuals < 1e-3))
        _check_residuals(sol, big_fun_with_parameters, x_test, p=[1, 1])


@pytest.mark.parametrize("path", PATHS)
def test_shock_layer(path):
    x = np.linspace(-1, 1, 5)
    x_test = np.linspace(-1, 1, 100)
    y = np.zeros((2, x.size))
    if path == "expressions":
        sol = solve_bvp(*SHOCK, x, y, constants={"eps": 1e-3})
    else:
        sol = solve_bvp(shock_fun, shock_bc, x, y)
    assert_equal(sol.status, 0)
    assert_(sol.success)
    assert_(sol.x.size < 110)
    sol_test = sol.sol(x_test)
    assert_allclose(sol_test[0], shock_sol(x_test), rtol=1e-5, atol=1e-5)
    _check_residuals(sol, shock_fun, x_test)


@pytest.mark.parametrize("path", PATHS)
def test_nonlin_bc(path):
    x = np.linspace(0, 0.1, 5)
    x_test = x
    y = np.zeros([2, x.size])
    if path == "expressions":
        sol = solve_bvp(*NONLIN_BC, x, y, constants=NONLIN_CONSTANTS)
    else:
        sol = solve_bvp(nonlin_bc_fun, nonlin_bc_bc, x, y)
    assert_equal(sol.status, 0)
    assert_(sol.success)
    assert_(sol.x.size < 8)
    sol_test = sol.sol(x_test)
    assert_allclose(sol_test[0], nonlin_bc_sol(x_test), rtol=1e-5, atol=1e-5)
    _check_residuals(sol, nonlin_bc_fun, x_test)


@pytest.mark.parametrize("path", PATHS)
def test_verbose(path):
    x = np.linspace(0, 1, 5)
    y = np.zeros((2, x.shape[0]))
    for verbose in [0, 1, 2]:
        old_stdout = sys.stdout
        sys.stdout = StringIO()
        try:
            if path == "expressions":
                sol = solve_bvp(*EXP, x, y, verbose=verbose)
            else:
                sol = solve_bvp(exp_fun, exp_bc, x, y, verbose=verbose)
            text = sys.stdout.getvalue()
        finally:
            sys.stdout = old_stdout
        assert_(sol.success)
        if verbose == 0:
            assert_(not text, text)
        if verbose >= 1:
            assert_("Solved in" in text, text)
        if verbose >= 2:
            assert_("Max residual" in text, text)


def test_parameter_validation_raises_value_errors():
    # scipy's test_parameter_validation: ValueError (InputError is one), on both paths
    x = [0, 1, 0.5]
    y = np.zeros((2, 3))
    for fun, bc in [(exp_fun, exp_bc), EXP]:
        with pytest.raises(ValueError, match="strictly increasing"):
            solve_bvp(fun, bc, x, y)
    x = np.linspace(0, 1, 5)
    for fun, bc in [(exp_fun, exp_bc), EXP]:
        with pytest.raises(ValueError, match=r"shape \(n, 5\)"):
            solve_bvp(fun, bc, x, np.zeros((2, 4)))
    y = np.zeros((2, x.shape[0]))
    with pytest.raises(ValueError):
        solve_bvp(lambda x, y, p: exp_fun(x, y), lambda ya, yb, p: exp_bc(ya, yb), x, y, p=[1])
    with pytest.raises(ValueError, match="2 boundary conditions for 2 states and 1 unknown"):
        solve_bvp(*EXP, x, y, p=[1])
    with pytest.raises(ValueError, match=r"returned shape \(3,\)"):
        solve_bvp(lambda x, y: np.zeros(3), exp_bc, x, y)
    for fun, bc in [(exp_fun, exp_bc), EXP]:
        with pytest.raises(ValueError, match=r"S: expected shape \(2, 2\)"):
            solve_bvp(fun, bc, x, y, S=np.array([[0, 0]]))


# ------------------------------------------------------------------ SymPy and strings


def test_sympy_expressions_lower_to_the_same_problem():
    sympy = pytest.importorskip("sympy")
    y0, y1, k = sympy.symbols("y0 y1 k")
    ya0, yb0 = sympy.symbols("ya0 yb0")
    x = np.linspace(0, 1, 5)
    guess = np.zeros((2, 5))
    a = solve_bvp([y1, -k * sympy.exp(y0)], [ya0, yb0], x, guess, params={"k": 1.0}, tol=1e-6)
    b = solve_bvp("y[1]; -k*exp(y[0])", "ya[0]; yb[0]", x, guess, params={"k": 1.0}, tol=1e-6)
    assert a.success and b.success
    assert_allclose(a.y, b.y, rtol=0, atol=0)
    assert abs(a.sol(0.5)[0] - 0.1405392144) < 1e-6
    # Piecewise, Abs, Rational, pi, E and IndexedBase print into the language
    Y = sympy.IndexedBase("y")
    xs = sympy.Symbol("x")
    e = sympy.Piecewise((Y[0] ** 2, xs < sympy.Rational(1, 2)), (sympy.Abs(Y[1]), True))
    assert diffbvp.to_expression(e) == "where((x < (1/2)), y[0]**2, abs(y[1]))"
    assert diffbvp.to_expression(sympy.pi * sympy.E) in ("exp(1)*pi", "pi*exp(1)")


def test_piecewise_right_hand_side_solves():
    # y'' = where(x < 0.5, (x - 0.5)^2, 0) (C1 in x), y(0) = y(1) = 0:
    # y = (x - 0.5)^4/12 + A (x - 1) left of 0.5, A (x - 1) right of it, A = 1/192
    x = np.linspace(0, 1, 11)
    r = solve_bvp(["y[1]", "where(x < 0.5, (x - 0.5)**2, 0)"], ["ya[0]", "yb[0]"], x,
                  np.zeros((2, 11)), tol=1e-6)
    assert r.success, r.message
    xs = np.linspace(0, 1, 21)
    a = 1 / 192
    exact = np.where(xs < 0.5, (xs - 0.5) ** 4 / 12 + a * (xs - 1), a * (xs - 1))
    assert_allclose(r.sol(xs)[0], exact, atol=1e-8)


# ------------------------------------------------------------------ derivatives vs closed forms


def test_sensitivities_decay_closed_form():
    # y' = -k y, y(0) = 1: y = exp(-k x), dy/dk = -x exp(-k x)
    k = 0.7
    x = np.linspace(0, 2, 5)
    r = solve_bvp(["-k*y[0]"], ["ya[0] - 1"], x, np.ones((1, 5)), params={"k": k}, tol=1e-8)
    assert r.success
    xs = np.linspace(0, 2, 9)
    s = r.sensitivities(xs)
    assert s["dy"].shape == (1, 9, 1) and s["names"] == ["k"]
    exact = -xs * np.exp(-k * xs)
    assert_allclose(s["dy"][0, :, 0], exact, rtol=1e-6, atol=1e-12)
    # at the nodes
    s = r.sensitivities()
    assert_allclose(s["dy"][0, :, 0], -r.x * np.exp(-k * r.x), rtol=1e-6, atol=1e-12)
    # adjoint gradient of G = y(2)^2: 2 y dy/dk = -4 exp(-4k)
    v, g = r.gradient("y[0]**2", [2.0])
    assert_allclose(v, np.exp(-4 * k), rtol=1e-6)
    assert_allclose(g, [-4 * np.exp(-4 * k)], rtol=1e-6)


def test_sensitivities_linear_two_parameters_closed_form():
    # y'' = a, y(0) = 0, y(1) = b: y = a x (x - 1)/2 + b x; dy/da = x(x-1)/2, dy/db = x
    x = np.linspace(0, 1, 4)
    r = solve_bvp(["y[1]", "a"], ["ya[0]", "yb[0] - b"], x, np.zeros((2, 4)),
                  params={"a": 2.0, "b": 3.0}, tol=1e-8)
    xs = np.linspace(0, 1, 7)
    s = r.sensitivities(xs)
    assert_allclose(s["dy"][0, :, 0], xs * (xs - 1) / 2, rtol=1e-6, atol=1e-12)
    assert_allclose(s["dy"][0, :, 1], xs, rtol=1e-6, atol=1e-12)
    # the slope y' = a (x - 1/2) + b: d/da = x - 1/2, d/db = 1
    assert_allclose(s["dy"][1, :, 0], xs - 0.5, rtol=1e-6, atol=1e-12)
    assert_allclose(s["dy"][1, :, 1], np.ones_like(xs), rtol=1e-6)
    # adjoint gradient of the weighted sum of y at the points: matches the forward one
    w = np.linspace(1, 2, 7)
    v, g = r.gradient("y[0]", xs, w)
    assert_allclose(g, [np.sum(w * xs * (xs - 1) / 2), np.sum(w * xs)], rtol=1e-6)


def test_integral_functional_gradient_closed_form():
    # y'' = k^2 y, y(0) = 1, y(1) = 0: y = sinh(k(1-x))/sinh(k);
    # G = ∫ y dx + y'(0)^2/2 = (cosh k - 1)/(k sinh k) + (k coth k)^2/2
    k = 2.0
    x = np.linspace(0, 1, 11)
    r = solve_bvp(["y[1]", "k**2*y[0]"], ["ya[0] - 1", "yb[0]"], x, np.zeros((2, 11)),
                  params={"k": k}, tol=1e-8)
    assert r.success
    v, g = r.integral("y[0]", endpoint="ya[1]**2/2")
    coth = 1 / np.tanh(k)
    mean = (np.cosh(k) - 1) / (k * np.sinh(k))
    d_mean = (k * np.sinh(k) ** 2 - (np.cosh(k) - 1) * (np.sinh(k) + k * np.cosh(k))) / (
        k * np.sinh(k)
    ) ** 2
    d_end = k * coth * (coth - k / np.sinh(k) ** 2)
    assert_allclose(v, mean + (k * coth) ** 2 / 2, rtol=1e-6)
    assert_allclose(g, [d_mean + d_end], rtol=1e-6)
    # the integrand alone, from SymPy
    sympy = pytest.importorskip("sympy")
    v2, g2 = r.integral(sympy.Symbol("y0"))
    assert_allclose([v2, g2[0]], [mean, d_mean], rtol=1e-6)
    # a state symbol in the end-point term is refused, naming the term
    with pytest.raises(InputError, match="endpoint"):
        r.integral("y[0]", endpoint="y[0]")


def test_sensitivities_sturm_liouville_unknown_closed_form():
    # y'' = -lam^2 y, y(0) = 0, y(pi/c) = 0, y'(0) = lam * A: lam = c; d lam/d c = 1
    c = 1.3
    x = np.linspace(0, np.pi / c, 5)
    r = solve_bvp(["y[1]", "-lam**2*y[0]"], ["ya[0]", "yb[0]", "ya[1] - lam"], x,
                  np.ones((2, 5)), p=[1.0], unknowns=["lam"], params={"c": c}, tol=1e-8)
    # the interval does not depend on c here (the mesh is fixed input): reformulate on [0, 1]
    # with t = c x / pi: y_t = (pi/c) y', the eigenvalue lam = c
    x = np.linspace(0, 1, 5)
    r = solve_bvp(["(pi/c)*y[1]", "-(pi/c)*lam**2*y[0]"], ["ya[0]", "yb[0]", "ya[1] - lam"], x,
                  np.vstack((np.sin(np.pi * x), np.cos(np.pi * x))), p=[1.0], unknowns=["lam"],
                  params={"c": c}, tol=1e-8)
    assert r.success
    assert_allclose(r.p, [c], rtol=1e-6)
    s = r.sensitivities([0.5])
    assert_allclose(s["dp"], [[1.0]], rtol=1e-6)
    # y(t) = sin(pi t): independent of c, so dy/dc = 0 at t = 0.5 up to the discretisation
    assert abs(s["dy"][0, 0, 0]) < 1e-6


def test_fit_recovers_parameter_with_confidence_interval():
    rng = np.random.default_rng(1)
    k_true = 0.7
    xd = np.linspace(0, 2, 15)
    yd = np.exp(-k_true * xd) + 1e-3 * rng.standard_normal(xd.size)
    f = fit_bvp(["-k*y[0]"], ["ya[0] - 1"], np.linspace(0, 2, 5), np.ones((1, 5)),
                {"k": 2.0}, xd, yd, bounds={"k": (0.1, 5.0)})
    assert f.success
    assert abs(f.params["k"] - k_true) < 4 * f.stderr[0] + 1e-4
    assert f.ci95[0, 0] < f.params["k"] < f.ci95[0, 1]
    assert 0 < f.stderr[0] < 0.01
    g = pickle.loads(pickle.dumps(f))
    assert_allclose(g.covariance, f.covariance)
    # a bound that excludes the optimum is respected
    f2 = fit_bvp(["-k*y[0]"], ["ya[0] - 1"], np.linspace(0, 2, 5), np.ones((1, 5)),
                 {"k": 2.0}, xd, yd, bounds={"k": (1.0, 5.0)})
    assert abs(f2.params["k"] - 1.0) < 1e-8


def test_fit_matches_scipy_least_squares_on_the_same_solves():
    # Bratu with two model parameters y'' = -a exp(y) + b, y(0) = y(1) = 0, fitted to y and
    # compared with scipy's trust-region reflective method run on diffbvp's own solves
    least_squares = pytest.importorskip("scipy.optimize").least_squares
    fun, bc = ["y[1]", "-a*exp(y[0]) + b"], ["ya[0]", "yb[0]"]
    x0, y0 = np.linspace(0, 1, 5), np.zeros((2, 5))
    xd = np.linspace(0.05, 0.95, 19)
    truth = solve_bvp(fun, bc, x0, y0, params={"a": 1.7, "b": 0.4}, tol=1e-9)
    yd = truth.sol(xd)[0] + 2e-4 * np.random.default_rng(3).standard_normal(xd.size)
    f = fit_bvp(fun, bc, x0, y0, {"a": 0.5, "b": 0.0}, xd, yd, tol=1e-9,
                bounds={"a": (0.0, 3.0), "b": (-1.0, 1.0)})
    assert f.success, f.message

    def resid(q):
        r = solve_bvp(fun, bc, x0, y0, params={"a": q[0], "b": q[1]}, tol=1e-9)
        return r.sol(xd)[0] - yd

    ref = least_squares(resid, [0.5, 0.0], bounds=([0.0, -1.0], [3.0, 1.0]), xtol=1e-12,
                        ftol=1e-12, gtol=1e-12)
    assert_allclose(f.x, ref.x, rtol=1e-5)
    assert_allclose(f.cost, ref.cost, rtol=1e-6)
    # the Jacobian is the exact one of the residuals at the optimum (central differences)
    h = 1e-6
    fd = np.stack([(resid(f.x + h * e) - resid(f.x - h * e)) / (2 * h) for e in np.eye(2)], 1)
    assert_allclose(f.jac, fd, rtol=1e-5, atol=1e-7)
    assert f.solution.success and f.solution.params == f.params


def test_fit_intervals_cover_the_truth_over_replicates():
    # y' = -k y, 15 points with 1 % noise: over 40 fresh-noise replicates the 95 % interval
    # holds k in at least 34 (a binomial(40, 0.95) gives fewer than 34 with probability 0.3 %)
    rng = np.random.default_rng(11)
    k_true, xd = 0.7, np.linspace(0, 2, 15)
    covered = 0
    for _ in range(40):
        yd = np.exp(-k_true * xd) * (1 + 0.01 * rng.standard_normal(xd.size))
        f = fit_bvp(["-k*y[0]"], ["ya[0] - 1"], np.linspace(0, 2, 5), np.ones((1, 5)),
                    {"k": 2.0}, xd, yd, bounds={"k": (0.1, 5.0)}, tol=1e-8)
        assert f.success, f.message
        covered += f.ci95[0, 0] <= k_true <= f.ci95[0, 1]
    assert covered >= 34, covered


def test_fit_refuses_more_observations_than_a_data_file_may_hold():
    # the loader's row cap, owned by the library, before any solve
    n = 1_000_001
    xd = np.linspace(0, 2, n)
    with pytest.raises(InputError, match="1000001 observations, more than 1000000"):
        fit_bvp(["-k*y[0]"], ["ya[0] - 1"], np.linspace(0, 2, 5), np.ones((1, 5)), {"k": 2.0},
                xd, np.exp(-0.7 * xd))


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"data_x": [0.5, 3.0], "data_y": [1.0, 1.0]}, r"data_x\[1\] = 3.0 is outside"),
        ({"bounds": {"k": (3.0, 5.0)}}, r"params\['k'\] = 2.0 is outside its bounds"),
        ({"bounds": {"k": (5.0, 3.0)}}, "lower bound must be below"),
        ({"sigma": [1.0, 2.0]}, "sigma: a number or 3 values"),
        ({"sigma": -1.0}, "sigma must be positive"),
        ({"component": 1}, "component must be a state index"),
        ({"params": {"k": "fast"}}, r"params\['k'\]: expected a number"),
    ],
)
def test_fit_refuses_bad_arguments_naming_them(kwargs, match):
    args = {"fun": ["-k*y[0]"], "bc": ["ya[0] - 1"], "x": np.linspace(0, 2, 5),
            "y": np.ones((1, 5)), "params": {"k": 2.0}, "data_x": [0.0, 1.0, 2.0],
            "data_y": [1.0, 0.5, 0.25]}
    args.update(kwargs)
    with pytest.raises(InputError, match=match):
        fit_bvp(**args)


def test_results_pickle_and_sol_matches_native_interpolant():
    x = np.linspace(0, 1, 5)
    r = solve_bvp(*EXP, x, np.zeros((2, 5)), tol=1e-6)
    xs = np.linspace(0, 1, 33)
    native = np.asarray(r._native.eval(xs.tolist(), 0))
    assert_allclose(r.sol(xs), native, rtol=1e-13, atol=1e-14)
    assert_allclose(r.sol(xs, 1), np.asarray(r._native.eval(xs.tolist(), 1)), rtol=1e-12,
                    atol=1e-13)
    assert r.sol(0.5).shape == (2,)
    r2 = pickle.loads(pickle.dumps(r))
    assert_allclose(r2.sol(xs), r.sol(xs))
    assert r2.status == 0
    with pytest.raises(InputError, match="unpickled"):
        r2.sensitivities()


# ------------------------------------------------------------------ hostile inputs


X5 = np.linspace(0, 1, 5)
Y5 = np.zeros((2, 5))


def test_unknown_symbol_names_expression_and_position():
    with pytest.raises(InputError) as e:
        solve_bvp(["y[1]", "-exp(y[0])*kk"], ["ya[0]", "yb[0]"], X5, Y5, params={"k": 1})
    text = str(e.value)
    assert 'fun[1] = "-exp(y[0])*kk"' in text and "unknown symbol 'kk'" in text, text
    assert "position 11" in text, text


def test_index_out_of_range_and_wrong_place():
    with pytest.raises(InputError, match=r"index out of range: y\[5\]"):
        solve_bvp(["y[1]", "y[5]"], ["ya[0]", "yb[0]"], X5, Y5)
    with pytest.raises(InputError, match=r"bc\[1\].*not available in a boundary"):
        solve_bvp(["y[1]", "y[0]"], ["ya[0]", "y[0]"], X5, Y5)
    with pytest.raises(InputError, match="both be expressions"):
        solve_bvp(["y[1]", "y[0]"], exp_bc, X5, Y5)


def test_division_by_zero_in_expression_is_an_evaluation_error():
    with pytest.raises(EvaluationError) as e:
        solve_bvp(["y[1]", "1/(y[0] - y[0])"], ["ya[0]", "yb[0] - 1"], X5, Y5)
    text = str(e.value)
    assert 'fun[1] = "1/(y[0] - y[0])"' in text, text
    assert "x = " in text, text


def test_nan_in_guesses():
    y = Y5.copy()
    y[1, 3] = np.nan
    for fun, bc in [(exp_fun, exp_bc), EXP]:
        with pytest.raises(InputError, match=r"y\[1, 3\].*not finite"):
            solve_bvp(fun, bc, X5, y)
    with pytest.raises(InputError, match="p is not finite"):
        solve_bvp(*SL, X5, np.ones((2, 5)), p=[np.nan])
    with pytest.raises(InputError, match=r"x\[2\] is not finite"):
        solve_bvp(*EXP, [0, 0.5, np.inf, 2, 3], Y5)


def test_wrong_shapes():
    with pytest.raises(InputError, match=r"y: 3 rows for 2 states"):
        solve_bvp(*EXP, X5, np.zeros((3, 5)))
    with pytest.raises(InputError, match="1-D"):
        solve_bvp(*EXP, np.zeros((2, 5)), Y5)
    with pytest.raises(InputError, match="2-D"):
        solve_bvp(*EXP, X5, np.zeros(5))
    with pytest.raises(InputError, match=r"fun returned shape \(2, 4\)"):
        solve_bvp(lambda x, y: np.zeros((2, 4)), exp_bc, X5, Y5)
    with pytest.raises(InputError, match=r"bc returned shape \(3,\)"):
        solve_bvp(exp_fun, lambda ya, yb: np.zeros(3), X5, Y5)
    with pytest.raises(InputError, match="tol"):
        solve_bvp(*EXP, X5, Y5, tol=2.0)
    with pytest.raises(InputError, match="verbose"):
        solve_bvp(*EXP, X5, Y5, verbose=7)


def test_callable_that_raises_or_returns_nan():
    def boom(x, y):
        raise RuntimeError("model blew up")

    with pytest.raises(EvaluationError, match="fun raised RuntimeError: model blew up"):
        solve_bvp(boom, exp_bc, X5, Y5)

    def nan_fun(x, y):
        with np.errstate(invalid="ignore"):
            return np.vstack((y[1], np.log(y[0] - 1)))

    with pytest.raises(EvaluationError, match="non-finite value .* component 1 at x = 0"):
        solve_bvp(nan_fun, exp_bc, X5, Y5)

    def bc_boom(ya, yb):
        raise KeyError("q")

    with pytest.raises(EvaluationError, match="bc raised KeyError"):
        solve_bvp(exp_fun, bc_boom, X5, Y5)


def test_million_node_mesh_is_refused_fast_and_solved_when_allowed():
    x = np.linspace(0, 1, 1_000_000)
    y = np.zeros((2, x.size))
    t0 = time.perf_counter()
    with pytest.raises(InputError, match="1000000 nodes, more than max_nodes = 1000"):
        solve_bvp(*EXP, x, y)
    with pytest.raises(InputError, match="1000000 nodes, more than max_nodes = 1000"):
        solve_bvp(exp_fun, exp_bc, x, y)
    assert time.perf_counter() - t0 < 5
    # allowed: it solves (a linear problem: one Newton step) and coarsens, in bounded time
    t0 = time.perf_counter()
    r = solve_bvp(*EXP, x, y, max_nodes=2_000_000)
    assert r.success
    assert time.perf_counter() - t0 < 60
    assert_allclose(r.sol(0.5)[0], exp_sol(0.5), atol=1e-5)


def test_continuation_follows_bratu_to_its_turning_point():
    # Bratu y'' + k e^y = 0: lower branch y(0.5) = 2 ln cosh(t/4), t = sqrt(2k) cosh(t/4);
    # the branch turns at k* = 3.5138...; beyond it there is no solution
    from scipy.optimize import brentq

    def exact(k):
        t = brentq(lambda t: t - np.sqrt(2 * k) * np.cosh(t / 4), 0.1, 4.79)
        return 2 * np.log(np.cosh(t / 4))

    fun, bc = ["y[1]", "-k*exp(y[0])"], ["ya[0]", "yb[0]"]
    x = np.linspace(0, 1, 5)
    ks = [1.0, 2.0, 3.0, 3.5]
    rs = diffbvp.continue_bvp(fun, bc, x, np.zeros((2, 5)), "k", ks, {"k": 0.5}, tol=1e-8)
    for k, r in zip(ks, rs):
        assert r.success and r.params["k"] == k
        assert abs(r.sol(0.5)[0] - exact(k)) < 1e-6 * exact(k), (k, r.sol(0.5)[0], exact(k))
    with pytest.raises(EvaluationError, match="stopped at k = 3.5"):
        diffbvp.continue_bvp(fun, bc, x, np.zeros((2, 5)), "k", [3.5, 3.6], {"k": 0.5},
                             tol=1e-6, min_step=1e-3)


def test_docstring_examples_run_and_print_what_they_show():
    # the examples in the docstrings of diffbvp.bvp (solve_bvp, integral, fit_bvp, ...)
    import doctest

    import diffbvp.bvp

    result = doctest.testmod(diffbvp.bvp, optionflags=doctest.ELLIPSIS)
    assert result.attempted >= 6
    assert result.failed == 0, result
