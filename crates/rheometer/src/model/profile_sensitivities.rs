//! Exact derivatives of a simulated experiment's SI profiles with respect to the law
//! parameters `(n, κ)` and the strengths of the model's effects: one forward sensitivity solve
//! ([`Sensitivities`]) on the converged solution, the diameter through
//! [`residual_jacobian`] of the model's own diameter function (dual numbers, no finite
//! differences).

use crate::error::FiberError;
use crate::model::bvp::FiberModel;
use crate::model::material_law::ViscosityLaw;
use crate::model::simulate::FiberSolution;
use diffbvp::sensitivity::{residual_jacobian, PointFunction, Sensitivities};
use diffbvp::{Bvp, DualNum};

/// `d(profile)/d(parameter)` at the output positions of one experiment.
///
/// Each block is a row-major `positions × parameters` matrix in the unit of the profile
/// quantity per unit of the parameter (`m` per unit `n` for the diameter, `K` per unit `κ`
/// for the temperature, ...). The parameters are `n` \[-\], `κ = ln(K / 1 Pa)` \[-\] and the
/// strengths of the model's effects in their own units, in the model's order.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileSensitivities {
    /// Parameter names: `"n"`, `"kappa"`, then the effects' strength names.
    pub parameters: Vec<String>,
    /// Output positions \[m\] (the rows).
    pub positions: Vec<f64>,
    /// `d(diameter)/d(parameter)` \[m per unit\].
    pub diameter: Vec<f64>,
    /// `d(velocity)/d(parameter)` \[m/s per unit\].
    pub velocity: Vec<f64>,
    /// `d(force)/d(parameter)` \[N per unit\].
    pub force: Vec<f64>,
    /// `d(temperature)/d(parameter)` \[K per unit\].
    pub temperature: Vec<f64>,
    /// `d(strain rate)/d(parameter)` \[1/s per unit\].
    pub strain_rate: Vec<f64>,
}

/// The fiber diameter `d̃(y, p)` as a point function of the state and the full parameter
/// vector (unknowns first).
struct Diameter<'a, L: ViscosityLaw> {
    model: &'a FiberModel<L>,
    unknowns: usize,
}

impl<L: ViscosityLaw> PointFunction for Diameter<'_, L> {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, _i: usize, _x: f64, y: &[D], p: &[D]) -> D {
        self.model.fiber_diameter(y, &p[self.unknowns..])
    }
}

/// Exact derivatives of `sol`'s SI profiles at `positions` \[m\] with respect to `n`, `κ` and
/// the model's strengths (see [`ProfileSensitivities`]).
pub fn profile_sensitivities<L: ViscosityLaw>(
    model: &FiberModel<L>,
    sol: &FiberSolution,
    positions: &[f64],
) -> Result<ProfileSensitivities, FiberError> {
    let sol = &sol.solution;
    let sens = Sensitivities::compute(model, sol)?;
    let si = model.coefficients().si;
    let xs: Vec<f64> = positions.iter().map(|s| s / si.length).collect();
    let g = Diameter {
        model,
        unknowns: model.num_unknowns(),
    };
    let (_, jac) = residual_jacobian(model, sol, &sens, &xs, &g)?;
    let q = sol.params.len();
    // p = [c, n, κ, strengths..., take-up factor]: n, κ and the strengths
    let mut parameters = vec!["n".to_string(), "kappa".to_string()];
    parameters.extend(
        model
            .physics
            .strength_parameters()
            .iter()
            .map(|(name, _)| name.to_string()),
    );
    let columns: Vec<usize> = (1..1 + parameters.len()).filter(|&j| j < q).collect();
    parameters.truncate(columns.len());
    let m = columns.len();
    let pick = |row: &[f64], scale: f64, out: &mut Vec<f64>| {
        out.extend(columns.iter().map(|&j| row[j] * scale));
    };
    let mut out = ProfileSensitivities {
        parameters,
        positions: positions.to_vec(),
        diameter: Vec::with_capacity(xs.len() * m),
        velocity: Vec::with_capacity(xs.len() * m),
        force: Vec::with_capacity(xs.len() * m),
        temperature: Vec::with_capacity(xs.len() * m),
        strain_rate: Vec::with_capacity(xs.len() * m),
    };
    for i in 0..xs.len() {
        pick(&jac[i * q..(i + 1) * q], si.diameter, &mut out.diameter);
    }
    // the state is (velocity, force, temperature, strain rate)
    let n = 4;
    let mut dy = vec![0.0; n * q];
    let mut dyp = vec![0.0; n * q];
    for &x in &xs {
        sens.at_into(x, &mut dy, &mut dyp);
        pick(&dy[..q], si.velocity, &mut out.velocity);
        pick(&dy[q..2 * q], si.force, &mut out.force);
        pick(&dy[2 * q..3 * q], si.temperature, &mut out.temperature);
        pick(&dy[3 * q..4 * q], si.strain_rate, &mut out.strain_rate);
    }
    Ok(out)
}
