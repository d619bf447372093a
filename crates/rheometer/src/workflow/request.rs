//! The rules of a request, written once for every door (the `rheometer` program and the Python
//! package): the limits of each value a user gives, the checks, and the words of a refusal.
//!
//! A door parses its own syntax (a flag's text, a Python object) into a number, asks the check
//! here, and renders a [`Refusal`] in its own words: the input as that door calls it
//! ([`Arg::name`]: `--max-nodes` on the command line, `max_nodes` in Python), then the reason,
//! which is the same text for both.

use crate::data::input::{
    max_fit_rows, show_count, LoadOptions, LoadedExperiments, MAX_PLAUSIBLE_DIAMETER_M,
};
use crate::fit::landscape::LANDSCAPE_MAX_NODES;
use crate::fit::IdentifyOptions;
use crate::model::effects::Effect;
use diffbvp::least_squares::Loss;
use std::fmt;

/// Largest number of output positions per profile (`simulate`'s `points`): the cap keeps a
/// run's memory and its CSV files bounded.
pub const MAX_POINTS: usize = 100_000;
/// Largest number of values per direction of a landscape or design grid.
pub(crate) const MAX_GRID_SIDE: usize = 1000;
/// Largest number of points of a landscape grid (N x M).
pub const MAX_GRID_POINTS: usize = 100_000;
/// Smallest mesh limit (the cold start begins on a mesh of 21 nodes).
pub const MIN_MAX_NODES: usize = 50;
/// Largest mesh limit.
pub const MAX_MAX_NODES: usize = 1_000_000;
/// Default mesh limit of the solves of `simulate`, `fit`, `diagnose`, `compare` and `design`.
pub const DEFAULT_MAX_NODES: usize = 20_000;
/// Smallest take-up diameter a user may give \[m\].
pub(crate) const MIN_TAKE_UP_DIAMETER_M: f64 = 1e-7;
/// Largest |κ| (K = e^κ Pa stays a finite positive number).
pub(crate) const MAX_ABS_KAPPA: f64 = 700.0;
/// Range of a BVP tolerance \[-\].
pub(crate) const TOL_RANGE: (f64, f64) = (1e-12, 0.1);
/// Range (exclusive) of a relative noise level given to the design \[-\].
pub(crate) const NOISE_RANGE: (f64, f64) = (0.0, 0.5);

/// The door a request came through: it decides how an input is named in a refusal.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Door {
    /// The `rheometer` program: flags (`--max-nodes`).
    Cli,
    /// The Python package: keyword arguments (`max_nodes`).
    Python,
}

/// An input of a workflow that a user gives through a door.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum Arg {
    MaxNodes,
    Points,
    Grid,
    Tol,
    N,
    Kappa,
    Start,
    NRange,
    KappaRange,
    RelativeUncertainty,
    FScale,
    Loss,
    TakeUpDiameter,
    RefitTop,
    Noise,
    Template,
    MassFlow,
    StencilVelocity,
    TakeUpDiameterRange,
    TakeUpVelocity,
    Discriminate,
    Model,
    ProfilePoints,
    Positions,
    Measurements,
    AllowLargeInputs,
}

impl Arg {
    /// The input's name at `door`: the flag or the keyword argument.
    pub fn name(self, door: Door) -> &'static str {
        let (cli, python) = match self {
            Arg::MaxNodes => ("--max-nodes", "max_nodes"),
            Arg::Points => ("--points", "points"),
            Arg::Grid => ("--grid", "grid"),
            Arg::Tol => ("--tol", "tol"),
            Arg::N => ("--n", "n"),
            Arg::Kappa => ("--kappa", "kappa"),
            Arg::Start => ("--start", "start"),
            Arg::NRange => ("--n-range", "n_range"),
            Arg::KappaRange => ("--kappa-range", "kappa_range"),
            Arg::RelativeUncertainty => ("--relative-uncertainty", "relative_uncertainty"),
            Arg::FScale => ("--f-scale", "f_scale"),
            Arg::Loss => ("--loss", "loss"),
            Arg::TakeUpDiameter => ("--take-up-diameter", "take_up_diameter"),
            Arg::RefitTop => ("--refit-top", "refit_top"),
            Arg::Noise => ("--noise", "noise"),
            Arg::Template => ("--template", "template"),
            Arg::MassFlow => ("--mass-flow", "mass_flow"),
            Arg::StencilVelocity => ("--stencil-velocity", "stencil_velocity"),
            Arg::TakeUpDiameterRange => ("--take-up-diameter", "take_up_diameter"),
            Arg::TakeUpVelocity => ("--take-up-velocity", "take_up_velocity"),
            Arg::Discriminate => ("--discriminate", "discriminate"),
            Arg::Model => ("--model", "model"),
            Arg::ProfilePoints => ("--points", "profile_points"),
            Arg::Positions => ("--positions", "positions"),
            Arg::Measurements => ("measurements", "measurements"),
            Arg::AllowLargeInputs => ("--allow-large-inputs", "allow_large_inputs"),
        };
        match door {
            Door::Cli => cli,
            Door::Python => python,
        }
    }
}

