"""Many independent fits over a Dask cluster (``dask.distributed``).

The same code runs on one machine (a ``LocalCluster``) and on a cluster (a ``Client``
connected to its scheduler)::

    from dask.distributed import Client, LocalCluster
    import diffbvp
    from diffbvp.distributed import bootstrap, map_fits, worker_env

    ds = diffbvp.load("data/pmma7n_synthetic/experiments.toml")
    base = diffbvp.fit(ds)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      env=worker_env(threads=1)) as cluster, Client(cluster) as client:
        boot = bootstrap(client, ds, base, replicates=64, seed=1)
    boot.std()          # bootstrap standard errors of n, kappa, ...
    boot.fits[0]        # a FitResult, as diffbvp.fit returns

What travels: the data set (its TOML text and the measurement arrays, about 15 kB for the
shipped 9 experiments) goes to every worker once (``client.scatter(..., broadcast=True)``); a
task is then only (replicate index, seed, fit options), and its result a pickled
:class:`~diffbvp.results.FitResult` (report and arrays, about 60 kB with the fitted profiles,
less with ``profile_points=2``). One task is one fit (0.2 to 1 s on the shipped data): coarse
enough that scheduling costs (about 1 ms a task) do not matter, fine enough to balance. A
worker holds one data set and one fit at a time (a few MB). Each fit already solves its
experiments in parallel (rayon); on a machine with ``c`` cores run ``w`` worker processes with
``threads = c // w`` rayon threads each (:func:`worker_env`), so that workers do not
oversubscribe the cores.

Results are deterministic: the same replicate index and seed give the same synthetic data and
so the same fit on any worker, in any order (``tests/test_distributed.py`` checks the
``LocalCluster`` results equal the serial ones).
"""

from __future__ import annotations

import math
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence

import numpy as np

from . import Dataset, FitResult, fit as _fit

__all__ = ["worker_env", "replicate_dataset", "bootstrap_fit", "bootstrap", "map_fits", "BootstrapResult"]


def worker_env(threads: int = 1) -> Dict[str, str]:
    """Environment for Dask workers: ``threads`` rayon threads per worker process
    (``RAYON_NUM_THREADS``), for ``LocalCluster(env=...)`` or a worker's environment."""
    return {"RAYON_NUM_THREADS": str(int(threads))}


def replicate_dataset(dataset: Dataset, base: FitResult, index: int, seed: int = 0,
                      noise: Optional[float] = None) -> Dataset:
    """Parametric-bootstrap replicate ``index``: the fitted model's diameters at the measurement
    positions with Gaussian relative noise of SD ``noise`` [-] (default: the fit's noise level,
    else its RMS relative residual). Deterministic in (``seed``, ``index``)."""
    sigma = noise
    if sigma is None:
        nl = base.report.get("noise_level")
        sigma = float(nl) if nl is not None and math.isfinite(float(nl)) else base.rms
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
        out: Dict[str, List[float]] = {}
        for f in self.fits:
            if f is None:
                continue
            for k, (v, _) in f.estimates().items():
                out.setdefault(k, [])
        for k in out:
            out[k] = [f.estimates()[k][0] if f is not None else math.nan for f in self.fits]
        return {k: np.asarray(v) for k, v in out.items()}

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


def bootstrap(client: Any, dataset: Dataset, base: FitResult, replicates: int = 100, seed: int = 0,
              noise: Optional[float] = None, fit_options: Optional[Mapping[str, Any]] = None) -> BootstrapResult:
    """Parametric bootstrap of ``base`` over the Dask ``client`` (``client=None``: serially
    in this process, the reference for the distributed run). Start each replicate's fit at
    ``base``'s estimate unless ``fit_options`` says otherwise."""
    opts = {"start": (base.n, base.kappa)}
    opts.update(fit_options or {})
    if client is None:
        outs = [_safe(bootstrap_fit, dataset, base, i, seed, noise, opts) for i in range(replicates)]
    else:
        ds_f, base_f = client.scatter([dataset, base], broadcast=True)
        futures = client.map(_safe, [bootstrap_fit] * replicates, [ds_f] * replicates,
                             [base_f] * replicates, list(range(replicates)),
                             [seed] * replicates, [noise] * replicates, [opts] * replicates,
                             pure=False)
        outs = client.gather(futures)
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
             fit_options: Optional[Sequence[Mapping[str, Any]]] = None) -> List[Any]:
    """Fits many data sets (e.g. a screening of materials) over ``client`` (None: serially).
    ``fit_options``: one dict of :func:`diffbvp.fit` keyword arguments per data set (default:
    none). Returns one :class:`FitResult` per data set, or the exception of a failed fit."""
    opts = list(fit_options) if fit_options is not None else [{}] * len(datasets)
    if len(opts) != len(datasets):
        raise ValueError(f"{len(datasets)} data sets but {len(opts)} option dicts")
    if client is None:
        outs = [_safe(_fit, d, **o) for d, o in zip(datasets, opts)]
    else:
        futures = [client.submit(_safe, _fit, d, pure=False, **o) for d, o in zip(datasets, opts)]
        outs = client.gather(futures)
    from .errors import DiffbvpError
    return [v if s == "ok" else DiffbvpError(v) for s, v in outs]
