"""diffbvp from Python: the simulation-based elongational rheometer with numpy in and out.

    >>> import diffbvp
    >>> ds = diffbvp.load("data/pmma7n_synthetic/experiments.toml")
    >>> fit = diffbvp.fit(ds)
    >>> fit
    FitResult(n=0.804±0.007, kappa=11.63±0.09, rms=1.7 %, noise=1.5 %)
    >>> fit.n.value, fit.n.stderr, fit.n.ci95

The functions are the library's workflows, as the ``rheometer`` program runs them: :func:`load`
(or :meth:`Dataset.from_arrays`), :func:`simulate`, :func:`fit`, :func:`compare`,
:func:`diagnose`, :func:`landscape`. Results are the library's values as plain data (see
:mod:`diffbvp.results`): a fit is its ``FitSummary``, a diagnosis its ``Diagnosis``, exactly the
JSON the program writes. Errors are :mod:`diffbvp.errors` exceptions with the program's
messages. Long calls release the GIL and stop on Ctrl-C (``KeyboardInterrupt``);
:func:`set_threads` chooses how many cores a call uses. :mod:`diffbvp.distributed` spreads many
fits over a Dask cluster.

Units: SI throughout, with the unit in every key (``diameter_m``, ``temperature_K``, ...);
``kappa`` = ln(K / 1 Pa); relative quantities are fractions (0.01 = 1 %).
"""

from __future__ import annotations

import os
import warnings as _warnings
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _native
from .bvp import (BvpFitResult, BvpResult, CubicInterpolant, continue_bvp, fit_bvp, solve_bvp,
                  to_expression)
from .errors import DiffbvpError, EvaluationError, FitError, InputError, SimulationError
from .results import (Candidate, Comparison, DesignResult, Diagnosis, Estimate, FitResult, Landscape, Result,
                      SimulationResult)

__all__ = [
    "Dataset",
    "load",
    "simulate",
    "fit",
    "compare",
    "diagnose",
    "landscape",
    "design",
    "DiffbvpError",
    "InputError",
    "SimulationError",
    "FitError",
    "set_threads",
    "threads",
    "FitResult",
    "Estimate",
    "Candidate",
    "SimulationResult",
    "Comparison",
    "Diagnosis",
    "Landscape",
    "DesignResult",
    "Result",
    "solve_bvp",
    "fit_bvp",
    "to_expression",
    "continue_bvp",
    "BvpResult",
    "BvpFitResult",
    "CubicInterpolant",
    "EvaluationError",
]

__version__ = _native.library_version()

PathLike = Union[str, "os.PathLike[str]"]


