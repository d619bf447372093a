"""Arrays in, arrays out; pickling; sensitivities against finite differences."""

from __future__ import annotations

import json
import pickle

import numpy as np
import pytest

import diffbvp
from conftest import PMMA, assert_same
from test_errors import _material


def _from_arrays(ds: diffbvp.Dataset) -> diffbvp.Dataset:
    meas = ds.measurements()
    exps = []
    for c in ds.conditions():
        e = {k: v for k, v in c.items() if k not in ("line", "data")}
        e["positions_m"], e["diameters_m"] = meas[c["name"]]
        exps.append(e)
    return diffbvp.Dataset.from_arrays(_material(), exps)


def test_dataset_from_arrays_fits_as_the_file(pmma, pmma_fit):
    ds = _from_arrays(pmma)
    assert ds.names == pmma.names and ds.path == "<conditions>"
    for k, (p, d) in pmma.measurements().items():
        p2, d2 = ds.measurements()[k]
        assert np.array_equal(p, p2) and np.array_equal(d, d2)
    assert_same(pmma_fit.summary, diffbvp.fit(ds).summary)


def test_pickle_round_trips(pmma, pmma_fit, radiation_diagnosis):
    for obj in (pmma_fit, radiation_diagnosis, diffbvp.simulate(pmma, 0.8, 11.7, points=5, take_up_from_data=True),
                pmma_fit.n, radiation_diagnosis.candidates[0]):
        back = pickle.loads(pickle.dumps(obj))
        assert type(back) is type(obj) and back == obj and repr(back) == repr(obj)
    ds = pickle.loads(pickle.dumps(pmma))
    assert ds.toml == pmma.toml and ds.names == pmma.names
    for k, (p, d) in pmma.measurements().items():
        assert np.array_equal(ds.measurements()[k][1], d)
    assert pickle.loads(pickle.dumps(radiation_diagnosis)).final_fit == radiation_diagnosis.final_fit


def test_repr_and_to_dict(pmma_fit, radiation_diagnosis):
    r = repr(pmma_fit)
    assert r.startswith("FitResult(n=0.804±0.007, kappa=11.63±0.09, rms=1.7 %")
    assert repr(pmma_fit.n) == "Estimate(n=0.804±0.007)" and float(pmma_fit.n) == pmma_fit.n.value
    assert str(pmma_fit.K).endswith(" Pa")
    d = pmma_fit.to_dict()
    assert d["n"] == pmma_fit.n.to_dict() and isinstance(d["covariance"]["matrix"], list)
    import json
    json.dumps(d)  # plain data
    json.dumps(radiation_diagnosis.to_dict())
    r = repr(radiation_diagnosis)
    assert "radiation" in r and radiation_diagnosis.verdict["kind"] in r
    assert "radiation" in repr(radiation_diagnosis.candidate("radiation"))
    # where the diagnosis' time went: the stages add up to its wall time
    times = radiation_diagnosis.stage_times
    assert set(times) == {"fits_s", "linearised_s", "scans_s", "refits_s", "pairs_s", "rest_s"}
    assert times["scans_s"] > 0 and all(v >= 0 for v in times.values())
    wall = radiation_diagnosis.to_dict()["wall_time_s"]
    assert sum(times.values()) == pytest.approx(wall, rel=1e-6)
    pd = pytest.importorskip("pandas")
    df = pd.DataFrame(pmma_fit.residuals_table())
    assert len(df) == pmma_fit.summary["residuals"]
    est = pd.DataFrame(pmma_fit.estimates_table())
    assert list(est.name) == ["n", "kappa"] and est.stderr[0] == pmma_fit.n.stderr
    cands = pd.DataFrame(radiation_diagnosis.candidates_table())
    assert cands.effect[0] == radiation_diagnosis.candidates[0].effect


def test_report_is_the_text_report(pmma_fit, radiation_diagnosis):
    # `.report` is what the command line prints, not the JSON's kind stamp
    assert pmma_fit.report == pmma_fit.text == str(pmma_fit)
    assert "n" in pmma_fit.report and len(pmma_fit.report.splitlines()) > 5
    assert radiation_diagnosis.report == str(radiation_diagnosis)
    assert "radiation" in radiation_diagnosis.report
    # the kind stays in the JSON form
    assert pmma_fit.to_dict()["report"] == "fit"
    # a result without a text report says so
    cand = radiation_diagnosis.candidate("radiation")
    with pytest.raises(AttributeError, match="report"):
        cand.report


