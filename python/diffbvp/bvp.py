"""Any boundary value problem from Python: scipy's :func:`scipy.integrate.solve_bvp`, drop-in.

``from diffbvp import solve_bvp`` instead of ``from scipy.integrate import solve_bvp``: the same
arguments, the same result (``sol``, ``p``, ``x``, ``y``, ``yp``, ``rms_residuals``,
``niter``, ``status``, ``message``, ``success``). Two paths:

* **expressions** (``fun`` and ``bc`` as lists of strings or SymPy expressions): the problem is
  parsed into expression trees that the Rust solver evaluates over dual numbers, with exact
  Jacobians, no Python call per point and the GIL released. Such a result also gives forward
  sensitivities (:meth:`BvpResult.sensitivities`) and adjoint gradients
  (:meth:`BvpResult.gradient`) with respect to named model parameters (``params=``), and
  :func:`fit_bvp` fits them to data.
* **callables** (numpy functions as scipy takes them): solved by scipy's own vectorised
  collocation (scipy must be installed), with the shapes and values checked and every failure
  raised as a :mod:`diffbvp.errors` exception; ``result.jacobian`` says whether the Jacobian was
  the user's or finite differences.

The expression language (see :mod:`diffbvp` docs and the book chapter "Your BVP from Python"):
``x``, ``y[i]`` in ``fun``; ``ya[i]``, ``yb[i]`` in ``bc``; ``p[i]`` (the unknowns, then the
model parameters) or their names; constants by name; ``+ - * / **``, ``exp log sqrt sin cos tan
sinh cosh tanh asin acos atan atan2 abs min max`` and ``where(condition, a, b)``.
"""

from __future__ import annotations

import re
import warnings
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from .errors import EvaluationError, InputError

__all__ = [
    "solve_bvp",
    "fit_bvp",
    "BvpResult",
    "CubicInterpolant",
    "BvpFitResult",
    "to_expression",
    "continue_bvp",
]

_STATUS_MESSAGES = {
    0: "The algorithm converged to the desired accuracy.",
    1: "The maximum number of mesh nodes is exceeded.",
    2: "A singular Jacobian encountered when solving the collocation system.",
    3: "The solver was unable to satisfy boundary conditions tolerance.",
}


class CubicInterpolant:
    """The C1 piecewise-cubic interpolant of a solution (values ``y`` and slopes ``yp`` at the
    nodes ``x``), called as scipy's ``PPoly``: ``sol(x, nu=0)`` gives ``(n,)`` for a scalar
    ``x`` and ``(n, len(x))`` for an array; ``nu`` (0 to 3) is the derivative order. Outside
    ``[x[0], x[-1]]`` the end pieces are extrapolated, as ``PPoly`` does. Picklable.

    >>> import numpy as np
    >>> s = CubicInterpolant(np.array([0.0, 1.0]), np.array([[0.0, 1.0]]), np.array([[0.0, 2.0]]))
    >>> float(s(0.5)[0]), float(s(1.0, 1)[0])
    (0.25, 2.0)
    """

    def __init__(self, x: np.ndarray, y: np.ndarray, yp: np.ndarray):
        self.x = np.asarray(x, dtype=float)
        self._y = np.asarray(y)
        self._yp = np.asarray(yp)
        # the coefficients are computed at the first call (a solve whose `sol` is never
        # evaluated does not pay for them)
        self._c: Optional[np.ndarray] = None

    @property
    def c(self) -> np.ndarray:
        """The coefficients, shape ``(4, n, len(x) - 1)``: ``y(x_i + s) = c[0] + c[1] s +
        c[2] s² + c[3] s³`` on interval ``i``."""
        if self._c is None:
            y, yp = self._y, self._yp
            h = np.diff(self.x)
            slope = np.diff(y, axis=1) / h
            f0, f1 = yp[:, :-1], yp[:, 1:]
            self._c = np.stack(
                (y[:, :-1], f0, (3 * slope - 2 * f0 - f1) / h, (f0 + f1 - 2 * slope) / h**2)
            )
        return self._c

    def __call__(self, x: Any, nu: int = 0) -> np.ndarray:
        if nu not in (0, 1, 2, 3):
            raise InputError(f"sol(x, nu): nu must be 0, 1, 2 or 3, got {nu!r}")
        xa = np.asarray(x, dtype=float)
        scalar = xa.ndim == 0
        xa = np.atleast_1d(xa).ravel()
        i = np.clip(np.searchsorted(self.x, xa, side="right") - 1, 0, self.x.size - 2)
        s = xa - self.x[i]
        c0, c1, c2, c3 = (ci[:, i] for ci in self.c)
        if nu == 0:
            v = c0 + s * (c1 + s * (c2 + s * c3))
        elif nu == 1:
            v = c1 + s * (2 * c2 + 3 * s * c3)
        elif nu == 2:
            v = 2 * c2 + 6 * s * c3
        else:
            v = 6 * c3 + 0 * s
        return v[:, 0] if scalar else v


