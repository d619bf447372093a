//! The two estimators of the rheometer as point functions of the simulated fiber.

use crate::model::bvp::FiberModel;
use crate::model::contributions::NusseltLaw;
use crate::model::material_law::ViscosityLaw;
use diffbvp::sensitivity::PointFunction;
use num_dual::DualNum;

/// Which cost the identification minimises. In JSON it is spelt as on the command line and in
/// Python (`"principled"`, `"paper"`); reports that spelt it capitalised still read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Estimator {
    /// The paper's cost (eq. opt:disc): `J = Σ_k ‖diag(√Δ) diag(√ε̇) (d(p) − d_fit)‖²` on `n_o`
    /// regular points per experiment, against the smoothed data, with the take-up diameter fixed
    /// at `d_fit(L)`. Biased by the smoothing step (see the book).
    #[serde(alias = "Paper")]
    Paper,
    /// Least squares of the relative residuals `(d_model − d_meas)/(σ d_meas)` against the raw
    /// measurements, with each experiment's take-up diameter fitted as a nuisance parameter
    /// (started from `d_fit(L)`); `σ` is the relative measurement uncertainty.
    #[serde(alias = "Principled")]
    Principled,
}

impl Estimator {
    /// Lower-case name for reports and file names.
    pub fn name(&self) -> &'static str {
        match self {
            Estimator::Paper => "paper",
            Estimator::Principled => "principled",
        }
    }
}

/// The paper's weighted residual `√Δ_j √ε̇(s_j) (d(s_j) − d_fit(s_j))` (dimensionless), `d` the
/// gauge's reading ([`FiberModel::observed_diameter`]).
pub(crate) struct PaperResidual<'a, L: ViscosityLaw, H: NusseltLaw> {
    /// The fiber model.
    pub model: &'a FiberModel<L, H>,
    /// `√Δ_j` (dimensionless grid spacing).
    pub sqrt_delta: &'a [f64],
    /// Smoothed diameters `d_fit(s_j)` (dimensionless).
    pub d_fit: &'a [f64],
}

impl<L: ViscosityLaw, H: NusseltLaw> PointFunction for PaperResidual<'_, L, H> {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, j: usize, _x: f64, y: &[D], p: &[D]) -> D {
        // the gauge's reading (instrument parameters, if any, enter here)
        let d = self.model.observed_diameter(y, p);
        let rate = y[3];
        let w = if rate.re() > 0.0 {
            rate.sqrt()
        } else {
            D::zero()
        };
        w * (d - self.d_fit[j]) * self.sqrt_delta[j]
    }
}

/// The relative residual `(d(s_j) − d_meas,j)/(σ_j d_meas,j)`, `d` the gauge's reading
/// ([`FiberModel::observed_diameter`]: `(1 + g) d + o` with the instrument parameters).
pub struct RelativeResidual<'a, L: ViscosityLaw, H: NusseltLaw> {
    /// The fiber model.
    pub model: &'a FiberModel<L, H>,
    /// Measured diameters (dimensionless).
    pub d_meas: &'a [f64],
    /// Relative uncertainty `σ_j` of each measurement \[-\] (all 1 for plain relative
    /// residuals; a noise that varies along the line weights the points by it).
    pub sigma: &'a [f64],
}

impl<L: ViscosityLaw, H: NusseltLaw> PointFunction for RelativeResidual<'_, L, H> {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, j: usize, _x: f64, y: &[D], p: &[D]) -> D {
        // the gauge's reading (instrument parameters, if any, enter here)
        let d = self.model.observed_diameter(y, p);
        (d / self.d_meas[j] - 1.0) / self.sigma[j]
    }
}
