"""Result objects of :mod:`diffbvp`: plain data (a dict from the library's JSON form plus numpy
arrays), attribute access, ``to_dict()``, tables for pandas, picklable, with a short ``repr``.

``to_dict()`` is strict JSON (``json.dumps(r.to_dict(), allow_nan=False)`` holds): a number
that does not exist (a NaN: a missing standard error, a landscape point without a solution; or
an infinity) is ``None``, as the ``rheometer`` program writes ``null``. It is the format to
exchange results in (a file, another program, another version); a pickle is for the same
package version on a trusted machine (Dask workers): unpickling checks a fit's and a
diagnosis' fields with the library's reader of fit reports and refuses a tampered one with
an :class:`~diffbvp.errors.InputError` naming the field. ``==`` compares results, not timing
(``wall_time_s``, ``stage_times`` are left out).

Units are SI and part of every array key (``position_m``, ``diameter_m``, ``temperature_K``,
``strain_rate_1_s``, ``viscosity_Pa_s``, ``force_N``, ``velocity_m_s``); relative residuals are
fractions (0.01 = 1 %).
"""

from __future__ import annotations

import copy
import math
from typing import Any, Dict, Iterator, List, Mapping, Optional, Tuple

import numpy as np

__all__ = [
    "Result",
    "Estimate",
    "FitResult",
    "Candidate",
    "SimulationResult",
    "Comparison",
    "Diagnosis",
    "Landscape",
    "DesignResult",
]


def _num(x: Any) -> float:
    """A JSON number as float; ``None`` (a NaN written as null) as ``nan``."""
    return math.nan if x is None else float(x)


def _plain(x: Any) -> Any:
    """Numpy arrays (recursively) as lists and non-finite floats as ``None``, for
    ``to_dict()``: strict JSON."""
    if isinstance(x, np.ndarray):
        return _plain(x.tolist())
    if isinstance(x, Mapping):
        return {k: _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, np.generic):
        return _plain(x.item())
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


# keys of a result that time the computation rather than describe its outcome: two runs of
# the same computation differ in them, so equality leaves them out
_TIMING_KEYS = frozenset({"wall_time_s", "stage_times"})


def _check_state(state: Any, kind: str, sizes: Tuple[int, ...]) -> None:
    """A pickled state of ``kind`` is a tuple of one of ``sizes`` parts whose first is a dict
    (else an :class:`~diffbvp.errors.InputError` naming what is wrong)."""
    from .errors import InputError
    if not isinstance(state, tuple) or len(state) not in sizes:
        raise InputError(f"the pickled {kind} is not a {kind}'s state (a tuple of "
                         f"{' or '.join(map(str, sizes))} parts): re-create it, or exchange "
                         "results as to_dict() / JSON")
    if not isinstance(state[0], dict):
        raise InputError(f"the pickled {kind}: its data is {type(state[0]).__name__}, not a dict")
    if len(state) > 1 and not isinstance(state[1], dict):
        raise InputError(f"the pickled {kind}: its arrays are {type(state[1]).__name__}, not a dict")


def _check_report(data: Dict[str, Any], kind: str) -> None:
    """The dict of a fit or a diagnosis checked by the library's reader of fit reports (the one
    ``rheometer fit --from`` uses): an :class:`~diffbvp.errors.InputError` naming the field
    (``n.value``)."""
    import json
    from . import _native
    from .errors import InputError
    try:
        text = json.dumps(data, allow_nan=False)
    except (TypeError, ValueError) as e:
        raise InputError(f"the pickled {kind}: its data is not JSON data ({e})") from None
    _native.check_fit_summary(text, f"the pickled {kind}")


def _pm(value: float, se: float, digits: int = 1) -> str:
    """``0.804±0.007``: the value to the standard error's first ``digits`` significant digits."""
    if not math.isfinite(value):
        return "nan"
    if not (math.isfinite(se) and se > 0):
        return f"{value:.4g}"
    decimals = max(0, digits - 1 - int(math.floor(math.log10(se))))
    decimals = min(decimals, 12)
    return f"{value:.{decimals}f}±{se:.{decimals}f}"


class Result:
    """Base of the result classes: ``_data`` (the library's JSON form, plain Python) and
    ``_arrays`` (numpy arrays). Keys of ``_data`` read as attributes."""

    __slots__ = ("_data", "_arrays")

    def __init__(self, data: Dict[str, Any], arrays: Optional[Dict[str, Any]] = None):
        object.__setattr__(self, "_data", data)
        object.__setattr__(self, "_arrays", arrays if arrays is not None else {})

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_"):
            raise AttributeError(name)
        for source in (self._data, self._arrays):
            if name in source:
                return source[name]
        raise AttributeError(
            f"{type(self).__name__} has no attribute {name!r}; keys: "
            f"{', '.join(sorted(set(self._data) | set(self._arrays)))}"
        )

    def __dir__(self) -> List[str]:
        return sorted(set(super().__dir__()) | set(self._data) | set(self._arrays))

    @property
    def report(self) -> str:
        """The text report, as the command line prints it (``str(result)``) — for a fit, a
        comparison, a diagnosis and a design. The JSON's own ``report`` field (which kind of
        report it is: ``"fit"``, ``"diagnosis"``, ...) stays a key of ``to_dict()``."""
        text = getattr(self, "text", None)
        if not isinstance(text, str):
            raise AttributeError(
                f"{type(self).__name__} has no text report; its values are in to_dict()"
            )
        return text

    def keys(self) -> List[str]:
        """The keys of the data and the arrays."""
        return list(self._data) + [k for k in self._arrays if k not in self._data]

    def to_dict(self) -> Dict[str, Any]:
        """Everything as plain Python (dicts, lists, floats; arrays as lists): JSON-ready."""
        out = copy.deepcopy(self._data)
        for k, v in self._arrays.items():
            out.setdefault(k, _plain(v))
        return _plain(out)

    def __getstate__(self) -> Tuple[Dict[str, Any], Dict[str, Any]]:
        return (self._data, self._arrays)

    def __setstate__(self, state: Tuple[Dict[str, Any], Dict[str, Any]]) -> None:
        object.__setattr__(self, "_data", state[0])
        object.__setattr__(self, "_arrays", state[1])

    def __eq__(self, other: object) -> bool:
        """Equal results: the same data and arrays, the timing (``wall_time_s``,
        ``stage_times``) left out, so that ``fit(ds) == fit(ds)``."""
        if type(other) is not type(self):
            return NotImplemented
        return _same(self.to_dict(), other.to_dict())  # type: ignore[attr-defined]

    __hash__ = None  # type: ignore[assignment]


