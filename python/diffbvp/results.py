"""Result objects of :mod:`diffbvp`: plain data (a dict from the library's JSON form plus numpy
arrays), attribute access, ``to_dict()``, tables for pandas, picklable, with a short ``repr``.

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
    "FitResult",
    "SimulationResult",
    "Comparison",
    "Diagnosis",
    "Landscape",
]


def _num(x: Any) -> float:
    """A JSON number as float; ``None`` (a NaN written as null) as ``nan``."""
    return math.nan if x is None else float(x)


def _plain(x: Any) -> Any:
    """Numpy arrays (recursively) as lists, for ``to_dict()``."""
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, Mapping):
        return {k: _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, np.generic):
        return x.item()
    return x


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
        if type(other) is not type(self):
            return NotImplemented
        return _same(self.to_dict(), other.to_dict())  # type: ignore[attr-defined]

    __hash__ = None  # type: ignore[assignment]


def _same(a: Any, b: Any) -> bool:
    """Structural equality that treats nan == nan (a missing standard error on both sides)."""
    if isinstance(a, float) and isinstance(b, float):
        return a == b or (math.isnan(a) and math.isnan(b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
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


class FitResult(Result):
    """The outcome of :func:`diffbvp.fit`.

    ``report`` is the dict ``rheometer fit --json`` writes (estimates, standard errors, 95 %
    intervals, correlation, warnings, error budget, take-up factors, per-experiment RMS); its
    keys also read as attributes (``fit.n``, ``fit.kappa``, ``fit.K_Pa`` [Pa],
    ``fit.rms_relative_residual`` [-], ...). Arrays: ``parameter_names``, ``parameters`` and
    ``covariance`` of the fit vector (n, κ, fitted strengths, take-up factors),
    ``residual_profiles`` (name → ``position_m`` [m], ``relative_residual`` [-]) and ``profiles`` (name → fitted
    profiles on uniform positions, SI units in the keys).
    """

    __slots__ = ("text", "notes")

    def __init__(self, report: Dict[str, Any], arrays: Dict[str, Any], text: str = "", notes: Optional[List[str]] = None):
        super().__init__(report, arrays)
        object.__setattr__(self, "text", text)
        object.__setattr__(self, "notes", list(notes or []))

    @classmethod
    def _from_native(cls, d: Dict[str, Any]) -> "FitResult":
        return cls(d["report"], d["arrays"], d.get("text", ""), d.get("notes", []))

    def __getstate__(self):  # type: ignore[override]
        return (self._data, self._arrays, self.text, self.notes)

    def __setstate__(self, state):  # type: ignore[override]
        object.__setattr__(self, "_data", state[0])
        object.__setattr__(self, "_arrays", state[1])
        object.__setattr__(self, "text", state[2])
        object.__setattr__(self, "notes", state[3])

    @property
    def report(self) -> Dict[str, Any]:
        """The fit report as ``rheometer fit --json`` writes it (NaN written as ``None``)."""
        return self._data

    @property
    def n(self) -> float:
        """Power index n [-]."""
        return _num(self._data["n"])

    @property
    def kappa(self) -> float:
        """κ = ln(K / 1 Pa) [-]."""
        return _num(self._data["kappa"])

    @property
    def stderr_n(self) -> float:
        """Standard error of n [-] (nan if it does not exist)."""
        return _num(self._data.get("stderr_n"))

    @property
    def stderr_kappa(self) -> float:
        """Standard error of κ [-] (nan if it does not exist)."""
        return _num(self._data.get("stderr_kappa"))

    @property
    def ci95_n(self) -> Tuple[float, float]:
        """95 % confidence interval of n [-] (nan at a bound)."""
        a, b = self._data["ci95_n"]
        return (_num(a), _num(b))

    @property
    def ci95_kappa(self) -> Tuple[float, float]:
        """95 % confidence interval of κ [-] (nan at a bound)."""
        a, b = self._data["ci95_kappa"]
        return (_num(a), _num(b))

    @property
    def rms(self) -> float:
        """RMS relative residual over all measurements [-] (0.016 = 1.6 %)."""
        return _num(self._data["rms_relative_residual"])

    @property
    def warnings(self) -> List[Dict[str, str]]:
        """Everything that makes the fit doubtful: ``{"code", "message"}`` (empty if good)."""
        return list(self._data.get("warnings", []))

    @property
    def effects(self) -> List[Dict[str, Any]]:
        """The model's extra effects with strength, unit and standard error."""
        return list(self._data.get("effects", []))

    @property
    def take_up_factors(self) -> np.ndarray:
        """Take-up factors φ_k = d_out,k / d_fit,k(L) [-], in experiment order."""
        return np.asarray(self._data["take_up_factors"], dtype=float)

    @property
    def residual_profiles(self) -> Dict[str, Dict[str, np.ndarray]]:
        """name → ``position_m`` [m] and ``relative_residual`` [-] = (d_model − d_meas)/d_meas
        at the measurement positions."""
        return self._arrays["residual_profiles"]

    @property
    def profiles(self) -> Dict[str, Dict[str, Any]]:
        """name → fitted profiles on uniform positions (SI units in the keys)."""
        return self._arrays.get("profiles", {})

    @property
    def covariance(self) -> Optional[np.ndarray]:
        """Covariance of the fit vector (``parameter_names``), None if singular."""
        return self._arrays.get("covariance")

    def estimates(self) -> Dict[str, Tuple[float, float]]:
        """name → (estimate, standard error) of n, κ and the effects' strengths."""
        out = {"n": (self.n, self.stderr_n), "kappa": (self.kappa, self.stderr_kappa)}
        for e in self.effects:
            out[e["effect"]] = (_num(e.get("strength")), _num(e.get("stderr")))
        return out

    def residuals_table(self) -> Dict[str, np.ndarray]:
        """Columns ``experiment``, ``position_m`` [m], ``relative_residual`` [-]
        (``pandas.DataFrame(fit.residuals_table())``)."""
        return _long_table(self._arrays["residual_profiles"], ["position_m", "relative_residual"])

    def profiles_table(self) -> Dict[str, np.ndarray]:
        """The fitted profiles of every experiment as one long table (SI units in the keys)."""
        return _long_table(self._arrays.get("profiles", {}), _PROFILE_KEYS)

    def flow_curve(self) -> Dict[str, np.ndarray]:
        """The identified law as the experiments see it: strain rate [1/s], temperature [K]
        and elongational viscosity [Pa s] along every fitted spin line (long table).

        TODO(restructure): the library's FitSummary will carry the flow curve (μ_e(ε̇) at
        reference temperatures with its confidence band); read it from there.
        """
        return _long_table(
            self._arrays.get("profiles", {}),
            ["strain_rate_1_s", "viscosity_Pa_s", "temperature_K", "position_m"],
        )

    def __repr__(self) -> str:
        parts = [f"n={_pm(self.n, self.stderr_n)}", f"kappa={_pm(self.kappa, self.stderr_kappa)}"]
        for e in self.effects:
            parts.append(f"{e['effect']}={_pm(_num(e.get('strength')), _num(e.get('stderr')))}")
        parts.append(f"rms={100 * self.rms:.2g} %")
        if self.warnings:
            parts.append(f"{len(self.warnings)} warning{'s' if len(self.warnings) > 1 else ''}")
        return f"FitResult({', '.join(parts)})"

    def __str__(self) -> str:
        return self.text or repr(self)


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
    """The outcome of :func:`diffbvp.compare`: the JSON of ``rheometer compare`` (``sigma``
    [-], ``chi2``, per-experiment ``rms``, runs test, lag-1 autocorrelation, systematic
    ``segments``, the noise model) plus ``text``."""

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

    def __repr__(self) -> str:
        d = self._data
        dof = max(1, d.get("points", 0) - d.get("fitted_parameters", 0))
        return (
            f"Comparison({len(d['experiments'])} experiments, {d.get('points')} points, "
            f"sigma={100 * _num(d.get('sigma')):.2g} %, chi2/dof={_num(d.get('chi2')) / dof:.3g})"
        )

    def __str__(self) -> str:
        return self.text or repr(self)