/// A value given to a request, for the words of a refusal.
#[derive(Debug, Clone, PartialEq)]
pub enum Given {
    /// Nothing worth repeating (the reason says it).
    Nothing,
    /// One number.
    Number(f64),
    /// A count.
    Count(usize),
    /// A name or other text.
    Text(String),
    /// A pair of numbers (a start, a range).
    Pair(f64, f64),
}

/// Why a request was refused: which input, what was given, and the reason (the same words at
/// every door).
#[derive(Debug, Clone, PartialEq)]
pub struct Refusal {
    /// The input.
    pub arg: Arg,
    /// What was given, where the message repeats it before the reason.
    pub given: Given,
    /// The reason and what to do, with other inputs it names written `@name@` or
    /// `@name=value@` (see [`Refusal::reason`]).
    pub reason: String,
}

impl Refusal {
    /// A refusal of `arg` whose reason does not repeat the value.
    pub fn new(arg: Arg, reason: String) -> Refusal {
        Refusal {
            arg,
            given: Given::Nothing,
            reason,
        }
    }

    /// A refusal of `arg` that repeats the value given before the reason.
    pub fn with(arg: Arg, given: Given, reason: String) -> Refusal {
        Refusal { arg, given, reason }
    }

    /// The refusal in `door`'s words: `--start 2,30: the start must …` on the command line,
    /// `start = (2, 30): the start must …` in Python.
    pub fn message(&self, door: Door) -> String {
        let name = self.arg.name(door);
        let given = match (&self.given, door) {
            (Given::Nothing, _) => String::new(),
            (Given::Number(v), Door::Cli) => format!(" {}", show(*v)),
            (Given::Number(v), Door::Python) => format!(" = {}", show(*v)),
            (Given::Count(v), Door::Cli) => format!(" {v}"),
            (Given::Count(v), Door::Python) => format!(" = {v}"),
            (Given::Text(t), Door::Cli) => format!(" {t}"),
            (Given::Text(t), Door::Python) => format!(" = {t:?}"),
            (Given::Pair(a, b), Door::Cli) => format!(" {},{}", show(*a), show(*b)),
            (Given::Pair(a, b), Door::Python) => format!(" = ({}, {})", show(*a), show(*b)),
        };
        format!("{name}{given}: {}", self.reason(door))
    }

    /// The reason alone in `door`'s words (for a door that names the input itself, as clap
    /// does for a flag): another input the reason names is written `@name@` or
    /// `@name=value@` (Python's name) in [`Refusal::reason`] and rendered here as
    /// `--name value` or `name="value"`; a switch, `@name=True@`, as `--name` or
    /// `name=True`.
    pub fn reason(&self, door: Door) -> String {
        let mut out = String::with_capacity(self.reason.len());
        let mut parts = self.reason.split('@');
        if let Some(first) = parts.next() {
            out.push_str(first);
        }
        let mut inside = true;
        for part in parts {
            if inside {
                let (name, value) = match part.split_once('=') {
                    Some((n, v)) => (n, Some(v)),
                    None => (part, None),
                };
                let shown = match (door, value) {
                    // a switch: `--allow-large-inputs` on the command line
                    (Door::Cli, Some("True")) => format!("--{}", name.replace('_', "-")),
                    (Door::Python, Some(v @ ("True" | "False"))) => format!("{name}={v}"),
                    (Door::Cli, None) => format!("--{}", name.replace('_', "-")),
                    (Door::Cli, Some(v)) => format!("--{} {v}", name.replace('_', "-")),
                    (Door::Python, None) => name.to_string(),
                    (Door::Python, Some(v)) => format!("{name}=\"{v}\""),
                };
                out.push_str(&shown);
            } else {
                out.push_str(part);
            }
            inside = !inside;
        }
        out
    }
}

impl fmt::Display for Refusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message(Door::Cli))
    }
}

impl std::error::Error for Refusal {}

pub(crate) use crate::report::format::show;

