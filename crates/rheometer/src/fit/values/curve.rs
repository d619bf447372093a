//! The flow curve of a fit as a value ([`FlowCurve`]): the identified elongational viscosity
//! `η_E(ε̇)` \[Pa s\] at one temperature, point by point ([`FlowPoint`]) with its statistical,
//! systematic and total 95 % bands ([`BandMethod`]), the curve at other temperatures
//! ([`Isotherm`]), and the curve as CSV. A fit's summary holds it;
//! [`flow_curve`](crate::fit::uncertainty::flow_curve) computes it.

use serde::{Deserialize, Serialize};

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
    /// Why the fit's law is not a result, if it is not ([`FitSummary::law_not_a_result`]
    /// of the fit the curve is drawn from): the figure then says so in its title and legend.
    ///
    /// [`FitSummary::law_not_a_result`]: crate::fit::FitSummary::law_not_a_result
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub not_a_result: Option<String>,
}

impl FlowCurve {
    /// The point nearest to `rate` \[1/s\] on a log scale.
    pub fn nearest(&self, rate: f64) -> Option<&FlowPoint> {
        self.points.iter().min_by(|a, b| {
            let d = |p: &FlowPoint| (p.strain_rate_per_s / rate).ln().abs();
            d(a).total_cmp(&d(b))
        })
    }

    /// The curve as CSV, units in the header: `strain_rate_per_s, eta_E_Pa_s`, the three bands
    /// (`stat95_low_Pa_s`, ...), `plateau_Pa_s` (Trouton), `extrapolated` (0/1),
    /// `law_is_a_result` (0 where the fit's law is no result, [`FlowCurve::not_a_result`]; the
    /// reason is in the JSON and the report), and one `eta_E_at_<T>K_Pa_s` column per
    /// isotherm; the curve's temperature in `temperature_K`.
    pub fn to_csv(&self) -> String {
        let mut s = String::from(
            "strain_rate_per_s,eta_E_Pa_s,stat95_low_Pa_s,stat95_high_Pa_s,sys95_low_Pa_s,\
             sys95_high_Pa_s,total95_low_Pa_s,total95_high_Pa_s,plateau_Pa_s,temperature_K,\
             extrapolated,law_is_a_result",
        );
        for iso in &self.isotherms {
            s.push_str(&format!(",eta_E_at_{:.2}K_Pa_s", iso.temperature_k));
        }
        s.push('\n');
        for (i, p) in self.points.iter().enumerate() {
            s.push_str(&format!(
                "{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{},{},{}",
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
                u8::from(p.extrapolated),
                // on every row, so a spreadsheet that keeps a few columns keeps it too
                u8::from(self.not_a_result.is_none())
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
