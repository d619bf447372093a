"""The numbers from Python equal those of the `rheometer` program built from the same tree
(within 1e-12; wall times excluded)."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

import diffbvp
from conftest import PMMA, RADIATION, assert_same, cli_json, run_cli


def test_fit_equals_cli_fit_json(rheometer, scratch, pmma_fit):
    ref = cli_json(rheometer, scratch, "fit", "fit", str(PMMA))
    # the whole FitSummary: estimates, covariance, noise, solver record, warnings, budget
    assert_same(ref, pmma_fit.summary)
    n, k = pmma_fit.n, pmma_fit.kappa
    assert (n.value, n.stderr, tuple(n.ci95)) == (ref["n"]["value"], ref["n"]["stderr"], tuple(ref["n"]["ci95"]))
    assert pmma_fit.K.value == pytest.approx(np.exp(k.value), rel=1e-15) and pmma_fit.K.unit == "Pa"
    assert pmma_fit.noise_level == ref["noise"]["level"]
    assert pmma_fit.warnings == ref["warnings"]
    # the README's numbers
    assert round(n.value, 3) == 0.804 and round(k.value, 2) == 11.63
    assert round(n.stderr, 3) == 0.007 and round(k.stderr, 2) == 0.09


def test_fit_with_effect_and_paper_estimator_equal_cli(rheometer, scratch):
    ref = cli_json(rheometer, scratch, "fit_rad", "fit", str(RADIATION), "--with", "radiation")
    got = diffbvp.fit(RADIATION, effects=["radiation"])
    assert_same(ref, got.summary)
    assert got.effects[0]["effect"] == "radiation"
    assert got.estimates()["radiation"].value == ref["effects"][0]["strength"]["value"]
    ref = cli_json(rheometer, scratch, "fit_paper", "fit", str(PMMA), "--estimator", "paper",
                   "--start", "0.5,11.51")
    assert_same(ref, diffbvp.fit(PMMA, estimator="paper", start=(0.5, 11.51)).summary)


def test_fit_arrays_are_consistent_with_the_summary(pmma_fit, pmma):
    # covariance diagonal = squared standard errors of n and kappa
    names = pmma_fit.covariance_names
    c = pmma_fit.covariance
    assert names[:2] == ["n", "kappa"] and c.shape == (len(names), len(names))
    assert np.sqrt(c[0, 0]) == pytest.approx(pmma_fit.n.stderr, rel=1e-12)
    assert np.sqrt(c[1, 1]) == pytest.approx(pmma_fit.kappa.stderr, rel=1e-12)
    assert np.array_equal(c, c.T)
    # residuals: RMS over all points equals the report's
    t = pmma_fit.residuals_table()
    assert np.sqrt(np.mean(t["relative_residual"] ** 2)) == pytest.approx(pmma_fit.rms, rel=1e-12)
    assert set(t["experiment"]) == set(pmma.names)
    # the fitted profiles end at the fitted take-up diameter, start at the die
    p = pmma_fit.profiles[pmma.names[0]]
    assert p["position_m"][0] == 0.0 and p["diameter_m"][0] == pytest.approx(1.134e-3, rel=1e-9)


def test_diagnosis_equals_cli_diagnose_json(rheometer, scratch, radiation_diagnosis):
    ref = cli_json(rheometer, scratch, "diagnose", "diagnose", str(RADIATION))
    d = radiation_diagnosis
    assert_same(ref, d.diagnosis)
    assert d.most_likely_missing == "radiation" and d.found[0] == "radiation"
    assert d.verdict["kind"] == ref["verdict"]["kind"]
    # candidates with their refit summaries, as FitResult values
    named = d.candidate("radiation")
    assert named is not None and named.refit is not None
    assert_same(ref["candidates"][[c["effect"] for c in ref["candidates"]].index("radiation")]["refit"],
                named.refit.summary)
    assert named.strength.value == named.refit.estimates()["radiation"].value
    assert 0.0 <= named.false_alarm <= 1.0
    assert d.final_fit is not None and d.final_fit.effects[0]["effect"] == "radiation"
    assert_same(ref["base_fit"], d.base_fit.summary)
    # the library's reasons, in the CLI's JSON as in Python's: the law with radiation is a
    # result (explained), the user's model without it is not
    assert ref["law_not_a_result"] is None and d.law_is_a_result and d.final_fit.law_is_a_result
    assert "radiation" in ref["base_law_not_a_result"]
    assert d.base_fit.law_not_a_result == ref["base_law_not_a_result"]
    assert not d.base_fit.law_is_a_result and "NOT A RESULT" in repr(d.base_fit)
    # the residual arrays belong to the base and the final fit
    base_rms = np.sqrt(np.mean(d.base_fit.residuals_table()["relative_residual"] ** 2))
    assert base_rms == pytest.approx(d.base_fit.rms, rel=1e-12)
    final_rms = np.sqrt(np.mean(d.final_fit.residuals_table()["relative_residual"] ** 2))
    assert final_rms == pytest.approx(d.final_fit.rms, rel=1e-12)


def test_compare_equals_cli_compare_json(rheometer, scratch, pmma_fit):
    fit_json = scratch / "fit_for_compare.json"
    fit_json.write_text(json.dumps(pmma_fit.summary))
    out = scratch / "cmp"
    p = run_cli(rheometer, "compare", str(PMMA), "--fit", str(fit_json), "--out", str(out))
    assert p.returncode == 0, p.stderr
    ref = json.loads((out / "compare.json").read_text())
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        got = diffbvp.compare(PMMA, pmma_fit)
    # one warning per warning the fit carries (the CLI prints them on stderr)
    assert len([w for w in caught if "carries a warning" in str(w.message)]) == len(pmma_fit.warnings)
    assert_same(ref, got._data)
    assert got.text.strip() == p.stdout.strip()
    # compared as it is, the comparison keeps the fit's one noise level
    assert got.noise_level == pmma_fit.noise_level
    # the JSON file read as a dict gives the same comparison
    again = diffbvp.compare(PMMA, json.loads(fit_json.read_text()))
    assert_same(got._data, again._data, rel=0.0)


def test_landscape_equals_cli_csv(rheometer, scratch):
    out = scratch / "land"
    p = run_cli(rheometer, "landscape", str(PMMA), "--grid", "5x3", "--n-range", "0.2,1",
                "--kappa-range", "10,13", "--out", str(out))
    assert p.returncode == 0, p.stderr
    lines = (out / "landscape.csv").read_text().splitlines()
    assert lines[0] == "n,kappa,cost,status,tol"
    rows = [l.split(",") for l in lines[1:]]
    got = diffbvp.landscape(PMMA, grid=(5, 3), n_range=(0.2, 1.0), kappa_range=(10.0, 13.0))
    t = got.table()
    assert len(rows) == 15 == len(t["cost"]) == len(t["tol"])
    assert got.tol == 1e-4 and got.point_tol.shape == (3, 5)
    for r, n, k, c, tol in zip(rows, t["n"], t["kappa"], t["cost"], t["tol"]):
        assert float(r[0]) == n and float(r[1]) == k
        assert float(r[2]) == pytest.approx(c, rel=1e-12)
        assert float(r[4]) == tol or (np.isnan(tol) and r[4] == "NaN")
    # the minimum's neighbourhood at --tol, points far from it (n = 0.2) at ten times --tol
    assert set(float(r[4]) for r in rows if r[3] == "ok") == {1e-4, 1e-3}