class Dataset:
    """A set of spinning experiments: material, air, per-experiment conditions and measured
    diameters. Immutable; picklable (the TOML text and the measurement arrays travel, no file
    is needed on the other side)."""

    __slots__ = ("_native",)

    def __init__(self, native: "_native.Dataset"):
        self._native = native

    @classmethod
    def load(cls, path: PathLike, *, allow_large_inputs: bool = False) -> "Dataset":
        """Reads a TOML experiments file and the CSV files (``position_m,diameter_m``) it
        names. Raises :class:`InputError` naming file, line, table and key; what the reader
        doubts but accepts (two experiments reading one data file, an extrapolated take-up)
        is a ``UserWarning`` each, with file and line, as the CLI prints it.

        The input caps are the command line's (the book's input reference, *Limits*: 16 MiB
        experiments file, 1,000,000 rows and 128 MiB per measurement file, 1000 experiments,
        4 GiB estimated fit memory); ``allow_large_inputs=True`` lifts them all, as
        ``--allow-large-inputs`` does."""
        return cls(_native.Dataset.load(os.fspath(path), _flag(allow_large_inputs, "allow_large_inputs")))

    @classmethod
    def from_toml(cls, text: str, path: PathLike = "<text>",
                  measurements: Optional[Mapping[str, Tuple[Sequence[float], Sequence[float]]]] = None,
                  *, allow_large_inputs: bool = False) -> "Dataset":
        """A data set from TOML text. ``path`` labels it in messages and resolves relative
        ``data`` files; ``measurements`` (name → (positions [m], diameters [m])) replaces
        them. The caps of :meth:`load` apply to the arrays as to files (lifted by
        ``allow_large_inputs=True``)."""
        m = {k: (np.asarray(p, dtype=float), np.asarray(d, dtype=float))
             for k, (p, d) in (measurements or {}).items()}
        return cls(_native.Dataset.from_toml(text, os.fspath(path), m,
                                             _flag(allow_large_inputs, "allow_large_inputs")))

    @classmethod
    def from_arrays(cls, material: Mapping[str, float], experiments: Sequence[Mapping[str, Any]], *,
                    defaults: Optional[Mapping[str, float]] = None,
                    relative_uncertainty: Optional[float] = None,
                    uncertainty: Optional[Mapping[str, float]] = None,
                    allow_large_inputs: bool = False) -> "Dataset":
        """A data set from dicts in the TOML file's layout and numpy arrays.

        ``material``: the ``[material]`` keys (``density_slope_kg_m3_K``, ...,
        ``air_heat_conductivity_W_m_K``); ``experiments``: one dict per experiment with its
        keys (``name``, ``mass_flow_kg_s``, ``inlet_diameter_m`` or ``inlet_velocity_m_s``,
        optional ``spinline_length_m``, ``inlet_temperature_K``, ``air_temperature_K``,
        ``take_up_diameter_m``, ...) and the measurements as ``positions_m`` and
        ``diameters_m`` (1-D arrays, metres); ``defaults``: keys shared by all experiments;
        ``relative_uncertainty``: the diameters' relative measurement uncertainty [-];
        ``uncertainty``: the ``[uncertainty]`` table of the error budget.

        The arrays meet the caps of a measurement file read by :meth:`load` (at most
        1,000,000 rows per experiment, and the rows a fit can hold within the estimated
        memory cap in all), checked on their lengths before any row is converted;
        ``allow_large_inputs=True`` lifts the caps, as for :meth:`load`. Ctrl-C stops the
        conversion (``KeyboardInterrupt``).

        Every value is checked as in a TOML file; messages name ``<conditions>`` with the
        line of the generated TOML (:attr:`toml`), or ``<arrays of experiment "NAME">`` with
        the line of a virtual CSV file (row ``i`` is line ``i + 2``).
        """
        exps: List[Dict[str, Any]] = []
        meas: Dict[str, Tuple[np.ndarray, np.ndarray]] = {}
        for e in experiments:
            e = dict(e)
            pos = e.pop("positions_m", None)
            dia = e.pop("diameters_m", None)
            if (pos is None) != (dia is None):
                raise InputError(
                    f"experiment {e.get('name')!r}: give both positions_m and diameters_m, or neither")
            if pos is not None:
                meas[str(e.get("name"))] = (np.asarray(pos, dtype=float), np.asarray(dia, dtype=float))
            exps.append(e)
        cond: Dict[str, Any] = {}
        if relative_uncertainty is not None:
            cond["relative_uncertainty"] = relative_uncertainty
        if uncertainty is not None:
            cond["uncertainty"] = dict(uncertainty)
        cond["material"] = dict(material)
        if defaults is not None:
            cond["defaults"] = dict(defaults)
        cond["experiment"] = exps
        return cls(_native.Dataset.from_conditions(cond, meas,
                                                   _flag(allow_large_inputs, "allow_large_inputs")))

    @classmethod
    def _from_state(cls, toml: str, path: str, measurements: Dict[str, Tuple[np.ndarray, np.ndarray]],
                    allow_large_inputs: bool = False) -> "Dataset":
        return cls(_native.Dataset.from_toml(toml, path, measurements, bool(allow_large_inputs)))

    def __reduce__(self):
        return (Dataset._from_state, (self.toml, self.path, self.measurements(), self.allow_large_inputs))

    def with_measurements(self, measurements: Mapping[str, Tuple[Sequence[float], Sequence[float]]]) -> "Dataset":
        """The same experiments with other measured diameters (name → (positions [m],
        diameters [m]); experiments not named keep theirs), e.g. a bootstrap replicate."""
        m = self.measurements()
        for k, (p, d) in measurements.items():
            m[k] = (np.asarray(p, dtype=float), np.asarray(d, dtype=float))
        return Dataset._from_state(self.toml, self.path, m, self.allow_large_inputs)

    @property
    def path(self) -> str:
        """The experiments file (or ``<conditions>``, ``<text>``)."""
        return self._native.path

    @property
    def toml(self) -> str:
        """The TOML text of the data set."""
        return self._native.toml

    @property
    def allow_large_inputs(self) -> bool:
        """Whether the input caps were lifted when it was made (``allow_large_inputs=True``);
        a pickled copy and :meth:`with_measurements` keep it."""
        return self._native.allow_large_inputs

    @property
    def data_digest(self) -> str:
        """The digest of the data (experiment names, conditions and measurements) that a fit
        made on them records in its summary (``FitResult.summary["data_digest"]``), as the
        ``rheometer`` program does: it tells this data set from other data with the same
        experiment names."""
        return self._native.data_digest

    @property
    def names(self) -> List[str]:
        """Experiment names, in file order."""
        return self._native.names

    @property
    def relative_uncertainty(self) -> Optional[float]:
        """Declared relative measurement uncertainty of the diameters [-], if any."""
        return self._native.relative_uncertainty

    def measurements(self) -> Dict[str, Tuple[np.ndarray, np.ndarray]]:
        """name → (positions [m], diameters [m])."""
        return self._native.measurements()

    def conditions(self) -> List[Dict[str, Any]]:
        """Per experiment: its conditions (SI units in the keys), TOML ``line`` and ``data``
        file."""
        return self._native.conditions()

    def measurements_table(self) -> Dict[str, np.ndarray]:
        """All measurements as columns ``experiment``, ``position_m``, ``diameter_m``."""
        exp: List[str] = []
        pos: List[np.ndarray] = []
        dia: List[np.ndarray] = []
        for k, (p, d) in self.measurements().items():
            exp.extend([k] * len(p))
            pos.append(p)
            dia.append(d)
        return {"experiment": np.asarray(exp),
                "position_m": np.concatenate(pos) if pos else np.zeros(0),
                "diameter_m": np.concatenate(dia) if dia else np.zeros(0)}

    def __len__(self) -> int:
        return len(self._native)

    def __repr__(self) -> str:
        return f"Dataset({self.path!r}, {len(self)} experiments)"