def _same(a: Any, b: Any) -> bool:
    """Structural equality that treats nan == nan (a missing standard error on both sides) and
    leaves the timing keys out (:data:`_TIMING_KEYS`)."""
    if isinstance(a, float) and isinstance(b, float):
        return a == b or (math.isnan(a) and math.isnan(b))
    if isinstance(a, dict) and isinstance(b, dict):
        ka = a.keys() - _TIMING_KEYS
        return ka == b.keys() - _TIMING_KEYS and all(_same(a[k], b[k]) for k in ka)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    return a == b


def _long_table(per_experiment: Mapping[str, Mapping[str, Any]], keys: List[str]) -> Dict[str, np.ndarray]:
    """Per-experiment arrays as one long table: ``experiment`` plus ``keys`` columns."""
    cols: Dict[str, List[Any]] = {"experiment": []}
    for k in keys:
        cols[k] = []
    for name, d in per_experiment.items():
        m = len(d[keys[0]])
        cols["experiment"].extend([name] * m)
        for k in keys:
            cols[k].extend(np.asarray(d[k]).tolist())
    return {k: np.asarray(v) for k, v in cols.items()}


_PROFILE_KEYS = [
    "position_m",
    "diameter_m",
    "velocity_m_s",
    "temperature_K",
    "strain_rate_1_s",
    "viscosity_Pa_s",
    "force_N",
]


class Estimate:
    """A named parameter of a fit with its uncertainty: the library's ``Estimate``.

    ``value`` in ``unit`` (``"-"`` dimensionless, ``"Pa"``, ``"m/s"``, ``"K"``, ...);
    ``stderr`` its standard error (0 for a fixed parameter, nan where none exists, e.g. a
    singular covariance); ``ci95`` the 95 % confidence interval (nan where not valid: an
    estimate at a bound of its search range, no standard error); ``fitted``; ``at_bound``
    (``"lower"``, ``"upper"`` or None). ``float(estimate)`` is its value.
    """

    __slots__ = ("name", "value", "unit", "stderr", "ci95", "fitted", "at_bound")

    def __init__(self, name: str, value: float, unit: str = "-", stderr: float = math.nan,
                 ci95: Tuple[float, float] = (math.nan, math.nan), fitted: bool = False,
                 at_bound: Optional[str] = None):
        self.name = name
        self.value = value
        self.unit = unit
        self.stderr = stderr
        self.ci95 = ci95
        self.fitted = fitted
        self.at_bound = at_bound

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], name: str = "") -> "Estimate":
        """From the library's JSON form (``{"name", "value", "unit", "stderr", "ci95",
        "fitted", "at_bound"}``; a null number is nan)."""
        if not isinstance(d, Mapping):  # a bare number (reports of earlier versions)
            return cls(name, _num(d), "-", 0.0, (_num(d), _num(d)))
        ci = d.get("ci95") or (None, None)
        return cls(d.get("name") or name, _num(d.get("value")), d.get("unit", "-"),
                   _num(d.get("stderr")), (_num(ci[0]), _num(ci[1])), bool(d.get("fitted", False)),
                   d.get("at_bound"))

    def to_dict(self) -> Dict[str, Any]:
        """The library's JSON form (nan as None, as serde writes it)."""
        def j(x: float) -> Optional[float]:
            return None if math.isnan(x) else x
        d: Dict[str, Any] = {"name": self.name, "value": j(self.value), "unit": self.unit,
                             "stderr": j(self.stderr), "ci95": [j(self.ci95[0]), j(self.ci95[1])],
                             "fitted": self.fitted}
        if self.at_bound is not None:
            d["at_bound"] = self.at_bound
        return d

    def __float__(self) -> float:
        return float(self.value)

    def __format__(self, spec: str) -> str:
        """``f"{fit.n:.3f}"`` formats the value; ``f"{fit.n}"`` is ``str``."""
        return format(self.value, spec) if spec else str(self)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Estimate):
            return NotImplemented
        return _same(self.to_dict(), other.to_dict())

    __hash__ = None  # type: ignore[assignment]

    def __getstate__(self) -> Dict[str, Any]:
        return {k: getattr(self, k) for k in self.__slots__}

    def __setstate__(self, state: Dict[str, Any]) -> None:
        for k, v in state.items():
            setattr(self, k, v)

    def __str__(self) -> str:
        unit = "" if self.unit in ("", "-") else f" {self.unit}"
        bound = f" (at its {self.at_bound} bound)" if self.at_bound else ""
        return f"{_pm(self.value, self.stderr)}{unit}{bound}"

    def __repr__(self) -> str:
        return f"Estimate({self.name}={self})"