class BvpResult(dict):
    """The result of :func:`solve_bvp`: scipy's fields as attributes (and dict keys) —
    ``sol``, ``p``, ``x``, ``y``, ``yp``, ``rms_residuals``, ``niter``, ``status``,
    ``message``, ``success`` — plus

    * ``jacobian``: ``"exact (expressions)"``, ``"user fun_jac"``, ``"user fun_jac and bc_jac"``,
      ``"finite differences"``, ...;
    * ``backend``: ``"diffbvp"`` (expressions) or ``"scipy"`` (callables);
    * ``params``: the model parameters' values by name (expressions).

    Results are picklable; the derivative methods need the solution the solve produced and are
    not available on an unpickled copy.
    """

    def __getattr__(self, name: str) -> Any:
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None

    def __setattr__(self, name: str, value: Any) -> None:
        if name.startswith("_"):
            object.__setattr__(self, name, value)
        else:
            self[name] = value

    def __getstate__(self) -> Dict[str, Any]:
        return {}

    def __setstate__(self, state: Dict[str, Any]) -> None:
        pass

    def __repr__(self) -> str:
        keys = ("status", "success", "message", "niter", "jacobian", "backend")
        inner = ", ".join(f"{k}={self.get(k)!r}" for k in keys)
        return f"BvpResult({inner}, nodes={np.size(self.get('x'))})"

    def _native_solution(self):
        native = getattr(self, "_native", None)
        if native is None:
            raise InputError(
                "derivatives need a converged solve of a problem given as expressions "
                "(fun and bc as strings or SymPy expressions) in this process; this result "
                f"is {'a failed solve' if not self.get('success') else 'from ' + str(self.get('backend'))}"
                " or an unpickled copy"
            )
        return native

    def sensitivities(self, x: Any = None) -> Dict[str, np.ndarray]:
        """Forward sensitivities with respect to the model parameters (``params=``):
        ``{"dy": (n, len(x), q), "dp": (k, q), "names": [...]}`` with
        ``dy[c, j, l] = ∂y_c(x_j)/∂q_l`` through the interpolant (at the nodes when ``x`` is
        None) and ``dp[i, l]`` the derivative of unknown ``i``. Exact (dual numbers and the
        implicit function theorem on the discrete solution).
        """
        native = self._native_solution()
        xs = None if x is None else [float(v) for v in np.atleast_1d(np.asarray(x, float))]
        dy, dp = native.sensitivities(xs)
        return {"dy": np.asarray(dy), "dp": np.asarray(dp), "names": list(self.params)}

    def gradient(
        self, functional: Any, x: Any, weights: Any = None
    ) -> Tuple[float, np.ndarray]:
        """Value and gradient with respect to the model parameters of
        ``G = Σ_j w_j g(x_j, y(x_j), p)`` by the adjoint method (one transposed solve,
        whatever the number of parameters). ``functional`` is an expression (string or SymPy)
        in ``x``, ``y[i]`` and the parameters; ``weights`` default to 1.
        """
        native = self._native_solution()
        xs = np.atleast_1d(np.asarray(x, dtype=float))
        w = np.ones_like(xs) if weights is None else np.atleast_1d(np.asarray(weights, float))
        if w.shape != xs.shape:
            raise InputError(f"gradient: {xs.size} points but {w.size} weights")
        value, grad = native.adjoint_gradient(to_expression(functional), xs.tolist(), w.tolist())
        return value, np.asarray(grad)

    def integral(self, integrand: Any, endpoint: Any = None) -> Tuple[float, np.ndarray]:
        """Value and gradient with respect to the model parameters of the integral functional
        ``G = ∫ g(x, y, p) dx + φ(y(a), y(b), p)`` by the adjoint method (one transposed solve).
        ``integrand`` is an expression (string or SymPy) in ``x``, ``y[i]`` and the parameters;
        ``endpoint`` (optional) one in ``ya[i]``, ``yb[i]`` and the parameters. The quadrature
        is Simpson's rule on the solution's cubic interpolant (exact for ``g`` linear in
        ``y``), and the gradient is that of the same quadrature.

        >>> import numpy as np
        >>> from diffbvp import solve_bvp
        >>> r = solve_bvp(["y[1]", "k**2*y[0]"], ["ya[0] - 1", "yb[0]"], np.linspace(0, 1, 11),
        ...               np.zeros((2, 11)), tol=1e-8, params={"k": 2.0})
        >>> G, dG = r.integral("y[0]")      # (cosh k - 1) / (k sinh k) and its d/dk
        >>> round(G, 6), round(float(dG[0]), 6)
        (0.380797, -0.085405)
        """
        native = self._native_solution()
        value, grad = native.integral(
            to_expression(integrand), None if endpoint is None else to_expression(endpoint)
        )
        return value, np.asarray(grad)


# ---------------------------------------------------------------- expressions from SymPy

_INDEXED_NAME = re.compile(r"^(y|ya|yb|p)_?(\d+)$")