def set_threads(n: Optional[int] = None) -> None:
    """Sets how many threads (cores) every later call of this process uses: a fit solves its
    experiments in parallel, a landscape its rows, a diagnosis its candidates. ``None``: the
    default (``RAYON_NUM_THREADS``, else one per core). Several processes on one machine (Dask
    workers) should share the cores: ``cores // processes`` each (see
    :mod:`diffbvp.distributed`)."""
    _native.set_threads(None if n is None else int(n))


def threads() -> int:
    """The number of threads a call of this process uses now (see :func:`set_threads`)."""
    return _native.threads()


def load(path: PathLike, *, allow_large_inputs: bool = False) -> Dataset:
    """Reads a TOML experiments file and its CSV files (see :meth:`Dataset.load`; the input
    caps are the command line's, lifted by ``allow_large_inputs=True``)."""
    return Dataset.load(path, allow_large_inputs=allow_large_inputs)


def _ds(dataset: Union[Dataset, PathLike]) -> "_native.Dataset":
    if isinstance(dataset, Dataset):
        return dataset._native
    if isinstance(dataset, (str, os.PathLike)):
        return Dataset.load(dataset)._native
    raise TypeError(f"expected a diffbvp.Dataset or a path, got {type(dataset).__name__}")


def _effects(effects: Union[None, str, Iterable[str]]) -> List[str]:
    if effects is None:
        return []
    if isinstance(effects, str):
        return [effects]
    return [str(e) for e in effects]