def law_not_a_result(fit: Mapping[str, Any]) -> Optional[str]:
    """Why the law of ``fit`` (a fit's dict, as ``rheometer fit --json`` writes it) is not a
    result, or None: n or kappa at a bound of its range (no valid interval there), an
    ``implausible`` warning, or a ``misfit`` warning (the model misses the data by several
    times the noise) (the warning's finding up to the first colon). None where the law was not
    fitted; a bound is no reason where the Newtonian law is preferred
    (``newtonian_test.law_not_estimated``: n and kappa are not estimates there). The library's
    ``FitSummary::law_not_a_result`` rule and words (the text report's ``NOT A RESULT:`` line,
    ``flow_curve.not_a_result``)."""
    if not any(p in ("n", "kappa") for p in fit.get("fitted", [])):
        return None
    # where the likelihood-ratio test prefers the Newtonian law, the result is that law and a
    # bound of n or kappa is one of its corners (newtonian_test.law_not_estimated)
    test = fit.get("newtonian_test") or {}
    newtonian_law = bool(test.get("law_not_estimated"))
    bounds = [] if newtonian_law else (fit.get("at_bound", []) or [])
    for name in ("n", "kappa"):
        for b in bounds:
            if b.get("parameter") != name:
                continue
            side, bound = b.get("side"), _num(b.get("bound"))
            newtonian = name == "n" and side == "upper" and bound == 1.0
            # under a misfit warning the likelihood-ratio test is not computed
            # (FitSummary::likelihood_skipped), so the reason points to nothing below
            skipped = any(w.get("code") == "misfit" for w in fit.get("warnings", []) or [])
            below = "" if skipped else "; whether the Newtonian law fits is said below"
            return (f"{name} is at its {side} bound {bound:.6g}, where the fit has no valid interval"
                    + (" (the Carreau-type law is Newtonian there and kappa is not determined"
                       f"{below})" if newtonian else ""))
    warnings = fit.get("warnings", []) or []
    for code in ("implausible", "misfit"):
        for w in warnings:
            if w.get("code") == code:
                return str(w.get("message", "")).split(":", 1)[0].strip()
    return None


