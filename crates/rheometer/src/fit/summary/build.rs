//! Building a [`FitSummary`] from an identification: the named estimates with their
//! uncertainties, the covariance in reported units, the estimates at a bound, and the checks.

use crate::data::noise_summary::NoiseSummary;
use crate::fit::estimator::Estimator;
use crate::fit::layout::EffectSlot;
use crate::fit::options::FitWarning;
use crate::fit::summary::checks::{self, bound_side};
use crate::fit::summary::{
    AtBound, BoundSide, Covariance, EffectEstimate, Estimate, FitSummary, SolverRecord,
};
use crate::model::effects::LawChoice;
use diffbvp::least_squares::{BlockCovariance, FitResult};
use nalgebra::DMatrix;

/// What an identification hands to [`FitSummary::new`]: the fit and its model's layout.
pub(crate) struct SummaryInput<'a> {
    pub estimator: Estimator,
    pub law: LawChoice,
    pub start: [f64; 2],
    pub experiments: Vec<String>,
    /// Names of the shared fitted parameters (the first entries of `fit.p`).
    pub names: &'a [String],
    pub effects: &'a [EffectSlot],
    /// The fitted local model parameters `[c, n, κ, strengths..., φ = 1]`.
    pub local_params: &'a [f64],
    /// `(n, κ)` of the fitted model.
    pub law_params: [f64; 2],
    pub fit: &'a FitResult,
    pub lower: &'a [f64],
    pub upper: &'a [f64],
    pub take_up_factors: Vec<f64>,
    pub rms: f64,
    pub rms_by_experiment: Vec<f64>,
    pub noise: NoiseSummary,
    pub data_warnings: Vec<FitWarning>,
    pub f_scale: f64,
    pub f_scale_source: String,
    pub bvp_tolerance: f64,
    pub nodes: Vec<usize>,
    pub wall_time_s: f64,
}

/// The fitted parameters' standard errors, correlation and bound sides.
struct Uncertainty {
    /// The factor on the fit's covariance for noise correlated along the line
    /// ([`NoiseModel::variance_inflation`](crate::data::noise_model::NoiseModel::variance_inflation); 1 for white noise).
    inflation: f64,
    se: Vec<f64>,
    have_se: bool,
    cov: Option<CovarianceView>,
    /// Correlation matrices whose conditioning is checked (see [`CovarianceView::groups`]).
    corr_groups: Option<Vec<DMatrix<f64>>>,
    sides: Vec<Option<BoundSide>>,
}

/// Above this many fitted parameters the conditioning is checked on sub-matrices (the
/// eigen-decomposition of the whole `P × P` correlation costs `P³`).
const DENSE_CONDITION_LIMIT: usize = 400;

/// The fit's covariance: dense for a dense fit, compact (through the Schur complement, never
/// `P × P`) for a block-arrow fit.
enum CovarianceView {
    Dense { c: Vec<f64>, np: usize },
    Block(BlockCovariance),
}

impl CovarianceView {
    fn of(fit: &FitResult) -> Option<Self> {
        if fit.block_jacobian.is_some() {
            fit.block_covariance().map(CovarianceView::Block)
        } else {
            fit.covariance()
                .map(|c| CovarianceView::Dense { c, np: fit.p.len() })
        }
    }

    fn get(&self, i: usize, j: usize) -> f64 {
        match self {
            CovarianceView::Dense { c, np } => c[i * np + j],
            CovarianceView::Block(b) => b.get(i, j),
        }
    }

    fn variances(&self) -> Vec<f64> {
        match self {
            CovarianceView::Dense { c, np } => (0..*np).map(|i| c[i * np + i]).collect(),
            CovarianceView::Block(b) => b.variances(),
        }
    }

    fn correlation(&self, i: usize, j: usize) -> f64 {
        self.get(i, j) / (self.get(i, i) * self.get(j, j)).sqrt()
    }

    /// The parameter groups whose correlation matrix is checked for conditioning: all `P`
    /// parameters up to [`DENSE_CONDITION_LIMIT`]; beyond, for a block-arrow fit, the shared
    /// parameters with each block's local ones (principal sub-matrices: their conditioning is
    /// never worse than the whole matrix', so the check may miss a combination spread over
    /// several experiments but never warns wrongly).
    fn groups(&self, np: usize) -> Vec<Vec<usize>> {
        match self {
            CovarianceView::Block(b) if np > DENSE_CONDITION_LIMIT => {
                let st = b.structure();
                (0..st.num_blocks())
                    .map(|k| (0..st.num_shared()).chain(st.locals(k)).collect())
                    .collect()
            }
            _ => vec![(0..np).collect()],
        }
    }

