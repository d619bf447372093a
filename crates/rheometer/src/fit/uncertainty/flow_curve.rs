//! The flow curve of a fit: the identified elongational viscosity `η_E(ε̇)` \[Pa s\] against the
//! strain rate \[1/s\] at one temperature, with its statistical 95 % band, its systematic band,
//! the Newtonian plateau (Trouton: `Tr·η₀(T)`, e.g. `3η₀`) and the strain-rate range the data
//! cover ([`FlowCurve`]).
//!
//! * **The law as the model uses it.** Values come from the model's own evaluation
//!   ([`FiberModel::viscosity_at`]: the law, the VFT zero-rate viscosity and any fitted VFT
//!   offsets), generic over the [`ViscosityLaw`]; derivatives with respect to the law's
//!   parameters are exact (dual numbers through the same evaluation).
//! * **Strain rates the data cover.** The model's strain rates at the measurement positions of
//!   the fitted solutions ([`StrainRateCoverage`](crate::fit::StrainRateCoverage)), shifted to the
//!   curve's temperature by the VFT factor `a_T = η₀(T)/η₀(T_ref)` (time–temperature superposition:
//!   the Carreau-type laws depend on `η₀(T)·ε̇` only, so a point of the spin line at temperature
//!   `T` and rate `ε̇` probes the curve at `T_ref` at the rate `a_T ε̇`). Outside that range,
//!   extended by a decade on each side, the curve is extrapolated and marked so.
//! * **Statistical band (95 %).** By the delta method on `ln η_E` from the covariance of the
//!   law's fitted parameters (`(n, κ)`), `η_E exp(±1.96 σ_ln)`; where the linearised interval
//!   of a law parameter is not trustworthy (see [`profile`](super::profile)), the envelope of
//!   the curves along its likelihood profile within the 95 % deviance instead.
//! * **Systematic band (95 %, `k = 1.96`).** From the error budget: each source's signed shifts
//!   of `(n, κ)` at one standard uncertainty (common sources summed over the experiments,
//!   per-experiment ones in quadrature), propagated to `ln η_E` by the same exact gradient and
//!   added in quadrature. The total band combines both in quadrature.

use crate::data::uncertainty::Scope;
use crate::fit::summary::{FitSummary, Z95};
use crate::fit::values::budget::ErrorBudget;
pub use crate::fit::values::curve::{BandMethod, FlowCurve, FlowPoint, Isotherm};
use crate::model::bvp::FiberModel;
use crate::model::contributions::NusseltLaw;
use crate::model::material_law::ViscosityLaw;
use num_dual::Dual64;

/// The 95 % point of the χ² distribution with one degree of freedom (`1.96²`).
pub const CHI2_1_95: f64 = Z95 * Z95;

/// Options of [`FlowCurve::of`].
#[derive(Debug, Clone, PartialEq)]
pub struct FlowCurveOptions {
    /// Temperature of the curve \[K\] (`None`: the coverage's reference temperature, the
    /// median die temperature).
    pub temperature_k: Option<f64>,
    /// Points per decade of strain rate.
    pub points_per_decade: usize,
    /// Decades of extrapolation drawn beyond the covered range on each side.
    pub extension_decades: f64,
    /// Other temperatures \[K\] to draw the curve at (VFT shift).
    pub isotherms_k: Vec<f64>,
}

impl Default for FlowCurveOptions {
    /// The coverage's temperature, 10 points per decade, one decade beyond each side, no
    /// isotherms.
    fn default() -> Self {
        FlowCurveOptions {
            temperature_k: None,
            points_per_decade: 10,
            extension_decades: 1.0,
            isotherms_k: Vec::new(),
        }
    }
}

/// `η_E` \[Pa s\] and its gradient with respect to the law's parameters at temperature `t_k`
/// \[K\] and strain rate `rate` \[1/s\], through the model's own evaluation.
fn eta_and_gradient<L: ViscosityLaw, H: NusseltLaw>(
    model: &FiberModel<L, H>,
    params: &[f64],
    t_k: f64,
    rate: f64,
) -> (f64, Vec<f64>) {
    let sc = &model.scaling;
    let t = Dual64::from_re(t_k / sc.reference.temperature);
    let r = Dual64::from_re(rate / sc.strain_rate());
    let mu_o = sc.reference.viscosity;
    let law = model.param_layout().law();
    let mut value = f64::NAN;
    let mut grad = Vec::with_capacity(law.len());
    let mut p: Vec<Dual64> = params.iter().map(|&v| Dual64::from_re(v)).collect();
    for i in law {
        p[i] = Dual64::from_re(params[i]).derivative();
        let m = model.viscosity_at(t, r, &p);
        p[i] = Dual64::from_re(params[i]);
        value = m.re * mu_o;
        grad.push(m.eps * mu_o);
    }
    if grad.is_empty() {
        value = model.viscosity_at(t.re, r.re, params) * mu_o;
    }
    (value, grad)
}

