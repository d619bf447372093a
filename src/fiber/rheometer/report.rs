//! Uncertainty and reports of an identification.
//!
//! Standard errors come from the Gauss–Newton approximation of the covariance,
//! `σ̂² (JᵀJ)⁻¹` with the residual variance `σ̂² = ‖r‖²/(N − p)`; 95% confidence intervals are
//! `± 1.96` standard errors (normal approximation; `N` is in the hundreds). For `K = e^κ` the
//! interval is the image of κ's. For the paper's estimator the residuals are weighted distances
//! to smoothed data, not measurement errors: its standard errors are shown for comparison only.

use super::estimator::Estimator;
use super::identify::Identification;
use serde::{Deserialize, Serialize};

/// The numbers of an identification, as written to JSON.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct FitReport {
    /// Estimator (`"paper"` or `"principled"`).
    pub estimator: Estimator,
    /// Start point `(n, κ)`.
    pub start: [f64; 2],
    /// Power index `n` \[-\].
    pub n: f64,
    /// `κ = ln(K / 1 Pa)` \[-\].
    pub kappa: f64,
    /// `K = e^κ` \[Pa\].
    #[serde(rename = "K_Pa")]
    pub k_pa: f64,
    /// Standard error of `n`.
    pub stderr_n: f64,
    /// Standard error of `κ`.
    pub stderr_kappa: f64,
    /// 95% confidence interval of `n`.
    pub ci95_n: [f64; 2],
    /// 95% confidence interval of `κ`.
    pub ci95_kappa: [f64; 2],
    /// 95% confidence interval of `K` \[Pa\].
    #[serde(rename = "ci95_K_Pa")]
    pub ci95_k_pa: [f64; 2],
    /// Correlation of `n` and `κ`.
    pub correlation_n_kappa: f64,
    /// Cost `J = ‖r‖²` of the estimator at the optimum.
    pub cost: f64,
    /// RMS of `(d_model − d_meas)/d_meas` over all raw measurements \[-\].
    pub rms_relative_residual: f64,
    /// Take-up factors `φ_k = d_out,k/d_fit,k(L)` (1 for the paper's estimator).
    pub take_up_factors: Vec<f64>,
    /// Number of residuals.
    pub residuals: usize,
    /// Gauss–Newton iterations (trial steps).
    pub iterations: usize,
    /// Trial points where a BVP failed (rejected steps).
    pub failed_evaluations: usize,
    /// Wall time \[s\].
    pub wall_time_s: f64,
    /// Why the fit stopped.
    pub termination: String,
    /// The model's extra effects with their strengths (empty for the paper's model).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub effects: Vec<EffectReport>,
}

/// An effect's strength in a fit report.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EffectReport {
    /// Canonical name (e.g. `"radiation"`).
    pub effect: String,
    /// Strength (in the effect's unit, see `unit`).
    pub strength: f64,
    /// Its standard error (`0` if fixed).
    pub stderr_strength: f64,
    /// 95% confidence interval.
    pub ci95_strength: [f64; 2],
    /// Unit of the strength.
    pub unit: String,
    /// Whether it was fitted (else fixed).
    pub fitted: bool,
}

impl FitReport {
    /// Builds the report of an identification.
    pub fn new(id: &Identification) -> Self {
        let se = id
            .fit
            .standard_errors()
            .unwrap_or_else(|| vec![f64::NAN; id.fit.p.len()]);
        let np = id.fit.p.len();
        let col = |name: &str| id.names.iter().position(|n| n == name);
        let (ni, ki) = (col("n"), col("kappa"));
        let corr = match (ni, ki, id.fit.correlation()) {
            (Some(a), Some(b), Some(c)) => c[a * np + b],
            _ => f64::NAN,
        };
        let sn = ni.map_or(f64::NAN, |i| se[i]);
        let sk = ki.map_or(f64::NAN, |i| se[i]);
        let z = 1.96;
        let effects = id
            .effects
            .iter()
            .map(|slot| {
                let e = &slot.effect;
                let strength = e.strength_of(id.local_params[slot.local]);
                let sd = slot.column.map_or(0.0, |c| se[c]);
                EffectReport {
                    effect: e.name().to_string(),
                    strength,
                    stderr_strength: sd,
                    ci95_strength: [strength - z * sd, strength + z * sd],
                    unit: e.unit().to_string(),
                    fitted: slot.column.is_some(),
                }
            })
            .collect();
        FitReport {
            estimator: id.estimator,
            start: id.start,
            n: id.n,
            kappa: id.kappa,
            k_pa: id.kappa.exp(),
            stderr_n: sn,
            stderr_kappa: sk,
            ci95_n: [id.n - z * sn, id.n + z * sn],
            ci95_kappa: [id.kappa - z * sk, id.kappa + z * sk],
            ci95_k_pa: [(id.kappa - z * sk).exp(), (id.kappa + z * sk).exp()],
            correlation_n_kappa: corr,
            cost: 2.0 * id.fit.cost,
            rms_relative_residual: id.rms_relative_residual,
            take_up_factors: id.take_up_factors.clone(),
            residuals: id.fit.num_residuals(),
            iterations: id.fit.iterations,
            failed_evaluations: id.fit.failed_evaluations,
            wall_time_s: id.wall_time_s,
            termination: id.fit.termination.to_string(),
            effects,
        }
    }