def simulate(dataset: Union[Dataset, PathLike], n: float, kappa: float, *,
             effects: Union[None, str, Iterable[str]] = None,
             take_up_diameter: Optional[float] = None, take_up_from_data: bool = False,
             points: int = 101, positions: Optional[Sequence[float]] = None,
             sensitivities: bool = False, tol: Optional[float] = None,
             max_nodes: Optional[int] = None) -> SimulationResult:
    """Simulates every experiment with the Carreau-type law (n [-], kappa = ln(K / 1 Pa); both
    required: there is no default law).

    ``effects``: fixed effects, ``"radiation=0.9"``; ``take_up_diameter`` [m] or
    ``take_up_from_data`` for experiments without a take-up condition; ``points`` uniform
    positions from 0 to L, or ``positions`` [m]; ``sensitivities``: exact d(profile)/d(n, κ,
    strengths) from forward sensitivities; ``tol``: BVP tolerance (default 1e-6);
    ``max_nodes``: mesh limit (default 20000). Raises :class:`SimulationError` naming the
    experiment and its TOML line.
    """
    pos = None if positions is None else [float(x) for x in np.asarray(positions, dtype=float).ravel()]
    d = _native.simulate(_ds(dataset), float(n), float(kappa), effects=_effects(effects),
                         take_up_diameter=take_up_diameter, take_up_from_data=take_up_from_data,
                         points=_int(points, "points"), positions=pos,
                         sensitivities=sensitivities, tol=tol,
                         max_nodes=_opt_int(max_nodes, "max_nodes"))
    return SimulationResult(d)


def fit(dataset: Union[Dataset, PathLike], *, start: Optional[Tuple[float, float]] = None,
        estimator: str = "principled", model: Optional[str] = None,
        effects: Union[None, str, Iterable[str]] = None, loss: str = "linear",
        f_scale: Optional[float] = None, relative_uncertainty: Optional[float] = None,
        error_budget: bool = True, tol: Optional[float] = None, max_nodes: Optional[int] = None,
        profile_points: int = 101,
        start_from: Union[None, FitResult, Diagnosis, Mapping[str, Any], PathLike] = None) -> FitResult:
    """Identifies (n, κ) and the strengths of fitted effects: the library's fit workflow, as
    ``rheometer fit``. Returns the fit's ``FitSummary`` (:class:`FitResult`).

    ``start``: (n, κ) (default: the paper's start heuristic); ``estimator``: ``"principled"``
    (relative least squares against the raw data, take-up diameters fitted) or ``"paper"``;
    ``model``: ``"carreau"`` or ``"newtonian"`` (default: carreau, or ``start_from``'s law); ``effects``: ``"radiation"`` (strength
    fitted), ``"radiation=0.9"`` (fixed), ``"air_coflow=40:decay_length=0.2"`` (shape fixed);
    ``loss``: ``"linear"``, ``"soft_l1"``, ``"huber"``, ``"cauchy"``; ``f_scale``: soft
    margin of a robust loss as a relative residual [-]; ``relative_uncertainty``: the
    diameters' noise [-] (default: the data set's); ``error_budget``: propagate the declared
    uncertainties of process conditions, instrument and material data (about half the fit's
    time; a bootstrap replicate can do without); ``tol``: BVP tolerance [-] kept as given
    (default: 1e-4, refined until the discretisation moves no estimate by more than 0.01
    standard errors); ``max_nodes``: mesh limit (default 20000); ``profile_points``:
    positions of the fitted profiles; ``start_from``: continue from a previous result (a
    :class:`FitResult`, a :class:`Diagnosis` — its final fit, the model with the effects it
    found — their dicts, or the path of a ``fit --json`` / ``diagnose --json`` file): its
    effects join the model (strengths fitted where they were fitted, fitted shapes free) and
    the fit starts from its law and strengths; ``effects`` adds further ones (``start`` not
    with it). Warnings of the fit are in ``FitResult.warnings``; a budget that could not be
    computed is in ``FitResult.notes`` and warned about.
    """
    d = _native.fit(_ds(dataset), start=None if start is None else (float(start[0]), float(start[1])),
                    estimator=estimator, model=model, effects=_effects(effects), loss=loss,
                    f_scale=f_scale, relative_uncertainty=relative_uncertainty,
                    error_budget=error_budget, tol=tol, max_nodes=_opt_int(max_nodes, "max_nodes"),
                    profile_points=_int(profile_points, "profile_points"),
                    start_from=_previous(start_from))
    result = FitResult._from_native(d)
    for note in result.notes:
        _warnings.warn(note, RuntimeWarning, stacklevel=2)
    return result


