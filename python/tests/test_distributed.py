"""Many fits over a Dask LocalCluster with 2 worker processes equal the serial ones."""

from __future__ import annotations

import math

import numpy as np
import pytest

import diffbvp
from conftest import assert_same
from diffbvp.distributed import bootstrap, map_fits

distributed = pytest.importorskip("dask.distributed")
dask = pytest.importorskip("dask")

REPLICATES = 4


def test_bootstrap_on_local_cluster_equals_serial(pmma, pmma_fit, scratch):
    opts = {"profile_points": 2}
    serial = bootstrap(None, pmma, pmma_fit, replicates=REPLICATES, seed=7, fit_options=opts)
    assert not serial.failed
    # dask's scratch space (its default is a folder in the working or temporary directory)
    # under the test's scratch directory: nothing left in /tmp
    with dask.config.set({"temporary-directory": str(scratch / "dask")}), \
            distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None,
                                  local_directory=str(scratch / "dask")) as cluster, \
            distributed.Client(cluster) as client:
        par = bootstrap(client, pmma, pmma_fit, replicates=REPLICATES, seed=7, fit_options=opts)
        # every worker process now runs its fits on one Rust thread
        assert set(client.run(diffbvp.threads).values()) == {1}
        many = map_fits(client, [pmma, pmma], [{"error_budget": False, "profile_points": 2},
                                               {"estimator": "paper", "start": (0.5, 11.51),
                                                "error_budget": False, "profile_points": 2}])
    assert not par.failed
    for a, b in zip(serial.fits, par.fits):
        assert isinstance(b, diffbvp.FitResult)
        assert a.n == b.n and a.kappa == b.kappa
        assert_same(a.summary, b.summary, rel=0.0)  # bitwise, wall times excepted
        assert np.array_equal(a.covariance, b.covariance)
        assert a.summary.get("error_budget") is None  # replicates skip the budget
    # replicates differ from each other and scatter around the base fit
    ns = [f.n.value for f in par.fits]
    assert len(set(ns)) == REPLICATES
    assert all(abs(n - pmma_fit.n.value) < 5 * pmma_fit.n.stderr for n in ns)
    assert many[0].n.value == pytest.approx(pmma_fit.n.value, rel=1e-12)
    assert many[1].summary["estimator"].lower() == "paper"
    # the bootstrap spread is of the order of the fit's standard error
    sd = par.std()
    assert 0.2 * pmma_fit.n.stderr < sd["n"] < 5 * pmma_fit.n.stderr


def test_bootstrap_twice_on_one_client(pmma, pmma_fit, scratch):
    # the same data set and base fit scattered twice on one client: each call's data under
    # keys of its own (it failed 14 times in 14 with lost dependencies or a hang when both
    # calls shared content-derived keys); a failed fit on a worker comes back as its exception
    opts = {"profile_points": 2}
    with dask.config.set({"temporary-directory": str(scratch / "dask2")}), \
            distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                     dashboard_address=None,
                                     local_directory=str(scratch / "dask2")) as cluster, \
            distributed.Client(cluster) as client:
        runs = [bootstrap(client, pmma, pmma_fit, replicates=2, seed=3, fit_options=opts)
                for _ in range(3)]
        bad = map_fits(client, [pmma], [{"max_nodes": 10, "error_budget": False}])
        boot_bad = bootstrap(client, pmma, pmma_fit, replicates=1, fit_options={"max_nodes": 10})
    for r in runs:
        assert not r.failed, r.failed
        assert [f.n.value for f in r.fits] == [f.n.value for f in runs[0].fits]
    # the worker's exception, class and message kept
    assert isinstance(bad[0], diffbvp.InputError) and "max_nodes" in str(bad[0])
    assert isinstance(boot_bad.errors[0], diffbvp.InputError)
    assert boot_bad.failed[0].startswith("InputError: max_nodes")


class _NoCluster:
    """A client that fails the test if anything is sent to it."""

    def __getattr__(self, name):
        raise AssertionError(f"client.{name} used before the arguments were checked")


@pytest.mark.parametrize("kwargs,arg", [
    ({"fit_options": {"profle_points": 2}}, "profle_points"),
    ({"fit_options": {"error_budgett": False}}, "error_budgett"),
    ({"fit_options": "profile_points=2"}, "fit_options"),
    ({"replicates": -5}, "replicates"),
    ({"replicates": 0}, "replicates"),
    ({"replicates": 2.5}, "replicates"),
    ({"seed": -1}, "seed"),
    ({"noise": 0.0}, "noise"),
    ({"noise": "big"}, "noise"),
    ({"threads_per_fit": 0}, "threads_per_fit"),
    ({"batch_size": 0}, "batch_size"),
], ids=lambda v: v if isinstance(v, str) else None)
def test_bootstrap_checks_before_scattering(pmma, pmma_fit, kwargs, arg):
    for client in (None, _NoCluster()):
        with pytest.raises(diffbvp.InputError) as e:
            bootstrap(client, pmma, pmma_fit, **{"replicates": 2, **kwargs})
        assert arg in str(e.value), str(e.value)
    if arg == "profle_points":
        assert "did you mean 'profile_points'" in str(e.value)


def test_bootstrap_refuses_a_base_fit_of_other_data(pmma, pmma_fit):
    name = pmma.names[0]
    pos, dia = pmma.measurements()[name]
    other = pmma.with_measurements({name: (pos, dia * 1.01)})
    assert other.data_digest != pmma.data_digest == pmma_fit.summary["data_digest"]
    with pytest.raises(diffbvp.InputError) as e:
        bootstrap(_NoCluster(), other, pmma_fit, replicates=2)
    assert str(e.value).startswith("base: a fit of other data"), str(e.value)


def test_map_fits_checks_before_sending_and_keeps_the_exception(pmma):
    with pytest.raises(diffbvp.InputError) as e:
        map_fits(_NoCluster(), [pmma], [{"estimatr": "paper"}])
    assert "fit_options[0]" in str(e.value) and "estimatr" in str(e.value)
    with pytest.raises(diffbvp.InputError) as e:
        map_fits(_NoCluster(), [pmma, pmma], [{}])
    assert "fit_options" in str(e.value)
    with pytest.raises(diffbvp.InputError) as e:
        map_fits(_NoCluster(), ["data/x.toml"])
    assert "datasets[0]" in str(e.value)
    out = map_fits(None, [pmma], [{"start": (0.5, 99.0), "error_budget": False}])
    assert isinstance(out[0], diffbvp.InputError) and "start" in str(out[0])