    /// Whether `(n, κ)` lies in the 95% confidence region box.
    pub fn covers(&self, n: f64, kappa: f64) -> bool {
        n >= self.ci95_n[0]
            && n <= self.ci95_n[1]
            && kappa >= self.ci95_kappa[0]
            && kappa <= self.ci95_kappa[1]
    }

    /// An lmfit-style text report.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        s.push_str(&format!("[[Fit: {} estimator]]\n", self.estimator.name()));
        s.push_str(&format!(
            "    start             = (n, kappa) = ({}, {})\n",
            self.start[0], self.start[1]
        ));
        s.push_str(&format!("    termination       = {}\n", self.termination));
        s.push_str(&format!(
            "    iterations        = {} ({} failed BVP trial points)\n",
            self.iterations, self.failed_evaluations
        ));
        s.push_str(&format!(
            "    wall time         = {:.3} s\n",
            self.wall_time_s
        ));
        s.push_str(&format!("    residuals         = {}\n", self.residuals));
        s.push_str(&format!("    cost J            = {:.6e}\n", self.cost));
        s.push_str(&format!(
            "    RMS (d_model - d_meas)/d_meas = {:.4} %\n",
            100.0 * self.rms_relative_residual
        ));
        s.push_str("[[Variables]]\n");
        if self.stderr_n.is_nan() && self.stderr_kappa.is_nan() && self.n == 1.0 {
            // a Newtonian model: the law has no fitted parameter and κ does not enter
            s.push_str("    law:   Newtonian (n = 1 fixed; kappa and K do not enter)\n");
        } else {
            s.push_str(&format!(
                "    n:     {:.5} +/- {:.5} ({:.2}%)  95% CI [{:.5}, {:.5}]\n",
                self.n,
                self.stderr_n,
                100.0 * self.stderr_n / self.n.abs(),
                self.ci95_n[0],
                self.ci95_n[1]
            ));
            s.push_str(&format!(
                "    kappa: {:.5} +/- {:.5} ({:.2}%)  95% CI [{:.5}, {:.5}]\n",
                self.kappa,
                self.stderr_kappa,
                100.0 * self.stderr_kappa / self.kappa.abs(),
                self.ci95_kappa[0],
                self.ci95_kappa[1]
            ));
            s.push_str(&format!(
                "    K:     {:.5e} Pa  95% CI [{:.5e}, {:.5e}] Pa\n",
                self.k_pa, self.ci95_k_pa[0], self.ci95_k_pa[1]
            ));
        }
        if self.estimator == Estimator::Principled {
            let f: Vec<String> = self
                .take_up_factors
                .iter()
                .map(|v| format!("{v:.4}"))
                .collect();
            s.push_str(&format!(
                "    take-up factors d_out/d_fit(L): [{}]\n",
                f.join(", ")
            ));
        }
        for e in &self.effects {
            if e.fitted {
                s.push_str(&format!(
                    "    {}: {:.5} +/- {:.5} {}  95% CI [{:.5}, {:.5}]\n",
                    e.effect,
                    e.strength,
                    e.stderr_strength,
                    e.unit,
                    e.ci95_strength[0],
                    e.ci95_strength[1]
                ));
            } else {
                s.push_str(&format!(
                    "    {}: {:.5} {} (fixed)\n",
                    e.effect, e.strength, e.unit
                ));
            }
        }
        if self.correlation_n_kappa.is_finite() {
            s.push_str("[[Correlations]]\n");
            s.push_str(&format!(
                "    C(n, kappa) = {:+.4}\n",
                self.correlation_n_kappa
            ));
        }
        s
    }
}