def test_set_threads(pmma):
    default = diffbvp.threads()
    try:
        diffbvp.set_threads(1)
        assert diffbvp.threads() == 1
        with pytest.raises(diffbvp.InputError, match="set_threads"):
            diffbvp.set_threads(0)
        one = diffbvp.simulate(pmma, 0.8, 11.7, points=5, take_up_from_data=True)
    finally:
        diffbvp.set_threads(None)
    assert diffbvp.threads() == default
    assert one == diffbvp.simulate(pmma, 0.8, 11.7, points=5, take_up_from_data=True)


def test_sensitivities_match_finite_differences(pmma):
    n, k = 0.8, 11.7
    pos = np.linspace(0.0, 0.51, 7)
    sim = diffbvp.simulate(pmma, n, k, take_up_from_data=True, positions=pos, sensitivities=True)
    name = pmma.names[4]
    s = sim.sensitivities[name]
    assert s["parameters"] == ["n", "kappa"]
    assert np.allclose(sim.profiles[name]["position_m"], pos)
    for j, (dn, dk) in enumerate([(1e-6, 0.0), (0.0, 1e-6)]):
        hi = diffbvp.simulate(pmma, n + dn, k + dk, take_up_from_data=True, positions=pos, tol=1e-10)
        lo = diffbvp.simulate(pmma, n - dn, k - dk, take_up_from_data=True, positions=pos, tol=1e-10)
        h = 2 * (dn + dk)
        for key in ("diameter_m", "temperature_K", "velocity_m_s"):
            fd = (hi.profiles[name][key] - lo.profiles[name][key]) / h
            ex = s[key][:, j]
            scale = np.max(np.abs(ex)) + 1e-300
            assert np.max(np.abs(fd - ex)) / scale < 1e-4, (key, j, fd, ex)


def test_take_up_rules(pmma):
    with pytest.raises(diffbvp.InputError, match="no take-up condition"):
        diffbvp.simulate(pmma, 0.8, 11.7)
    sim = diffbvp.simulate(pmma, 0.8, 11.7, take_up_diameter=1e-4, points=3)
    for e in sim:
        assert e["profiles"]["diameter_m"][-1] == pytest.approx(1e-4, rel=1e-6)


def test_a_stand_in_effect_makes_the_law_no_result():
    """Strain hardening (data/strain_hardening, outside the candidates, truth n = 0.8):
    radiation brings the residuals to the noise with a biased law, but only with a strength
    that differs between the experiments, so it is a stand-in and the law is no result (also
    in the pair that challenges the stand-in and replaces it, radiation with a gauge scale)."""
    from conftest import ROOT

    d = diffbvp.diagnose(diffbvp.load(ROOT / "data" / "strain_hardening" / "experiments.toml"))
    assert d.verdict["kind"] == "none_of_the_candidates" and not d.law_is_a_result, d.verdict
    stand_ins = d.verdict["stand_ins"]
    # the stand-ins are exactly the found effects whose one-strength test fails, radiation
    # among them
    failing = [c["effect"] for c in d.consistency if c["p_value"] < c["level"]]
    stand_in_effects = [c["effect"] for c in stand_ins]
    assert stand_in_effects == failing and "radiation" in failing, (stand_ins, d.consistency)
    assert all(e in d.found for e in stand_in_effects), (stand_ins, d.found)
    c = d.consistency[0]
    assert c["p_value"] < c["level"] and c["dof"][0] == len(c["conditions"]) >= 1, c
    assert len(c["by_experiment"]) == 9
    assert "NONE OF THE CANDIDATES" in d.text and "With it: n =" not in d.text


