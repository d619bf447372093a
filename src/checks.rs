//! Up-front checks of command-line values (sizes, ranges, domains), so that a bad value is
//! refused with the flag and value named before any work starts, and failures of one
//! experiment's simulation named with the experiment and its TOML line.

use rheometer::data::input::{parse_experiments, Location};
use rheometer::design::DesignEstimate;
use rheometer::fit::{IdentifyOptions, LandscapeSample};
use rheometer::model::Effect;
use rheometer::workflow::failure_hints::ExperimentFailure;
use std::error::Error;
use std::path::Path;

pub use rheometer::report::format::show;
pub use rheometer::workflow::request::DEFAULT_MAX_NODES;
use rheometer::workflow::request::{self, Arg, Door, Refusal, MAX_GRID_POINTS};

/// A refusal as clap shows it after the flag and the value it names: the reason alone.
fn reason(r: Refusal) -> String {
    r.reason(Door::Cli)
}

/// A value as given, for a message: trimmed and, if very long, cut to its first 40
/// characters.
fn given(s: &str) -> String {
    let t = s.trim();
    match t.char_indices().nth(40) {
        Some((i, _)) => format!("{}… ({} characters)", &t[..i], t.chars().count()),
        None => t.to_string(),
    }
}

fn number(s: &str) -> Result<f64, String> {
    if s.trim() == "--" {
        return Err(
            "\"--\" is not a number; negative numbers need no \"--\": write e.g. \
                    --n -0.1 or --n=-0.1"
                .into(),
        );
    }
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("\"{}\" is not a number", given(s)))?;
    if !v.is_finite() {
        return Err(format!("{} is not a finite number", given(s)));
    }
    Ok(v)
}

/// A whole number of the flag's text `s`: the number, or why it is none (`range` and `what`
/// for the words: "give 2 to 100000 {what}").
fn whole(s: &str, range: std::ops::RangeInclusive<usize>, what: &str) -> Result<i128, String> {
    let (lo, hi) = (*range.start(), *range.end());
    match s.trim().parse::<i128>() {
        Ok(v) => Ok(v),
        Err(_) if number(s).is_ok() => Err(format!(
            "give {lo} to {hi} {what} (got {}): a whole number is needed",
            given(s)
        )),
        Err(_) => Err(format!(
            "\"{}\" is not a whole number; give {lo} to {hi} {what}",
            given(s)
        )),
    }
}

/// `--points`: 2 to [`request::MAX_POINTS`].
pub fn parse_points(s: &str) -> Result<usize, String> {
    let what = "output positions per profile";
    request::points(whole(s, 2..=request::MAX_POINTS, what)?).map_err(reason)
}

/// `--max-nodes`: [`request::MIN_MAX_NODES`] to [`request::MAX_MAX_NODES`].
pub fn parse_max_nodes(s: &str) -> Result<usize, String> {
    let range = request::MIN_MAX_NODES..=request::MAX_MAX_NODES;
    match whole(s, range, "nodes") {
        Ok(v) => request::max_nodes(v).map_err(reason),
        Err(_) => Err(format!(
            "the mesh limit must lie in {}..={} nodes (got {}; default {DEFAULT_MAX_NODES})",
            request::MIN_MAX_NODES,
            request::MAX_MAX_NODES,
            given(s)
        )),
    }
}

/// `--relative-uncertainty`: in (0, 1), like the TOML key `relative_uncertainty`.
pub fn parse_fraction(s: &str) -> Result<f64, String> {
    request::relative_uncertainty(number(s)?).map_err(reason)
}

/// `--f-scale`: a positive, finite relative residual below 1.
pub fn parse_f_scale(s: &str) -> Result<f64, String> {
    request::f_scale(number(s)?).map_err(reason)
}