def to_expression(e: Any) -> str:
    """The expression-language text of ``e``: a string as it is, a number, or a SymPy
    expression (``Piecewise`` becomes nested ``where``, ``Abs`` ``abs``, ``E`` ``exp(1)``;
    symbols named ``y0``/``y_0`` become ``y[0]``, likewise ``ya``, ``yb``, ``p``; an
    ``IndexedBase('y')[0]`` prints as ``y[0]``).

    >>> to_expression("y[1]")
    'y[1]'
    """
    if isinstance(e, str):
        return e
    if isinstance(e, (int, float, np.integer, np.floating)):
        return repr(float(e))
    try:
        import sympy
    except ImportError:  # pragma: no cover - a non-string without sympy
        raise InputError(
            f"expression {e!r} of type {type(e).__name__}: give a string, or install sympy "
            "for SymPy expressions"
        ) from None
    if not isinstance(e, sympy.Basic):
        raise InputError(
            f"expression {e!r} of type {type(e).__name__}: give a string or a SymPy expression"
        )
    return _printer().doprint(e)


_PRINTER = None


def _printer():
    global _PRINTER
    if _PRINTER is not None:
        return _PRINTER
    from sympy.printing.str import StrPrinter

    class _Printer(StrPrinter):
        def _print_Symbol(self, s):
            m = _INDEXED_NAME.match(s.name)
            return f"{m.group(1)}[{m.group(2)}]" if m else s.name

        def _print_Exp1(self, e):
            return "exp(1)"

        def _print_Pi(self, e):
            return "pi"

        def _print_Abs(self, e):
            return f"abs({self._print(e.args[0])})"

        def _print_Float(self, e):
            return repr(float(e))

        def _print_Rational(self, e):
            return f"({e.p}/{e.q})"

        def _print_Piecewise(self, e):
            out = None
            for value, cond in reversed(e.args):
                if cond == True:  # noqa: E712 - sympy's true
                    out = self._print(value)
                    continue
                if out is None:
                    out = "(0/0)"  # no otherwise-branch: NaN where nothing holds
                out = f"where({self._print(cond)}, {self._print(value)}, {out})"
            return out

        def _print_Relational(self, e):
            if e.rel_op not in ("<", "<=", ">", ">="):
                raise InputError(
                    f"condition {e}: only <, <=, > and >= are supported in where/Piecewise"
                )
            return f"({self._print(e.lhs)} {e.rel_op} {self._print(e.rhs)})"

        def _print_Indexed(self, e):
            return f"{self._print(e.base.label)}[{self._print(e.indices[0])}]"

    _PRINTER = _Printer()
    return _PRINTER


def _is_expressions(obj: Any) -> bool:
    if isinstance(obj, str):
        return True
    if callable(obj) and not _is_sympy(obj):
        return False
    if isinstance(obj, np.ndarray):
        return obj.dtype == object or obj.dtype.kind in "US"
    return isinstance(obj, (list, tuple))


def _is_sympy(obj: Any) -> bool:
    return type(obj).__module__.startswith("sympy")


def _expressions(obj: Any, what: str) -> List[str]:
    if isinstance(obj, str):
        items = [s for s in re.split(r"[;\n]", obj) if s.strip()]
    elif _is_sympy(obj) and hasattr(obj, "__iter__"):
        items = list(obj)
    elif isinstance(obj, np.ndarray):
        items = list(obj.ravel())
    else:
        items = list(obj)
    if not items:
        raise InputError(f"{what}: no expressions given")
    return [to_expression(e) for e in items]


# ---------------------------------------------------------------- input checks


