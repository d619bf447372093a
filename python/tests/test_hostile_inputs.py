"""Hostile inputs to the rheometer's Python functions: every bad argument is refused before any
work with a `diffbvp` exception that names the argument as Python calls it (never a CLI flag,
never a bare OverflowError, TypeError or KeyError from deep inside)."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import diffbvp
from diffbvp import InputError

# (call, the argument the message must name); each raises InputError
CASES = [
    # mesh limits, counts and sizes (negative and float integers included)
    (lambda ds: diffbvp.fit(ds, max_nodes=-1), "max_nodes"),
    (lambda ds: diffbvp.fit(ds, max_nodes=2.5), "max_nodes"),
    (lambda ds: diffbvp.fit(ds, max_nodes=10**30), "max_nodes"),
    (lambda ds: diffbvp.fit(ds, profile_points=-5), "profile_points"),
    (lambda ds: diffbvp.fit(ds, profile_points=1), "profile_points"),
    (lambda ds: diffbvp.simulate(ds, 0.8, 11.7, take_up_from_data=True, points=-1), "points"),
    (lambda ds: diffbvp.simulate(ds, 0.8, 11.7, take_up_from_data=True, points=10**7), "points"),
    (lambda ds: diffbvp.simulate(ds, 0.8, 11.7, take_up_from_data=True, max_nodes=-7), "max_nodes"),
    (lambda ds: diffbvp.landscape(ds, grid=(-3, 5)), "grid"),
    (lambda ds: diffbvp.landscape(ds, grid=(2000, 2)), "grid"),
    (lambda ds: diffbvp.landscape(ds, grid=(5, 5), max_nodes=5000), "max_nodes"),
    (lambda ds: diffbvp.diagnose(ds, refit_top=-2), "refit_top"),
    (lambda ds: diffbvp.diagnose(ds, refit_top=0), "refit_top"),
    (lambda ds: diffbvp.design(ds, grid=(1, 9)), "grid"),
    (lambda ds: diffbvp.design(ds, grid=(3.5, 3)), "grid"),
    # numbers out of their domain
    (lambda ds: diffbvp.fit(ds, tol=0.0), "tol"),
    (lambda ds: diffbvp.fit(ds, tol=float("nan")), "tol"),
    (lambda ds: diffbvp.fit(ds, relative_uncertainty=0.0), "relative_uncertainty"),
    (lambda ds: diffbvp.fit(ds, relative_uncertainty=-0.01), "relative_uncertainty"),
    (lambda ds: diffbvp.fit(ds, f_scale=2.0, loss="huber"), "f_scale"),
    (lambda ds: diffbvp.fit(ds, f_scale=0.02), "f_scale"),
    (lambda ds: diffbvp.fit(ds, loss="l2"), "loss"),
    (lambda ds: diffbvp.fit(ds, estimator="bayes"), "estimator"),
    (lambda ds: diffbvp.fit(ds, start=(5.0, 11.0)), "start"),
    (lambda ds: diffbvp.fit(ds, start=(0.8, float("inf"))), "start"),
    (lambda ds: diffbvp.fit(ds, model="newtonian", start=(0.8, 11.0)), "start"),
    (lambda ds: diffbvp.fit(ds, model="maxwell"), "model"),
    (lambda ds: diffbvp.fit(ds, effects=["radiaton"]), "effects"),
    (lambda ds: diffbvp.fit(ds, effects=["radiation=abc"]), "effects"),
    (lambda ds: diffbvp.simulate(ds, -0.1, 11.7, take_up_from_data=True), "n"),
    (lambda ds: diffbvp.simulate(ds, 0.8, 1e4, take_up_from_data=True), "kappa"),
    (lambda ds: diffbvp.simulate(ds, float("nan"), 11.7, take_up_from_data=True), "n"),
    (lambda ds: diffbvp.simulate(ds, 0.8, 11.7, take_up_from_data=True, tol=5.0), "tol"),
    (lambda ds: diffbvp.simulate(ds, 0.8, 11.7, take_up_from_data=True, positions=[]), "positions"),
    (lambda ds: diffbvp.simulate(ds, 0.8, 11.7, take_up_from_data=True,
                                 positions=[0.1, float("nan")]), "positions"),
    (lambda ds: diffbvp.landscape(ds, n_range=(0.5, 0.5)), "n_range"),
    (lambda ds: diffbvp.landscape(ds, kappa_range=(20.0, 9.0)), "kappa_range"),
    (lambda ds: diffbvp.landscape(ds, kappa_range=(9.0, 1e300)), "kappa_range"),
    (lambda ds: diffbvp.landscape(ds, tol=-1.0), "tol"),
    (lambda ds: diffbvp.compare(ds, n=0.8), "kappa"),
    (lambda ds: diffbvp.compare(ds, n=0.8, kappa=11.7, tol=1.0), "tol"),
    # the design's ranges under the experiments file's plausibility bounds
    (lambda ds: diffbvp.design(ds, mass_flow=(1e-300, 1e300)), "mass_flow"),
    (lambda ds: diffbvp.design(ds, mass_flow=(-1.0, 1e-5)), "mass_flow"),
    (lambda ds: diffbvp.design(ds, mass_flow=(2e-5, 1e-5)), "mass_flow"),
    (lambda ds: diffbvp.design(ds, take_up_velocity=(1e-9, 1e9)), "take_up_velocity"),
    (lambda ds: diffbvp.design(ds, take_up_diameter=(0.0, 1.0)), "take_up_diameter"),
    (lambda ds: diffbvp.design(ds, mass_flow=(1e-5, 2e-5), stencil_velocity=(1.0, 2.0)),
     "mass_flow"),
    (lambda ds: diffbvp.design(ds, template="no_such_run"), "template"),
    (lambda ds: diffbvp.design(ds, criterion="z"), "criterion"),
    (lambda ds: diffbvp.design(ds, noise=0.0), "noise"),
    (lambda ds: diffbvp.design(ds, discriminate=["radiation", "radiation"]), "discriminate"),
    (lambda ds: diffbvp.design(ds, mass_flow=(1e-5,)), "mass_flow"),
]


@pytest.mark.parametrize("call,arg", CASES, ids=[f"{i:02d}-{a}" for i, (_, a) in enumerate(CASES)])
def test_refused_naming_the_argument(pmma, call, arg):
    with pytest.raises(InputError) as e:
        call(pmma)
    msg = str(e.value)
    assert arg in msg, msg
    # Python's words, not the command line's
    assert "--" not in msg.split(":")[0], msg


def test_a_tampered_design_pickle_is_refused():
    r = diffbvp.DesignResult({"candidates": []}, "text", "csv")
    back = pickle.loads(pickle.dumps(r))
    assert back.to_dict() == r.to_dict() and back.text == "text"
    with pytest.raises(TypeError):
        back.__setstate__(("not a dict", 1))


def test_no_refusal_is_a_bare_python_error(pmma):
    # the values Python itself would choke on (a negative into an unsigned, a float into an
    # int) come back as InputError naming the argument, not OverflowError/TypeError
    for call in (lambda: diffbvp.fit(pmma, max_nodes=-(2**70)),
                 lambda: diffbvp.landscape(pmma, grid=(2**70, 2))):
        with pytest.raises(InputError):
            call()
    assert np.isfinite(diffbvp.fit(pmma, max_nodes=20000).n.value)


# --- sizes: one limit for files and arrays, with one override (finding 7) ---------------------

def _long_arrays(ds, name, rows):
    """`rows` plausible measurements of experiment `name` (its profile interpolated)."""
    pos, dia = ds.measurements()[name]
    p = np.linspace(pos[0], pos[-1], rows)
    return p, np.interp(p, pos, dia)


def test_arrays_meet_the_row_cap_of_files(pmma):
    import time
    name = pmma.names[0]
    p, d = _long_arrays(pmma, name, 1_000_001)
    t0 = time.time()
    with pytest.raises(InputError) as e:
        diffbvp.Dataset.from_toml(pmma.toml, pmma.path, measurements={name: (p, d)})
    msg = str(e.value)
    assert msg.startswith("measurements: ") and name in msg, msg
    assert "1,000,001 rows" in msg and "1,000,000" in msg and "allow_large_inputs=True" in msg, msg
    assert "--" not in msg, msg
    # refused on the lengths, before a row is converted
    assert time.time() - t0 < 1.0
    # the same cap through from_arrays (the dicts of the TOML file's layout)
    import tomllib
    doc = tomllib.loads(pmma.toml)
    exps = []
    for e in doc["experiment"]:
        e = {k: v for k, v in e.items() if k != "data"}
        pos, dia = pmma.measurements()[e["name"]]
        e["positions_m"], e["diameters_m"] = (p, d) if e["name"] == name else (pos, dia)
        exps.append(e)
    with pytest.raises(InputError) as e:
        diffbvp.Dataset.from_arrays(doc["material"], exps, defaults=doc.get("defaults"))
    assert "measurements: " in str(e.value) and "allow_large_inputs" in str(e.value)
    # lifted by the one override, which a pickle and a re-measured copy keep
    big = diffbvp.Dataset.from_arrays(doc["material"], exps, defaults=doc.get("defaults"),
                                      allow_large_inputs=True)
    assert big.allow_large_inputs and len(big.measurements()[name][0]) == 1_000_001
    again = pickle.loads(pickle.dumps(big))
    assert again.allow_large_inputs and len(again.measurements()[name][0]) == 1_000_001
    assert not pmma.allow_large_inputs


def test_arrays_in_all_meet_the_fit_memory_cap(pmma):
    # nine experiments of a million rows each: within the per-file cap, beyond what a fit can
    # hold within the 4 GiB estimate (load() refuses nine such files the same way)
    many = {n: _long_arrays(pmma, n, 1_000_000) for n in pmma.names}
    with pytest.raises(InputError) as e:
        diffbvp.Dataset.from_toml(pmma.toml, pmma.path, measurements=many)
    msg = str(e.value)
    assert msg.startswith("measurements: ") and "max_fit_memory_bytes" in msg, msg
    assert "allow_large_inputs=True" in msg, msg


def test_load_names_its_override_in_python_words(pmma, scratch):
    # a CSV file of more rows than the cap: load() refuses it naming allow_large_inputs=True,
    # never the command line's flag; with the override it loads
    name = pmma.names[0]
    p, d = _long_arrays(pmma, name, 1_000_001)
    csv = scratch / "long.csv"
    csv.write_text("position_m,diameter_m\n" + "\n".join(f"{a!r},{b!r}" for a, b in zip(p.tolist(), d.tolist())) + "\n")
    toml = scratch / "long.toml"
    text = pmma.toml
    import tomllib
    first = tomllib.loads(text)["experiment"][0]["data"]
    toml.write_text(text.replace(f'"{first}"', f'"{csv}"', 1))
    for call in (lambda: diffbvp.load(toml), lambda: diffbvp.Dataset.load(toml)):
        with pytest.raises(InputError) as e:
            call()
        msg = str(e.value)
        assert "allow_large_inputs=True" in msg and "--allow-large-inputs" not in msg, msg
    with pytest.raises(InputError) as e:
        diffbvp.load(toml, allow_large_inputs="yes")
    assert str(e.value).startswith("allow_large_inputs: ")


def test_ctrl_c_stops_a_large_from_arrays():
    import signal
    import subprocess
    import sys
    import time
    from conftest import PMMA, ROOT
    script = f"""
