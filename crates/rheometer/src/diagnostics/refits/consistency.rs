//! Is each fitted effect's strength the same in every experiment? (the diagnosis' stage 10,
//! and the check of `fit --with`)
//!
//! A physical constant (an emissivity, a Nusselt factor, the gauge's calibration, the air's
//! profile around one line) has one value in every run. An effect that brings the residuals to
//! the noise only with a strength that changes with the experiment's conditions does not
//! explain the data: it stands in for something else (an effect outside the candidates whose
//! imprint grows with the draw-down, say), and the law fitted with it is biased.
//!
//! The test is the score (Lagrange-multiplier) test of the final fit, which needs no new fit:
//! the strength is let vary linearly with the conditions that differ between the experiments
//! (`ln Q`, the draw-down `2 ln(d_first/d_last)` of the measured diameters, the inlet and the
//! air temperature, those that vary), i.e. its residual column, restricted to each experiment's
//! rows, times the centred condition. Projected off the fitted parameters' columns (the law,
//! every strength and shape, each experiment's take-up factor: exactly, block by block, so the
//! cost is linear in the experiments), these `d` columns remove `ΔJ` of the cost `J` to first
//! order; `F = (ΔJ/d) / ((J − ΔJ)/(N − P − d))` follows the F distribution with `(d, N − P − d)`
//! degrees of freedom when the strength is the same everywhere and the residuals are Gaussian
//! with the fit's weights. The variance comes from the residuals themselves, so an uncertain
//! noise level does not enter. An effect fails the test when `P(F > f)` is below
//! [`CONSISTENCY_LEVEL`] divided by the number of effects tested.

use crate::data::statistics::distributions::f_survival;
use crate::fit::summary::text::fmt_p;
use crate::fit::{FitWarning, Identification, WarningCode};
use crate::model::setup::ExperimentSet;
use crate::report::format::{fmt_at, unit_suffix};
use diffbvp::least_squares::Loss;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use std::ops::Range;

/// Significance level of the test, for all named effects together (divided among them).
pub const CONSISTENCY_LEVEL: f64 = 0.01;

/// An experiment's name and a value for it.
pub type ByExperiment = (String, f64);

/// Whether a named effect's strength is the same in every experiment (see the module
/// documentation).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Consistency {
    /// The effect.
    pub effect: String,
    /// Unit of its strength.
    pub unit: String,
    /// Its strength in the final fit (one value for every experiment), in `unit`.
    pub strength: f64,
    /// The experiment conditions the strength was let vary with (those that differ between the
    /// experiments): `"ln mass flow"`, `"draw-down"`, `"inlet temperature"`,
    /// `"air temperature"`.
    pub conditions: Vec<String>,
    /// The test statistic `F` \[-\].
    pub f_statistic: f64,
    /// Its degrees of freedom `(d, N − P − d)`.
    pub dof: [usize; 2],
    /// `P(F > f_statistic)` for a strength that is the same in every experiment \[-\].
    pub p_value: f64,
    /// The level `p_value` is compared with (the overall level divided among the effects
    /// tested) \[-\].
    pub level: f64,
    /// Share of the final fit's cost `J` a strength varying with the conditions would remove,
    /// to first order \[-\].
    pub share_of_cost: f64,
    /// Per experiment, the strength such a varying fit gives, to first order about
    /// `strength`, in `unit`.
    pub by_experiment: Vec<ByExperiment>,
}

impl Consistency {
    /// Whether the data are consistent with one strength for every experiment.
    pub fn consistent(&self) -> bool {
        self.p_value.is_nan() || self.p_value >= self.level
    }

    /// The experiments with the lowest and the highest first-order strength (name, strength).
    pub fn extremes(&self) -> Option<(&ByExperiment, &ByExperiment)> {
        let lo = self
            .by_experiment
            .iter()
            .min_by(|a, b| a.1.total_cmp(&b.1))?;
        let hi = self
            .by_experiment
            .iter()
            .max_by(|a, b| a.1.total_cmp(&b.1))?;
        Some((lo, hi))
    }

    /// A strength in words, to a tenth of the spread between the experiments, with its unit.
    pub fn strength_words(&self, v: f64) -> String {
        let spread = self.extremes().map_or(0.0, |(lo, hi)| hi.1 - lo.1);
        format!("{}{}", fmt_at(v, spread / 10.0), unit_suffix(&self.unit))
    }

