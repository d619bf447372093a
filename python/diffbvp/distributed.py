"""Many independent fits over a Dask cluster (``dask.distributed``).

The same code runs on one machine (a ``LocalCluster``) and on a cluster (a ``Client``
connected to its scheduler)::

    from dask.distributed import Client, LocalCluster
    import diffbvp
    from diffbvp.distributed import bootstrap, map_fits

    ds = diffbvp.load("data/pmma7n_synthetic/experiments.toml")
    base = diffbvp.fit(ds)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True) as cluster, \
            Client(cluster) as client:
        boot = bootstrap(client, ds, base, replicates=64, seed=1)
    boot.std()          # bootstrap standard deviations of n, kappa, ...
    boot.fits[0]        # a FitResult, as diffbvp.fit returns

**Cores.** One fit already solves its experiments in parallel (9 on the shipped data), on every
core of its process by default. Worker processes that share a machine must share its cores, or
they oversubscribe them (two workers × two threads on two cores ran 0.5–0.8 times as fast as
one process alone). Every task therefore sets its process's Rust thread count first
(:func:`diffbvp.set_threads`): ``threads_per_fit`` (default 1: as many worker processes as
cores, one task thread each). With one worker process per machine of ``c`` cores give
``threads_per_fit=c``; in general ``c // (worker processes per machine)``. The environment
variable ``RAYON_NUM_THREADS`` (:func:`worker_env`) does the same for every call of a worker
process, if set before its first call.

**What travels.** The data set (its TOML text and the measurement arrays, about 15 kB for the
shipped 9 experiments) and the base fit go to every worker once per call
(``client.scatter(..., broadcast=True)``: keys of their own, so that calls on one
client, the same data or not, never share or release each other's data); a task is then only (replicate indices, seed, fit
options), and its result the pickled :class:`~diffbvp.results.FitResult` of each replicate
(the ``FitSummary`` dict and the residual arrays, about 40 kB with ``profile_points=2``, plus
about 50 kB per 100 profile points).

**Granularity.** One fit takes 0.2 to 1 s on the shipped data (without / with the error
budget); a task is ``batch_size`` fits (default: one, or more when there are more than 8
replicates per worker), so that the scheduler's cost per task (about 1 ms) stays far below the
work and the last tasks still balance. A worker holds one data set and one fit at a time (a
few MB).

**Checked before anything travels.** ``replicates``, ``seed``, ``noise``, ``batch_size`` and
``threads_per_fit`` are checked, every key of ``fit_options`` must be an argument of
:func:`diffbvp.fit` (a typo is an :class:`~diffbvp.errors.InputError` naming the key at once,
not a failed replicate), and the base fit must have been made on the data set (the data digest
its summary records, else its experiment names). A replicate that fails on a worker keeps its
exception: :attr:`BootstrapResult.errors` (and :func:`map_fits`' list) hold the exception
object with its class and attributes (``experiment``, ``hints``, ...).

Results are deterministic: the same replicate index and seed give the same synthetic data and
so the same fit on any worker, in any order, with any thread count
(``tests/test_distributed.py`` checks the ``LocalCluster`` results equal the serial ones
bitwise).
"""

from __future__ import annotations

import difflib
import inspect
import math
import pickle
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence

import numpy as np

from . import Dataset, FitResult, _int, fit as _fit, set_threads
from .errors import DiffbvpError, InputError

__all__ = ["worker_env", "replicate_dataset", "bootstrap_fit", "bootstrap", "map_fits", "BootstrapResult"]

# replicates per worker above which a task fits several of them
_TASKS_PER_WORKER = 8


def worker_env(threads: int = 1) -> Dict[str, str]:
    """Environment for Dask workers: ``threads`` rayon threads per worker process
    (``RAYON_NUM_THREADS``), for ``LocalCluster(env=...)`` or a worker's environment."""
    return {"RAYON_NUM_THREADS": str(int(threads))}


