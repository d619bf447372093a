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
shipped 9 experiments) and the base fit go to every worker once
(``client.scatter(..., broadcast=True)``); a task is then only (replicate indices, seed, fit
options), and its result the pickled :class:`~diffbvp.results.FitResult` of each replicate
(the ``FitSummary`` dict and the residual arrays, about 40 kB with ``profile_points=2``, plus
about 50 kB per 100 profile points).

**Granularity.** One fit takes 0.2 to 1 s on the shipped data (without / with the error
budget); a task is ``batch_size`` fits (default: one, or more when there are more than 8
replicates per worker), so that the scheduler's cost per task (about 1 ms) stays far below the
work and the last tasks still balance. A worker holds one data set and one fit at a time (a
few MB).

Results are deterministic: the same replicate index and seed give the same synthetic data and
so the same fit on any worker, in any order, with any thread count
(``tests/test_distributed.py`` checks the ``LocalCluster`` results equal the serial ones
bitwise).
"""

from __future__ import annotations

import math
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence

import numpy as np

from . import Dataset, FitResult, fit as _fit, set_threads

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
    order), ``failed`` (index → error message)."""

    def __init__(self, fits: List[Optional[FitResult]], failed: Dict[int, str]):
        self.fits = fits
        self.failed = failed

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
        return (self.fits, self.failed)

    def __setstate__(self, s):
        self.fits, self.failed = s

    def __repr__(self) -> str:
        s = self.std()
        parts = ", ".join(f"sd({k})={v:.3g}" for k, v in s.items())
        return f"BootstrapResult({len(self.fits)} replicates, {len(self.failed)} failed, {parts})"


def _safe(fn, *args, **kwargs):
    try:
        return ("ok", fn(*args, **kwargs))
    except Exception as e:  # a failed replicate is reported, not fatal to the others
        return ("error", f"{type(e).__name__}: {e}")


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
    if int(batch_size) < 1:
        raise ValueError(f"batch_size must be at least 1 (got {batch_size})")
    b = int(batch_size)
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
    the module's notes on granularity)."""
    opts = {"start": (base.n.value, base.kappa.value)}
    opts.update(fit_options or {})
    if client is None:
        outs = [_safe(bootstrap_fit, dataset, base, i, seed, noise, opts) for i in range(replicates)]
    else:
        ds_f, base_f = client.scatter([dataset, base], broadcast=True)
        futures = [client.submit(_bootstrap_batch, ds_f, base_f, b, seed, noise, opts, threads_per_fit,
                                 pure=False)
                   for b in _batches(replicates, client, batch_size)]
        outs = [o for batch in client.gather(futures) for o in batch]
    fits: List[Optional[FitResult]] = []
    failed: Dict[int, str] = {}
    for i, (status, value) in enumerate(outs):
        if status == "ok":
            fits.append(value)
        else:
            fits.append(None)
            failed[i] = value
    return BootstrapResult(fits, failed)


def map_fits(client: Any, datasets: Sequence[Dataset],
             fit_options: Optional[Sequence[Mapping[str, Any]]] = None,
             threads_per_fit: Optional[int] = 1, batch_size: Optional[int] = None) -> List[Any]:
    """Fits many data sets (e.g. a screening of materials) over ``client`` (None: serially).
    ``fit_options``: one dict of :func:`diffbvp.fit` keyword arguments per data set (default:
    none); ``threads_per_fit``, ``batch_size`` as for :func:`bootstrap`. Returns one
    :class:`FitResult` per data set, or the exception of a failed fit."""
    opts = list(fit_options) if fit_options is not None else [{}] * len(datasets)
    if len(opts) != len(datasets):
        raise ValueError(f"{len(datasets)} data sets but {len(opts)} option dicts")
    if client is None:
        outs = [_safe(_fit, d, **o) for d, o in zip(datasets, opts)]
    else:
        futures = [client.submit(_fit_batch, [datasets[i] for i in b], [opts[i] for i in b],
                                 threads_per_fit, pure=False)
                   for b in _batches(len(datasets), client, batch_size)]
        outs = [o for batch in client.gather(futures) for o in batch]
    from .errors import DiffbvpError
    return [v if s == "ok" else DiffbvpError(v) for s, v in outs]