class FitResult(Result):
    """The outcome of :func:`diffbvp.fit`: the library's ``FitSummary`` as a dict (exactly the
    JSON ``rheometer fit --json`` writes) plus arrays.

    Estimates (:class:`Estimate`: ``value``, ``stderr``, ``ci95``, ``unit``): ``fit.n`` [-],
    ``fit.kappa`` = ln(K / 1 Pa) [-], ``fit.K`` [Pa], the effects' strengths and shapes in
    :meth:`estimates`. ``fit.noise_level`` [-] is the one noise level the misfit is judged
    against (``fit.noise``: where it comes from, the noise model); ``fit.rms`` [-] the RMS
    relative residual; ``fit.warnings`` everything that makes the fit doubtful;
    ``fit.law_not_a_result`` why the law (n, κ) is no result (None where it is one);
    ``fit.covariance`` the covariance of the fitted shared parameters
    (``fit.covariance_names``) in their reported units; ``fit.error_budget`` the systematic
    uncertainty from what the data cannot identify. Every other key of the summary reads as an
    attribute (``fit.solver``, ``fit.take_up_factors``, ``fit.at_bound``, ...).

    Arrays: ``residual_profiles`` (name → ``position_m`` [m], ``relative_residual`` [-]) and
    ``profiles`` (name → fitted profiles on uniform positions, SI units in the keys).
    """

    __slots__ = ("text", "notes", "context")

    def __init__(self, summary: Dict[str, Any], arrays: Optional[Dict[str, Any]] = None, text: str = "",
                 notes: Optional[List[str]] = None, context: Optional[str] = None):
        super().__init__(summary, arrays)
        object.__setattr__(self, "text", text)
        object.__setattr__(self, "notes", list(notes or []))
        # why the diagnosis this fit belongs to says its law is no result (None: no diagnosis,
        # or the diagnosis leaves it one)
        object.__setattr__(self, "context", context)

    @classmethod
    def _from_native(cls, d: Dict[str, Any]) -> "FitResult":
        return cls(d["summary"], d["arrays"], d.get("text", ""), d.get("notes", []))

    def __getstate__(self):  # type: ignore[override]
        return (self._data, self._arrays, self.text, self.notes, self.context)

    def __setstate__(self, state):  # type: ignore[override]
        # checked before it is taken: a tampered pickle is refused here, naming the field,
        # not later with a bare KeyError
        _check_state(state, "FitResult", (4, 5))
        _check_report(state[0], "FitResult")
        object.__setattr__(self, "_data", state[0])
        object.__setattr__(self, "_arrays", state[1])
        object.__setattr__(self, "text", str(state[2]))
        object.__setattr__(self, "notes", [str(x) for x in state[3]])
        # a state pickled before the context was kept has four parts
        object.__setattr__(self, "context", state[4] if len(state) > 4 else None)

    @property
    def summary(self) -> Dict[str, Any]:
        """The library's ``FitSummary`` as a dict, as ``rheometer fit --json`` writes it (a
        nan written as ``None``); ``diffbvp.compare`` reads it back."""
        return self._data

    @property
    def n(self) -> Estimate:
        """Power index n [-] of the Carreau-type law."""
        return Estimate.from_dict(self._data["n"], "n")

    @property
    def kappa(self) -> Estimate:
        """κ = ln(K / 1 Pa) [-]."""
        return Estimate.from_dict(self._data["kappa"], "kappa")

    @property
    def K(self) -> Estimate:  # noqa: N802 (the law's symbol)
        """K = e^κ [Pa] (its interval is the image of κ's)."""
        return Estimate.from_dict(self._data.get("K_Pa", {"value": None}), "K")

    @property
    def noise_level(self) -> float:
        """The one relative noise level σ [-] of these data and this model (declared, else
        estimated; nan if neither)."""
        return _num(self._data.get("noise", {}).get("level"))

    @property
    def rms(self) -> float:
        """RMS relative residual over all measurements [-] (0.016 = 1.6 %)."""
        return _num(self._data["rms_relative_residual"])

    @property
    def law_not_a_result(self) -> Optional[str]:
        """Why this fit's law (n, kappa) is not a result, or None: the fit's own rule
        (:func:`law_not_a_result`: n or kappa at a bound, an ``implausible`` or ``misfit``
        warning), else, for a fit of a diagnosis (``Diagnosis.base_fit``, ``final_fit``), the
        diagnosis' reason (``Diagnosis.law_not_a_result``: an ambiguous verdict, a misfit no
        candidate explains; for the user's model, the effects the diagnosis found missing)."""
        return law_not_a_result(self._data) or self.context

    @property
    def law_is_a_result(self) -> bool:
        """Whether this fit's law may be used as a result (no reason in
        :attr:`law_not_a_result`; a fit without a fitted law has none either)."""
        return self.law_not_a_result is None

    @property
    def warnings(self) -> List[Dict[str, str]]:
        """Everything that makes the fit doubtful: ``{"code", "message"}`` (empty if good)."""
        return list(self._data.get("warnings", []))

    @property
    def effects(self) -> List[Dict[str, Any]]:
        """The model's extra effects: ``{"effect", "category", "strength", "shapes"}`` (the
        strength and shapes as estimate dicts; see :meth:`estimates`)."""
        return list(self._data.get("effects", []))

    @property
    def error_budget(self) -> Optional[Dict[str, Any]]:
        """The error budget (systematic shifts of the estimates from the declared
        uncertainties of process conditions, instrument and material data), None if not
        computed."""
        return self._data.get("error_budget")

    @property
    def take_up_factors(self) -> np.ndarray:
        """Take-up factors φ_k = d_out,k / d_fit,k(L) [-], in the order of ``experiments``."""
        return np.asarray(self._data["take_up_factors"], dtype=float)

    @property
    def covariance_names(self) -> List[str]:
        """The parameters of :attr:`covariance`, in order (``"n"``, ``"kappa"``, effects,
        ``"effect.shape"``); empty without a covariance."""
        c = self._data.get("covariance")
        return list(c["names"]) if c else []

    @property
    def covariance(self) -> Optional[np.ndarray]:
        """Covariance of the fitted shared parameters (:attr:`covariance_names`) in their
        reported units (strengths in the effects' units), None where singular or nothing is
        fitted."""
        c = self._data.get("covariance")
        if not c:
            return None
        k = len(c["names"])
        return np.asarray([_num(v) for v in c["matrix"]], dtype=float).reshape(k, k)

    @property
    def residual_profiles(self) -> Dict[str, Dict[str, np.ndarray]]:
        """name → ``position_m`` [m] and ``relative_residual`` [-] = (d_model − d_meas)/d_meas
        at the measurement positions."""
        return self._arrays.get("residual_profiles", {})

    @property
    def profiles(self) -> Dict[str, Dict[str, Any]]:
        """name → fitted profiles on uniform positions (SI units in the keys; empty for the
        refits of a diagnosis)."""
        return self._arrays.get("profiles", {})

    def estimates(self) -> Dict[str, Estimate]:
        """Every named estimate: ``n``, ``kappa``, then each effect's strength and shapes
        (shapes named ``effect.shape``), as the library's ``FitSummary::parameters``."""
        out = {"n": self.n, "kappa": self.kappa}
        for e in self.effects:
            s = Estimate.from_dict(e["strength"], e["effect"])
            out[s.name or e["effect"]] = s
            for sh in e.get("shapes", []):
                x = Estimate.from_dict(sh)
                x.name = f"{e['effect']}.{x.name}"
                out[x.name] = x
        return out

    def estimates_table(self) -> Dict[str, np.ndarray]:
        """One row per estimate: ``name``, ``value``, ``unit``, ``stderr``, ``ci95_low``,
        ``ci95_high``, ``fitted`` (``pandas.DataFrame(fit.estimates_table())``)."""
        est = list(self.estimates().values())
        return {
            "name": np.asarray([e.name for e in est]),
            "value": np.asarray([e.value for e in est], dtype=float),
            "unit": np.asarray([e.unit for e in est]),
            "stderr": np.asarray([e.stderr for e in est], dtype=float),
            "ci95_low": np.asarray([e.ci95[0] for e in est], dtype=float),
            "ci95_high": np.asarray([e.ci95[1] for e in est], dtype=float),
            "fitted": np.asarray([e.fitted for e in est], dtype=bool),
        }

    def residuals_table(self) -> Dict[str, np.ndarray]:
        """Columns ``experiment``, ``position_m`` [m], ``relative_residual`` [-]
        (``pandas.DataFrame(fit.residuals_table())``)."""
        return _long_table(self.residual_profiles, ["position_m", "relative_residual"])

    def profiles_table(self) -> Dict[str, np.ndarray]:
        """The fitted profiles of every experiment as one long table (SI units in the keys)."""
        return _long_table(self.profiles, _PROFILE_KEYS)

    def flow_curve(self) -> Dict[str, Any]:
        """The flow curve η_E(ε̇) of the fit at one temperature (the library's ``FlowCurve``),
        as columns of numpy arrays: ``strain_rate_1_s`` [1/s], ``eta_Pa_s`` [Pa s], the 95 %
        bands ``stat95_lo/hi_Pa_s`` (statistical), ``sys95_lo/hi_Pa_s`` (systematic, from the
        error budget), ``total95_lo/hi_Pa_s``, and ``extrapolated`` (outside the strain rates
        the data cover). The curve's temperature, plateau, covered range and finding are in
        ``summary["flow_curve"]``. A fit without a flow curve (it could not be computed)
        returns the fitted profiles' own columns instead (strain rate, viscosity, temperature
        and position along every spin line, with an ``experiment`` column).
        """
        curve = self._data.get("flow_curve")
        if curve is None:
            return _long_table(self.profiles, ["strain_rate_1_s", "viscosity_Pa_s", "temperature_K", "position_m"])
        pts = curve.get("points", [])
        col = lambda f: np.asarray([_num(f(p)) for p in pts], dtype=float)
        return {
            "strain_rate_1_s": col(lambda p: p["strain_rate_per_s"]),
            "eta_Pa_s": col(lambda p: p["eta_pa_s"]),
            "stat95_lo_Pa_s": col(lambda p: p["stat95_pa_s"][0]),
            "stat95_hi_Pa_s": col(lambda p: p["stat95_pa_s"][1]),
            "sys95_lo_Pa_s": col(lambda p: p["sys95_pa_s"][0]),
            "sys95_hi_Pa_s": col(lambda p: p["sys95_pa_s"][1]),
            "total95_lo_Pa_s": col(lambda p: p["total95_pa_s"][0]),
            "total95_hi_Pa_s": col(lambda p: p["total95_pa_s"][1]),
            "extrapolated": np.asarray([bool(p["extrapolated"]) for p in pts], dtype=bool),
        }

    def __repr__(self) -> str:
        n, k = self.n, self.kappa
        parts = [f"n={_pm(n.value, n.stderr)}", f"kappa={_pm(k.value, k.stderr)}"]
        for e in self.effects:
            s = Estimate.from_dict(e["strength"], e["effect"])
            parts.append(f"{e['effect']}={_pm(s.value, s.stderr)}")
        parts.append(f"rms={100 * self.rms:.2g} %")
        if math.isfinite(self.noise_level):
            parts.append(f"noise={100 * self.noise_level:.2g} %")
        if self.warnings:
            parts.append(f"{len(self.warnings)} warning{'s' if len(self.warnings) > 1 else ''}")
        if self.law_not_a_result is not None:
            parts.append("NOT A RESULT")
        return f"FitResult({', '.join(parts)})"

    def __str__(self) -> str:
        return self.text or repr(self)