def _check_inputs(x, y, p, tol, max_nodes, bc_tol, complex_ok):
    try:
        x = np.asarray(x, dtype=float)
    except (TypeError, ValueError) as e:
        raise InputError(f"x: expected a 1-D array of numbers ({e})") from None
    if x.ndim != 1:
        raise InputError(f"x: expected a 1-D array, got shape {x.shape}")
    if x.size < 2:
        raise InputError(f"x: at least 2 nodes are needed, got {x.size}")
    if not np.isfinite(x).all():
        j = int(np.flatnonzero(~np.isfinite(x))[0])
        raise InputError(f"x[{j}] is not finite ({x[j]})")
    if not (x[1:] > x[:-1]).all():
        j = int(np.flatnonzero(x[1:] <= x[:-1])[0])
        raise InputError(
            f"x must be strictly increasing: x[{j}] = {x[j]} and x[{j + 1}] = {x[j + 1]}"
        )
    ya = np.asarray(y)
    if ya.dtype.kind == "c" and not complex_ok:
        raise InputError(
            "y is complex: the expression path is real; give fun and bc as callables for "
            "complex problems (solved by scipy)"
        )
    try:
        ya = np.asarray(ya, dtype=complex if ya.dtype.kind == "c" else float)
    except (TypeError, ValueError) as e:
        raise InputError(f"y: expected a 2-D array of numbers ({e})") from None
    if ya.ndim != 2:
        raise InputError(f"y: expected a 2-D array (states × nodes), got shape {ya.shape}")
    if ya.shape[1] != x.size:
        raise InputError(
            f"y: expected shape (n, {x.size}) (one column per node of x), got {ya.shape}"
        )
    if not np.isfinite(ya).all():
        c, j = (int(v[0]) for v in np.nonzero(~np.isfinite(ya)))
        raise InputError(f"y[{c}, {j}] (state {c} at x = {x[j]}) is not finite ({ya[c, j]})")
    if p is None:
        pa = np.zeros(0)
    else:
        try:
            pa = np.asarray(p, dtype=float)
        except (TypeError, ValueError) as e:
            raise InputError(f"p: expected a 1-D array of numbers ({e})") from None
        if pa.ndim != 1:
            raise InputError(f"p: expected a 1-D array, got shape {pa.shape}")
        if not np.isfinite(pa).all():
            raise InputError(f"p is not finite: {pa}")
    if not (isinstance(tol, (int, float)) and 0 < tol < 1):
        raise InputError(f"tol must be in (0, 1), got {tol!r}")
    if bc_tol is not None and not (isinstance(bc_tol, (int, float)) and 0 < bc_tol < np.inf):
        raise InputError(f"bc_tol must be positive and finite, got {bc_tol!r}")
    if not (isinstance(max_nodes, (int, np.integer)) and max_nodes >= 2):
        raise InputError(f"max_nodes must be an integer of at least 2, got {max_nodes!r}")
    if x.size > max_nodes:
        raise InputError(
            f"x has {x.size} nodes, more than max_nodes = {max_nodes}: give a coarser initial "
            "mesh or raise max_nodes"
        )
    return x, ya, pa


# ---------------------------------------------------------------- solve_bvp


def solve_bvp(
    fun: Any,
    bc: Any,
    x: Any,
    y: Any,
    p: Any = None,
    S: Any = None,
    fun_jac: Optional[Callable] = None,
    bc_jac: Optional[Callable] = None,
    tol: float = 1e-3,
    max_nodes: int = 1000,
    verbose: int = 0,
    bc_tol: Optional[float] = None,
    *,
    params: Optional[Mapping[str, float]] = None,
    constants: Optional[Mapping[str, float]] = None,
    unknowns: Optional[Sequence[str]] = None,
) -> BvpResult:
    """Solve ``y' = f(x, y, p) + S y / (x - a)``, ``bc(y(a), y(b), p) = 0`` — scipy's
    :func:`scipy.integrate.solve_bvp`, same arguments and result.

    ``fun``/``bc`` are either numpy callables (scipy's contract: ``fun(x, y[, p])`` with ``x``
    of shape ``(m,)`` and ``y`` of shape ``(n, m)`` returns ``(n, m)``; ``bc(ya, yb[, p])``
    returns ``(n + k,)``), or **expressions**: lists of strings or SymPy expressions, one per
    state and one per boundary condition, e.g. ``fun=["y[1]", "-k*exp(y[0])"]``,
    ``bc=["ya[0]", "yb[0]"]``. Expressions are solved in Rust with exact Jacobians and the GIL
    released; ``params`` (name → value) declares fixed model parameters that
    :meth:`BvpResult.sensitivities`, :meth:`BvpResult.gradient` and :func:`fit_bvp`
    differentiate with respect to; ``constants`` (name → value) are folded in; ``unknowns``
    names the unknown parameters ``p`` (default: reachable as ``p[0]``, ...).

    ``tol`` bounds the RMS collocation residual of every interval relative to ``1 + |f|``
    (scipy's measure), ``bc_tol`` the absolute boundary residuals (default ``tol``). On the
    expression path the mesh is refined by scipy's rule (1 or 2 nodes per interval above
    ``tol``), as scipy does; nodes are never removed.

    Statuses as scipy's: 0 converged, 1 maximum number of nodes exceeded (or no convergence,
    the message says which), 2 singular Jacobian, 3 ``bc_tol`` not met. Bad input raises
    :class:`diffbvp.errors.InputError`; a non-finite value or a failing callable
    :class:`diffbvp.errors.EvaluationError`.

    >>> import numpy as np
    >>> from diffbvp import solve_bvp
    >>> x = np.linspace(0, 1, 5)
    >>> r = solve_bvp(["y[1]", "-exp(y[0])"], ["ya[0]", "yb[0]"], x, np.zeros((2, 5)), tol=1e-6)
    >>> r.status, round(float(r.sol(0.5)[0]), 6)
    (0, 0.140539)
    """
    if not isinstance(verbose, (int, np.integer)) or verbose not in (0, 1, 2):
        raise InputError(f"verbose must be 0, 1 or 2, got {verbose!r}")
    expr_fun, expr_bc = _is_expressions(fun), _is_expressions(bc)
    if expr_fun != expr_bc:
        raise InputError(
            "fun and bc must both be expressions (strings or SymPy) or both be callables; "
            f"got fun as {'expressions' if expr_fun else 'a callable'} and bc as "
            f"{'expressions' if expr_bc else 'a callable'}"
        )
    if expr_fun:
        return _solve_expressions(
            fun, bc, x, y, p, S, fun_jac, bc_jac, tol, max_nodes, verbose, bc_tol,
            params, constants, unknowns,
        )
    if params is not None or constants is not None or unknowns is not None:
        raise InputError(
            "params, constants and unknowns belong to the expression path; with callables "
            "pass model parameters through a closure"
        )
    return _solve_callables(
        fun, bc, x, y, p, S, fun_jac, bc_jac, tol, max_nodes, verbose, bc_tol
    )