def test_a_robust_loss_weights_the_diagnosis_and_outliers_are_no_missing_physics():
    """Gross outliers on a correct model (data/hidden_outliers, made by the independent
    simulator): with the huber loss the diagnosis weights the points as the robust fit does,
    says so, and names nothing; the law is a result. A soft margin without a robust loss is
    an input error, in ``diagnose`` as in ``fit``."""
    from conftest import ROOT

    ds = diffbvp.load(ROOT / "data" / "hidden_outliers" / "experiments.toml")
    d = diffbvp.diagnose(ds, loss="huber")
    w = d.robust
    assert w is not None and w["loss"] == "huber" and w["down_weighted"] >= 7, w
    assert d.verdict["kind"] == "adequate" and d.law_is_a_result, d.verdict
    assert d.found == [] and "Loss huber: the points are weighted" in d.text
    assert d.law_not_a_result is None and d.base_fit.law_is_a_result
    # the same verdict with the law's kappa at a bound, in a JSON written before the library
    # wrote its reason: no result (the library's rule, applied to the fit)
    data = json.loads(json.dumps(d.diagnosis))
    data.pop("law_not_a_result")
    fit = data.get("final_fit") or data["base_fit"]
    fit["at_bound"] = [{"parameter": "kappa", "side": "lower", "bound": 7.0}]
    assert not diffbvp.Diagnosis(data).law_is_a_result
    for run in (diffbvp.diagnose, diffbvp.fit):
        with pytest.raises(diffbvp.InputError, match="f_scale = 0.02: a soft margin needs a robust loss"):
            run(ds, f_scale=0.02)


def test_a_pair_as_good_with_another_law_makes_the_law_no_result():
    """Radiation and warm air hide each other (data/radiation_warm_air, truth n = 0.8): the best
    single candidate reaches the noise with a biased law; the true pair, fitted jointly, is
    better but not beyond the look-elsewhere margin, so it stands beside it and the law is no
    result."""
    from conftest import ROOT

    d = diffbvp.diagnose(diffbvp.load(ROOT / "data" / "radiation_warm_air" / "experiments.toml"))
    p = d.pair
    assert p is not None and sorted(p["effects"]) == ["air_temperature_profile", "radiation"], p
    assert not p["replaces"] and p["delta_bic"] > p["delta_bic_of_steps"] - p["replace_margin"]
    assert p["laws_disagree"] is not None
    assert d.found == [d.most_likely_missing]
    assert any("neither law is a result" in w["message"] for w in d.final_fit.warnings)
    # the verdict's own kind says so: a notebook that checks it never takes this law
    assert d.verdict["kind"] == "ambiguous" and not d.law_is_a_result, d.verdict
    # nor one that takes a fit alone: the diagnosis' reason is the text report's words, the
    # final fit is no result (its own warning), and the user's model lacks the effect found
    assert f"NOT A RESULT: {d.law_not_a_result})" in " ".join(d.text.split()), d.law_not_a_result
    assert not d.final_fit.law_is_a_result and "NOT A RESULT" in repr(d.final_fit)
    assert d.found[0] in d.base_fit.law_not_a_result and not d.base_fit.law_is_a_result
    assert pickle.loads(pickle.dumps(d.base_fit)).law_not_a_result == d.base_fit.law_not_a_result
    assert ["air_temperature_profile", "radiation"] in [sorted(a) for a in d.verdict["alternatives"]]
    assert d.verdict["n_range"][0] <= 0.8 <= d.verdict["n_range"][1], d.verdict
    # the two explanations' envelope holds the truth
    lo = min(d.final_fit.n.ci95[0], p["fit"]["n"]["ci95"][0])
    hi = max(d.final_fit.n.ci95[1], p["fit"]["n"]["ci95"][1])
    assert lo <= 0.8 <= hi, (lo, hi)