def _arrays_of(x: Any) -> Any:
    """Lists of numbers (recursively) as float numpy arrays (``None`` as nan)."""
    if isinstance(x, Mapping):
        return {k: _arrays_of(v) for k, v in x.items()}
    if isinstance(x, list) and x and all(v is None or (isinstance(v, (int, float)) and not isinstance(v, bool)) for v in x):
        return np.asarray([_num(v) for v in x], dtype=float)
    if isinstance(x, list):
        return [_arrays_of(v) for v in x]
    return x


class SimulationResult(Result):
    """The outcome of :func:`diffbvp.simulate`: ``law`` = (n, κ), ``experiments`` (list of
    ``{"name", "nodes", "take_up_from_data_m", "profiles", "sensitivities"}``).

    ``profiles[name]`` holds the SI profiles; with ``sensitivities=True``,
    ``sensitivities[name]`` holds ``parameters`` (``["n", "kappa", strengths...]``) and, per
    quantity (``diameter_m``, ``velocity_m_s``, ``temperature_K``, ``force_N``,
    ``strain_rate_1_s``), a (positions × parameters) array of exact derivatives (unit of the
    quantity per unit of the parameter).
    """

    __slots__ = ()

    @property
    def names(self) -> List[str]:
        """Experiment names."""
        return [e["name"] for e in self._data["experiments"]]

    @property
    def profiles(self) -> Dict[str, Dict[str, Any]]:
        """name → profiles (SI units in the keys; ``terms``: force terms [N/m], heat terms [W/m])."""
        return {e["name"]: e["profiles"] for e in self._data["experiments"]}

    @property
    def sensitivities(self) -> Dict[str, Optional[Dict[str, Any]]]:
        """name → exact d(profile)/d(parameters) (or None without ``sensitivities=True``)."""
        return {e["name"]: e["sensitivities"] for e in self._data["experiments"]}

    def table(self) -> Dict[str, np.ndarray]:
        """All profiles as one long table (``pandas.DataFrame(sim.table())``)."""
        return _long_table(self.profiles, _PROFILE_KEYS)

    def __iter__(self) -> Iterator[Dict[str, Any]]:
        return iter(self._data["experiments"])

    def __repr__(self) -> str:
        n, k = self._data["law"]
        return f"SimulationResult(n={n}, kappa={k}, {len(self._data['experiments'])} experiments)"