def _singular_values(S, n):
    if S is None:
        return None
    Sa = np.asarray(S, dtype=float)
    if Sa.shape != (n, n):
        raise InputError(f"S: expected shape ({n}, {n}), got {Sa.shape}")
    if not np.all(np.isfinite(Sa)):
        raise InputError("S is not finite")
    return Sa


def _solve_expressions(
    fun, bc, x, y, p, S, fun_jac, bc_jac, tol, max_nodes, verbose, bc_tol,
    params, constants, unknowns,
):
    from . import _native

    if fun_jac is not None or bc_jac is not None:
        raise InputError(
            "fun_jac/bc_jac are not used with expressions: their Jacobians are exact already"
        )
    x, ya, pa = _check_inputs(x, y, p, tol, max_nodes, bc_tol, complex_ok=False)
    fun_s = _expressions(fun, "fun")
    bc_s = _expressions(bc, "bc")
    n = len(fun_s)
    if ya.shape[0] != n:
        raise InputError(
            f"y: {ya.shape[0]} rows for {n} states (fun has {n} expressions); expected shape "
            f"({n}, {x.size})"
        )
    k = pa.size
    if unknowns is None:
        unknowns = [""] * k
    unknowns = [str(u) for u in unknowns]
    if len(unknowns) != k:
        raise InputError(f"unknowns: {len(unknowns)} names for {k} values of p")
    params = dict(params or {})
    pnames = list(params)
    pvals = []
    for name, v in params.items():
        try:
            v = float(v)
        except (TypeError, ValueError):
            raise InputError(f"params[{name!r}]: expected a number, got {v!r}") from None
        if not np.isfinite(v):
            raise InputError(f"params[{name!r}] is not finite ({v})")
        pvals.append(v)
    consts = []
    for name, v in dict(constants or {}).items():
        try:
            consts.append((str(name), float(v)))
        except (TypeError, ValueError):
            raise InputError(f"constants[{name!r}]: expected a number, got {v!r}") from None
    Sa = _singular_values(S, n)
    if Sa is not None and x[0] != 0.0:
        raise InputError(f"S: a singular term needs the interval to start at 0, got x[0] = {x[0]}")
    if len(bc_s) != n + k:
        raise InputError(
            f"bc: {len(bc_s)} boundary conditions for {n} states and {k} unknown parameters; "
            f"n + k = {n + k} are needed"
        )
    problem = _native.ExprProblem(
        fun_s, bc_s, unknowns, pnames, consts,
        None if Sa is None else [float(v) for v in Sa.ravel()],
    )
    status, message, native = problem.solve(
        x.tolist(), np.ascontiguousarray(ya), pa.tolist(), pvals, float(tol),
        None if bc_tol is None else float(bc_tol), int(max_nodes), 0, True,
    )
    if native is not None:
        res, max_res, max_bc = _result_of(native, k, dict(zip(pnames, pvals)))
    else:
        # scipy returns its last iterate; the toolkit returns none: the guess, with the message
        res = _expr_result(dict(zip(pnames, pvals)), status)
        res.x = x
        res.y = ya.copy()
        res.yp = np.asarray(problem.rhs(x.tolist(), np.ascontiguousarray(ya), pa.tolist() + pvals))
        res.p = pa if k else None
        res.rms_residuals = np.full(x.size - 1, np.nan)
        res.niter = 0
        res.message = f"{_STATUS_MESSAGES.get(status, 'Failed.')} {message}"
        res.sol = CubicInterpolant(res.x, res.y, res.yp)
        max_res = max_bc = float("nan")
    _report(verbose, res, max_res, max_bc)
    return res


def _expr_result(params: Dict[str, float], status: int) -> BvpResult:
    res = BvpResult()
    res.jacobian = "exact (expressions)"
    res.backend = "diffbvp"
    res.params = params
    res.status = status
    res.success = status == 0
    return res


def _result_of(native: Any, k: int, params: Dict[str, float]) -> Tuple[BvpResult, float, float]:
    """The result of a converged native solution, with its largest residuals."""
    res = _expr_result(params, 0)
    res.x = np.asarray(native.x)
    res.y = np.asarray(native.y)
    res.yp = np.asarray(native.yp)
    res.p = np.asarray(native.unknowns) if k else None
    res.rms_residuals = np.asarray(native.rms_residuals)
    newton, refinements, coarsenings, max_res, max_bc = native.stats
    res.niter = 1 + refinements + coarsenings
    res.message = _STATUS_MESSAGES[0]
    res.sol = CubicInterpolant(res.x, res.y, res.yp)
    object.__setattr__(res, "_native", native)
    return res, max_res, max_bc


