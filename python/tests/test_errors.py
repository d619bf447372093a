"""Bad input raises diffbvp.errors exceptions with the CLI's messages (file, line, experiment)."""

from __future__ import annotations

import numpy as np
import pytest

import diffbvp
from conftest import PMMA, run_cli
from diffbvp.errors import DiffbvpError, InputError, SimulationError


def cli_error(rheometer, *args) -> str:
    p = run_cli(rheometer, *args)
    assert p.returncode != 0
    first = p.stderr.strip().splitlines()[0]
    assert first.startswith("error: ")
    return p.stderr.strip()[len("error: "):]


def test_missing_file_names_the_file(rheometer, scratch):
    missing = scratch / "no_such" / "experiments.toml"
    with pytest.raises(InputError) as e:
        diffbvp.load(missing)
    assert str(missing) in str(e.value)
    assert str(e.value) == cli_error(rheometer, "fit", str(missing))
    assert isinstance(e.value, ValueError) and isinstance(e.value, DiffbvpError)


def test_bad_toml_value_names_the_line_and_key(rheometer, scratch):
    text = PMMA.read_text().replace("mass_flow_kg_s = 3.08e-05", "mass_flow_kg_s = -3.08e-05", 1)
    lines = text.splitlines()
    line = next(i + 1 for i, l in enumerate(lines) if "-3.08e-05" in l)
    bad = scratch / "bad.toml"
    bad.write_text(text)
    with pytest.raises(InputError) as e:
        diffbvp.load(bad)
    msg = str(e.value)
    assert f"{bad}:{line}:" in msg and "mass_flow_kg_s" in msg
    assert msg == cli_error(rheometer, "fit", str(bad))


def test_malformed_toml_names_the_line(scratch):
    bad = scratch / "malformed.toml"
    bad.write_text("[material]\ndensity_slope_kg_m3_K = = 3\n")
    with pytest.raises(InputError, match=r"malformed\.toml:2"):
        diffbvp.load(bad)


def test_conditions_dict_errors_name_table_and_key(pmma):
    c = pmma.conditions()[0]
    exp = {k: v for k, v in c.items() if k not in ("line", "data", "stencil_velocity_mm_s", "take_up_pressure_bar")}
    material = {"density_slope_kg_m3_K": -0.964}
    with pytest.raises(InputError, match=r"<conditions>:\d+: \[material\]: missing required key"):
        diffbvp.Dataset.from_arrays(material, [exp])


def test_measurement_arrays_are_checked_like_csv_rows(pmma):
    toml_material = _material()
    c = pmma.conditions()[0]
    pos, dia = pmma.measurements()[c["name"]]
    dia = dia.copy()
    dia[3] = 1e-9  # 1 nm: implausible
    exp = {"name": c["name"], "mass_flow_kg_s": c["mass_flow_kg_s"], "inlet_diameter_m": c["inlet_diameter_m"],
           "spinline_length_m": 0.51, "inlet_temperature_K": 513.15, "air_temperature_K": 293.15,
           "positions_m": pos, "diameters_m": dia}
    with pytest.raises(InputError) as e:
        diffbvp.Dataset.from_arrays(toml_material, [exp])
    assert f'<arrays of experiment "{c["name"]}">:5' in str(e.value)  # row 3 is line 5


def test_bad_arguments_name_the_argument(pmma):
    with pytest.raises(InputError, match="power index n must be >= 0"):
        diffbvp.simulate(pmma, -1.0, 11.0)
    with pytest.raises(InputError, match="start must lie within the fit's bounds"):
        diffbvp.fit(pmma, start=(2.0, 11.0))
    with pytest.raises(InputError, match="not an estimator"):
        diffbvp.fit(pmma, estimator="bayes")
    with pytest.raises(InputError, match="unknown effect|not a"):
        diffbvp.fit(pmma, effects=["radiaton"])
    with pytest.raises(InputError, match="at least 2 points"):
        diffbvp.landscape(pmma, grid=(1, 5))
    with pytest.raises(InputError, match=r"tol: the tolerance must lie in"):
        diffbvp.fit(pmma, tol=0.5)
    with pytest.raises(InputError, match="relative_uncertainty: a relative uncertainty must lie in"):
        diffbvp.compare(pmma, n=0.8, kappa=11.7, relative_uncertainty=2.0)
    with pytest.raises(InputError, match="no \\(n, kappa\\) to start from"):
        diffbvp.fit(pmma, model="newtonian", start=(0.5, 11.0))
    with pytest.raises(InputError, match="refit_top"):
        diffbvp.diagnose(pmma, refit_top=0)


def test_a_bad_fit_summary_is_refused_naming_the_field(pmma, pmma_fit):
    bad = dict(pmma_fit.summary)
    bad["take_up_factors"] = bad["take_up_factors"][:3]  # not one per experiment
    with pytest.raises(InputError, match="the fit"):
        diffbvp.compare(pmma, bad)
    bad = dict(pmma_fit.summary)
    bad["n"] = dict(bad["n"], value=7.0)  # outside any law's range
    with pytest.raises(InputError, match="the fit.*n"):
        diffbvp.compare(pmma, bad)
    # a dictionary that is no fit report: the first field it lacks is named
    with pytest.raises(InputError, match=r"the fit: field .* missing \(a fit report"):
        diffbvp.compare(pmma, {"hello": 1})


def test_failed_simulation_names_experiment_line_and_causes(rheometer, pmma):
    with pytest.raises(SimulationError) as e:
        diffbvp.simulate(pmma, 0.0, 20.0, take_up_from_data=True)
    err = e.value
    cli = cli_error(rheometer, "simulate", str(PMMA), "--n", "0", "--kappa", "20",
                    "--take-up-from-data", "--out", "target/pytest-scratch/sim_fail")
    # the same message and cause; the hints differ only in naming the flag or the argument
    assert str(err).splitlines()[:2] == cli.splitlines()[:2]
    assert err.experiment == "v0p27_p2" and err.line == 36 and err.path == str(PMMA)
    assert any("n = 0 is strong strain thinning" in h for h in err.hints)


def _material():
    return {
        "density_slope_kg_m3_K": -0.964, "density_intercept_kg_m3": 1572.33,
        "heat_capacity_slope_J_kg_K2": 3.2, "heat_capacity_intercept_J_kg_K": 648.22,
        "vft_mu_c_Pa_s": 0.00037074, "vft_B_K": 3649.0, "vft_T_VF_K": 273.15,
        "air_density_kg_m3": 1.0, "air_heat_capacity_J_kg_K": 1000.0,
        "air_kinematic_viscosity_m2_s": 2e-05, "air_heat_conductivity_W_m_K": 0.031,
    }
