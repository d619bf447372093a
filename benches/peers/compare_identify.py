#!/usr/bin/env python3
"""Whole-process timing of `rheometer fit` against the CasADi identification peer, in alternation.

Runs, ROUNDS times each and alternating (ours, peer, ours, peer, ...), the two commands

    ours: target/release/rheometer fit EXPERIMENTS --json target/compare-identify/ours.json
    peer: PYTHON benches/peers/casadi_identify.py EXPERIMENTS --json target/compare-identify/peer.json

as separate processes, and prints each one's wall times [s], their medians [s] and the ratio of
the medians peer/ours. Alternating spreads the load of a shared machine over both. It then
compares the estimates of the last runs: n, kappa and the cost J of both, and the differences in
our standard errors. Whole process means everything a user waits for: start-up, reading the
data, the fit, and for ours also the report it prints by default (start heuristic, profile
likelihood intervals, Newtonian test, error budget, flow curve); the peer's output is only the
fit. Build ours first (`cargo build --release`); PYTHON defaults to the venv of
`benches/peers/README.md`. Standard library only; the exit code is 0 only if every run succeeded.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def run(cmd):
    """Wall time [s] of one process; exits with its output if it fails."""
    t0 = time.perf_counter()
    p = subprocess.run(cmd, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    dt = time.perf_counter() - t0
    if p.returncode != 0:
        sys.stderr.write(f"failed ({p.returncode}): {' '.join(cmd)}\n{p.stdout[-2000:]}\n{p.stderr[-2000:]}\n")
        sys.exit(1)
    return dt


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("experiments", nargs="?", default="data/pmma7n_synthetic/experiments.toml")
    ap.add_argument("--rounds", type=int, default=5, help="runs of each (default 5, at least 1)")
    ap.add_argument("--python", default=os.path.join(ROOT, "target/peer-venv/bin/python"),
                    help="Python with casadi and numpy (default: target/peer-venv/bin/python)")
    ap.add_argument("--rheometer", default=os.path.join(ROOT, "target/release/rheometer"))
    a = ap.parse_args()
    out = os.path.join(ROOT, "target", "compare-identify")
    os.makedirs(out, exist_ok=True)
    ours_json, peer_json = os.path.join(out, "ours.json"), os.path.join(out, "peer.json")
    ours = [a.rheometer, "fit", a.experiments, "--json", ours_json]
    peer = [a.python, os.path.join(ROOT, "benches/peers/casadi_identify.py"), a.experiments, "--json", peer_json]
    t_ours, t_peer = [], []
    for k in range(max(1, a.rounds)):
        t_ours.append(run(ours))
        t_peer.append(run(peer))
        print(f"round {k + 1}: ours {t_ours[-1]:.3f} s, peer {t_peer[-1]:.3f} s", flush=True)
    mo, mp = statistics.median(t_ours), statistics.median(t_peer)
    print(f"\nwhole process, median of {len(t_ours)} alternating runs each (os.cpu_count() = {os.cpu_count()}):")
    print(f"  ours (rheometer fit)      {mo:8.3f} s   [{min(t_ours):.3f} .. {max(t_ours):.3f}]")
    print(f"  peer (CasADi + IPOPT)     {mp:8.3f} s   [{min(t_peer):.3f} .. {max(t_peer):.3f}]")
    print(f"  ratio peer/ours           {mp / mo:8.1f}")
    with open(ours_json) as f:
        o = json.load(f)
    with open(peer_json) as f:
        p = json.load(f)
    sn, sk = o["n"]["stderr"], o["kappa"]["stderr"]
    print("\nestimates (last runs):")
    print(f"  ours: n = {o['n']['value']:.6f} ± {sn:.4f}, kappa = {o['kappa']['value']:.6f} ± {sk:.4f}, "
          f"J = {o['cost']:.7e}; fit alone {o['solver']['wall_time_s']:.3f} s")
    print(f"  peer: n = {p['n']:.6f}, kappa = {p['kappa']:.6f}, J = {p['cost']:.7e}; "
          f"IPOPT {p['ipopt_status']} in {p['ipopt_iterations']} iterations, build {p['build_s']:.3f} s, "
          f"solve {p['solve_s']:.3f} s")
    print(f"  peer - ours: n {(p['n'] - o['n']['value']) / sn:+.4f} SE, kappa {(p['kappa'] - o['kappa']['value']) / sk:+.4f} SE, "
          f"J {100 * (p['cost'] - o['cost']) / o['cost']:+.4f} %")
    return 0 if p["success"] else 1


if __name__ == "__main__":
    sys.exit(main())