/// `--loss` and `--f-scale` of `fit` and `diagnose`.
#[derive(clap::Args)]
pub struct LossArgs {
    /// The loss: linear (least squares), or a robust loss that down-weights outliers:
    /// soft_l1, huber, cauchy (as in scipy's least_squares; needs the principled estimator).
    #[arg(long, default_value = "linear", value_parser = diffbvp::least_squares::Loss::parse)]
    pub loss: diffbvp::least_squares::Loss,
    /// Soft margin of a robust loss as a relative residual (e.g. 0.02 for 2 %; default: the
    /// robust noise scale of the data); only with --loss soft_l1, huber or cauchy.
    #[arg(long = "f-scale", value_parser = parse_f_scale, allow_hyphen_values = true)]
    pub f_scale: Option<f64>,
}

impl LossArgs {
    /// Sets the loss and its soft margin of `opts`. Errors: a soft margin without a robust
    /// loss, a robust loss with the paper's estimator (of `opts`).
    pub fn apply(&self, opts: &mut IdentifyOptions) -> Result<(), Refusal> {
        let (loss, margin) = request::robust_loss(self.loss, self.f_scale)?;
        request::loss_for(loss, opts.estimator)?;
        opts.loss = loss;
        opts.f_scale = margin;
        Ok(())
    }
}

/// `--tol`: a BVP tolerance in the range `request::tol` holds.
pub fn parse_tol(s: &str) -> Result<f64, String> {
    request::tol(number(s)?).map_err(reason)
}

/// `--refit-top`: 1 to the number of built-in candidate effects.
pub fn parse_refit_top(s: &str) -> Result<usize, String> {
    let most = Effect::builtin().len();
    let what = "candidates to refit (the number of candidate effects is the most)";
    request::refit_top(whole(s, 1..=most, what)?).map_err(reason)
}

/// `--n`: the Carreau-type law's domain, a finite n >= 0.
pub fn parse_n(s: &str) -> Result<f64, String> {
    request::n(number(s)?).map_err(reason)
}

/// `--kappa`: a finite κ within the bound `request::kappa` holds.
pub fn parse_kappa(s: &str) -> Result<f64, String> {
    request::kappa(number(s)?).map_err(reason)
}

/// `--take-up-diameter`: a diameter in the range `request::take_up_diameter` holds.
pub fn parse_take_up_diameter(s: &str) -> Result<f64, String> {
    request::take_up_diameter(number(s)?).map_err(reason)
}

/// Checks that `(lo, hi)` given with the flag of `arg` is increasing and within `[min, max]`,
/// the fit's bounds of the parameter `name`.
pub fn check_range(
    arg: Arg,
    name: &str,
    range: (f64, f64),
    bounds: [f64; 2],
) -> Result<(), Refusal> {
    request::range(arg, name, range, bounds).map(|_| ())
}

/// Checks `--start N,KAPPA` against the fit's bounds.
pub fn check_start(start: (f64, f64), opts: &IdentifyOptions) -> Result<(), Refusal> {
    request::start(start, opts).map(|_| ())
}

/// Two values separated by one of `separators` ("0.5,11" or "41x41"); `form` and `what` name
/// the expected form and kind of value in messages.
fn parse_two<T: std::str::FromStr>(
    s: &str,
    separators: &[char],
    form: &str,
    what: &str,
) -> Result<(T, T), String> {
    let parts: Vec<&str> = s.split(separators).collect();
    if parts.len() != 2 {
        return Err(format!("expected {form}, got \"{}\"", given(s)));
    }
    let value = |p: &str| {
        p.trim()
            .parse::<T>()
            .map_err(|_| format!("\"{}\" is not {what}", given(p)))
    };
    Ok((value(parts[0])?, value(parts[1])?))
}

/// A pair "A,B" of finite numbers (`--start`, `--n-range`, `--kappa-range`).
pub fn parse_pair(s: &str) -> Result<(f64, f64), String> {
    let (a, b) = parse_two::<f64>(s, &[','], "two numbers \"A,B\"", "a number")?;
    if !a.is_finite() || !b.is_finite() {
        return Err(format!("\"{}\" contains a non-finite number", given(s)));
    }
    Ok((a, b))
}