    /// "from 0.09 (v0p27_p1) to 0.84 (v1p06_p3)": the lowest and the highest first-order
    /// strength (empty without experiments).
    pub fn spread_words(&self) -> String {
        match self.extremes() {
            Some((lo, hi)) => format!(
                "from {} ({}) to {} ({})",
                self.strength_words(lo.1),
                lo.0,
                self.strength_words(hi.1),
                hi.0
            ),
            None => String::new(),
        }
    }

    /// "F = 20.06 on 2 and 220 degrees of freedom, p = 9.9e-9".
    pub fn test_words(&self) -> String {
        format!(
            "F = {:.2} on {} and {} degrees of freedom, {}",
            self.f_statistic,
            self.dof[0],
            self.dof[1],
            fmt_p(self.p_value)
        )
    }
}

/// The `implausible` warning of a fit whose effect fails the test: the law is not a result.
pub fn warning(c: &Consistency) -> FitWarning {
    FitWarning::new(
        WarningCode::Implausible,
        format!(
            "{} does not have one strength in every experiment: letting it vary with {} removes \
             {:.1} % of J ({}), to first order {}; an effect that must change with the \
             experiment's conditions stands in for something else, and the material law (n, \
             kappa) fitted with it is biased and not a result",
            c.effect,
            c.conditions.join(", "),
            100.0 * c.share_of_cost,
            c.test_words(),
            c.spread_words()
        ),
    )
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `v −= (q·v) q` for each unit vector `q` of `basis` (on `rows` of `v`).
fn remove(v: &mut [f64], basis: &[Vec<f64>]) {
    for q in basis {
        let c = dot(v, q);
        for (x, y) in v.iter_mut().zip(q) {
            *x -= c * y;
        }
    }
}

/// Appends `v` (normalised) to `basis` unless it lies in its span (norm below `tol` after the
/// projection, done twice for accuracy).
fn extend_basis(basis: &mut Vec<Vec<f64>>, mut v: Vec<f64>, tol: f64) {
    remove(&mut v, basis);
    remove(&mut v, basis);
    let norm = dot(&v, &v).sqrt();
    if norm > tol {
        basis.push(v.into_iter().map(|x| x / norm).collect());
    }
}

/// An orthonormal basis of the final fit's Jacobian columns: per experiment its local columns
/// (the take-up factor) on its rows, then the shared columns with those removed.
struct FitSpan {
    blocks: Vec<(Range<usize>, Vec<Vec<f64>>)>,
    shared: Vec<Vec<f64>>,
}

impl FitSpan {
    /// The span of `id`'s Jacobian (block-arrow or dense), and its shared columns; `None`
    /// where the Jacobian is missing or its shape does not match the experiments' rows.
    fn of(id: &Identification, rows: &[Range<usize>]) -> Option<(Self, Vec<Vec<f64>>)> {
        let f = &id.fit;
        let n = f.residuals.len();
        let ns = id.names.len();
        let (shared, locals): (Vec<Vec<f64>>, Vec<Vec<Vec<f64>>>) = match &f.block_jacobian {
            Some(b) => {
                let st = b.structure();
                if st.num_residuals() != n
                    || st.num_shared() != ns
                    || st.num_blocks() != rows.len()
                    || (0..rows.len()).any(|k| st.rows(k) != rows[k])
                {
                    return None;
                }
                let sh = b.shared();
                let shared = (0..ns)
                    .map(|j| (0..n).map(|i| sh[i * ns + j]).collect())
                    .collect();
                let locals = (0..rows.len())
                    .map(|k| {
                        let nl = st.locals(k).len();
                        let l = b.local(k);
                        (0..nl)
                            .map(|c| (0..rows[k].len()).map(|i| l[i * nl + c]).collect())
                            .collect()
                    })
                    .collect();
                (shared, locals)
            }
            None => {
                let p = f.p.len();
                let x = &f.jacobian;
                if x.len() != n * p || p != ns + rows.len() {
                    return None;
                }
                let shared = (0..ns)
                    .map(|j| (0..n).map(|i| x[i * p + j]).collect())
                    .collect();
                let locals = rows
                    .iter()
                    .enumerate()
                    .map(|(k, r)| vec![r.clone().map(|i| x[i * p + ns + k]).collect()])
                    .collect();
                (shared, locals)
            }
        };
        let mut span = FitSpan {
            blocks: Vec::with_capacity(rows.len()),
            shared: Vec::with_capacity(ns),
        };
        for (r, cols) in rows.iter().zip(locals) {
            let mut basis = Vec::new();
            for c in cols {
                let tol = 1e-10 * dot(&c, &c).sqrt();
                extend_basis(&mut basis, c, tol);
            }
            span.blocks.push((r.clone(), basis));
        }
        for c in &shared {
            let mut v = c.clone();
            span.project_blocks(&mut v);
            let tol = 1e-10 * dot(c, c).sqrt();
            let basis = &mut span.shared;
            extend_basis(basis, v, tol);
        }
        Some((span, shared))
    }

    fn project_blocks(&self, v: &mut [f64]) {
        for (r, basis) in &self.blocks {
            remove(&mut v[r.clone()], basis);
        }
    }

    /// `v` with its component in the span removed (twice, for accuracy).
    fn orthogonal(&self, mut v: Vec<f64>) -> Vec<f64> {
        for _ in 0..2 {
            self.project_blocks(&mut v);
            remove(&mut v, &self.shared);
        }
        v
    }
}

/// The conditions that differ between the experiments of the final fit (named, centred, one
/// value per experiment), at most one fewer than the experiments; `None` where an experiment
/// of the fit is not in `set` or has no measurements.
fn conditions(id: &Identification, set: &ExperimentSet) -> Option<Vec<(String, Vec<f64>)>> {
    let mut raw: Vec<(&str, Vec<f64>)> = vec![
        ("ln mass flow", Vec::new()),
        ("draw-down", Vec::new()),
        ("inlet temperature", Vec::new()),
        ("air temperature", Vec::new()),
    ];
    for name in &id.summary.experiments {
        let k = set.experiments.iter().position(|e| &e.name == name)?;
        let e = &set.experiments[k];
        let m = set.measurements.get(k)?.as_ref()?;
        let (first, last) = (m.diameters.first()?, m.diameters.last()?);
        raw[0].1.push(e.mass_flow.ln());
        raw[1].1.push(2.0 * (first / last).ln());
        raw[2].1.push(e.inlet_temperature);
        raw[3].1.push(e.air_temperature);
    }
    let m = id.summary.experiments.len();
    let mut basis = vec![vec![1.0 / (m as f64).sqrt(); m]];
    let mut kept = Vec::new();
    for (name, z) in raw {
        if z.iter().any(|v| !v.is_finite()) {
            continue;
        }
        let before = basis.len();
        let scale = dot(&z, &z).sqrt();
        extend_basis(&mut basis, z.clone(), 1e-6 * scale.max(1e-300));
        if basis.len() > before {
            let mean = z.iter().sum::<f64>() / m as f64;
            kept.push((name.to_string(), z.iter().map(|v| v - mean).collect()));
        }
    }
    Some(kept)
}

/// Solves the small symmetric positive definite system `g x = b` (row-major `g`, Cholesky);
/// `None` if `g` is not positive definite.
fn solve_spd(g: &[f64], b: &[f64]) -> Option<Vec<f64>> {
    let d = b.len();
    let chol = DMatrix::from_row_slice(d, d, g).cholesky()?;
    Some(
        chol.solve(&DVector::from_column_slice(b))
            .as_slice()
            .to_vec(),
    )
}

/// The test for each of `effects` (their strengths fitted in `id`, a least-squares fit on
/// `set`); empty where it cannot be done (one experiment, no condition that varies, a
/// Jacobian that is not there, a robust loss).
pub fn check(id: &Identification, effects: &[String], set: &ExperimentSet) -> Vec<Consistency> {
    if id.fit.loss != Loss::Linear {
        return Vec::new();
    }
    let mut rows = Vec::with_capacity(id.residual_profiles.len());
    let mut at = 0;
    for (s, _) in &id.residual_profiles {
        rows.push(at..at + s.len());
        at += s.len();
    }
    let r = &id.fit.residuals;
    if at != r.len() || rows.len() < 2 {
        return Vec::new();
    }
    let Some(conds) = conditions(id, set).filter(|c| !c.is_empty()) else {
        return Vec::new();
    };
    let Some((span, shared)) = FitSpan::of(id, &rows) else {
        return Vec::new();
    };
    let tested: Vec<(&String, usize, f64, &str)> = effects
        .iter()
        .filter_map(|e| {
            let slot = id.effects.iter().find(|s| s.effect.id().name() == e)?;
            let col = slot.column?;
            Some((e, col, slot.effect.param_per_strength(), slot.effect.unit()))
        })
        .collect();
    let level = CONSISTENCY_LEVEL / tested.len().max(1) as f64;
    let n = r.len();
    let p = id.fit.p.len();
    let d = conds.len();
    let cost = dot(r, r);
    tested
        .into_iter()
        .filter_map(|(effect, col, per, unit)| {
            let columns: Vec<Vec<f64>> = conds
                .iter()
                .map(|(_, z)| {
                    let mut c = shared[col].clone();
                    for (k, rr) in rows.iter().enumerate() {
                        for v in &mut c[rr.clone()] {
                            *v *= z[k];
                        }
                    }
                    span.orthogonal(c)
                })
                .collect();
            let g: Vec<f64> = columns
                .iter()
                .flat_map(|a| columns.iter().map(move |b| dot(a, b)))
                .collect();
            let b: Vec<f64> = columns.iter().map(|c| dot(c, r)).collect();
            let beta = solve_spd(&g, &b)?;
            let removed = dot(&beta, &b).clamp(0.0, cost);
            let df2 = n.checked_sub(p + d).filter(|&v| v > 0)?;
            let f = (removed / d as f64) / ((cost - removed).max(1e-300) / df2 as f64);
            let strength = id.summary.effect(effect)?.strength.value;
            let by_experiment = id
                .summary
                .experiments
                .iter()
                .enumerate()
                .map(|(k, name)| {
                    let shift: f64 = conds.iter().zip(&beta).map(|((_, z), b)| -b * z[k]).sum();
                    (name.clone(), strength + shift / per)
                })
                .collect();
            Some(Consistency {
                effect: effect.clone(),
                unit: unit.to_string(),
                strength,
                conditions: conds.iter().map(|(c, _)| c.clone()).collect(),
                f_statistic: f,
                dof: [d, df2],
                p_value: f_survival(f, d as f64, df2 as f64),
                level,
                share_of_cost: removed / cost.max(1e-300),
                by_experiment,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_spd_solve() {
        let g = [4.0, 2.0, 2.0, 3.0];
        let x = solve_spd(&g, &[2.0, 1.0]).expect("positive definite");
        assert!((4.0 * x[0] + 2.0 * x[1] - 2.0).abs() < 1e-14);
        assert!((2.0 * x[0] + 3.0 * x[1] - 1.0).abs() < 1e-14);
        assert!(solve_spd(&[1.0, 2.0, 2.0, 1.0], &[1.0, 1.0]).is_none());
    }

    #[test]
    fn projection_removes_block_and_shared_columns() {
        // two blocks of 3 rows, one local column each, one shared column
        let rows = [0..3, 3..6];
        let shared = vec![1.0, 2.0, 0.5, -1.0, 0.3, 2.0];
        let mut span = FitSpan {
            blocks: Vec::new(),
            shared: Vec::new(),
        };
        for (k, r) in rows.iter().enumerate() {
            let mut basis = Vec::new();
            extend_basis(&mut basis, vec![1.0 + k as f64, 1.0, -1.0], 1e-12);
            span.blocks.push((r.clone(), basis));
        }
        let mut v = shared.clone();
        span.project_blocks(&mut v);
        extend_basis(&mut span.shared, v, 1e-12);
        let w = span.orthogonal(vec![0.3, -0.7, 1.1, 2.0, 0.1, -0.4]);
        assert!(dot(&w, &shared).abs() < 1e-13);
        assert!(dot(&w[0..3], &[1.0, 1.0, -1.0]).abs() < 1e-13);
        assert!(dot(&w[3..6], &[2.0, 1.0, -1.0]).abs() < 1e-13);
        assert!(dot(&w, &w) > 0.1);
    }
}