def _report(verbose, res, max_res, max_bc):
    if verbose == 0:
        return
    if verbose >= 2:
        print(f"{'Max residual':^15}{'Max BC residual':^17}{'Total nodes':^13}")
        print(f"{max_res:^15.2e}{max_bc:^17.2e}{res.x.size:^13}")
    if res.success:
        print(f"Solved in {res.niter} iterations, number of nodes {res.x.size}. ")
        print(f"Maximum relative residual: {max_res:.2e} ")
        print(f"Maximum boundary residual: {max_bc:.2e}")
    else:
        print(res.message)


# ---------------------------------------------------------------- callables (scipy)


def _raising(f, what):
    """``f`` with an exception re-raised as an :class:`EvaluationError` naming ``what`` (a
    thin wrapper: one Python call layer, no array work, so the solve runs at scipy's speed)."""

    def call(*args):
        try:
            return f(*args)
        except (EvaluationError, InputError):
            raise
        except Exception as e:  # noqa: BLE001 - re-raised as ours, with the cause
            x = np.asarray(args[0]).ravel() if what.startswith("fun") else None
            at = "" if x is None or x.size == 0 else (
                f" (called with x in [{x.min():g}, {x.max():g}], {x.size} points)")
            raise EvaluationError(f"{what} raised {type(e).__name__}: {e}{at}") from e

    return call


def _check_fun_output(out, n, x, what):
    out = np.asarray(out)
    if out.shape != (n, x.size):
        raise InputError(
            f"{what} returned shape {out.shape}; expected ({n}, {x.size}) (states × points, "
            "scipy's contract)"
        )
    if not np.all(np.isfinite(out)):
        c, j = (int(v[0]) for v in np.nonzero(~np.isfinite(out)))
        raise EvaluationError(
            f"{what} returned a non-finite value {out[c, j]} in component {c} at x = {x[j]:g} "
            "(at the initial guess)"
        )


def _check_bc_output(out, nk, what):
    out = np.asarray(out)
    if out.shape != (nk,):
        raise InputError(f"{what} returned shape {out.shape}; expected ({nk},) (n + k residuals)")
    if not np.all(np.isfinite(out)):
        c = int(np.flatnonzero(~np.isfinite(out))[0])
        raise EvaluationError(
            f"{what} returned a non-finite value in component {c} (at the initial guess)"
        )


def _solve_callables(fun, bc, x, y, p, S, fun_jac, bc_jac, tol, max_nodes, verbose, bc_tol):
    if not callable(fun) or not callable(bc):
        raise InputError("fun and bc must be callables or expressions")
    try:
        from scipy.integrate import solve_bvp as scipy_solve_bvp
    except ImportError:
        raise InputError(
            "fun and bc are Python callables, which diffbvp solves with scipy's collocation: "
            "install scipy, or give fun and bc as expressions (strings or SymPy)"
        ) from None
    x, ya, pa = _check_inputs(x, y, p, tol, max_nodes, bc_tol, complex_ok=True)
    n, k = ya.shape[0], pa.size
    _singular_values(S, n)
    f = _raising(fun, "fun")
    g = _raising(bc, "bc")
    fj = None if fun_jac is None else _raising(fun_jac, "fun_jac")
    gj = None if bc_jac is None else _raising(bc_jac, "bc_jac")
    # shapes and values checked once, at the guess; later calls go to the user's functions
    # through the thin wrapper only (a non-finite value later shows in scipy's status)
    pargs = () if p is None else (pa,)
    _check_fun_output(f(x, ya, *pargs), n, x, "fun")
    _check_bc_output(g(ya[:, 0], ya[:, -1], *pargs), n + k, "bc")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        try:
            r = scipy_solve_bvp(
                f, g, x, ya, p=None if p is None else pa, S=S, fun_jac=fj, bc_jac=gj,
                tol=tol, max_nodes=max_nodes, verbose=verbose, bc_tol=bc_tol,
            )
        except (EvaluationError, InputError):
            raise
        except ValueError as e:
            raise InputError(f"solve_bvp: {e}") from e
    res = BvpResult(r)
    parts = []
    parts.append("user fun_jac" if fun_jac is not None else "finite differences for fun")
    parts.append("user bc_jac" if bc_jac is not None else "finite differences for bc")
    if fun_jac is not None and bc_jac is not None:
        res.jacobian = "user fun_jac and bc_jac"
    elif fun_jac is None and bc_jac is None:
        res.jacobian = "finite differences"
    else:
        res.jacobian = ", ".join(parts)
    res.backend = "scipy"
    res.params = {}
    if not res.success:
        res.message = f"{res.message} (status {res.status}; {res.x.size} nodes, largest RMS " \
            f"residual {np.max(res.rms_residuals):.3e}, tol {tol:.1e})"
    return res


# ---------------------------------------------------------------- fits