    fn correlation_of(&self, group: &[usize]) -> DMatrix<f64> {
        DMatrix::from_fn(group.len(), group.len(), |a, b| {
            self.correlation(group[a], group[b])
        })
    }
}

impl Uncertainty {
    fn of(input: &SummaryInput<'_>) -> Self {
        let fit = input.fit;
        let np = fit.p.len();
        let cov = CovarianceView::of(fit);
        let inflation = input.noise.variance_inflation();
        let se_opt: Option<Vec<f64>> = cov.as_ref().map(|c| {
            c.variances()
                .into_iter()
                .map(|x| (x * inflation).max(0.0).sqrt())
                .collect()
        });
        let sides = (0..np)
            .map(|c| match (input.lower.get(c), input.upper.get(c)) {
                (Some(&lo), Some(&hi)) => bound_side(fit.p[c], lo, hi),
                _ => None,
            })
            .collect();
        let corr_groups = cov
            .as_ref()
            .map(|c| c.groups(np).iter().map(|g| c.correlation_of(g)).collect());
        Uncertainty {
            inflation,
            have_se: se_opt.is_some(),
            se: se_opt.unwrap_or_else(|| vec![f64::NAN; np]),
            cov,
            corr_groups,
            sides,
        }
    }

    fn column(&self, c: Option<usize>) -> (f64, Option<BoundSide>) {
        c.map_or((0.0, None), |c| (self.se[c], self.sides[c]))
    }
}

impl FitSummary {
    /// The summary of an identification, with its checks ([`summary::checks`]).
    pub(crate) fn new(input: SummaryInput<'_>) -> Self {
        let u = Uncertainty::of(&input);
        let col = |name: &str| input.names.iter().position(|n| n == name);
        let (ni, ki) = (col("n"), col("kappa"));
        let [n_value, k_value] = input.law_params;
        let law_estimate = |name: &str, c: Option<usize>, value: f64| match c {
            Some(_) => {
                let (se, side) = u.column(c);
                Estimate::fitted(name, value, "-", se, side)
            }
            None => Estimate::fixed(name, value, "-"),
        };
        let n = law_estimate("n", ni, n_value);
        let kappa = law_estimate("kappa", ki, k_value);
        let k_pa = Estimate {
            name: "K".into(),
            value: k_value.exp(),
            unit: "Pa".into(),
            stderr: k_value.exp() * kappa.stderr,
            ci95: [kappa.ci95[0].exp(), kappa.ci95[1].exp()],
            fitted: kappa.fitted,
            at_bound: kappa.at_bound,
        };
        let np = input.fit.p.len();
        let correlation_n_kappa = match (ni, ki, &u.cov) {
            (Some(a), Some(b), Some(c)) => c.correlation(a, b),
            _ => f64::NAN,
        };
        let effects = effect_estimates(&input, &u);
        let covariance = covariance(&input, &u);
        let at_bound = at_bound_list(&input, &u);
        let fit = input.fit;
        let mut summary = FitSummary {
            estimator: input.estimator,
            law: input.law,
            fitted: input.names.to_vec(),
            experiments: input.experiments,
            data_digest: String::new(),
            start: input.start,
            n,
            kappa,
            k_pa,
            correlation_n_kappa,
            covariance,
            effects,
            take_up_factors: input.take_up_factors,
            cost: 2.0 * fit.cost,
            rms_relative_residual: input.rms,
            rms_relative_residual_by_experiment: input.rms_by_experiment,
            residuals: fit.num_residuals(),
            noise: input.noise,
            solver: SolverRecord {
                iterations: fit.iterations,
                failed_evaluations: fit.failed_evaluations,
                termination: Some(fit.termination.clone()),
                wall_time_s: input.wall_time_s,
                bvp_tolerance: input.bvp_tolerance,
                nodes: input.nodes,
                discretisation_shift_se: f64::NAN,
                check_nodes: Vec::new(),
            },
            at_bound,
            warnings: Vec::new(),
            loss: fit.loss,
            f_scale: input.f_scale,
            f_scale_source: input.f_scale_source,
            down_weighted: fit.down_weighted(),
            error_budget: None,
            strain_rates: None,
            intervals: Vec::new(),
            newtonian_test: None,
            flow_curve: None,
        };
        let mut w = input.data_warnings;
        checks::check_bounds(&summary, &mut w);
        checks::check_uncertainty(
            &summary,
            input.effects,
            u.have_se,
            u.corr_groups.as_deref(),
            np,
            &mut w,
        );
        checks::check_misfit(&summary, &mut w);
        checks::check_noise_free(&summary, &mut w);
        checks::check_convergence(fit, &mut w);
        checks::check_law(&summary, &mut w);
        checks::check_fixed_effects(&summary, &mut w);
        summary.warnings = w;
        summary
    }
}