/// The caps of the loader as a request sets them: `base`, or none at all with the override
/// every door offers (`--allow-large-inputs` on the command line, `allow_large_inputs=True`
/// in Python); inputs must still be regular files.
pub fn load_options(base: LoadOptions, allow_large_inputs: bool) -> LoadOptions {
    if !allow_large_inputs {
        return base;
    }
    LoadOptions {
        max_toml_bytes: u64::MAX,
        max_csv_bytes: u64::MAX,
        max_line_bytes: usize::MAX,
        max_rows_per_file: usize::MAX,
        max_experiments: usize::MAX,
        max_fit_memory_bytes: u64::MAX,
        ..base
    }
}

/// How `door` lifts the input caps, for the message of an exceeded one: `on the command line:
/// --allow-large-inputs`, `in Python: allow_large_inputs=True`.
pub fn lift_caps(door: Door) -> &'static str {
    match door {
        Door::Cli => "on the command line: --allow-large-inputs",
        Door::Python => "in Python: allow_large_inputs=True",
    }
}

/// The message of a loader's error in `door`'s words: an exceeded cap (also of a data
/// file) says how that door lifts the caps (`... (on the command line:
/// --allow-large-inputs)`); any other error as it is.
pub fn input_message(e: &crate::data::input::InputError, door: Door) -> String {
    match e.exceeded_limit() {
        Some(_) => format!("{e} ({})", lift_caps(door)),
        None => e.to_string(),
    }
}

/// Measurement arrays given directly rather than as files (Python's `Dataset.from_arrays`,
/// `Dataset.from_toml(measurements=...)`), checked on their lengths before any row is
/// converted: the caps of a measurement file in `options` apply to them alike, at most
/// [`LoadOptions::max_rows_per_file`] rows per experiment and, in all `experiments`, the rows
/// a fit can hold within [`LoadOptions::max_fit_memory_bytes`] (`max_fit_rows`). `rows`:
/// each experiment's name and number of rows.
pub fn measurement_rows(
    rows: &[(&str, usize)],
    experiments: usize,
    options: &LoadOptions,
) -> Result<(), Refusal> {
    let thin = "thin the data (every 10th row carries the same information for the smoothing \
                and the fit, at a tenth of the cost), or lift the caps with \
                @allow_large_inputs=True@";
    if let Some((name, n)) = rows.iter().find(|(_, n)| *n > options.max_rows_per_file) {
        return Err(Refusal::new(
            Arg::Measurements,
            format!(
                "experiment \"{name}\" has {} rows, more than the {} a measurement file may \
                 hold (the cap `max_rows_per_file` of the loader); {thin}",
                show_count(*n as u64),
                show_count(options.max_rows_per_file as u64)
            ),
        ));
    }
    let total = rows.iter().map(|(_, n)| *n as u64).sum::<u64>();
    let most = max_fit_rows(experiments as u64, options.max_fit_memory_bytes);
    if total > most {
        return Err(Refusal::new(
            Arg::Measurements,
            format!(
                "{} rows in all, more than a fit of {experiments} experiments can hold within \
                 the estimated memory cap `max_fit_memory_bytes` ({} rows); {thin}",
                show_count(total),
                show_count(most)
            ),
        ));
    }
    Ok(())
}

/// A whole number `v` of `arg` within `lo..=hi`; `what` says what is counted ("give 2 to
/// 100000 {what}").
pub fn count_in(arg: Arg, v: i128, lo: usize, hi: usize, what: &str) -> Result<usize, Refusal> {
    usize::try_from(v)
        .ok()
        .filter(|v| (lo..=hi).contains(v))
        .ok_or_else(|| Refusal::new(arg, format!("give {lo} to {hi} {what} (got {v})")))
}

/// `points`: 2 to [`MAX_POINTS`] output positions per profile.
pub fn points(v: i128) -> Result<usize, Refusal> {
    count_in(
        Arg::Points,
        v,
        2,
        MAX_POINTS,
        "output positions per profile",
    )
}

/// Output positions \[m\] used for every experiment of `loaded`: 1 to [`MAX_POINTS`] finite
/// positions on the shortest spin line, `0 <= s <= L`.
pub fn positions(p: &[f64], loaded: &LoadedExperiments) -> Result<(), Refusal> {
    if p.is_empty() || p.len() > MAX_POINTS || p.iter().any(|x| !x.is_finite()) {
        return Err(Refusal::new(
            Arg::Positions,
            format!("give 1 to {MAX_POINTS} finite positions along the spin line (m)"),
        ));
    }
    let shortest = loaded
        .set
        .experiments
        .iter()
        .min_by(|a, b| a.spinline_length.total_cmp(&b.spinline_length));
    if let Some(e) = shortest {
        let l = e.spinline_length;
        if let Some(&x) = p.iter().find(|&&x| !(0.0..=l).contains(&x)) {
            return Err(Refusal::new(
                Arg::Positions,
                format!(
                    "{} m lies outside the spin line: every position must lie in [0, {}] m \
                     (the shortest line, experiment {}, is {} m long)",
                    show(x),
                    show(l),
                    e.name,
                    show(l)
                ),
            ));
        }
    }
    Ok(())
}

