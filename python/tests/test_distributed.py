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
