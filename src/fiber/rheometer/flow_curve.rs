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
//!   the fitted solutions ([`StrainRateCoverage`]), shifted to the curve's temperature by the
//!   VFT factor `a_T = η₀(T)/η₀(T_ref)` (time–temperature superposition: the Carreau-type laws
//!   depend on `η₀(T)·ε̇` only, so a point of the spin line at temperature `T` and rate `ε̇`
//!   probes the curve at `T_ref` at the rate `a_T ε̇`). Outside that range, extended by a decade
//!   on each side, the curve is extrapolated and marked so.
//! * **Statistical band (95 %).** By the delta method on `ln η_E` from the covariance of the
//!   law's fitted parameters (`(n, κ)`), `η_E exp(±1.96 σ_ln)`; where the linearised interval
//!   of a law parameter is not trustworthy (see [`profile`](super::profile)), the envelope of
//!   the curves along its likelihood profile within the 95 % deviance instead.
//! * **Systematic band (95 %, `k = 1.96`).** From the error budget: each source's signed shifts
//!   of `(n, κ)` at one standard uncertainty (common sources summed over the experiments,
//!   per-experiment ones in quadrature), propagated to `ln η_E` by the same exact gradient and
//!   added in quadrature. The total band combines both in quadrature.

use super::budget::ErrorBudget;
use super::data::Rheometer;
use super::summary::{FitSummary, Z95};
use crate::fiber::contributions::NusseltLaw;
use crate::fiber::material_law::ViscosityLaw;
use crate::fiber::model::FiberModel;
use crate::fiber::statistics::median;
use crate::fiber::uncertainty::Scope;
use crate::solution::Solution;
use num_dual::Dual64;
use serde::{Deserialize, Serialize};

/// The 95 % point of the χ² distribution with one degree of freedom (`1.96²`).
pub const CHI2_1_95: f64 = Z95 * Z95;

/// A measurement position counts towards the strain rates the data cover where the model's
/// strain rate exceeds this fraction of its largest value along that experiment's line: where
/// the fiber still draws. Downstream the fiber has frozen; its diameter no longer depends on
/// the law, while its reduced rate `a_T ε̇` (tiny rate, huge shift factor) would claim
/// coverage up to 1e12 1/s.
pub const DRAWING_FRACTION: f64 = 0.01;

/// The strain rates \[1/s\] of a fit's model at the measurement positions where the fiber
/// draws ([`DRAWING_FRACTION`]) (JSON: `strain_rates` of a fit).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StrainRateCoverage {
    /// Temperature the reduced rates refer to \[K\]: the median die (inlet) temperature.
    pub reference_temperature_k: f64,
    /// Smallest, median and largest model strain rate at the measurement positions where the
    /// fiber draws \[1/s\], as they occur on the spin line.
    pub measured_per_s: [f64; 3],
    /// The same rates shifted to `reference_temperature_k` by the VFT factor
    /// `η₀(T)/η₀(T_ref)` \[1/s\]: the part of the flow curve at `T_ref` the data probe.
    pub reduced_per_s: [f64; 3],
    /// Coldest and hottest melt temperature at those positions \[K\].
    pub temperature_k: [f64; 2],
}