/// Text with inputs written `@name@` or `@name=value@` (Python's names) in `door`'s words
/// (see [`Refusal::reason`]); for messages of a workflow that knows its door.
pub(crate) fn in_words_of(text: &str, door: Door) -> String {
    Refusal::new(Arg::Tol, text.to_string()).reason(door)
}

/// The mesh limit: [`MIN_MAX_NODES`] to [`MAX_MAX_NODES`] nodes.
pub fn max_nodes(v: i128) -> Result<usize, Refusal> {
    usize::try_from(v)
        .ok()
        .filter(|v| (MIN_MAX_NODES..=MAX_MAX_NODES).contains(v))
        .ok_or_else(|| {
            Refusal::new(
                Arg::MaxNodes,
                format!(
                    "the mesh limit must lie in {MIN_MAX_NODES}..={MAX_MAX_NODES} nodes (got \
                     {v}; default {DEFAULT_MAX_NODES})"
                ),
            )
        })
}

/// The mesh limit of a landscape: in the range of [`max_nodes`] and at most
/// `LANDSCAPE_MAX_NODES` (its solves' cap), which is also the default.
pub fn landscape_max_nodes(v: Option<i128>) -> Result<usize, Refusal> {
    match v {
        None => Ok(LANDSCAPE_MAX_NODES),
        Some(v) => {
            let m = max_nodes(v)?;
            if m > LANDSCAPE_MAX_NODES {
                return Err(Refusal::with(
                    Arg::MaxNodes,
                    Given::Count(m),
                    format!(
                        "the landscape caps its meshes at {LANDSCAPE_MAX_NODES} nodes (points \
                         that need more are marked missing); give at most {LANDSCAPE_MAX_NODES}"
                    ),
                ));
            }
            Ok(m)
        }
    }
}

/// A BVP tolerance in [1e-12, 0.1].
pub fn tol(v: f64) -> Result<f64, Refusal> {
    if !(TOL_RANGE.0..=TOL_RANGE.1).contains(&v) {
        return Err(Refusal::new(
            Arg::Tol,
            format!(
                "the tolerance must lie in [{:e}, {}] (got {})",
                TOL_RANGE.0,
                TOL_RANGE.1,
                show(v)
            ),
        ));
    }
    Ok(v)
}

/// A relative uncertainty in (0, 1), like the TOML key `relative_uncertainty`.
pub fn relative_uncertainty(v: f64) -> Result<f64, Refusal> {
    if !(v > 0.0 && v < 1.0) {
        return Err(Refusal::new(
            Arg::RelativeUncertainty,
            format!(
                "a relative uncertainty must lie in (0, 1) like the TOML key \
                 relative_uncertainty (got {}; 0.01 is 1 %)",
                show(v)
            ),
        ));
    }
    Ok(v)
}

/// The soft margin of a robust loss: a relative residual in (0, 1).
pub fn f_scale(v: f64) -> Result<f64, Refusal> {
    if !(v > 0.0 && v < 1.0) {
        return Err(Refusal::new(
            Arg::FScale,
            format!(
                "f_scale is a relative residual in (0, 1) (got {}; 0.02 is 2 %)",
                show(v)
            ),
        ));
    }
    Ok(v)
}

/// A loss with its soft margin: a margin needs a robust loss.
pub fn robust_loss(loss: Loss, margin: Option<f64>) -> Result<(Loss, Option<f64>), Refusal> {
    if let Some(c) = margin {
        f_scale(c)?;
        if loss.is_linear() {
            return Err(Refusal::with(
                Arg::FScale,
                Given::Number(c),
                "a soft margin needs a robust loss, but the loss is linear (least squares, the \
                 default of @loss@); add @loss=soft_l1@ (or huber, cauchy), or drop @f_scale@"
                    .into(),
            ));
        }
    }
    Ok((loss, margin))
}