/// The `--grid` size "NxM": the counts per direction and in all that `request::grid` allows
/// (at most [`MAX_GRID_POINTS`] points).
pub fn parse_grid(s: &str) -> Result<(usize, usize), String> {
    let (a, b) = parse_two::<i128>(s, &['x', 'X'], "\"NxM\"", "a count")?;
    request::grid(a, b, MAX_GRID_POINTS).map_err(reason)
}

/// The failure `e` prefixed with the experiment's name and its line in the experiments file
/// `toml` (with hints) where the error chain names an experiment whose simulation failed;
/// other errors unchanged. `law` are the law parameters `(n, κ)` of the solve where the error
/// does not state them.
pub fn name_experiment(e: Box<dyn Error>, toml: &Path, law: Option<[f64; 2]>) -> Box<dyn Error> {
    if e.downcast_ref::<ExperimentFailure>().is_some() {
        return e;
    }
    let Some((name, _)) = rheometer::workflow::failure_hints::failed_experiment(e.as_ref()) else {
        return e;
    };
    let loaded = std::fs::read_to_string(toml)
        .ok()
        .and_then(|text| parse_experiments(&text, toml).ok());
    match loaded {
        Some(loaded) => rheometer::workflow::failure_hints::name_experiment(e, &loaded, toml, law),
        None => {
            let unlocated = Location {
                path: toml.to_path_buf(),
                line: None,
            };
            Box::new(ExperimentFailure::unlocated(&name, unlocated, e))
        }
    }
}

/// The mesh limit of a landscape: `--max-nodes` (at most the cap of the landscape's solves)
/// or that cap.
pub fn landscape_max_nodes(max_nodes: Option<usize>) -> Result<usize, Refusal> {
    request::landscape_max_nodes(max_nodes.map(|m| m as i128))
}

/// The estimate of a landscape's run time, from its sample rows (computed and timed exactly as
/// the landscape computes its rows, [`Rheometer::landscape_sample`](rheometer::fit::Rheometer::landscape_sample); the run keeps them):
/// "landscape: 441 points on 2 threads, about 16 s (measured on 3 of its 21 rows, 1.5 s in
/// all: about 0.65 s per row of 21 points)". `grid` is (n values, κ values), `sample_s` the
/// wall time the sample took.
pub fn landscape_estimate(sample: &LandscapeSample, grid: (usize, usize), sample_s: f64) -> String {
    let threads = rayon::current_num_threads().clamp(1, grid.1.max(1));
    let about = about(sample_s + sample.remaining_s(threads));
    format!(
        "landscape: {} points on {threads} threads, about {about} (measured on {} of its {} \
         rows, {sample_s:.1} s in all: about {:.2} s per row of {} points)",
        grid.0 * grid.1,
        sample.rows(),
        grid.1,
        sample.row_s(),
        grid.0
    )
}

/// A duration for people: "16 s", "12 min", "1.5 h".
fn about(t: f64) -> String {
    if t < 90.0 {
        format!("{t:.0} s")
    } else if t < 5400.0 {
        format!("{:.0} min", t / 60.0)
    } else {
        format!("{:.1} h", t / 3600.0)
    }
}

/// What a long design says once its first rows are done (`None` under 10 s left: a short
/// design says nothing), e.g. "design: 100000 candidates on 2 threads, about 55 s more
/// (measured on 2 of its 1000 rows: 0.11 s per row of 100 candidates)".
pub fn design_estimate(e: &DesignEstimate) -> Option<String> {
    (e.remaining_s >= 10.0).then(|| {
        format!(
            "design: {} candidates on {} threads, about {} more (measured on {} of its {} \
             rows: {:.2} s per row of {} candidates)",
            e.candidates,
            e.threads,
            about(e.remaining_s),
            e.rows_measured,
            e.rows,
            e.measured_s * e.threads as f64 / e.rows_measured.max(1) as f64,
            e.candidates / e.rows.max(1)
        )
    })
}