/// The effects' strengths and shapes with their uncertainties.
fn effect_estimates(input: &SummaryInput<'_>, u: &Uncertainty) -> Vec<EffectEstimate> {
    input
        .effects
        .iter()
        .map(|slot| {
            let e = &slot.effect;
            let value = e.strength_of(input.local_params[slot.local]);
            let strength = match slot.column {
                Some(_) => {
                    let (se, side) = u.column(slot.column);
                    let side = side.map(|s| {
                        if e.param_per_strength() < 0.0 {
                            s.flipped()
                        } else {
                            s
                        }
                    });
                    Estimate::fitted(e.name(), value, e.unit(), se, side)
                }
                None => Estimate::fixed(e.name(), value, e.unit()),
            };
            let shapes = slot
                .shapes
                .iter()
                .map(|sh| {
                    let v = input.local_params[sh.local];
                    match sh.column {
                        Some(_) => {
                            let (se, side) = u.column(sh.column);
                            Estimate::fitted(sh.parameter.name, v, sh.parameter.unit, se, side)
                        }
                        None => Estimate::fixed(sh.parameter.name, v, sh.parameter.unit),
                    }
                })
                .collect();
            EffectEstimate {
                effect: e.name().to_string(),
                category: Some(e.category()),
                strength,
                shapes,
            }
        })
        .collect()
}

/// The covariance of the shared fitted parameters in reported units (strengths whose model
/// parameter runs against the strength change the sign of their rows and columns).
fn covariance(input: &SummaryInput<'_>, u: &Uncertainty) -> Option<Covariance> {
    let cov = u.cov.as_ref()?;
    let ns = input.names.len();
    if ns == 0 {
        return None;
    }
    let sign: Vec<f64> = (0..ns)
        .map(|c| {
            input
                .effects
                .iter()
                .find(|s| s.column == Some(c))
                .filter(|_| input.names[c] != "n" && input.names[c] != "kappa")
                .map_or(1.0, |s| s.effect.param_per_strength().signum())
        })
        .collect();
    let mut matrix = Vec::with_capacity(ns * ns);
    for i in 0..ns {
        for j in 0..ns {
            matrix.push(sign[i] * sign[j] * cov.get(i, j) * u.inflation);
        }
    }
    Some(Covariance {
        names: input.names.to_vec(),
        matrix,
    })
}

/// The fitted parameters (shared and take-up factors) at a bound of their search range.
fn at_bound_list(input: &SummaryInput<'_>, u: &Uncertainty) -> Vec<AtBound> {
    let fit = input.fit;
    let ns = input.names.len();
    let mut out = Vec::new();
    for (c, side) in u.sides.iter().enumerate() {
        let Some(side) = *side else { continue };
        let bound_param = match side {
            BoundSide::Lower => input.lower[c],
            BoundSide::Upper => input.upper[c],
        };
        let entry = if c < ns {
            let name = input.names[c].clone();
            match input.effects.iter().find(|e| e.column == Some(c)) {
                Some(slot) if name != "n" && name != "kappa" => {
                    let e = &slot.effect;
                    AtBound {
                        parameter: name,
                        side: if e.param_per_strength() < 0.0 {
                            side.flipped()
                        } else {
                            side
                        },
                        bound: e.strength_of(bound_param),
                        value: e.strength_of(fit.p[c]),
                    }
                }
                _ => AtBound {
                    parameter: name,
                    side,
                    bound: bound_param,
                    value: fit.p[c],
                },
            }
        } else {
            let k = c - ns;
            let exp = input
                .experiments
                .get(k)
                .cloned()
                .unwrap_or_else(|| format!("#{}", k + 1));
            AtBound {
                parameter: format!("take_up_factor[{exp}]"),
                side,
                bound: bound_param,
                value: fit.p[c],
            }
        };
        out.push(entry);
    }
    out
}