/// A robust loss needs the principled estimator (relative residuals): the paper's estimator
/// fits with the linear loss only.
pub fn loss_for(loss: Loss, estimator: crate::fit::Estimator) -> Result<(), Refusal> {
    if loss.is_linear() || estimator == crate::fit::Estimator::Principled {
        return Ok(());
    }
    Err(Refusal::with(
        Arg::Loss,
        Given::Text(loss.to_string()),
        "a robust loss needs the principled estimator (relative residuals); the paper's \
         estimator fits with the linear loss only: drop @loss@ or use \
         @estimator=principled@"
            .into(),
    ))
}

/// `n`: the Carreau-type law's domain, a finite n >= 0.
pub fn n(v: f64) -> Result<f64, Refusal> {
    if !(v >= 0.0 && v.is_finite()) {
        return Err(Refusal::new(
            Arg::N,
            format!(
                "the power index n must be >= 0 (the Carreau-type law's domain; 1 is \
                 Newtonian), got {}",
                show(v)
            ),
        ));
    }
    Ok(v)
}

/// `κ`: finite with |κ| <= 700.
pub fn kappa(v: f64) -> Result<f64, Refusal> {
    if v.is_nan() || v.abs() > MAX_ABS_KAPPA {
        return Err(Refusal::new(
            Arg::Kappa,
            format!(
                "kappa = ln(K / 1 Pa) must lie in [-{MAX_ABS_KAPPA}, {MAX_ABS_KAPPA}] (K = \
                 e^kappa overflows beyond; the fit searches [7, 20]), got {}",
                show(v)
            ),
        ));
    }
    Ok(v)
}

/// A take-up diameter in [1e-7, 0.02] m.
pub fn take_up_diameter(v: f64) -> Result<f64, Refusal> {
    if !(MIN_TAKE_UP_DIAMETER_M..=MAX_PLAUSIBLE_DIAMETER_M).contains(&v) {
        return Err(Refusal::new(
            Arg::TakeUpDiameter,
            format!(
                "a take-up diameter must lie in [{MIN_TAKE_UP_DIAMETER_M:e}, \
                 {MAX_PLAUSIBLE_DIAMETER_M}] m (got {} m; the unit is metres)",
                show(v)
            ),
        ));
    }
    Ok(v)
}

/// The number of candidates to refit: 1 to the number of built-in candidate effects.
pub fn refit_top(v: i128) -> Result<usize, Refusal> {
    count_in(
        Arg::RefitTop,
        v,
        1,
        Effect::builtin().len(),
        "candidates to refit (the number of candidate effects is the most)",
    )
}

/// A relative noise level for the design, in `NOISE_RANGE` (exclusive).
pub fn noise(v: f64) -> Result<f64, Refusal> {
    if !(v > NOISE_RANGE.0 && v < NOISE_RANGE.1) {
        return Err(Refusal::new(
            Arg::Noise,
            format!(
                "the noise is a relative level in ({}, {}) (got {}; 0.015 is 1.5 %)",
                NOISE_RANGE.0,
                NOISE_RANGE.1,
                show(v)
            ),
        ));
    }
    Ok(v)
}

/// A grid of `a` x `b` points: 2 to 1000 values per direction and at most
/// `max_points` points.
pub fn grid(a: i128, b: i128, max_points: usize) -> Result<(usize, usize), Refusal> {
    let side = |v: i128| usize::try_from(v).ok();
    let (Some(a), Some(b)) = (side(a), side(b)) else {
        return Err(Refusal::new(
            Arg::Grid,
            "the grid needs at least 2 points per direction".into(),
        ));
    };
    if a < 2 || b < 2 {
        return Err(Refusal::new(
            Arg::Grid,
            "the grid needs at least 2 points per direction".into(),
        ));
    }
    if a > MAX_GRID_SIDE || b > MAX_GRID_SIDE || a.saturating_mul(b) > max_points {
        return Err(Refusal::new(
            Arg::Grid,
            format!(
                "{a}x{b} is too large: at most {MAX_GRID_SIDE} values per direction and \
                 {max_points} points (a 41x41 grid of the shipped data takes seconds; zoom in \
                 with @n_range@ and @kappa_range@ instead)"
            ),
        ));
    }
    Ok((a, b))
}

/// A start `(n, κ)` within the fit's bounds of `opts`.
pub fn start((n, kappa): (f64, f64), opts: &IdentifyOptions) -> Result<(f64, f64), Refusal> {
    let inside = |v: f64, i: usize| v >= opts.lower[i] && v <= opts.upper[i];
    if !inside(n, 0) || !inside(kappa, 1) {
        return Err(Refusal::with(
            Arg::Start,
            Given::Pair(n, kappa),
            format!(
                "the start must lie within the fit's bounds n in [{}, {}] and kappa in [{}, {}]",
                opts.lower[0], opts.upper[0], opts.lower[1], opts.upper[1]
            ),
        ));
    }
    Ok((n, kappa))
}