def test_a_fit_and_a_diagnosis_continue_from_a_previous_result(radiation_diagnosis, rheometer,
                                                                scratch):
    """``start_from`` as ``--from``: the diagnosis' effects join the model, the fit starts from
    its law and strengths, and the numbers are the CLI's; a diagnosis from a fit has the fit's
    effects in the user's model."""
    from conftest import RADIATION, cli_json
    ds = diffbvp.load(RADIATION)
    assert "radiation" in radiation_diagnosis.found
    fit = diffbvp.fit(ds, start_from=radiation_diagnosis)
    assert "radiation" in fit.summary["fitted"]
    path = scratch / "radiation_diagnosis.json"
    path.write_text(json.dumps(radiation_diagnosis.diagnosis))
    assert_same(diffbvp.fit(ds, start_from=path).summary, fit.summary, rel=0.0)
    cli = cli_json(rheometer, scratch, "fit_from", "fit", str(RADIATION), "--from", str(path))
    assert_same(cli, fit.summary, rel=1e-12)
    # the same optimum as the diagnosis' final fit, which it starts from
    final = radiation_diagnosis.final_fit
    assert abs(fit.n.value - final.n.value) <= 0.05 * final.n.stderr
    with pytest.raises(diffbvp.InputError, match="start_from"):
        diffbvp.fit(ds, start_from=fit, start=(0.5, 12.0))
    with pytest.raises(diffbvp.InputError, match="effects radiation"):
        diffbvp.fit(ds, start_from=fit, effects="radiation=0.5")
    with pytest.raises(TypeError, match="start_from"):
        diffbvp.fit(ds, start_from=3)
    # the law is the file's unless model says otherwise
    newtonian = diffbvp.fit(ds, model="newtonian", error_budget=False)
    again = diffbvp.fit(ds, start_from=newtonian, error_budget=False)
    assert again.summary["law"] == newtonian.summary["law"] != fit.summary["law"]
    assert diffbvp.fit(ds, start_from=newtonian, model="carreau",
                       error_budget=False).summary["law"] == fit.summary["law"]
    d = diffbvp.diagnose(ds, start_from=fit, refit_top=2)
    assert "radiation" in d.base_fit.summary["fitted"]
    assert all(c.effect != "radiation" for c in d.candidates)


def test_a_law_at_its_bound_is_no_result_in_python_as_in_the_report(pmma, pmma_fit):
    """300 K of warm air fixed where there is none: n runs to its upper bound 1. The fit's
    ``law_not_a_result`` is the text report's ``NOT A RESULT:`` reason and the flow curve's
    ``not_a_result``, word for word; the shipped fit's law is a result. An ``implausible``
    warning alone makes a law no result too (the library's rule)."""
    assert pmma_fit.law_is_a_result and pmma_fit.law_not_a_result is None
    assert "not_a_result" not in (pmma_fit.summary.get("flow_curve") or {})
    f = diffbvp.fit(pmma, effects="air_temperature_profile=300", error_budget=False)
    why = f.law_not_a_result
    assert why is not None and not f.law_is_a_result, f.summary["at_bound"]
    assert repr(f).endswith("NOT A RESULT)") and "NOT A RESULT" not in repr(pmma_fit), repr(f)
    assert why.startswith("n is at its upper bound 1"), why
    flat = " ".join(f.text.split())
    assert f"NOT A RESULT: {why}" in flat, f.text
    assert f.summary["flow_curve"]["not_a_result"] == why
    data = json.loads(json.dumps(pmma_fit.summary))
    data["warnings"] = [{"code": "implausible", "message": "n = 0.01 is implausible here: biased"}]
    assert diffbvp.results.law_not_a_result(data) == "n = 0.01 is implausible here"
    data["warnings"] = [{"code": "misfit", "message": "misfit far above the noise: the RMS ..."},
                        {"code": "large_uncertainty", "message": "kappa: wide"}]
    assert diffbvp.results.law_not_a_result(data) == "misfit far above the noise"
    data["warnings"] = [{"code": "large_uncertainty", "message": "kappa: wide"}]
    assert diffbvp.results.law_not_a_result(data) is None
    # n at its upper bound 1 with a misfit: no likelihood-ratio test "below" to point to
    # (the library's words for the shipped data with the air at 600 K)
    data["at_bound"] = [{"parameter": "n", "side": "upper", "bound": 1.0, "value": 1.0}]
    assert diffbvp.results.law_not_a_result(data) == (
        "n is at its upper bound 1, where the fit has no valid interval (the Carreau-type law "
        "is Newtonian there and kappa is not determined; whether the Newtonian law fits is said "
        "below)")
    data["warnings"] = [{"code": "misfit", "message": "misfit far above the noise: ..."}]
    assert diffbvp.results.law_not_a_result(data) == (
        "n is at its upper bound 1, where the fit has no valid interval (the Carreau-type law "
        "is Newtonian there and kappa is not determined)")
