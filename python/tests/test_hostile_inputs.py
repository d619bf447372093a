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