class BvpFitResult(dict):
    """The result of :func:`fit_bvp` (attributes and dict keys, picklable): ``params`` (name →
    value), ``x`` (array), ``cost`` (½ Σ r²), ``residuals``, ``jac`` (exact, from forward
    sensitivities), ``covariance`` (``s² (JᵀJ)⁻¹`` with ``s² = 2 cost / (m − q)``),
    ``stderr``, ``ci95`` (``(q, 2)``, normal approximation), ``success``, ``message``,
    ``nfev``, ``solution`` (the :class:`BvpResult` at the optimum)."""

    __getattr__ = BvpResult.__getattr__

    def __setattr__(self, name: str, value: Any) -> None:
        self[name] = value


def fit_bvp(
    fun: Any,
    bc: Any,
    x: Any,
    y: Any,
    params: Mapping[str, float],
    data_x: Any,
    data_y: Any,
    component: int = 0,
    bounds: Optional[Mapping[str, Tuple[float, float]]] = None,
    sigma: Any = None,
    p: Any = None,
    tol: float = 1e-6,
    max_nodes: int = 5000,
    constants: Optional[Mapping[str, float]] = None,
    unknowns: Optional[Sequence[str]] = None,
    xtol: float = 1e-10,
    ftol: float = 1e-12,
    max_iterations: int = 100,
) -> BvpFitResult:
    """Fit the model parameters ``params`` (name → start value) of a problem given as
    expressions to observations ``data_y ≈ y_component(data_x)`` by the toolkit's bounded
    trust-region least squares, in Rust with the GIL released: the Jacobian exact from forward
    sensitivities, each solve warm-started from the last accepted one, Ctrl-C honoured.
    ``bounds`` maps names to ``(low, high)``; ``sigma`` weights the residuals
    ``(y - data)/sigma``; ``xtol``, ``ftol`` and ``max_iterations`` (trial steps) end the fit,
    and ``message`` says which did. ``data_x`` must lie within ``[x[0], x[-1]]`` and holds at
    most 1,000,000 observations.

    >>> import numpy as np
    >>> from diffbvp import fit_bvp
    >>> xd = np.linspace(0, 1, 6)
    >>> f = fit_bvp(["-k*y[0]"], ["ya[0] - 1"], np.linspace(0, 1, 5), np.ones((1, 5)),
    ...             {"k": 1.0}, xd, np.exp(-0.7 * xd))
    >>> round(f.params["k"], 5)
    0.7
    """
    from . import _native

    names = list(params)
    if not names:
        raise InputError("fit_bvp: params must name at least one model parameter")
    p0 = []
    for name in names:
        try:
            v = float(params[name])
        except (TypeError, ValueError):
            raise InputError(f"params[{name!r}]: expected a number, got {params[name]!r}") from None
        if not np.isfinite(v):
            raise InputError(f"params[{name!r}] is not finite ({v})")
        p0.append(v)
    x, ya, pa = _check_inputs(x, y, p, tol, max_nodes, None, complex_ok=False)
    xd = np.asarray(data_x, dtype=float).ravel()
    yd = np.asarray(data_y, dtype=float).ravel()
    if xd.shape != yd.shape or xd.size == 0:
        raise InputError(f"data_x and data_y: {xd.size} and {yd.size} values; they must match")
    if not (np.isfinite(xd).all() and np.isfinite(yd).all()):
        raise InputError("data_x and data_y must be finite")
    outside = (xd < x[0]) | (xd > x[-1])
    if outside.any():
        j = int(np.flatnonzero(outside)[0])
        raise InputError(
            f"data_x[{j}] = {xd[j]} is outside the interval [{x[0]}, {x[-1]}] of x"
        )
    try:
        sig = np.broadcast_to(np.asarray(1.0 if sigma is None else sigma, float), yd.shape)
    except ValueError:
        raise InputError(f"sigma: a number or {yd.size} values, got shape "
                         f"{np.shape(sigma)}") from None
    if not (sig > 0).all() or not np.isfinite(sig).all():
        raise InputError("sigma must be positive and finite")
    lo = np.full(len(p0), -np.inf)
    hi = np.full(len(p0), np.inf)
    for name, (a, b) in dict(bounds or {}).items():
        if name not in names:
            raise InputError(f"bounds: {name!r} is not one of the fitted params {names}")
        i = names.index(name)
        lo[i], hi[i] = float(a), float(b)
        if not lo[i] < hi[i]:
            raise InputError(f"bounds[{name!r}] = ({a}, {b}): the lower bound must be below "
                             "the upper one")
        if not lo[i] <= p0[i] <= hi[i]:
            raise InputError(f"params[{name!r}] = {p0[i]} is outside its bounds ({a}, {b})")
    fun_s = _expressions(fun, "fun")
    bc_s = _expressions(bc, "bc")
    n, k = len(fun_s), pa.size
    if ya.shape[0] != n:
        raise InputError(f"y: {ya.shape[0]} rows for {n} states; expected shape ({n}, {x.size})")
    if not (isinstance(component, (int, np.integer)) and 0 <= component < n):
        raise InputError(f"component must be a state index in 0..{n - 1}, got {component!r}")
    unknowns = [""] * k if unknowns is None else [str(u) for u in unknowns]
    if len(unknowns) != k:
        raise InputError(f"unknowns: {len(unknowns)} names for {k} values of p")
    consts = [(str(a), float(b)) for a, b in dict(constants or {}).items()]
    problem = _native.ExprProblem(fun_s, bc_s, unknowns, names, consts, None)
    if len(bc_s) != n + k:
        raise InputError(f"bc: {len(bc_s)} boundary conditions for {n} states and {k} unknown "
                         f"parameters; n + k = {n + k} are needed")
    (pf, cost, resid, jac, termination, success, iterations, accepted,
     native) = problem.fit(
        x.tolist(), np.ascontiguousarray(ya), pa.tolist(), p0, list(range(len(p0))),
        lo.tolist(), hi.tolist(), xd, yd, np.ascontiguousarray(sig), int(component),
        float(tol), int(max_nodes), float(xtol), float(ftol), int(max_iterations),
    )
    pf = np.asarray(pf)
    J = np.asarray(jac).reshape(xd.size, len(p0))
    dof = max(yd.size - pf.size, 1)
    s2 = 2 * cost / dof if sigma is None else 1.0
    try:
        cov = np.linalg.inv(J.T @ J) * s2
    except np.linalg.LinAlgError:
        cov = np.full((pf.size, pf.size), np.nan)
    se = np.sqrt(np.clip(np.diag(cov), 0, None))
    res = BvpFitResult()
    res.params = dict(zip(names, pf.tolist()))
    res.x = pf
    res.cost = float(cost)
    res.residuals = np.asarray(resid)
    res.jac = J
    res.covariance = cov
    res.stderr = se
    res.ci95 = np.stack((pf - 1.959963984540054 * se, pf + 1.959963984540054 * se), axis=1)
    res.success = bool(success)
    res.message = f"{termination} ({iterations} trial steps, {accepted} accepted)"
    res.nfev = int(iterations) + 1
    res.solution = _result_of(native, k, dict(zip(names, pf.tolist())))[0]
    return res


