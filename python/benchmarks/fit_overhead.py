"""A fit from Python against the same fit from Rust (python/examples/fit_timing.rs), both timed
in-process, medians over RUNS runs each, alternating blocks so that load changes on a shared
machine hit both alike.

    python python/benchmarks/fit_overhead.py [RUNS]
"""
import statistics
import subprocess
import sys
import time
from pathlib import Path

import diffbvp

root = Path(__file__).resolve().parents[2]
runs = int(sys.argv[1]) if len(sys.argv) > 1 else 20
data = root / "data" / "pmma7n_synthetic" / "experiments.toml"
ds = diffbvp.load(data)
diffbvp.fit(ds)  # warm-up (imports, first allocation)
exe = root / "target" / "release" / "examples" / "fit_timing"
if not exe.exists():
    subprocess.run(["cargo", "build", "--release", "-p", "diffbvp-python", "--example", "fit_timing"],
                   cwd=root, check=True)
py_times, rs_times = [], []
block = 5
for _ in range(0, runs, block):
    for _ in range(block):
        t0 = time.perf_counter()
        f = diffbvp.fit(ds)
        py_times.append(time.perf_counter() - t0)
    # one more run than kept: the first of a process warms up (as diffbvp.fit above)
    out = subprocess.run([str(exe), str(block + 1), str(data)], cwd=root, capture_output=True, text=True, check=True)
    rs_times += [float(l.split(":")[1].split()[0]) for l in out.stdout.splitlines() if l.startswith("run")][1:]
mp, mr = statistics.median(py_times), statistics.median(rs_times)
print(f"python: median {mp:.4f} s over {len(py_times)} fits (n={f.n.value:.6f}, kappa={f.kappa.value:.6f})")
print(f"rust:   median {mr:.4f} s over {len(rs_times)} fits")
print(f"python / rust = {mp / mr:.3f}")