import signal, sys, time, numpy as np, diffbvp
signal.signal(signal.SIGINT, signal.default_int_handler)
ds = diffbvp.load({str(PMMA)!r})
m = {{}}
for n, (pos, dia) in ds.measurements().items():
    p = np.linspace(pos[0], pos[-1], 2_000_000)
    m[n] = (p, np.interp(p, pos, dia))
print("ready", flush=True)
t0 = time.time()
try:
    diffbvp.Dataset.from_toml(ds.toml, ds.path, measurements=m, allow_large_inputs=True)
except KeyboardInterrupt:
    print("interrupted", time.time() - t0, flush=True)
    sys.exit(3)
print("finished", time.time() - t0, flush=True)
"""
    p = subprocess.Popen([sys.executable, "-c", script], cwd=ROOT, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "ready"
    time.sleep(1.0)
    t = time.time()
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=120)
    assert p.returncode == 3, (out, err)
    assert time.time() - t < 5, out


# --- results: equality, strict JSON, validated pickles (findings 10, 11, 12) -------------------

def test_equal_fits_are_equal_whatever_their_timing(pmma):
    a = diffbvp.fit(pmma, error_budget=False)
    b = diffbvp.fit(pmma, error_budget=False)
    assert a == b
    # the same result timed otherwise is still the same result
    c = pickle.loads(pickle.dumps(a))
    c.summary["solver"]["wall_time_s"] += 1.0
    assert c == a
    other = diffbvp.fit(pmma, error_budget=False, estimator="paper")
    assert a != other
    # one spelling (finding 14): the result says the estimator as the argument names it
    assert a.summary["estimator"] == "principled"
    assert other.summary["estimator"] == "paper"


def test_landscape_to_dict_is_strict_json(pmma):
    import json
    import math
    # kappa up to 20 on n near 0: points without a solution (nan costs)
    ls = diffbvp.landscape(pmma, grid=(3, 3), n_range=(0.0, 1.0), kappa_range=(7.0, 20.0))
    d = ls.to_dict()
    json.dumps(d, allow_nan=False)
    cost = np.asarray(ls.cost, dtype=float)
    flat = [x for row in d["cost"] for x in row] if isinstance(d["cost"][0], list) else d["cost"]
    assert sum(x is None for x in flat) == int(np.sum(~np.isfinite(cost)))
    assert all(x is None or math.isfinite(x) for x in flat)
    # a point without a solution (nan) and an infinite cost are null, documented
    made = diffbvp.Landscape({"n": [0.5, 0.6], "kappa": [11.0], "estimator": "paper",
                              "cost": [[float("nan"), float("inf")]], "status": [[1, 0]]},
                             {"point_tol": np.array([[np.nan, 1e-4]])})
    d = made.to_dict()
    assert d["cost"] == [[None, None]] and d["point_tol"] == [[None, 1e-4]]
    json.dumps(d, allow_nan=False)
    assert "null" in diffbvp.results.__doc__ or "None" in diffbvp.results.__doc__


def _tampered(fit, edit):
    state = list(fit.__getstate__())
    summary = pickle.loads(pickle.dumps(state[0]))
    edit(summary)
    state[0] = summary
    return tuple(state)


@pytest.mark.parametrize("edit,field", [
    (lambda s: s["n"].__setitem__("value", "0.8"), "n.value"),
    (lambda s: s.pop("n"), "n"),
    (lambda s: s["n"].__setitem__("value", 7.5), "n"),
    (lambda s: s["kappa"].__setitem__("value", None), "kappa"),
], ids=["string-value", "missing-n", "n-7.5", "kappa-null"])
def test_a_tampered_fit_pickle_is_refused_at_load_naming_the_field(pmma_fit, edit, field):
    state = _tampered(pmma_fit, edit)
    blob = pickle.dumps(state)
    tampered = diffbvp.FitResult.__new__(diffbvp.FitResult)
    with pytest.raises(InputError) as e:
        tampered.__setstate__(pickle.loads(blob))
    msg = str(e.value)
    assert "pickled FitResult" in msg and field in msg, msg
    # the same through pickle.loads of a whole object
    good = pickle.dumps(pmma_fit)
    assert pickle.loads(good) == pmma_fit
    with pytest.raises(InputError):
        diffbvp.FitResult.__new__(diffbvp.FitResult).__setstate__(("not", "a", "state"))


def test_a_tampered_diagnosis_pickle_is_refused(radiation_diagnosis):
    state = list(radiation_diagnosis.__getstate__())
    data = pickle.loads(pickle.dumps(state[0]))
    data["base_fit"]["n"]["value"] = "x"
    data.pop("final_fit", None)
    with pytest.raises(InputError) as e:
        diffbvp.Diagnosis.__new__(diffbvp.Diagnosis).__setstate__((data, state[1], state[2]))
    assert "pickled Diagnosis" in str(e.value) and "n.value" in str(e.value)