/// `η_E` \[Pa s\] with the law's parameters replaced by `law`.
fn eta_with_law<L: ViscosityLaw, H: NusseltLaw>(
    model: &FiberModel<L, H>,
    params: &[f64],
    law: &[f64],
    t_k: f64,
    rate: f64,
) -> f64 {
    let mut p = params.to_vec();
    for (i, v) in model.param_layout().law().zip(law) {
        p[i] = *v;
    }
    let sc = &model.scaling;
    model.viscosity_at(t_k / sc.reference.temperature, rate / sc.strain_rate(), &p)
        * sc.reference.viscosity
}

/// The covariance of the law's parameters (names of `law`) from the summary, row-major, with
/// zero rows for parameters not fitted (`None`: no covariance at all).
fn law_covariance(summary: &FitSummary, names: &[&str]) -> Option<Vec<f64>> {
    let c = summary.covariance.as_ref()?;
    let k = names.len();
    let mut m = vec![0.0; k * k];
    let mut any = false;
    for (i, a) in names.iter().enumerate() {
        for (j, b) in names.iter().enumerate() {
            if let Some(v) = c.get(a, b) {
                m[i * k + j] = v;
                any = true;
            }
        }
    }
    any.then_some(m)
}

/// The systematic shift vectors of the law's parameters `(n, κ)` at one standard uncertainty:
/// one per common source (summed over the experiments), one per experiment for per-experiment
/// sources.
fn systematic_shifts(budget: &ErrorBudget) -> Vec<[f64; 2]> {
    let mut out = Vec::new();
    for e in budget.available() {
        let scope = e.scope;
        let per: Vec<[f64; 2]> = e
            .by_experiment
            .iter()
            .map(|x| {
                [
                    x.sigma * x.dn_dq.unwrap_or(0.0),
                    x.sigma * x.dkappa_dq.unwrap_or(0.0),
                ]
            })
            .collect();
        if per.is_empty() {
            out.push([
                e.sigma * e.dn_dq.unwrap_or(0.0),
                e.sigma * e.dkappa_dq.unwrap_or(0.0),
            ]);
        } else if scope == Scope::Common {
            out.push(
                per.iter()
                    .fold([0.0, 0.0], |a, v| [a[0] + v[0], a[1] + v[1]]),
            );
        } else {
            out.extend(per);
        }
    }
    out
}

impl FlowCurve {
    /// The flow curve of `summary` (a fit of `model`'s law with local model parameters
    /// `params`; any experiment's model of the fit: they share the material and the law).
    /// Errors: the summary has no strain-rate coverage (a report written before it existed).
    pub fn of<L: ViscosityLaw, H: NusseltLaw>(
        model: &FiberModel<L, H>,
        params: &[f64],
        summary: &FitSummary,
        options: &FlowCurveOptions,
    ) -> Result<FlowCurve, String> {
        let cov_range = summary
            .strain_rates
            .as_ref()
            .ok_or("the fit has no strain-rate coverage (a report from an older version)")?;
        let t_c = options
            .temperature_k
            .unwrap_or(cov_range.reference_temperature_k);
        if !(t_c.is_finite() && t_c > model.material.vft_t_vf) {
            return Err(format!(
                "flow-curve temperature {t_c} K must lie above the Vogel temperature {} K",
                model.material.vft_t_vf
            ));
        }
        // where the Newtonian law is preferred the curve is that law's (flat), its band the
        // thinning the data still allow (FitSummary::profile_trace)
        let newtonian: Vec<f64>;
        let params = if summary.newtonian_on_data() {
            newtonian = params
                .iter()
                .enumerate()
                .map(|(i, &v)| {
                    if i == model.param_layout().law().start {
                        1.0
                    } else {
                        v
                    }
                })
                .collect();
            &newtonian[..]
        } else {
            params
        };
        // the coverage shifted from its reference temperature to t_c
        let eta0 = |t: f64| eta_with_law(model, params, &law_values(model, params), t, 0.0);
        let shift = eta0(cov_range.reference_temperature_k) / eta0(t_c);
        let [lo, med, hi] = cov_range.reduced_per_s.map(|v| v * shift);
        let rates = rate_grid(lo, hi, options);
        let names = model.law.param_names();
        let cov = law_covariance(summary, names);
        let profile_band = summary.profile_band_needed();
        let shifts = summary
            .error_budget
            .as_ref()
            .map(systematic_shifts)
            .unwrap_or_default();
        let band = if profile_band {
            BandMethod::Profile
        } else if cov.is_some() && summary.law_fitted() {
            BandMethod::Delta
        } else {
            BandMethod::None
        };
        let trace = summary.profile_trace(CHI2_1_95);
        let inputs = PointInputs {
            model,
            params,
            t_c,
            covered: [lo, hi],
            band,
            cov: cov.as_deref(),
            trace: &trace,
            shifts: &shifts,
        };
        let points = rates.iter().map(|&rate| inputs.point(rate)).collect();
        let law = law_values(model, params);
        let isotherms = options
            .isotherms_k
            .iter()
            .filter(|t| t.is_finite() && **t > model.material.vft_t_vf)
            .map(|&t| Isotherm {
                temperature_k: t,
                eta_pa_s: rates
                    .iter()
                    .map(|&r| eta_with_law(model, params, &law, t, r))
                    .collect(),
            })
            .collect();
        Ok(FlowCurve {
            temperature_k: t_c,
            trouton: model.material.trouton,
            plateau_pa_s: eta0(t_c),
            covered_per_s: [lo, hi],
            median_per_s: med,
            band,
            systematic: !shifts.is_empty(),
            points,
            isotherms,
            finding: summary.law_finding(),
            not_a_result: summary.law_not_a_result(),
        })
    }
}