class Comparison(Result):
    """The outcome of :func:`diffbvp.compare`: the library's ``Comparison`` as a dict, the JSON
    of ``rheometer compare`` (``noise``: the one noise level and its model, ``chi2``,
    ``chi2_per_dof``, per-experiment ``rms``, runs test, lag-1 autocorrelation, systematic
    ``segments``, ``stations``, ``trends``) plus ``text``."""

    __slots__ = ("text", "notes")

    def __init__(self, data: Dict[str, Any], text: str = "", notes: Optional[List[str]] = None):
        super().__init__(data, {})
        object.__setattr__(self, "text", text)
        object.__setattr__(self, "notes", list(notes or []))

    def __getstate__(self):  # type: ignore[override]
        return (self._data, self.text, self.notes)

    def __setstate__(self, state):  # type: ignore[override]
        object.__setattr__(self, "_data", state[0])
        object.__setattr__(self, "_arrays", {})
        object.__setattr__(self, "text", state[1])
        object.__setattr__(self, "notes", state[2])

    def table(self) -> Dict[str, np.ndarray]:
        """Every measurement point: experiment, position, measured and model diameter [m],
        relative residual [-], strain rate [1/s], temperature [K], speed [m/s], outlier flag."""
        rows: Dict[str, List[Any]] = {}
        for e in self._data["experiments"]:
            for p in e["points"]:
                rows.setdefault("experiment", []).append(e["name"])
                for k, v in p.items():
                    rows.setdefault(k, []).append(_num(v) if not isinstance(v, bool) else v)
        return {k: np.asarray(v) for k, v in rows.items()}

    @property
    def noise_level(self) -> float:
        """The noise level σ [-] the misfit is judged against (the fit's, when the fit is
        compared as it is)."""
        return _num(self._data.get("noise", {}).get("level"))

    def __repr__(self) -> str:
        d = self._data
        return (
            f"Comparison({len(d['experiments'])} experiments, {d.get('points')} points, "
            f"noise={100 * self.noise_level:.2g} %, chi2/dof={_num(d.get('chi2_per_dof')):.3g})"
        )

    def __str__(self) -> str:
        return self.text or repr(self)


class Candidate(Result):
    """One candidate effect of a diagnosis: the library's ``Candidate`` as a dict (``effect``,
    ``unit``, linearised ``linear_score``/``linear_strength``/``linear_stderr``, ``delta_bic``,
    ``delta_aic``, ``status``, ``false_alarm`` [-], ``share_of_excess`` [-], the search's
    ``profiles``, ...); ``refit`` is its refit as a :class:`FitResult` (None if not
    refitted)."""

    __slots__ = ()

    @property
    def refit(self) -> Optional[FitResult]:
        """The best refit with the effect (strength and shapes freed), None if not refitted."""
        r = self._data.get("refit")
        return FitResult(r) if r is not None else None

    @property
    def strength(self) -> Optional[Estimate]:
        """The refitted strength of the effect (its unit), None if not refitted."""
        r = self.refit
        if r is None:
            return None
        for e in r.effects:
            if e["effect"] == self._data["effect"]:
                return Estimate.from_dict(e["strength"], e["effect"])
        return None

    def __repr__(self) -> str:
        d = self._data
        s = self.strength
        strength = f", strength={s}" if s is not None else ""
        return (f"Candidate({d['effect']}, ΔBIC={_num(d.get('delta_bic')):.1f}{strength}, "
                f"status={d.get('status')!r}, false_alarm={_num(d.get('false_alarm')):.3g})")


