"""Speed-up of a parametric bootstrap over a Dask LocalCluster against the serial run.

    python python/benchmarks/dask_speedup.py [REPLICATES] [WORKERS]

Serial: the replicates one after another in this process (each fit solves its experiments in
parallel on all cores with rayon). Dask: WORKERS worker processes, one task thread and
cores/WORKERS rayon threads each. Both produce the same fits (checked)."""
import os
import sys
import time
from pathlib import Path

import diffbvp
from diffbvp.distributed import bootstrap, worker_env

root = Path(__file__).resolve().parents[2]
replicates = int(sys.argv[1]) if len(sys.argv) > 1 else 16
workers = int(sys.argv[2]) if len(sys.argv) > 2 else 2
ds = diffbvp.load(root / "data" / "pmma7n_synthetic" / "experiments.toml")
base = diffbvp.fit(ds)
opts = {"profile_points": 2, "error_budget": os.environ.get("BUDGET") == "1"}

if __name__ == "__main__":
    from dask.distributed import Client, LocalCluster

    t0 = time.perf_counter()
    serial = bootstrap(None, ds, base, replicates=replicates, seed=3, fit_options=opts)
    ts = time.perf_counter() - t0
    threads = max(1, (os.cpu_count() or 1) // workers)
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                      env=worker_env(threads), local_directory=str(root / "target" / "dask-bench")) as cluster, \
            Client(cluster) as client:
        client.run(lambda: __import__("diffbvp"))  # workers import the package before timing
        t0 = time.perf_counter()
        par = bootstrap(client, ds, base, replicates=replicates, seed=3, fit_options=opts)
        tp = time.perf_counter() - t0
    same = all(a.n == b.n and a.kappa == b.kappa for a, b in zip(serial.fits, par.fits))
    print(f"{replicates} bootstrap fits: serial {ts:.2f} s, Dask {workers} workers x {threads} rayon "
          f"threads {tp:.2f} s, speed-up {ts / tp:.2f}; identical results: {same}")
    print(serial)
