"""Speed-up of a parametric bootstrap over a Dask LocalCluster against the serial run.

    python python/benchmarks/dask_speedup.py [REPLICATES] [WORKERS] [ROUNDS]

Serial: the replicates one after another in this process, each fit on all cores (rayon).
Dask: WORKERS worker processes with one task thread each, each fit on cores // WORKERS Rust
threads (``threads_per_fit``). ROUNDS alternating rounds (serial, Dask, serial, ...) so that a
load change on a shared machine hits both alike; the medians are compared. Both produce the
same fits (checked bitwise). BUDGET=1 fits with the error budget (larger tasks)."""
import os
import statistics
import sys
import time
from pathlib import Path

import diffbvp
from diffbvp.distributed import bootstrap

root = Path(__file__).resolve().parents[2]
replicates = int(sys.argv[1]) if len(sys.argv) > 1 else 16
workers = int(sys.argv[2]) if len(sys.argv) > 2 else 2
rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 3
ds = diffbvp.load(root / "data" / "pmma7n_synthetic" / "experiments.toml")
base = diffbvp.fit(ds)
opts = {"profile_points": 2, "error_budget": os.environ.get("BUDGET") == "1"}

if __name__ == "__main__":
    from dask.distributed import Client, LocalCluster

    cores = os.cpu_count() or 1
    threads = max(1, cores // workers)
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                      local_directory=str(root / "target" / "dask-bench")) as cluster, \
            Client(cluster) as client:
        # workers import the package and run one fit before timing
        bootstrap(client, ds, base, replicates=workers, seed=99, fit_options=opts, threads_per_fit=threads)
        ts, tp, same = [], [], True
        for _ in range(rounds):
            t0 = time.perf_counter()
            serial = bootstrap(None, ds, base, replicates=replicates, seed=3, fit_options=opts)
            ts.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            par = bootstrap(client, ds, base, replicates=replicates, seed=3, fit_options=opts,
                            threads_per_fit=threads)
            tp.append(time.perf_counter() - t0)
            same = same and all(a.n == b.n and a.kappa == b.kappa and (a.covariance == b.covariance).all()
                                for a, b in zip(serial.fits, par.fits))
    ms, mp = statistics.median(ts), statistics.median(tp)
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"{replicates} bootstrap fits (error budget: {opts['error_budget']}), {cores} cores, "
          f"load average {load:.1f}:")
    print(f"  serial, {diffbvp.threads()} Rust threads: " + ", ".join(f"{t:.2f}" for t in ts) + f" s (median {ms:.2f} s)")
    print(f"  Dask {workers} workers x {threads} Rust threads: " + ", ".join(f"{t:.2f}" for t in tp)
          + f" s (median {mp:.2f} s)")
    print(f"  speed-up {ms / mp:.2f}; identical results: {same}")
    print(serial)