impl Rheometer {
    /// The strain rates the data cover, from the fitted `solutions` (one per experiment) at the
    /// measurement positions where the fiber draws (`None` without a positive rate).
    pub fn strain_rate_coverage(&self, solutions: &[Solution]) -> Option<StrainRateCoverage> {
        let mut inlet: Vec<f64> = self
            .experiments
            .iter()
            .map(|e| e.inlet_temperature)
            .collect();
        let t_ref = median(&mut inlet);
        let (mut raw, mut reduced) = (Vec::new(), Vec::new());
        let (mut t_lo, mut t_hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut y = [0.0; 4];
        let mut yp = [0.0; 4];
        for (k, sol) in solutions.iter().enumerate() {
            let (Some(model), Some(m)) = (self.models.get(k), self.measurements.get(k)) else {
                continue;
            };
            let sc = &model.scaling;
            let (lo, t_o) = (sc.reference.length, sc.reference.temperature);
            let eta0_ref = model.viscosity_at(t_ref / t_o, 0.0, &sol.params);
            let states: Vec<(f64, f64, f64)> = m
                .positions
                .iter()
                .map(|&s| {
                    sol.eval_into(s / lo, &mut y, &mut yp);
                    (y[2], y[3] * sc.strain_rate(), y[2] * t_o)
                })
                .collect();
            let peak = states.iter().map(|s| s.1).fold(0.0, f64::max);
            for &(t_nd, rate, t) in &states {
                if !(rate > DRAWING_FRACTION * peak && rate.is_finite() && t.is_finite()) {
                    continue;
                }
                let a_t = model.viscosity_at(t_nd, 0.0, &sol.params) / eta0_ref;
                raw.push(rate);
                reduced.push(rate * a_t);
                t_lo = t_lo.min(t);
                t_hi = t_hi.max(t);
            }
        }
        let three = |v: &mut Vec<f64>| -> Option<[f64; 3]> {
            let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            (lo.is_finite() && hi.is_finite()).then(|| [lo, median(v), hi])
        };
        Some(StrainRateCoverage {
            reference_temperature_k: t_ref,
            measured_per_s: three(&mut raw)?,
            reduced_per_s: three(&mut reduced)?,
            temperature_k: [t_lo, t_hi],
        })
    }
}

/// How the statistical band was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum BandMethod {
    /// Delta method on `ln η_E` from the covariance of the law's parameters.
    #[default]
    Delta,
    /// Envelope of the curves along the likelihood profiles within the 95 % deviance.
    Profile,
    /// No fitted law parameter (or no covariance): no statistical band.
    None,
}

/// One strain rate of a [`FlowCurve`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FlowPoint {
    /// Strain rate `ε̇` \[1/s\].
    pub strain_rate_per_s: f64,
    /// Elongational viscosity `η_E` \[Pa s\].
    pub eta_pa_s: f64,
    /// Statistical 95 % band \[Pa s\] (`[η, η]` without one).
    pub stat95_pa_s: [f64; 2],
    /// Systematic 95 % band \[Pa s\] (`[η, η]` without an error budget).
    pub sys95_pa_s: [f64; 2],
    /// Both combined in quadrature (on `ln η`) \[Pa s\].
    pub total95_pa_s: [f64; 2],
    /// Outside the strain rates the data cover: the law is extrapolated here.
    pub extrapolated: bool,
}

/// The curve at another melt temperature (VFT shift), without bands.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Isotherm {
    /// Temperature \[K\].
    pub temperature_k: f64,
    /// `η_E` \[Pa s\] at the strain rates of the curve's points.
    pub eta_pa_s: Vec<f64>,
}