class Diagnosis(Result):
    """The outcome of :func:`diffbvp.diagnose`: the library's ``Diagnosis`` as a dict (the
    JSON of ``rheometer diagnose``).

    ``verdict`` (``{"kind": "explained" | "adequate" | "ambiguous" |
    "none_of_the_candidates", ...}``), ``law_is_a_result``,
    ``found`` (the effects found, in order), ``most_likely_missing``, ``pair`` (the best
    pair of candidates fitted jointly, where one qualifies: ``replaces`` says whether it is
    the explanation, ``laws_disagree`` whether an explanation as good disagrees on n),
    ``candidates`` (best
    first, as :class:`Candidate` with their refits), ``base_fit`` (the user's model) and
    ``final_fit`` (with all found effects, fitted jointly) as :class:`FitResult`,
    ``calibration`` (the look-elsewhere calibration), ``further_steps``, ``alternatives``,
    ``indistinguishable``, ``detection``, ``consistency`` (for each found effect, whether its
    strength is the same in every experiment). Arrays: ``residuals_before`` and
    ``residuals_after`` (name → ``position_m``, ``relative_residual``) of the base and final
    fit.
    """

    __slots__ = ("text",)

    def __init__(self, data: Dict[str, Any], arrays: Optional[Dict[str, Any]] = None, text: str = ""):
        super().__init__(data, arrays)
        object.__setattr__(self, "text", text)

    @classmethod
    def _from_native(cls, d: Dict[str, Any]) -> "Diagnosis":
        final = d.get("final_arrays")
        arrays = {"residuals_before": d["base_arrays"]["residual_profiles"],
                  "residuals_after": final["residual_profiles"] if final is not None else None}
        return cls(d["diagnosis"], arrays, d.get("text", ""))

    def __getstate__(self):  # type: ignore[override]
        return (self._data, self._arrays, self.text)

    def __setstate__(self, state):  # type: ignore[override]
        _check_state(state, "Diagnosis", (3,))
        _check_report(state[0], "Diagnosis")
        for k, v in zip(("_data", "_arrays", "text"), state):
            object.__setattr__(self, k, v)

    @property
    def diagnosis(self) -> Dict[str, Any]:
        """The library's ``Diagnosis`` as a dict, as ``rheometer diagnose --json`` writes it."""
        return self._data

    @property
    def verdict(self) -> Dict[str, Any]:
        """What the diagnosis concludes: ``{"kind": "explained", "effects", "rms_over_noise"}``,
        ``{"kind": "adequate"}``, ``{"kind": "ambiguous", "effects", "alternatives",
        "rms_over_noise", "n_range", "kappa_range"}`` (explanations as good that disagree on
        the law, each alternative a list of effects: the law is not a result, ``n_range`` and
        ``kappa_range`` span them all) or
        ``{"kind": "none_of_the_candidates", "helps", "unexplained", "rms_over_noise",
        "stand_ins"}`` (``stand_ins``: found effects that bring the residuals to the noise only
        with a strength that differs between the experiments, see ``consistency``)."""
        return self._data["verdict"]

    @property
    def consistency(self) -> List[Dict[str, Any]]:
        """For each found effect, the test that its strength is the same in every experiment
        (a score test of the final fit against a strength varying with the conditions that
        differ between the experiments): ``effect``, ``unit``, ``strength``, ``conditions``,
        ``f_statistic``, ``dof``, ``p_value``, ``level``, ``share_of_cost`` and
        ``by_experiment`` (name, first-order strength). An effect with ``p_value < level`` is a
        stand-in for something else, and the verdict is "none of the candidates"."""
        return list(self._data.get("consistency", []))

    @property
    def robust(self) -> Optional[Dict[str, Any]]:
        """How a robust loss (``diagnose(..., loss=...)``) weighted the points: ``loss``,
        ``f_scale`` (soft margin, relative residual), ``f_scale_source``, ``down_weighted``
        (points beyond the margin), ``points``, ``smallest_weight``; ``None`` for least
        squares."""
        return self._data.get("robust")

    @property
    def law_not_a_result(self) -> Optional[str]:
        """Why the reported law (n, kappa) (the final fit's, else the user's) is not a result,
        or None: the verdict is "ambiguous" or "none of the candidates" (then no law of this
        diagnosis is a result, whatever its interval), or that fit fails the fit's own rule
        (:func:`law_not_a_result`: n or kappa at a bound of its range, an ``implausible`` or
        ``misfit`` warning). The library writes the reason into the JSON
        (``Diagnosis::law_not_a_result``, the text report's "NOT A RESULT" words); for a JSON
        written before it did, the same rule is applied here."""
        if "law_not_a_result" in self._data:
            return self._data["law_not_a_result"]
        kind = self.verdict.get("kind")
        if kind not in ("adequate", "explained"):
            return f"the verdict is {kind}, see the verdict"
        fit = self._data.get("final_fit") or self._data.get("base_fit") or {}
        return law_not_a_result(fit)

    @property
    def law_is_a_result(self) -> bool:
        """Whether the reported law (n, kappa) may be used as a result: no reason in
        :attr:`law_not_a_result` (the library's ``Diagnosis::law_is_a_result`` rule)."""
        return self.law_not_a_result is None

    def _base_law_not_a_result(self) -> Optional[str]:
        """Why the user's model's law is not a result: the library's
        ``Diagnosis::base_law_not_a_result``, from the JSON (its words are not repeated here:
        a JSON written before the library wrote it gives the fit no reason beyond its own)."""
        return self._data.get("base_law_not_a_result")

    @property
    def found(self) -> List[str]:
        """The effects found, in the order they were found."""
        return list(self._data.get("found", []))

    @property
    def stage_times(self) -> Dict[str, float]:
        """Where the diagnosis' wall time went [s]: ``fits_s``, ``linearised_s`` (linearisation,
        detection limits, false-alarm calibration), ``scans_s``, ``refits_s``, ``pairs_s``,
        ``rest_s``; they add up to the wall time (empty for a report written before they were
        kept)."""
        return dict(self._data.get("stage_times", {}))

    @property
    def most_likely_missing(self) -> Optional[str]:
        """The best single candidate that may be named (the forward search's first step), or
        None. A pair that explains the data better replaces it in ``found`` (see ``pair``).
        Under an "ambiguous" verdict it is one of the explanations the data cannot tell apart
        (the report's words), not the cause: the verdict's ``alternatives`` are as good; under
        "none_of_the_candidates" it is a stand-in or helps only in part (the report says which),
        not the cause either."""
        return self._data.get("most_likely_missing")

    @property
    def pair(self) -> Optional[Dict[str, Any]]:
        """The best pair of candidates fitted jointly, where one qualifies (``effects``,
        ``delta_bic``, ``delta_bic_of_steps``, ``replaces``, ``laws_disagree``), or None."""
        return self._data.get("pair")

    @property
    def candidates(self) -> List[Candidate]:
        """The candidates of the first step, best first."""
        return [Candidate(c) for c in self._data.get("candidates", [])]

    def candidate(self, effect: str) -> Optional[Candidate]:
        """The candidate named ``effect``, if it was one."""
        return next((c for c in self.candidates if c._data["effect"] == effect), None)

    @property
    def base_fit(self) -> FitResult:
        """The user's model fitted (principled estimator), with its one noise level; its
        ``law_not_a_result`` says why its law is no result where the diagnosis found effects
        missing from it or leaves no law a result."""
        return FitResult(self._data["base_fit"], {"residual_profiles": self._arrays.get("residuals_before") or {}},
                         context=self._base_law_not_a_result())

    @property
    def final_fit(self) -> Optional[FitResult]:
        """The fit with all found effects (fitted jointly), None if nothing was found; its
        ``law_not_a_result`` carries the diagnosis' reason (:attr:`law_not_a_result`), e.g.
        under an ambiguous verdict, where its interval alone would look like a result."""
        f = self._data.get("final_fit")
        if f is None:
            return None
        return FitResult(f, {"residual_profiles": self._arrays.get("residuals_after") or {}},
                         context=self.law_not_a_result)

    @property
    def noise_level(self) -> float:
        """The noise level the judgement used [-] (the base fit's)."""
        return self.base_fit.noise_level

    def candidates_table(self) -> Dict[str, np.ndarray]:
        """One row per candidate: ``effect`` and its scalar results (``delta_bic``,
        ``false_alarm``, ``share_of_excess``, ``status``, ...) plus the refitted ``strength``
        and its ``strength_stderr`` (nan where not refitted)."""
        rows: Dict[str, List[Any]] = {}
        cands = self.candidates
        scalar_keys = [k for k, v in (cands[0]._data.items() if cands else [])
                       if v is None or isinstance(v, (int, float, str, bool))]
        for c in cands:
            for k in scalar_keys:
                v = c._data.get(k)
                rows.setdefault(k, []).append(math.nan if v is None else v)
            s = c.strength
            rows.setdefault("strength", []).append(s.value if s is not None else math.nan)
            rows.setdefault("strength_stderr", []).append(s.stderr if s is not None else math.nan)
        return {k: np.asarray(v) for k, v in rows.items()}

    def __repr__(self) -> str:
        d = self._data
        kind = d.get("verdict", {}).get("kind")
        named = self.candidate(self.most_likely_missing) if self.most_likely_missing else None
        dbic = f", ΔBIC={_num(named._data.get('delta_bic')):.0f}" if named is not None else ""
        return (f"Diagnosis(verdict={kind!r}, found={self.found!r}{dbic}, "
                f"rms/noise={_num(d['base_fit'].get('noise', {}).get('rms_over_noise')):.3g}, "
                f"{len(d.get('candidates', []))} candidates)")

    def __str__(self) -> str:
        return self.text or repr(self)


