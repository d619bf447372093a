"""One front door: the same bad request refused by the `rheometer` program and by Python with
the same reason, each door naming the input in its own words (a flag on the command line, an
argument in Python). The rules live once, in the library's request module; this test fails
if either door grows its own copy that drifts."""

from __future__ import annotations

import re

import pytest

import diffbvp
from conftest import PMMA, cli_json, run_cli

# (CLI arguments, Python call, the flag, the Python argument)
CASES = [
    (["fit", str(PMMA), "--max-nodes", "7"],
     lambda ds: diffbvp.fit(ds, max_nodes=7), "--max-nodes", "max_nodes"),
    (["fit", str(PMMA), "--max-nodes", "-3"],
     lambda ds: diffbvp.fit(ds, max_nodes=-3), "--max-nodes", "max_nodes"),
    (["fit", str(PMMA), "--tol", "0.5"],
     lambda ds: diffbvp.fit(ds, tol=0.5), "--tol", "tol"),
    (["fit", str(PMMA), "--start", "2,30"],
     lambda ds: diffbvp.fit(ds, start=(2, 30)), "--start", "start"),
    (["fit", str(PMMA), "--f-scale", "0.02"],
     lambda ds: diffbvp.fit(ds, f_scale=0.02), "--f-scale", "f_scale"),
    (["compare", str(PMMA), "--n", "0.8", "--kappa", "11.7", "--take-up-from-data",
      "--relative-uncertainty", "1.5"],
     lambda ds: diffbvp.compare(ds, n=0.8, kappa=11.7, take_up_from_data=True,
                                relative_uncertainty=1.5), "--relative-uncertainty",
     "relative_uncertainty"),
    (["fit", str(PMMA), "--model", "newtonian", "--start", "0.8,11"],
     lambda ds: diffbvp.fit(ds, model="newtonian", start=(0.8, 11.0)), "--start", "start"),
    (["simulate", str(PMMA), "--n", "-0.5", "--kappa", "11", "--take-up-from-data"],
     lambda ds: diffbvp.simulate(ds, n=-0.5, kappa=11.0, take_up_from_data=True), "--n", "n"),
    (["simulate", str(PMMA), "--n", "0.8", "--kappa", "900", "--take-up-from-data"],
     lambda ds: diffbvp.simulate(ds, n=0.8, kappa=900.0, take_up_from_data=True), "--kappa",
     "kappa"),
    (["simulate", str(PMMA), "--n", "0.8", "--kappa", "11", "--take-up-from-data",
      "--points", "1"],
     lambda ds: diffbvp.simulate(ds, n=0.8, kappa=11.0, take_up_from_data=True, points=1),
     "--points", "points"),
    (["landscape", str(PMMA), "--grid", "1x5", "--out", "target/pytest-scratch/never"],
     lambda ds: diffbvp.landscape(ds, grid=(1, 5)), "--grid", "grid"),
    (["landscape", str(PMMA), "--n-range", "0.9,0.1", "--out", "target/pytest-scratch/never"],
     lambda ds: diffbvp.landscape(ds, n_range=(0.9, 0.1)), "--n-range", "n_range"),
    (["design", str(PMMA), "--mass-flow", "1e-300,1e300"],
     lambda ds: diffbvp.design(ds, mass_flow=(1e-300, 1e300)), "--mass-flow", "mass_flow"),
    (["design", str(PMMA), "--template", "nonexistent"],
     lambda ds: diffbvp.design(ds, template="nonexistent"), "--template", "template"),
    (["design", str(PMMA), "--noise", "0.7"],
     lambda ds: diffbvp.design(ds, noise=0.7), "--noise", "noise"),
    (["design", str(PMMA), "--discriminate", "radiation"],
     lambda ds: diffbvp.design(ds, discriminate=["radiation"]), "--discriminate", "discriminate"),
]

FLAGS = re.compile(r"--[a-z][a-z-]*")