def replicate_dataset(dataset: Dataset, base: FitResult, index: int, seed: int = 0,
                      noise: Optional[float] = None) -> Dataset:
    """Parametric-bootstrap replicate ``index``: the fitted model's diameters at the measurement
    positions with Gaussian relative noise of SD ``noise`` [-] (default: the fit's one noise
    level, else its RMS relative residual). Deterministic in (``seed``, ``index``)."""
    sigma = noise
    if sigma is None:
        sigma = base.noise_level if math.isfinite(base.noise_level) else base.rms
    rng = np.random.default_rng([int(seed), int(index)])
    measured = dataset.measurements()
    new = {}
    for name in dataset.names:
        if name not in measured:
            continue
        pos, d = measured[name]
        r = base.residual_profiles[name]["relative_residual"]
        model = d * (1.0 + r)  # relative residual = (d_model - d_meas) / d_meas
        new[name] = (pos, model * (1.0 + sigma * rng.standard_normal(len(pos))))
    return dataset.with_measurements(new)


def bootstrap_fit(dataset: Dataset, base: FitResult, index: int, seed: int = 0,
                  noise: Optional[float] = None, fit_options: Optional[Mapping[str, Any]] = None) -> FitResult:
    """Fits replicate ``index`` (:func:`replicate_dataset`) with ``fit_options`` (keyword
    arguments of :func:`diffbvp.fit`); the task a worker runs."""
    opts = {"error_budget": False}
    opts.update(fit_options or {})
    return _fit(replicate_dataset(dataset, base, index, seed, noise), **opts)


class BootstrapResult:
    """The fits of a parametric bootstrap: ``fits`` (list of :class:`FitResult` in replicate
    order, ``None`` where a fit failed), ``failed`` (index → error message, ``"Class:
    message"``) and ``errors`` (index → the exception the worker raised, with its class and
    attributes)."""

    def __init__(self, fits: List[Optional[FitResult]], failed: Dict[int, str],
                 errors: Optional[Dict[int, BaseException]] = None):
        self.fits = fits
        self.failed = failed
        self.errors = dict(errors or {})

    def estimates(self) -> Dict[str, np.ndarray]:
        """name → estimates of every replicate (nan where a fit failed)."""
        per_fit = [f.estimates() if f is not None else {} for f in self.fits]
        names: List[str] = []
        for e in per_fit:
            names.extend(k for k in e if k not in names)
        return {k: np.asarray([e[k].value if k in e else math.nan for e in per_fit], dtype=float)
                for k in names}

    def std(self) -> Dict[str, float]:
        """Bootstrap standard deviation of every estimate."""
        return {k: float(np.nanstd(v, ddof=1)) for k, v in self.estimates().items()}

    def __getstate__(self):
        return (self.fits, self.failed, self.errors)

    def __setstate__(self, s):
        self.fits, self.failed = s[0], s[1]
        self.errors = s[2] if len(s) > 2 else {}

    def __repr__(self) -> str:
        s = self.std()
        parts = ", ".join(f"sd({k})={v:.3g}" for k, v in s.items())
        return f"BootstrapResult({len(self.fits)} replicates, {len(self.failed)} failed, {parts})"


# the keyword arguments of diffbvp.fit that a fit_options dict may set
_FIT_ARGS = tuple(p for p in inspect.signature(_fit).parameters if p != "dataset")


