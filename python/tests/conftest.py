"""Shared fixtures: the repository's data, the `rheometer` binary of the same tree, a scratch
directory under target/ (nothing is left in /tmp)."""

from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
from pathlib import Path

import pytest

import diffbvp

ROOT = Path(__file__).resolve().parents[2]
PMMA = ROOT / "data" / "pmma7n_synthetic" / "experiments.toml"
RADIATION = ROOT / "data" / "hidden_radiation" / "experiments.toml"
SCRATCH = ROOT / "target" / "pytest-scratch"

# keys that differ between two runs of the same computation
VOLATILE = {"wall_time_s", "stage_times"}


def assert_same(ref, got, path="", rel=1e-12):
    """Structural equality, floats within `rel` (relative, absolute below 1), wall times
    ignored."""
    if isinstance(ref, dict):
        assert isinstance(got, dict), path
        assert ref.keys() == got.keys(), (path, set(ref) ^ set(got))
        for k in ref:
            if k not in VOLATILE:
                assert_same(ref[k], got[k], f"{path}.{k}", rel)
    elif isinstance(ref, list):
        assert isinstance(got, list) and len(ref) == len(got), path
        for i, (a, b) in enumerate(zip(ref, got)):
            assert_same(a, b, f"{path}[{i}]", rel)
    elif isinstance(ref, float) or isinstance(got, float):
        a, b = float(ref), float(got)
        if math.isnan(a) or math.isnan(b):
            assert math.isnan(a) and math.isnan(b), (path, a, b)
        else:
            assert abs(a - b) <= rel * max(1.0, abs(a)), (path, a, b)
    else:
        assert ref == got, (path, ref, got)


@pytest.fixture(scope="session")
def rheometer() -> Path:
    """The `rheometer` binary built from this tree (built here if missing)."""
    exe = Path(os.environ.get("DIFFBVP_RHEOMETER", ROOT / "target" / "release" / "rheometer"))
    if not exe.exists():
        subprocess.run(["cargo", "build", "--release", "--bin", "rheometer"], cwd=ROOT, check=True)
    return exe


@pytest.fixture(scope="session")
def scratch():
    """A scratch directory under target/, removed at the end."""
    SCRATCH.mkdir(parents=True, exist_ok=True)
    yield SCRATCH
    shutil.rmtree(SCRATCH, ignore_errors=True)


def run_cli(exe: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(exe), "--quiet", *args], cwd=ROOT, capture_output=True, text=True)


def cli_json(exe: Path, scratch: Path, name: str, *args: str) -> dict:
    out = scratch / f"{name}.json"
    p = run_cli(exe, *args, "--json", str(out))
    assert p.returncode == 0, p.stderr
    return json.loads(out.read_text())


@pytest.fixture(scope="session")
def pmma() -> diffbvp.Dataset:
    return diffbvp.load(PMMA)


@pytest.fixture(scope="session")
def pmma_fit(pmma) -> diffbvp.FitResult:
    return diffbvp.fit(pmma)


@pytest.fixture(scope="session")
def radiation_diagnosis() -> diffbvp.Diagnosis:
    return diffbvp.diagnose(diffbvp.load(RADIATION))