def compare(dataset: Union[Dataset, PathLike], fit: Optional[FitResult] = None, *,
            n: Optional[float] = None, kappa: Optional[float] = None, newtonian: bool = False,
            take_up_from_data: bool = False, effects: Union[None, str, Iterable[str]] = None,
            relative_uncertainty: Optional[float] = None, tol: Optional[float] = None,
            max_nodes: Optional[int] = None) -> Comparison:
    """Compares the model with the measurements: the library's compare workflow, as
    ``rheometer compare``. The model is a fit's (a :class:`FitResult`, or the dict of a
    ``FitSummary`` such as the JSON of ``rheometer fit --json``: its law, effects, take-up
    factors and, compared as it is, its noise level) or given by ``n``/``kappa`` (or
    ``newtonian=True``). ``effects`` add or override effects (``"radiation=0.9"``);
    ``relative_uncertainty`` overrides the noise level [-]; ``tol``: BVP tolerance (default
    1e-6). A fit that carries warnings is compared with a ``RuntimeWarning`` for each."""
    summary = None
    notes: List[str] = []
    if fit is not None:
        summary = fit.summary if isinstance(fit, FitResult) else dict(fit)
        for w in summary.get("warnings", []):
            notes.append(f"the fit carries a warning: [{w.get('code')}] {w.get('message')}")
    d = _native.compare(_ds(dataset), summary, n=n, kappa=kappa, newtonian=newtonian,
                        take_up_from_data=take_up_from_data, effects=_effects(effects),
                        relative_uncertainty=relative_uncertainty, tol=tol,
                        max_nodes=_opt_int(max_nodes, "max_nodes"))
    for w in notes:
        _warnings.warn(w, RuntimeWarning, stacklevel=2)
    return Comparison(d["comparison"], d["text"], notes)