def reason(text: str) -> str:
    """The reason of a refusal: the text after the input's name and value, with every flag or
    argument name it mentions reduced to its bare words (`--loss` and `loss` -> `loss`) and
    Python's `name="value"` to the CLI's `name value`."""
    line = next((l for l in text.splitlines() if l.strip()), "")
    line = re.sub(r"^(error: )?invalid value '[^']*' for '[^']*': ", "", line)
    line = re.sub(r"^error: ", "", line)
    # drop "<input>[ value]: " at the start (both doors put the input first)
    line = re.sub(r"^(--[a-z-]+|[a-z_]+)( = \([^)]*\)| = \S+| \S+)?: ", "", line)
    line = re.sub(r'([a-z_]+)="([^"]*)"', r"\1 \2", line)
    line = FLAGS.sub(lambda m: m.group(0)[2:].replace("-", "_"), line)
    return line.strip()


@pytest.mark.parametrize("cli_args,call,flag,arg", CASES, ids=[" ".join(c[0][:1] + c[0][2:]) for c in CASES])
def test_same_refusal_at_both_doors(rheometer, pmma, cli_args, call, flag, arg):
    p = run_cli(rheometer, *cli_args)
    assert p.returncode != 0, p.stdout
    with pytest.raises(diffbvp.InputError) as e:
        call(pmma)
    py = str(e.value)
    # each door names the input in its own words, and not in the other door's
    assert flag in p.stderr, p.stderr
    assert py.startswith(arg), py
    assert flag not in py, py
    # the same reason
    assert reason(p.stderr) == reason(py), (p.stderr, py)


def test_python_design_returns_what_the_cli_writes(rheometer, scratch, pmma):
    ref = cli_json(rheometer, scratch, "design", "design", str(PMMA), "--grid", "3x3")
    got = diffbvp.design(pmma, grid=(3, 3))
    # everything but the wall times, to the last bit: one workflow behind both doors
    from conftest import assert_same

    assert_same(ref, got.to_dict())
    assert got.ranked and got.ranked[0]["rank"] == 1
    assert "Which experiment next" in got.text
    assert got.csv.splitlines()[0].startswith("i,j,mass_flow_kg_s,take_up,")
    assert len(got.csv.splitlines()) == 1 + 9


def test_a_missing_take_up_names_the_input_at_each_door(rheometer, pmma):
    # bad-input finding D51: the model with an effect and no take-up condition in the TOML
    p = run_cli(rheometer, "compare", str(PMMA), "--with", "radiation=0.9", "--n", "0.8",
                "--kappa", "11.7", "--out", "target/pytest-scratch/never")
    assert p.returncode != 0, p.stdout
    assert "has no take-up condition" in p.stderr and "--take-up-from-data" in p.stderr, p.stderr
    with pytest.raises(diffbvp.DiffbvpError) as e:
        diffbvp.compare(pmma, n=0.8, kappa=11.7, effects="radiation=0.9")
    py = str(e.value)
    assert "has no take-up condition" in py and "take_up_from_data=True" in py, py
    assert "--" not in py, py


def test_the_readers_warnings_reach_python(scratch):
    """The loader's warnings (here: two experiments reading one data file, finding 36 of the
    hostile round) are a ``UserWarning`` in Python, as the CLI prints them; the shipped data
    give none."""
    import shutil
    import warnings

    folder = scratch / "shared_data_file"
    shutil.rmtree(folder, ignore_errors=True)
    shutil.copytree(PMMA.parent, folder)
    toml = folder / "experiments.toml"
    text = toml.read_text()
    assert text.count('data = "v0p27_p2.csv"') == 1
    toml.write_text(text.replace('data = "v0p27_p2.csv"', 'data = "./v0p27_p1.csv"'))
    with pytest.warns(UserWarning, match="experiments v0p27_p1 and v0p27_p2 read the same data file"):
        diffbvp.load(toml)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        diffbvp.load(PMMA)