/// What each point of a flow curve is evaluated with: the model with its parameters at the
/// curve's temperature `t_c`, the strain rates the data cover, and the band's method and
/// inputs (the law's covariance, the profile trace, the systematic shifts).
struct PointInputs<'a, L: ViscosityLaw, H: NusseltLaw> {
    model: &'a FiberModel<L, H>,
    params: &'a [f64],
    t_c: f64,
    covered: [f64; 2],
    band: BandMethod,
    cov: Option<&'a [f64]>,
    trace: &'a [Vec<f64>],
    shifts: &'a [[f64; 2]],
}

impl<L: ViscosityLaw, H: NusseltLaw> PointInputs<'_, L, H> {
    /// The curve's point at strain rate `rate` with its statistical, systematic and total bands.
    fn point(&self, rate: f64) -> FlowPoint {
        let [lo, hi] = self.covered;
        let (eta, g) = eta_and_gradient(self.model, self.params, self.t_c, rate);
        let var = |d: &[f64]| -> f64 {
            let s: f64 = g.iter().zip(d).map(|(gi, di)| gi * di).sum();
            (s / eta).powi(2)
        };
        let stat_ln = match (&self.band, &self.cov) {
            (BandMethod::Delta, Some(c)) => {
                let k = g.len();
                let mut v = 0.0;
                for i in 0..k {
                    for j in 0..k {
                        v += g[i] * c[i * k + j] * g[j];
                    }
                }
                Some(Z95 * v.max(0.0).sqrt() / eta)
            }
            _ => None,
        };
        let stat95 = match self.band {
            BandMethod::Profile => self.trace.iter().fold([eta, eta], |[l, h], law| {
                let v = eta_with_law(self.model, self.params, law, self.t_c, rate);
                [l.min(v), h.max(v)]
            }),
            _ => {
                let s = stat_ln.unwrap_or(0.0);
                [eta * (-s).exp(), eta * s.exp()]
            }
        };
        let sys_ln = Z95 * self.shifts.iter().map(|d| var(d)).sum::<f64>().sqrt();
        let (sl, sh) = ((eta / stat95[0]).ln(), (stat95[1] / eta).ln());
        let tot = |s: f64| (s * s + sys_ln * sys_ln).sqrt();
        FlowPoint {
            strain_rate_per_s: rate,
            eta_pa_s: eta,
            stat95_pa_s: stat95,
            sys95_pa_s: [eta * (-sys_ln).exp(), eta * sys_ln.exp()],
            total95_pa_s: [eta * (-tot(sl)).exp(), eta * tot(sh).exp()],
            extrapolated: rate < lo * (1.0 - 1e-12) || rate > hi * (1.0 + 1e-12),
        }
    }
}

/// The curve's strain rates: log-spaced over the covered range `[lo, hi]` extended by the
/// options' decades on each side, at the options' points per decade.
fn rate_grid(lo: f64, hi: f64, options: &FlowCurveOptions) -> Vec<f64> {
    let ext = 10f64.powf(options.extension_decades.max(0.0));
    let (a, b) = ((lo / ext).log10(), (hi * ext).log10());
    let count = ((b - a) * options.points_per_decade.max(2) as f64).ceil() as usize + 1;
    (0..count)
        .map(|i| 10f64.powf(a + (b - a) * i as f64 / (count - 1) as f64))
        .collect()
}

/// The law's parameters among the local model parameters `params`.
fn law_values<L: ViscosityLaw, H: NusseltLaw>(
    model: &FiberModel<L, H>,
    params: &[f64],
) -> Vec<f64> {
    params[model.param_layout().law()].to_vec()
}
