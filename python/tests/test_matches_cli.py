"""The numbers from Python equal those of the `rheometer` program built from the same tree
(within 1e-12; wall times excluded)."""

from __future__ import annotations

import json

import numpy as np
import pytest

import diffbvp
from conftest import PMMA, RADIATION, assert_same, cli_json, run_cli


def test_fit_equals_cli_fit_json(rheometer, scratch, pmma_fit):
    ref = cli_json(rheometer, scratch, "fit", "fit", str(PMMA))
    assert_same(ref, pmma_fit.report)
    # the README's numbers
    assert round(pmma_fit.n, 3) == 0.804 and round(pmma_fit.kappa, 2) == 11.63
    assert round(pmma_fit.stderr_n, 3) == 0.007 and round(pmma_fit.stderr_kappa, 2) == 0.09


def test_fit_with_effect_and_paper_estimator_equal_cli(rheometer, scratch):
    ref = cli_json(rheometer, scratch, "fit_rad", "fit", str(RADIATION), "--with", "radiation")
    got = diffbvp.fit(RADIATION, effects=["radiation"])
    assert_same(ref, got.report)
    assert got.effects[0]["effect"] == "radiation"
    ref = cli_json(rheometer, scratch, "fit_paper", "fit", str(PMMA), "--estimator", "paper",
                   "--start", "0.5,11.51")
    assert_same(ref, diffbvp.fit(PMMA, estimator="paper", start=(0.5, 11.51)).report)


def test_fit_arrays_are_consistent_with_the_report(pmma_fit, pmma):
    # covariance diagonal = squared standard errors of n and kappa
    names = pmma_fit.parameter_names
    c = pmma_fit.covariance
    assert names[:2] == ["n", "kappa"] and c.shape == (len(names), len(names))
    assert np.sqrt(c[0, 0]) == pytest.approx(pmma_fit.stderr_n, rel=1e-12)
    assert np.sqrt(c[1, 1]) == pytest.approx(pmma_fit.stderr_kappa, rel=1e-12)
    # residuals: RMS over all points equals the report's
    t = pmma_fit.residuals_table()
    assert np.sqrt(np.mean(t["relative_residual"] ** 2)) == pytest.approx(pmma_fit.rms, rel=1e-12)
    assert set(t["experiment"]) == set(pmma.names)
    # the fitted profiles end at the fitted take-up diameter, start at the die
    p = pmma_fit.profiles[pmma.names[0]]
    assert p["position_m"][0] == 0.0 and p["diameter_m"][0] == pytest.approx(1.134e-3, rel=1e-9)


def test_diagnosis_equals_cli_diagnose_json(rheometer, scratch, radiation_diagnosis):
    out = scratch / "diag"
    ref = cli_json(rheometer, scratch, "diagnose", "diagnose", str(RADIATION), "--out", str(out))
    assert_same(ref, radiation_diagnosis._data)
    assert radiation_diagnosis.most_likely_missing == "radiation"
    assert radiation_diagnosis.best_fit is not None
    assert radiation_diagnosis.best_fit.effects[0]["effect"] == "radiation"


def test_compare_equals_cli_compare_json(rheometer, scratch, pmma_fit):
    fit_json = scratch / "fit_for_compare.json"
    fit_json.write_text(json.dumps(pmma_fit.report))
    out = scratch / "cmp"
    p = run_cli(rheometer, "compare", str(PMMA), "--fit", str(fit_json), "--out", str(out))
    assert p.returncode == 0, p.stderr
    ref = json.loads((out / "compare.json").read_text())
    with pytest.warns(RuntimeWarning, match="carries a warning"):
        got = diffbvp.compare(PMMA, pmma_fit)
    assert_same(ref, got._data)
    assert got.text.strip() == p.stdout.strip()


def test_landscape_equals_cli_csv(rheometer, scratch):
    out = scratch / "land"
    p = run_cli(rheometer, "landscape", str(PMMA), "--grid", "4x3", "--n-range", "0.6,1",
                "--kappa-range", "10,13", "--out", str(out))
    assert p.returncode == 0, p.stderr
    rows = [l.split(",") for l in (out / "landscape.csv").read_text().splitlines()[1:]]
    got = diffbvp.landscape(PMMA, grid=(4, 3), n_range=(0.6, 1.0), kappa_range=(10.0, 13.0))
    t = got.table()
    assert len(rows) == 12 == len(t["cost"])
    for r, n, k, c in zip(rows, t["n"], t["kappa"], t["cost"]):
        assert float(r[0]) == n and float(r[1]) == k
        assert float(r[2]) == pytest.approx(c, rel=1e-12)