def diagnose(dataset: Union[Dataset, PathLike], *, model: Optional[str] = None,
             effects: Union[None, str, Iterable[str]] = None,
             candidates: Optional[Iterable[str]] = None, refit_top: Optional[int] = None,
             start: Optional[Tuple[float, float]] = None, loss: str = "linear",
             f_scale: Optional[float] = None, tol: Optional[float] = None,
             max_nodes: Optional[int] = None,
             start_from: Union[None, FitResult, Diagnosis, Mapping[str, Any], PathLike] = None
             ) -> Diagnosis:
    """Which physical effects are missing? The library's diagnose workflow, as ``rheometer
    diagnose``: fits your model (``model``, ``effects``), scores every candidate effect
    (default: all built-in ones, or ``candidates`` by name), searches and refits them, ranks
    them by ΔBIC with a look-elsewhere calibration (false-alarm probability), adds the found
    effect and searches again, and gives a verdict (explained, adequate, ambiguous, none of the
    candidates; ``Diagnosis.law_is_a_result`` says whether its law may be used).
    ``refit_top``: how many candidates get the search and refits; ``start``: (n, κ) of your
    fit; ``loss`` (``"soft_l1"``, ``"huber"``, ``"cauchy"``) and ``f_scale``: a robust loss
    whose fit of your model weights the points for every fit of the diagnosis (default: least
    squares, the gross outliers of the noise model left out; ``Diagnosis.robust`` says how it
    weighted them); ``tol``: BVP tolerance (default 1e-4); ``start_from``: a previous result
    whose effects are in your model, fitted from its law and strengths (as in :func:`fit`), so
    that the search looks for what is still missing. Takes about 5 s on the shipped data and up
    to half a minute where two effects are missing (2 cores)."""
    d = _native.diagnose(_ds(dataset), model=model, effects=_effects(effects),
                         candidates=None if candidates is None else [str(c) for c in candidates],
                         refit_top=_opt_int(refit_top, "refit_top"), start=start, loss=loss,
                         f_scale=f_scale, tol=tol, max_nodes=_opt_int(max_nodes, "max_nodes"),
                         start_from=_previous(start_from))
    return Diagnosis._from_native(d)


def _previous(start_from: Union[None, FitResult, Diagnosis, Mapping[str, Any], PathLike]
              ) -> Optional[str]:
    """A result to continue from as the JSON text the library reads (``fit --from``)."""
    import json
    if start_from is None:
        return None
    if isinstance(start_from, FitResult):
        return json.dumps(start_from.summary)
    if isinstance(start_from, Diagnosis):
        return json.dumps(start_from.diagnosis)
    if isinstance(start_from, Mapping):
        return json.dumps(dict(start_from))
    if isinstance(start_from, (str, os.PathLike)):
        try:
            with open(start_from, encoding="utf-8") as f:
                return f.read()
        except OSError as e:
            raise InputError(f"start_from: cannot read {os.fspath(start_from)}: {e}") from e
    raise TypeError("start_from: give a FitResult, a Diagnosis, their dict, or the path of a "
                    f"fit or diagnosis JSON file (got {type(start_from).__name__})")


def landscape(dataset: Union[Dataset, PathLike], *, grid: Tuple[int, int] = (41, 41),
              n_range: Tuple[float, float] = (0.0, 1.0),
              kappa_range: Tuple[float, float] = (9.0, 16.0), estimator: str = "paper",
              tol: float = 1e-4, max_nodes: Optional[int] = None,
              uniform_tol: bool = False) -> Landscape:
    """The cost J(n, κ) on a grid (paper Fig. 4), as ``rheometer landscape``: ``grid`` =
    (number of n values, number of κ values); ``tol``: BVP tolerance (a picture: fits check
    their own discretisation). Points whose row neighbour's cost is more than twice their row's
    lowest are solved at ten times ``tol`` (at most 1e-3; their costs to a few 1e-4 relative),
    unless ``uniform_tol``; the result's ``point_tol`` array says which. Ctrl-C stops it between grid
    points (``KeyboardInterrupt``)."""
    d = _native.landscape(_ds(dataset), grid=_grid(grid),
                          n_range=(float(n_range[0]), float(n_range[1])),
                          kappa_range=(float(kappa_range[0]), float(kappa_range[1])),
                          estimator=estimator, tol=tol, max_nodes=_opt_int(max_nodes, "max_nodes"),
                          uniform_tol=bool(uniform_tol))
    return Landscape(d)