class Diagnosis(Result):
    """The outcome of :func:`diffbvp.diagnose`: the JSON of ``rheometer diagnose``
    (``candidates`` best first with ΔBIC, strengths and refits, ``indistinguishable`` pairs,
    ``most_likely_missing``, ``outliers``, ``rms_over_noise``, ...), the user's fit
    ``base_fit`` and the refit with the best candidate ``best_fit`` (as :class:`FitResult`),
    and the residuals before and after (name → ``position_m``, ``relative_residual``)."""

    __slots__ = ("text", "base_fit", "best_fit")

    def __init__(self, data: Dict[str, Any], arrays: Dict[str, Any], text: str = "",
                 base_fit: Optional[FitResult] = None, best_fit: Optional[FitResult] = None):
        super().__init__(data, arrays)
        object.__setattr__(self, "text", text)
        object.__setattr__(self, "base_fit", base_fit)
        object.__setattr__(self, "best_fit", best_fit)

    @classmethod
    def _from_native(cls, d: Dict[str, Any]) -> "Diagnosis":
        best = d.get("best_fit")
        arrays = {"residuals_before": d["residuals_before"], "residuals_after": d["residuals_after"]}
        return cls(d["diagnosis"], arrays, d.get("text", ""),
                   FitResult._from_native(d["base_fit"]),
                   FitResult._from_native(best) if best is not None else None)

    def __getstate__(self):  # type: ignore[override]
        return (self._data, self._arrays, self.text, self.base_fit, self.best_fit)

    def __setstate__(self, state):  # type: ignore[override]
        for k, v in zip(("_data", "_arrays", "text", "base_fit", "best_fit"), state):
            object.__setattr__(self, k, v)

    def to_dict(self) -> Dict[str, Any]:
        out = super().to_dict()
        out["base_fit"] = self.base_fit.to_dict() if self.base_fit else None
        out["best_fit"] = self.best_fit.to_dict() if self.best_fit else None
        return out

    @property
    def most_likely_missing(self) -> Optional[str]:
        """The effect that earns its place with the best ΔBIC, or None."""
        return self._data.get("most_likely_missing")

    def candidates_table(self) -> Dict[str, np.ndarray]:
        """One row per candidate: ``effect`` and its scalar results (ΔBIC, strength, ...)."""
        rows: Dict[str, List[Any]] = {}
        cands = self._data.get("candidates", [])
        scalar_keys = [k for k, v in (cands[0].items() if cands else [])
                       if v is None or isinstance(v, (int, float, str, bool))]
        for c in cands:
            for k in scalar_keys:
                v = c.get(k)
                rows.setdefault(k, []).append(math.nan if v is None else v)
        return {k: np.asarray(v) for k, v in rows.items()}

    def __repr__(self) -> str:
        d = self._data
        best = d.get("most_likely_missing")
        dbic = ""
        for c in d.get("candidates", []):
            name = c.get("effect") or c.get("name")
            if best is not None and name == best:
                v = c.get("delta_bic")
                if v is not None:
                    dbic = f", ΔBIC={v:.0f}"
        return (
            f"Diagnosis(most_likely_missing={best!r}{dbic}, "
            f"rms/noise={_num(d.get('rms_over_noise')):.3g}, "
            f"{len(d.get('candidates', []))} candidates)"
        )

    def __str__(self) -> str:
        return self.text or repr(self)


class Landscape(Result):
    """The outcome of :func:`diffbvp.landscape`: grid vectors ``n`` and ``kappa``, ``cost``
    J(n, κ) as a (len(kappa) × len(n)) array (nan where no solution), ``status`` (0 computed, 1
    failed, 2 not computed), ``minimum`` (n, κ, J) of the grid."""

    __slots__ = ()

    def __repr__(self) -> str:
        m = self._data.get("minimum")
        at = f", minimum at n={m[0]:.4g}, kappa={m[1]:.4g}" if m else ""
        return (
            f"Landscape({len(self._data['n'])}x{len(self._data['kappa'])}, "
            f"{self._data['estimator']} estimator{at})"
        )

    def table(self) -> Dict[str, np.ndarray]:
        """Long table: ``n``, ``kappa``, ``cost``, ``status`` (n varying fastest)."""
        n, k = np.meshgrid(self._data["n"], self._data["kappa"])
        return {
            "n": n.ravel(),
            "kappa": k.ravel(),
            "cost": np.asarray(self._data["cost"]).ravel(),
            "status": np.asarray(self._data["status"]).ravel(),
        }