/// The identified elongational viscosity against strain rate at one temperature (JSON:
/// `flow_curve` of a fit, and `flow_curve.json` of `rheometer fit --out`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FlowCurve {
    /// Temperature of the curve \[K\].
    pub temperature_k: f64,
    /// Trouton ratio `η_E0/η_s0` of the material \[-\].
    pub trouton: f64,
    /// Newtonian plateau `Tr·η_s0(T)` \[Pa s\] (the zero-rate elongational viscosity).
    pub plateau_pa_s: f64,
    /// Strain rates the data cover at this temperature \[1/s\] (`[min, max]`).
    pub covered_per_s: [f64; 2],
    /// Median strain rate of the data at this temperature \[1/s\].
    pub median_per_s: f64,
    /// How the statistical band was obtained.
    pub band: BandMethod,
    /// Whether the systematic band comes from an error budget (else it is zero width).
    pub systematic: bool,
    /// The curve, ascending in strain rate.
    pub points: Vec<FlowPoint>,
    /// The curve at other melt temperatures along the line.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub isotherms: Vec<Isotherm>,
    /// What the data support, in one sentence (e.g. "no strain thinning detected ...").
    #[serde(default)]
    pub finding: String,
}

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
        // the coverage shifted from its reference temperature to t_c
        let eta0 = |t: f64| eta_with_law(model, params, &law_values(model, params), t, 0.0);
        let shift = eta0(cov_range.reference_temperature_k) / eta0(t_c);
        let [lo, med, hi] = cov_range.reduced_per_s.map(|v| v * shift);
        let ext = 10f64.powf(options.extension_decades.max(0.0));
        let (a, b) = ((lo / ext).log10(), (hi * ext).log10());
        let count = ((b - a) * options.points_per_decade.max(2) as f64).ceil() as usize + 1;
        let rates: Vec<f64> = (0..count)
            .map(|i| 10f64.powf(a + (b - a) * i as f64 / (count - 1) as f64))
            .collect();
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
        let points = rates
            .iter()
            .map(|&rate| {
                let (eta, g) = eta_and_gradient(model, params, t_c, rate);
                let var = |d: &[f64]| -> f64 {
                    let s: f64 = g.iter().zip(d).map(|(gi, di)| gi * di).sum();
                    (s / eta).powi(2)
                };
                let stat_ln = match (&band, &cov) {
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
                let stat95 = match band {
                    BandMethod::Profile => trace.iter().fold([eta, eta], |[l, h], law| {
                        let v = eta_with_law(model, params, law, t_c, rate);
                        [l.min(v), h.max(v)]
                    }),
                    _ => {
                        let s = stat_ln.unwrap_or(0.0);
                        [eta * (-s).exp(), eta * s.exp()]
                    }
                };
                let sys_ln = Z95 * shifts.iter().map(|d| var(d)).sum::<f64>().sqrt();
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
            })
            .collect();
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
        })
    }

    /// The point nearest to `rate` \[1/s\] on a log scale.
    pub fn nearest(&self, rate: f64) -> Option<&FlowPoint> {
        self.points.iter().min_by(|a, b| {
            let d = |p: &FlowPoint| (p.strain_rate_per_s / rate).ln().abs();
            d(a).total_cmp(&d(b))
        })
    }

    /// The curve as CSV, units in the header: `strain_rate_per_s, eta_E_Pa_s`, the three bands
    /// (`stat95_low_Pa_s`, ...), `plateau_Pa_s` (Trouton), `extrapolated` (0/1), and one
    /// `eta_E_at_<T>K_Pa_s` column per isotherm; the curve's temperature in `temperature_K`.
    pub fn to_csv(&self) -> String {
        let mut s = String::from(
            "strain_rate_per_s,eta_E_Pa_s,stat95_low_Pa_s,stat95_high_Pa_s,sys95_low_Pa_s,\
             sys95_high_Pa_s,total95_low_Pa_s,total95_high_Pa_s,plateau_Pa_s,temperature_K,\
             extrapolated",
        );
        for iso in &self.isotherms {
            s.push_str(&format!(",eta_E_at_{:.2}K_Pa_s", iso.temperature_k));
        }
        s.push('\n');
        for (i, p) in self.points.iter().enumerate() {
            s.push_str(&format!(
                "{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{},{}",
                p.strain_rate_per_s,
                p.eta_pa_s,
                p.stat95_pa_s[0],
                p.stat95_pa_s[1],
                p.sys95_pa_s[0],
                p.sys95_pa_s[1],
                p.total95_pa_s[0],
                p.total95_pa_s[1],
                self.plateau_pa_s,
                self.temperature_k,
                u8::from(p.extrapolated)
            ));
            for iso in &self.isotherms {
                s.push_str(&format!(
                    ",{:.6e}",
                    iso.eta_pa_s.get(i).copied().unwrap_or(f64::NAN)
                ));
            }
            s.push('\n');
        }
        s
    }
}

/// The law's parameters among the local model parameters `params`.
fn law_values<L: ViscosityLaw, H: NusseltLaw>(
    model: &FiberModel<L, H>,
    params: &[f64],
) -> Vec<f64> {
    params[model.param_layout().law()].to_vec()
}