def design(dataset: Union[Dataset, PathLike], *, template: Optional[str] = None,
           mass_flow: Optional[Tuple[float, float]] = None,
           stencil_velocity: Optional[Tuple[float, float]] = None,
           take_up_diameter: Optional[Tuple[float, float]] = None,
           take_up_velocity: Optional[Tuple[float, float]] = None,
           grid: Tuple[int, int] = (9, 9), criterion: str = "d",
           discriminate: Optional[Sequence[str]] = None,
           start: Optional[Tuple[float, float]] = None, noise: Optional[float] = None,
           tol: float = 1e-6, max_nodes: Optional[int] = None) -> DesignResult:
    """Which experiment next, as ``rheometer design``: candidates on a ``grid`` of mass flows
    (``mass_flow`` in kg/s, or ``stencil_velocity`` in mm/s) x take-up values
    (``take_up_diameter`` in m, or ``take_up_velocity`` in m/s), each a ``(min, max)`` range
    within the plausible ranges of the experiments file (default: from the data set), copies of
    the experiment ``template``; ranked by ``criterion`` ("d": volume of the confidence region,
    "a": mean variance, "e": worst direction) of (n, κ) after adding the candidate, or, with
    ``discriminate=["mass_flow_scale", "nusselt_scale"]``, by how well it tells those rival
    explanations apart. ``noise``: the relative measurement noise (default: the data set's
    relative_uncertainty, else the fit's residual level). The result's dict is what
    ``rheometer design --json`` writes.

    >>> import diffbvp
    >>> d = diffbvp.design("data/pmma7n_synthetic/experiments.toml", grid=(3, 3))  # doctest: +SKIP
    >>> d.ranked[0]["candidate"]["mass_flow"]  # doctest: +SKIP
    """
    r = _native.design(_ds(dataset), template=template,
                       mass_flow=_pair(mass_flow, "mass_flow"), stencil_velocity=_pair(stencil_velocity, "stencil_velocity"),
                       take_up_diameter=_pair(take_up_diameter, "take_up_diameter"),
                       take_up_velocity=_pair(take_up_velocity, "take_up_velocity"),
                       grid=_grid(grid),
                       criterion=criterion,
                       discriminate=None if discriminate is None else [str(e) for e in discriminate],
                       start=_pair(start, "start"), noise=noise, tol=tol,
                       max_nodes=None if max_nodes is None else _int(max_nodes, "max_nodes"))
    return DesignResult(r["design"], r["text"], r["csv"])


def _pair(v: Optional[Sequence[float]], name: str) -> Optional[Tuple[float, float]]:
    """A pair of floats for the argument ``name`` (or None)."""
    if v is None:
        return None
    try:
        a, b = v
        return (float(a), float(b))
    except (TypeError, ValueError):
        raise InputError(f"{name}: expected a pair of numbers, got {v!r}") from None


def _int(v: Any, name: str) -> int:
    """A whole number for the argument ``name`` (an int, or a float without a fraction); its
    range is the library's to check, up to a size no count reaches."""
    if isinstance(v, bool):
        raise InputError(f"{name}: expected a whole number, got {v!r}")
    if isinstance(v, (int, np.integer)):
        i = int(v)
    elif isinstance(v, (float, np.floating)) and float(v).is_integer():
        i = int(v)
    else:
        raise InputError(f"{name}: expected a whole number, got {v!r}")
    if abs(i) > 2**100:
        raise InputError(f"{name}: {i} is far outside any accepted range")
    return i


def _flag(v: Any, name: str) -> bool:
    """A switch for the argument ``name``: ``True`` or ``False`` (numpy's bools too)."""
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    raise InputError(f"{name}: expected True or False, got {v!r}")


def _grid(v: Any) -> Tuple[int, int]:
    """The argument ``grid``: a pair of whole numbers."""
    try:
        a, b = v
    except (TypeError, ValueError):
        raise InputError(f"grid: expected a pair of whole numbers (N, M), got {v!r}") from None
    return (_int(a, "grid"), _int(b, "grid"))


def _opt_int(v: Any, name: str) -> Optional[int]:
    """``None``, or a whole number for the argument ``name`` (see :func:`_int`)."""
    return None if v is None else _int(v, name)