def _check_fit_options(options: Any, name: str = "fit_options") -> Dict[str, Any]:
    """``options`` as a dict whose every key is a keyword argument of :func:`diffbvp.fit`;
    else an :class:`InputError` naming the key (and the closest argument)."""
    if options is None:
        return {}
    if not isinstance(options, Mapping):
        raise InputError(f"{name}: expected a dict of diffbvp.fit keyword arguments, "
                         f"got {type(options).__name__}")
    for key in options:
        if key not in _FIT_ARGS:
            close = difflib.get_close_matches(str(key), _FIT_ARGS, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise InputError(f"{name}: {key!r} is not an argument of diffbvp.fit{hint} "
                             f"(the arguments are {', '.join(_FIT_ARGS)})")
    return dict(options)


def _check_base(dataset: Any, base: Any) -> None:
    """``base`` is a fit of ``dataset``: the data digest its summary records (or, for a
    summary without one, its experiment names) matches the data set's."""
    if not isinstance(dataset, Dataset):
        raise InputError(f"dataset: expected a diffbvp.Dataset, got {type(dataset).__name__}")
    if not isinstance(base, FitResult):
        raise InputError(f"base: expected the diffbvp.FitResult of a fit of the data set, "
                         f"got {type(base).__name__}")
    recorded = base.summary.get("data_digest")
    if recorded:
        if recorded != dataset.data_digest:
            raise InputError(
                f"base: a fit of other data (its data digest {recorded} differs from the data "
                f"set's {dataset.data_digest}): the replicates would be simulated from another "
                "data set's fit; fit this data set first (diffbvp.fit(dataset))")
        return
    names = base.summary.get("experiments") or list(base.residual_profiles)
    if list(names) != list(dataset.names):
        raise InputError(f"base: a fit of the experiments {list(names)}, the data set has "
                         f"{list(dataset.names)}; fit this data set first")


def _check_threads(v: Optional[int]) -> Optional[int]:
    if v is None:
        return None
    t = _int(v, "threads_per_fit")
    if t < 1:
        raise InputError(f"threads_per_fit: give at least 1 thread, or None (got {t})")
    return t


def _check_batch(v: Optional[int]) -> Optional[int]:
    if v is None:
        return None
    b = _int(v, "batch_size")
    if b < 1:
        raise InputError(f"batch_size: give at least 1 replicate per task, or None (got {b})")
    return b


def _portable(e: BaseException) -> BaseException:
    """``e`` itself if it pickles (to travel back from a worker with its class and
    attributes), else a :class:`DiffbvpError` with its class name and message."""
    try:
        pickle.loads(pickle.dumps(e))
        return e
    except Exception:
        return DiffbvpError(f"{type(e).__name__}: {e}")


def _safe(fn, *args, **kwargs):
    try:
        return ("ok", fn(*args, **kwargs))
    except Exception as e:  # a failed replicate is reported, not fatal to the others
        return ("error", _portable(e))


def _use_threads(threads: Optional[int]) -> None:
    if threads is not None:
        set_threads(threads)


def _bootstrap_batch(dataset: Dataset, base: FitResult, indices: Sequence[int], seed: int,
                     noise: Optional[float], opts: Mapping[str, Any], threads: Optional[int]) -> List[Any]:
    """A task: the replicates ``indices`` one after another on ``threads`` Rust threads."""
    _use_threads(threads)
    return [_safe(bootstrap_fit, dataset, base, i, seed, noise, opts) for i in indices]


def _fit_batch(datasets: Sequence[Dataset], opts: Sequence[Mapping[str, Any]], threads: Optional[int]) -> List[Any]:
    _use_threads(threads)
    return [_safe(_fit, d, **o) for d, o in zip(datasets, opts)]


def _batches(count: int, client: Any, batch_size: Optional[int]) -> List[List[int]]:
    """Indices ``0..count`` cut into tasks of ``batch_size`` (default: one per task, or more
    beyond ``_TASKS_PER_WORKER`` tasks per worker)."""
    if batch_size is None:
        workers = max(1, len(client.scheduler_info().get("workers", {}))) if client is not None else 1
        batch_size = max(1, count // (_TASKS_PER_WORKER * workers))
    b = _check_batch(batch_size) or 1
    return [list(range(i, min(i + b, count))) for i in range(0, count, b)]


def bootstrap(client: Any, dataset: Dataset, base: FitResult, replicates: int = 100, seed: int = 0,
              noise: Optional[float] = None, fit_options: Optional[Mapping[str, Any]] = None,
              threads_per_fit: Optional[int] = 1, batch_size: Optional[int] = None) -> BootstrapResult:
    """Parametric bootstrap of ``base`` over the Dask ``client`` (``client=None``: serially
    in this process on all its threads, the reference for the distributed run). Each
    replicate's fit starts at ``base``'s estimate and skips the error budget unless
    ``fit_options`` (keyword arguments of :func:`diffbvp.fit`) says otherwise.

    ``threads_per_fit``: Rust threads of each worker process (default 1: one worker process
    per core; None leaves the workers' setting); ``batch_size``: replicates per task (see
    the module's notes on granularity).

    Everything is checked before anything is sent (see the module's notes): a typo in
    ``fit_options``, ``replicates < 1`` or a base fit of other data raise
    :class:`~diffbvp.errors.InputError` naming the argument. Repeated calls on one client
    work (each call scatters its data under keys of its own)."""
    _check_base(dataset, base)
    replicates = _int(replicates, "replicates")
    if replicates < 1:
        raise InputError(f"replicates: give at least 1 replicate (got {replicates})")
    seed = _int(seed, "seed")
    if seed < 0:
        raise InputError(f"seed: give a whole number >= 0 (got {seed})")
    if noise is not None:
        if isinstance(noise, bool) or not isinstance(noise, (int, float, np.floating, np.integer)) \
                or not (0.0 < float(noise) < 1.0):
            raise InputError(f"noise: a relative noise level in (0, 1) (got {noise!r}; 0.015 is 1.5 %)")
        noise = float(noise)
    threads_per_fit = _check_threads(threads_per_fit)
    batch_size = _check_batch(batch_size)
    opts: Dict[str, Any] = {"start": (base.n.value, base.kappa.value)}
    opts.update(_check_fit_options(fit_options))
    if client is None:
        outs = [_safe(bootstrap_fit, dataset, base, i, seed, noise, opts) for i in range(replicates)]
    else:
        batches = _batches(replicates, client, batch_size)
        # hash=False: keys of this call's own; with content-derived keys a second call on the
        # same data shares the first call's keys, whose release by the first call loses the
        # second call's dependencies (FutureCancelledError) or leaves it waiting
        ds_f, base_f = client.scatter([dataset, base], broadcast=True, hash=False)
        futures = [client.submit(_bootstrap_batch, ds_f, base_f, b, seed, noise, opts, threads_per_fit,
                                 pure=False)
                   for b in batches]
        outs = [o for batch in client.gather(futures) for o in batch]
        del futures, ds_f, base_f
    fits: List[Optional[FitResult]] = []
    failed: Dict[int, str] = {}
    errors: Dict[int, BaseException] = {}
    for i, (status, value) in enumerate(outs):
        if status == "ok":
            fits.append(value)
        else:
            fits.append(None)
            failed[i] = f"{type(value).__name__}: {value}"
            errors[i] = value
    return BootstrapResult(fits, failed, errors)


def map_fits(client: Any, datasets: Sequence[Dataset],
             fit_options: Optional[Sequence[Mapping[str, Any]]] = None,
             threads_per_fit: Optional[int] = 1, batch_size: Optional[int] = None) -> List[Any]:
    """Fits many data sets (e.g. a screening of materials) over ``client`` (None: serially).
    ``fit_options``: one dict of :func:`diffbvp.fit` keyword arguments per data set (default:
    none); ``threads_per_fit``, ``batch_size`` as for :func:`bootstrap`. Returns one
    :class:`FitResult` per data set, or the exception a failed fit raised (its class and
    attributes kept). Every data set and option dict is checked before anything is sent."""
    datasets = list(datasets)
    for i, d in enumerate(datasets):
        if not isinstance(d, Dataset):
            raise InputError(f"datasets[{i}]: expected a diffbvp.Dataset, got {type(d).__name__}")
    opts = list(fit_options) if fit_options is not None else [{}] * len(datasets)
    if len(opts) != len(datasets):
        raise InputError(f"fit_options: {len(datasets)} data sets but {len(opts)} option dicts")
    opts = [_check_fit_options(o, f"fit_options[{i}]") for i, o in enumerate(opts)]
    threads_per_fit = _check_threads(threads_per_fit)
    batch_size = _check_batch(batch_size)
    if client is None:
        outs = [_safe(_fit, d, **o) for d, o in zip(datasets, opts)]
    else:
        futures = [client.submit(_fit_batch, [datasets[i] for i in b], [opts[i] for i in b],
                                 threads_per_fit, pure=False)
                   for b in _batches(len(datasets), client, batch_size)]
        outs = [o for batch in client.gather(futures) for o in batch]
    return [v for _, v in outs]
