"""Writes rheometer.ipynb (kept as a script so that the notebook's source is reviewable)."""
import nbformat as nbf

cells = [
    ("md", """# The rheometer from Python

Load the shipped synthetic PMMA-like data (truth (n, κ) = (0.8, 11.71)), identify the
Carreau-type elongational viscosity, plot the profiles and the flow curve, then find what is
missing from the model on a data set with a hidden effect and add it."""),
    ("code", """from pathlib import Path
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import diffbvp

# the repository root (this notebook lives in python/examples/)
root = next(p for p in [Path.cwd(), *Path.cwd().parents] if (p / "data" / "pmma7n_synthetic").exists())
out = root / "target" / "notebook"
out.mkdir(parents=True, exist_ok=True)
ds = diffbvp.load(root / "data" / "pmma7n_synthetic" / "experiments.toml")
ds"""),
    ("code", """fit = diffbvp.fit(ds)
fit"""),
    ("code", """print(fit)            # the same report as `rheometer fit`"""),
    ("md", """The fit's outcome is the library's `FitSummary`: named estimates with standard errors and
95 % intervals, the covariance, the one noise level the misfit is judged against, warnings and
the error budget."""),
    ("code", """print("n     =", fit.n, "  95 % CI", fit.n.ci95)
print("kappa =", fit.kappa, "  K =", fit.K)
print(f"noise level {100 * fit.noise_level:.2f} %, RMS relative residual {100 * fit.rms:.2f} %")
for w in fit.warnings:
    print("warning:", w["code"], "-", w["message"])
pd.DataFrame(fit.estimates_table())"""),
    ("code", """pd.DataFrame(fit.covariance, index=fit.covariance_names, columns=fit.covariance_names)"""),
    ("md", """## Fitted diameter profiles against the measurements"""),
    ("code", """meas = ds.measurements()
fig, axes = plt.subplots(3, 3, figsize=(11, 8), sharex=True)
for ax, name in zip(axes.flat, ds.names):
    p = fit.profiles[name]
    s, d = meas[name]
    ax.plot(s, 1e6 * d, ".", ms=3, label="measured")
    ax.plot(p["position_m"], 1e6 * p["diameter_m"], "-", label="fitted")
    ax.set_yscale("log"); ax.set_title(name, fontsize=9)
for ax in axes[-1]:
    ax.set_xlabel("position s [m]")
for ax in axes[:, 0]:
    ax.set_ylabel("diameter [µm]")
axes[0, 0].legend()
fig.tight_layout(); fig.savefig(out / "profiles.png", dpi=80)"""),
    ("md", """## The flow curve

The deliverable: the elongational viscosity η_E(ε̇) at the die temperature, with its 95 %
statistical band (and the total band with the systematic uncertainties of the error budget);
dashed where extrapolated beyond the strain rates the data cover."""),
    ("code", """fc = pd.DataFrame(fit.flow_curve())
inside = ~fc.extrapolated
fig, ax = plt.subplots(figsize=(6, 4))
ax.fill_between(fc.strain_rate_1_s, fc.total95_lo_Pa_s, fc.total95_hi_Pa_s, alpha=0.2, label="95 % total")
ax.fill_between(fc.strain_rate_1_s, fc.stat95_lo_Pa_s, fc.stat95_hi_Pa_s, alpha=0.4, label="95 % statistical")
ax.loglog(fc.strain_rate_1_s[inside], fc.eta_Pa_s[inside], "k-", label="identified law")
ax.loglog(fc.strain_rate_1_s, fc.eta_Pa_s, "k--", lw=0.8)
ax.set_xlabel("strain rate [1/s]"); ax.set_ylabel("elongational viscosity [Pa s]")
ax.legend(fontsize=7); fig.tight_layout(); fig.savefig(out / "flow_curve.png", dpi=80)
print(fit.summary["flow_curve"]["finding"])"""),
    ("md", """## Residuals as a table"""),
    ("code", """res = pd.DataFrame(fit.residuals_table())
res.groupby("experiment").relative_residual.agg(lambda r: 100 * np.sqrt(np.mean(r**2))).rename("RMS [%]")"""),
    ("md", """## When the model fails: a data set with a hidden effect

`diagnose` searches every candidate effect, refits the promising ones, ranks them by ΔBIC with a
look-elsewhere calibration (the false-alarm probability of the search), adds what it finds and
searches again, and gives a verdict."""),
    ("code", """hidden = diffbvp.load(root / "data" / "hidden_radiation" / "experiments.toml")
diag = diffbvp.diagnose(hidden)
print(diag.verdict)
diag"""),
    ("code", """cols = ["effect", "delta_bic", "false_alarm", "share_of_excess", "status", "strength", "strength_stderr"]
pd.DataFrame(diag.candidates_table())[cols].head(8)"""),
    ("md", """Add the effect it found to the model and fit again (the same model as the diagnosis' final
fit)."""),
    ("code", """missing = diag.found
assert missing[:1] == ["radiation"], missing
refit = diffbvp.fit(hidden, effects=missing)
base = diag.base_fit
print("paper's model:", base)
print("with", " + ".join(missing) + ":", refit)
print("diagnosis' final fit:", diag.final_fit)
assert refit.rms < base.rms
assert abs(refit.n.value - diag.final_fit.n.value) < refit.n.stderr"""),
    ("code", """fig, ax = plt.subplots(figsize=(7, 3.5))
for label, f in [("paper's model", base), ("with " + " + ".join(missing), refit)]:
    t = pd.DataFrame(f.residuals_table())
    ax.plot(t.position_m, 100 * t.relative_residual, ".", ms=2, label=f"{label}: RMS {100 * f.rms:.2f} %")
ax.set_xlabel("position s [m]"); ax.set_ylabel("relative residual [%]"); ax.legend()
fig.tight_layout(); fig.savefig(out / "residuals_before_after.png", dpi=80)"""),
]

nb = nbf.v4.new_notebook()
nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
nb.cells = [nbf.v4.new_markdown_cell(src) if kind == "md" else nbf.v4.new_code_cell(src) for kind, src in cells]
from pathlib import Path
nbf.write(nb, Path(__file__).resolve().parent / "rheometer.ipynb")