# ---------------------------------------------------------------- continuation


def continue_bvp(
    fun: Any,
    bc: Any,
    x: Any,
    y: Any,
    param: str,
    values: Sequence[float],
    params: Mapping[str, float],
    p: Any = None,
    tol: float = 1e-3,
    max_nodes: int = 1000,
    constants: Optional[Mapping[str, float]] = None,
    unknowns: Optional[Sequence[str]] = None,
    min_step: float = 1e-8,
) -> List[BvpResult]:
    """Natural-parameter continuation of a problem given as expressions: solve at each of
    ``values`` of the model parameter ``param`` in turn (``params`` holds the start values of
    all model parameters), each solve starting from the previous solution moved along its exact
    tangent ``y + (dy/dq) Δq`` (forward sensitivities). A step that fails is halved, down to
    ``min_step``; then :class:`EvaluationError` names the value reached and the last failure
    (past a turning point there is no solution nearby). Returns one result per value.

    >>> import numpy as np
    >>> rs = continue_bvp(["y[1]", "-k*exp(y[0])"], ["ya[0]", "yb[0]"], np.linspace(0, 1, 5),
    ...                   np.zeros((2, 5)), "k", [1.0, 2.0, 3.0], {"k": 0.5}, tol=1e-6)
    >>> [round(float(r.sol(0.5)[0]), 4) for r in rs]
    [0.1405, 0.329, 0.6401]
    """
    params = dict(params)
    if param not in params:
        raise InputError(f"continue_bvp: {param!r} is not one of the model parameters {list(params)}")
    names = list(params)
    col = names.index(param)
    kw = dict(tol=tol, max_nodes=max_nodes, constants=constants, unknowns=unknowns)
    cur = solve_bvp(fun, bc, x, y, p=p, params=params, **kw)
    if not cur.success:
        raise EvaluationError(
            f"continue_bvp: no solution at the start {param} = {params[param]}: {cur.message}"
        )
    q = float(params[param])
    out = []
    for target in [float(v) for v in values]:
        step = target - q
        while q != target:
            trial = q + step if abs(step) < abs(target - q) else target
            s = cur.sensitivities()
            yg = cur.y + s["dy"][:, :, col] * (trial - q)
            pg = None if cur.p is None else cur.p + s["dp"][:, col] * (trial - q)
            nxt = solve_bvp(fun, bc, cur.x, yg, p=pg, params={**params, param: trial}, **kw)
            if nxt.success:
                cur, q = nxt, trial
                params[param] = trial
                continue
            step /= 2
            if abs(step) < min_step:
                raise EvaluationError(
                    f"continue_bvp: stopped at {param} = {q} (target {target}): the step fell "
                    f"below min_step = {min_step:g}; last failure at {param} = {trial}: "
                    f"{nxt.message}"
                )
        out.append(cur)
    return out