class Landscape(Result):
    """The outcome of :func:`diffbvp.landscape`: grid vectors ``n`` and ``kappa``, ``cost``
    J(n, κ) as a (len(kappa) × len(n)) array (nan where no solution), ``status`` (0 computed, 1
    failed, 2 not computed), ``point_tol`` (the BVP tolerance of each cost, nan where none;
    ``tol`` is the landscape's own), ``minimum`` (n, κ, J) of the grid."""

    __slots__ = ()

    def __repr__(self) -> str:
        m = self._data.get("minimum")
        at = f", minimum at n={m[0]:.4g}, kappa={m[1]:.4g}" if m else ""
        return (
            f"Landscape({len(self._data['n'])}x{len(self._data['kappa'])}, "
            f"{self._data['estimator']} estimator{at})"
        )

    def table(self) -> Dict[str, np.ndarray]:
        """Long table: ``n``, ``kappa``, ``cost``, ``status``, ``tol`` (each cost's BVP
        tolerance; the CSV's columns, n varying fastest)."""
        n, k = np.meshgrid(self._data["n"], self._data["kappa"])
        return {
            "n": n.ravel(),
            "kappa": k.ravel(),
            "cost": np.asarray(self._data["cost"]).ravel(),
            "status": np.asarray(self._data["status"]).ravel(),
            "tol": np.asarray(
                self._data.get("point_tol", np.full(np.shape(self._data["cost"]), np.nan))
            ).ravel(),
        }


class DesignResult(Result):
    """The outcome of :func:`diffbvp.design`: the dict ``rheometer design --json`` writes (for a
    design for estimation: ``current`` uncertainty, ranked ``candidates`` with their predicted
    standard errors, the criterion; with ``discriminate``: the rivals' separations), plus
    ``text`` (the report) and ``csv`` (every candidate, as ``design.csv``)."""

    __slots__ = ("text", "csv")

    def __init__(self, data: Dict[str, Any], text: str = "", csv: str = ""):
        super().__init__(data, {})
        object.__setattr__(self, "text", text)
        object.__setattr__(self, "csv", csv)

    def __getstate__(self):  # type: ignore[override]
        return (self._data, self.text, self.csv)

    def __setstate__(self, state):  # type: ignore[override]
        if not (isinstance(state, tuple) and len(state) == 3 and isinstance(state[0], dict)):
            raise TypeError("DesignResult: the pickled state is not (dict, text, csv)")
        object.__setattr__(self, "_data", state[0])
        object.__setattr__(self, "_arrays", {})
        object.__setattr__(self, "text", state[1])
        object.__setattr__(self, "csv", state[2])

    @property
    def ranked(self) -> List[Dict[str, Any]]:
        """The feasible candidates, best first."""
        cands = [c for c in self._data.get("candidates", []) if c.get("rank") is not None]
        return sorted(cands, key=lambda c: c["rank"])

    def __repr__(self) -> str:
        n = len(self._data.get("candidates", []))
        return f"DesignResult({n} candidates, {len(self.ranked)} feasible)"

    def __str__(self) -> str:
        return self.text