/// A range `(lo, hi)` of `arg` (the parameter `name`), increasing and within the fit's bounds
/// `[min, max]`.
pub fn range(
    arg: Arg,
    name: &str,
    (lo, hi): (f64, f64),
    [min, max]: [f64; 2],
) -> Result<(f64, f64), Refusal> {
    let refuse = |reason: String| Refusal::with(arg, Given::Pair(lo, hi), reason);
    if lo == hi {
        return Err(refuse(format!(
            "the range is a single value; give MIN,MAX with MIN < MAX, within the fit's bounds \
             [{min}, {max}] of {name}"
        )));
    }
    if lo > hi {
        return Err(refuse(format!(
            "give MIN,MAX with MIN < MAX (did you mean {},{}?)",
            show(hi),
            show(lo)
        )));
    }
    if lo < min || hi > max {
        return Err(refuse(format!(
            "{name} must lie within the fit's bounds [{min}, {max}]"
        )));
    }
    Ok((lo, hi))
}

/// A Newtonian model has no (n, κ) to start from: refused with a start.
pub fn newtonian_start(newtonian: bool, start: Option<(f64, f64)>) -> Result<(), Refusal> {
    match start {
        Some(_) if newtonian => Err(Refusal::new(
            Arg::Start,
            "the Newtonian model (@model=newtonian@, n = 1) has no (n, kappa) to start from; \
             drop @start@ or fit the Carreau-type law (@model=carreau@)"
                .into(),
        )),
        _ => Ok(()),
    }
}

/// A tolerance the user gave: checked, and kept as given (the fit's discretisation shift is
/// only reported, it does not tighten a given tolerance); `None` leaves the fit's schedule.
pub fn given_tol(opts: &mut IdentifyOptions, v: Option<f64>) -> Result<(), Refusal> {
    if let Some(t) = v {
        opts.simulate.tol = tol(t)?;
        opts.max_discretisation_shift = Some(f64::INFINITY);
    }
    Ok(())
}

/// The ranges of a design's candidate grid, as a user gives them (each `None` for the default
/// taken from the data set).
#[derive(Debug, Clone, Default)]
pub struct DesignRanges {
    /// The experiment the candidates copy (default: the first).
    pub template: Option<String>,
    /// Mass-flow range \[kg/s\].
    pub mass_flow: Option<(f64, f64)>,
    /// Stencil-velocity range \[mm/s\] (mass flow proportional to it).
    pub stencil_velocity: Option<(f64, f64)>,
    /// Take-up-diameter range \[m\].
    pub take_up_diameter: Option<(f64, f64)>,
    /// Take-up-speed range \[m/s\].
    pub take_up_velocity: Option<(f64, f64)>,
    /// The grid: mass flows x take-up values.
    pub grid: (usize, usize),
}

/// A design range of `arg` checked against `(min, max)`, the plausibility bounds of the TOML
/// key `key` (in the range's unit), then spread over `m` values.
fn design_range(
    arg: Arg,
    (lo, hi): (f64, f64),
    m: usize,
    key: &str,
    (min, max): (f64, f64),
) -> Result<Vec<f64>, Refusal> {
    let refuse = |reason: String| Refusal::with(arg, Given::Pair(lo, hi), reason);
    if !(lo > 0.0 && lo < hi) {
        return Err(refuse("give MIN,MAX with 0 < MIN < MAX".into()));
    }
    if lo < min || hi > max {
        return Err(refuse(format!(
            "the range must lie within [{}, {}], the plausible range of the TOML key {key}",
            show(min),
            show(max)
        )));
    }
    Ok(diffbvp::mesh::linspace(lo, hi, m))
}

