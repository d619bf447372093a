"""Ctrl-C (SIGINT) interrupts a long call: KeyboardInterrupt, promptly."""

from __future__ import annotations

import signal
import subprocess
import sys
import time

from conftest import PMMA, ROOT

# the child restores Python's own Ctrl-C handler: a shell that starts the tests in the
# background passes SIGINT on as ignored, and Python then installs no handler at all
SCRIPT = f"""
import signal, sys, time, diffbvp
signal.signal(signal.SIGINT, signal.default_int_handler)
ds = diffbvp.load({str(PMMA)!r})
print("ready", flush=True)
t0 = time.time()
try:
    diffbvp.{{call}}
except KeyboardInterrupt:
    print("interrupted after", time.time() - t0, flush=True)
    sys.exit(3)
print("finished", flush=True)
"""


def _interrupt(call: str, after: float = 1.0) -> tuple:
    p = subprocess.Popen([sys.executable, "-c", SCRIPT.replace("{call}", call)], cwd=ROOT,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "ready"
    time.sleep(after)
    t = time.time()
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=120)
    return p.returncode, out, err, time.time() - t


def test_ctrl_c_stops_a_landscape():
    code, out, err, dt = _interrupt("landscape(ds, grid=(60, 60), tol=1e-6)")
    assert code == 3, (out, err)
    assert dt < 10, dt


def test_ctrl_c_stops_a_diagnose():
    # data/two_effects (several seconds of search), not the shipped set: its diagnosis ends in
    # about a second on a fast 2-core machine, before a signal sent after 2 s arrives
    two = ROOT / "data" / "two_effects" / "experiments.toml"
    code, out, err, dt = _interrupt(f"diagnose(diffbvp.load({str(two)!r}))", after=1.0)
    assert code == 3, (out, err)
    assert dt < 20, dt