/// The candidate grid of `ranges` on the loaded data (defaults from the data set), each range
/// within the plausibility bounds the experiments file enforces for the same quantity.
pub fn design_grid(
    ranges: &DesignRanges,
    loaded: &LoadedExperiments,
) -> Result<crate::design::CandidateGrid, Refusal> {
    use crate::design::CandidateGrid;
    let set = &loaded.set;
    let names = || {
        set.experiments
            .iter()
            .map(|e| e.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let template = match &ranges.template {
        None => 0,
        Some(name) => set
            .experiments
            .iter()
            .position(|e| &e.name == name)
            .ok_or_else(|| {
                Refusal::with(
                    Arg::Template,
                    Given::Text(name.clone()),
                    format!("no such experiment (the data set has {})", names()),
                )
            })?,
    };
    let (m, k) = ranges.grid;
    let mass_flows = design_mass_flows(ranges, loaded, template, m)?;
    let take_up = design_take_up(ranges, set, k)?;
    Ok(CandidateGrid {
        template,
        mass_flows,
        take_up,
        positions: None,
    })
}

/// The plausible range of the experiments file's key `key` (unbounded above where it has
/// none).
fn plausible_bounds(key: &str) -> (f64, f64) {
    crate::data::input::PLAUSIBLE_RANGES
        .iter()
        .find(|(k, _, _)| *k == key)
        .map_or((0.0, f64::INFINITY), |&(_, min, max)| (min, max))
}

/// The design grid's `m` mass flows: the range given (directly, or as stencil velocities of
/// the experiment `template`), else from half the smallest to twice the largest of the data.
fn design_mass_flows(
    ranges: &DesignRanges,
    loaded: &LoadedExperiments,
    template: usize,
    m: usize,
) -> Result<Vec<f64>, Refusal> {
    let set = &loaded.set;
    let flows = match (ranges.mass_flow, ranges.stencil_velocity) {
        (Some(_), Some(_)) => {
            return Err(Refusal::new(
                Arg::MassFlow,
                "give @mass_flow@ or @stencil_velocity@, not both".into(),
            ))
        }
        (Some(r), None) => design_range(
            Arg::MassFlow,
            r,
            m,
            "mass_flow_kg_s",
            plausible_bounds("mass_flow_kg_s"),
        )?,
        (None, Some(r)) => {
            let v0 = loaded.details[template]
                .stencil_velocity_mm_s
                .ok_or_else(|| {
                    Refusal::new(
                        Arg::StencilVelocity,
                        format!(
                            "needs the template's stencil_velocity_mm_s, which experiment {} \
                             does not give; use @mass_flow@ instead",
                            set.experiments[template].name
                        ),
                    )
                })?;
            let q0 = set.experiments[template].mass_flow;
            // the mass flows must stay plausible: the stencil range maps onto them
            let (qmin, qmax) = plausible_bounds("mass_flow_kg_s");
            let vbounds = (qmin * v0 / q0, qmax * v0 / q0);
            design_range(
                Arg::StencilVelocity,
                r,
                m,
                "mass_flow_kg_s (through the template's stencil velocity)",
                vbounds,
            )?
            .into_iter()
            .map(|v| q0 * v / v0)
            .collect()
        }
        (None, None) => {
            let flows: Vec<f64> = set.experiments.iter().map(|e| e.mass_flow).collect();
            let lo = flows.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = flows.iter().copied().fold(0.0, f64::max);
            diffbvp::mesh::linspace(0.5 * lo, 2.0 * hi, m)
        }
    };
    Ok(flows)
}

/// The design grid's `k` take-up conditions: the diameters or velocities given, else
/// diameters from 0.6 times the smallest to 1.3 times the largest take-up diameter of the data.
fn design_take_up(
    ranges: &DesignRanges,
    set: &crate::model::setup::ExperimentSet,
    k: usize,
) -> Result<crate::design::TakeUpAxis, Refusal> {
    use crate::data::take_up::{resolve_take_up, MissingTakeUp};
    use crate::design::TakeUpAxis;
    use crate::model::setup::TakeUp;
    let axis = match (ranges.take_up_diameter, ranges.take_up_velocity) {
        (Some(_), Some(_)) => {
            return Err(Refusal::new(
                Arg::TakeUpDiameterRange,
                "give @take_up_diameter@ or @take_up_velocity@, not both".into(),
            ))
        }
        (Some(r), None) => TakeUpAxis::Diameter(design_range(
            Arg::TakeUpDiameterRange,
            r,
            k,
            "take_up_diameter_m",
            (MIN_TAKE_UP_DIAMETER_M, MAX_PLAUSIBLE_DIAMETER_M),
        )?),
        (None, Some(r)) => TakeUpAxis::Velocity(design_range(
            Arg::TakeUpVelocity,
            r,
            k,
            "take_up_velocity_m_s",
            plausible_bounds("take_up_velocity_m_s"),
        )?),
        (None, None) => {
            let mut d = Vec::new();
            for (e, meas) in set.experiments.iter().zip(&set.measurements) {
                if let Ok(r) = resolve_take_up(e, meas.as_ref(), MissingTakeUp::FromData, None) {
                    if let TakeUp::Diameter(v) = r.take_up {
                        d.push(v);
                    }
                }
            }
            if d.is_empty() {
                return Err(Refusal::new(
                    Arg::TakeUpDiameterRange,
                    "no take-up diameter in the data to take a default range from; give \
                     @take_up_diameter@ or @take_up_velocity@"
                        .into(),
                ));
            }
            let lo = d.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = d.iter().copied().fold(0.0, f64::max);
            TakeUpAxis::Diameter(diffbvp::mesh::linspace(0.6 * lo, 1.3 * hi, k))
        }
    };
    Ok(axis)
}

/// The rival effects of a design for discrimination: two or more distinct effects.
pub fn rivals(effects: Vec<Effect>) -> Result<Vec<Effect>, Refusal> {
    if effects.len() < 2 {
        return Err(Refusal::new(
            Arg::Discriminate,
            format!(
                "give at least two rival effects (e.g. mass_flow_scale,nusselt_scale); the \
                 effects are {}",
                crate::model::effects::ALL_NAMES.join(", ")
            ),
        ));
    }
    for (i, e) in effects.iter().enumerate() {
        if effects[..i].iter().any(|o| o.id() == e.id()) {
            return Err(Refusal::new(
                Arg::Discriminate,
                format!("effect {} given twice", e.name()),
            ));
        }
    }
    Ok(effects)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_door_names_the_input_in_its_own_words() {
        let r = start((2.0, 30.0), &IdentifyOptions::default()).unwrap_err();
        let cli = r.message(Door::Cli);
        let py = r.message(Door::Python);
        assert!(cli.starts_with("--start 2,30: the start must lie"), "{cli}");
        assert!(
            py.starts_with("start = (2, 30): the start must lie"),
            "{py}"
        );
        assert_eq!(
            cli.split_once(": ").unwrap().1,
            py.split_once(": ").unwrap().1
        );
        let r = max_nodes(7).unwrap_err();
        assert_eq!(
            r.message(Door::Python),
            "max_nodes: the mesh limit must lie in 50..=1000000 nodes (got 7; default 20000)"
        );
        assert!(max_nodes(-3).is_err() && max_nodes(50).is_ok());
        let r = robust_loss(Loss::Linear, Some(0.02)).unwrap_err();
        assert_eq!(
            r.message(Door::Cli),
            "--f-scale 0.02: a soft margin needs a robust loss, but the loss is linear (least \
             squares, the default of --loss); add --loss soft_l1 (or huber, cauchy), or drop \
             --f-scale"
        );
        assert_eq!(
            r.message(Door::Python),
            "f_scale = 0.02: a soft margin needs a robust loss, but the loss is linear (least \
             squares, the default of loss); add loss=\"soft_l1\" (or huber, cauchy), or drop \
             f_scale"
        );
    }

    #[test]
    fn ranges_and_numbers() {
        assert!(range(Arg::NRange, "n", (0.5, 0.5), [0.0, 1.0]).is_err());
        let r = range(Arg::NRange, "n", (0.9, 0.1), [0.0, 1.0]).unwrap_err();
        assert!(r.reason.contains("did you mean 0.1,0.9?"), "{}", r.reason);
        assert!(range(Arg::NRange, "n", (0.1, 0.9), [0.0, 1.0]).is_ok());
        assert_eq!(show(1e308), "1e308");
        assert!(n(-0.1).is_err() && kappa(701.0).is_err() && tol(1.0).is_err());
        assert!(noise(0.5).is_err() && noise(0.015).is_ok());
        assert!(grid(1, 5, MAX_GRID_POINTS).is_err() && grid(1001, 2, usize::MAX).is_err());
        assert!(newtonian_start(true, Some((0.8, 11.0))).is_err());
        assert!(newtonian_start(false, Some((0.8, 11.0))).is_ok());
    }

    #[test]
    fn arrays_meet_the_caps_of_files_with_one_override() {
        let caps = LoadOptions::default();
        let r = measurement_rows(&[("a", 10), ("b", 10_000_000)], 2, &caps).unwrap_err();
        let py = r.message(Door::Python);
        assert!(
            py.starts_with("measurements: experiment \"b\" has 10,000,000 rows"),
            "{py}"
        );
        assert!(py.ends_with("allow_large_inputs=True"), "{py}");
        assert!(r.message(Door::Cli).ends_with("--allow-large-inputs"));
        assert!(measurement_rows(&[("a", 1_000_000)], 1, &caps).is_ok());
        let lifted = load_options(caps, true);
        assert!(measurement_rows(&[("b", 10_000_000)], 1, &lifted).is_ok());
        // nine files of a million rows exceed the fit-memory cap
        let nine: Vec<(&str, usize)> = (0..9).map(|_| ("x", 1_000_000)).collect();
        assert!(measurement_rows(&nine, 9, &LoadOptions::default()).is_err());
    }
}
