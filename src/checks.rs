//! Up-front checks of command-line values (sizes, ranges, domains), so that a bad value is
//! refused with the flag and value named before any work starts, and failures of one
//! experiment's simulation named with the experiment and its TOML line.

use rheometer::effects::Effect;
use rheometer::failure_hints::ExperimentFailure;
use rheometer::input::{parse_experiments, Location, MAX_PLAUSIBLE_DIAMETER_M};
use rheometer::rheometer::landscape::LANDSCAPE_MAX_NODES;
use rheometer::rheometer::{IdentifyOptions, LandscapeSample};
use std::error::Error;
use std::path::Path;

/// Largest `--points` of `simulate` (rows per profile CSV; 1e6 rows took 1.8 GB of memory and
/// 86 MB per CSV for the 9 shipped experiments, 1e5 a tenth).
pub const MAX_POINTS: usize = 100_000;
/// Largest number of values per direction of `landscape --grid`.
pub const MAX_GRID_SIDE: usize = 1000;
/// Largest number of points of `landscape --grid` (N x M).
pub const MAX_GRID_POINTS: usize = 100_000;
/// Smallest `--max-nodes` (the cold start begins on a mesh of 21 nodes).
pub const MIN_MAX_NODES: usize = 50;
/// Largest `--max-nodes`.
pub const MAX_MAX_NODES: usize = 1_000_000;
/// Default `--max-nodes` of the solves of `simulate`, `fit`, `diagnose` and `compare`.
pub const DEFAULT_MAX_NODES: usize = 20_000;
/// Smallest take-up diameter accepted from `--take-up-diameter` \[m\].
pub const MIN_TAKE_UP_DIAMETER_M: f64 = 1e-7;
/// Largest |κ| (K = e^κ Pa stays a finite positive number).
pub const MAX_ABS_KAPPA: f64 = 700.0;
/// Tolerance range of `landscape --tol`.
pub const TOL_RANGE: (f64, f64) = (1e-12, 0.1);

/// A number as people read it: the shortest form that reads back exactly, in exponent
/// notation below 1e-4 and from 1e6 on (`1e308`, not 309 digits).
pub fn show(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-4..1e6).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
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

/// A whole number within `range` (inclusive); `what` says what is counted, as in "give
/// 2 to 100000 {what}". Negative and non-integer values get the same range message.
fn count_in(s: &str, range: std::ops::RangeInclusive<usize>, what: &str) -> Result<usize, String> {
    let (lo, hi) = (*range.start(), *range.end());
    let out_of_range = |got: &str| format!("give {lo} to {hi} {what} (got {got})");
    match s.trim().parse::<i128>() {
        Ok(v) => usize::try_from(v)
            .ok()
            .filter(|v| range.contains(v))
            .ok_or_else(|| out_of_range(&given(s))),
        Err(_) if number(s).is_ok() => Err(format!(
            "{}: {}",
            out_of_range(&given(s)),
            "a whole number is needed"
        )),
        Err(_) => Err(format!(
            "\"{}\" is not a whole number; give {lo} to {hi} {what}",
            given(s)
        )),
    }
}

/// `--points`: 2 to [`MAX_POINTS`].
pub fn parse_points(s: &str) -> Result<usize, String> {
    count_in(s, 2..=MAX_POINTS, "output positions per profile")
}

/// `--max-nodes`: [`MIN_MAX_NODES`] to [`MAX_MAX_NODES`].
pub fn parse_max_nodes(s: &str) -> Result<usize, String> {
    let v = count_in(s, 0..=usize::MAX, "nodes").map_err(|_| {
        format!(
            "the mesh limit must lie in {MIN_MAX_NODES}..={MAX_MAX_NODES} nodes (got {}; \
             default {DEFAULT_MAX_NODES})",
            given(s)
        )
    })?;
    if !(MIN_MAX_NODES..=MAX_MAX_NODES).contains(&v) {
        return Err(format!(
            "the mesh limit must lie in {MIN_MAX_NODES}..={MAX_MAX_NODES} nodes (got {v}; \
             default {DEFAULT_MAX_NODES})"
        ));
    }
    Ok(v)
}

/// `--relative-uncertainty`: in (0, 1), like the TOML key `relative_uncertainty`.
pub fn parse_fraction(s: &str) -> Result<f64, String> {
    let v = number(s)?;
    if !(v > 0.0 && v < 1.0) {
        return Err(format!(
            "a relative uncertainty must lie in (0, 1) like the TOML key relative_uncertainty \
             (got {}; 0.01 is 1 %)",
            show(v)
        ));
    }
    Ok(v)
}

/// `--f-scale`: a positive, finite relative residual below 1.
pub fn parse_f_scale(s: &str) -> Result<f64, String> {
    let v = number(s)?;
    if !(v > 0.0 && v < 1.0) {
        return Err(format!(
            "f_scale is a relative residual in (0, 1) (got {}; 0.02 is 2 %)",
            show(v)
        ));
    }
    Ok(v)
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
    /// Sets the loss and its soft margin of `opts`. Error: a soft margin without a robust loss.
    pub fn apply(&self, opts: &mut IdentifyOptions) -> Result<(), String> {
        if let Some(c) = self.f_scale {
            if self.loss.is_linear() {
                return Err(format!(
                    "--f-scale {}: a soft margin needs a robust loss, but the loss is linear \
                     (least squares, the default of --loss); add --loss soft_l1 (or huber, \
                     cauchy), or drop --f-scale",
                    show(c)
                ));
            }
        }
        opts.loss = self.loss;
        opts.f_scale = self.f_scale;
        Ok(())
    }
}

/// `--tol`: in [`TOL_RANGE`].
pub fn parse_tol(s: &str) -> Result<f64, String> {
    let v = number(s)?;
    if !(TOL_RANGE.0..=TOL_RANGE.1).contains(&v) {
        return Err(format!(
            "the tolerance must lie in [{:e}, {}] (got {})",
            TOL_RANGE.0,
            TOL_RANGE.1,
            show(v)
        ));
    }
    Ok(v)
}

/// `--refit-top`: 1 to the number of built-in candidate effects.
pub fn parse_refit_top(s: &str) -> Result<usize, String> {
    let most = Effect::builtin().len();
    count_in(
        s,
        1..=most,
        "candidates to refit (the number of candidate effects is the most)",
    )
}

/// `--n`: the Carreau-type law's domain, a finite n >= 0.
pub fn parse_n(s: &str) -> Result<f64, String> {
    check_n(number(s)?)
}

/// Checks that `v` lies in the Carreau-type law's domain of n (finite, >= 0).
pub fn check_n(v: f64) -> Result<f64, String> {
    if !(v >= 0.0 && v.is_finite()) {
        return Err(format!(
            "the power index n must be >= 0 (the Carreau-type law's domain; 1 is Newtonian), \
             got {}",
            show(v)
        ));
    }
    Ok(v)
}

/// `--kappa`: a finite κ with |κ| <= [`MAX_ABS_KAPPA`].
pub fn parse_kappa(s: &str) -> Result<f64, String> {
    check_kappa(number(s)?)
}

/// Checks that `v` is a usable κ (finite, |κ| <= [`MAX_ABS_KAPPA`]).
pub fn check_kappa(v: f64) -> Result<f64, String> {
    if v.is_nan() || v.abs() > MAX_ABS_KAPPA {
        return Err(format!(
            "kappa = ln(K / 1 Pa) must lie in [-{MAX_ABS_KAPPA}, {MAX_ABS_KAPPA}] (K = e^kappa \
             overflows beyond; the fit searches [7, 20]), got {}",
            show(v)
        ));
    }
    Ok(v)
}

/// `--take-up-diameter`: in [[`MIN_TAKE_UP_DIAMETER_M`], `MAX_PLAUSIBLE_DIAMETER_M`] m.
pub fn parse_take_up_diameter(s: &str) -> Result<f64, String> {
    let v = number(s)?;
    if !(MIN_TAKE_UP_DIAMETER_M..=MAX_PLAUSIBLE_DIAMETER_M).contains(&v) {
        return Err(format!(
            "a take-up diameter must lie in [{MIN_TAKE_UP_DIAMETER_M:e}, \
             {MAX_PLAUSIBLE_DIAMETER_M}] m (got {} m; the unit is metres)",
            show(v)
        ));
    }
    Ok(v)
}

/// Checks that `(lo, hi)` given with `flag` is increasing and within `[min, max]`, the fit's
/// bounds of the parameter `name`.
pub fn check_range(
    flag: &str,
    name: &str,
    (lo, hi): (f64, f64),
    [min, max]: [f64; 2],
) -> Result<(), String> {
    let given = format!("{flag} {},{}", show(lo), show(hi));
    if lo == hi {
        return Err(format!(
            "{given}: the range is a single value; give MIN,MAX with MIN < MAX, within the \
             fit's bounds [{min}, {max}] of {name}"
        ));
    }
    if lo > hi {
        return Err(format!(
            "{given}: give MIN,MAX with MIN < MAX (did you mean {},{}?)",
            show(hi),
            show(lo)
        ));
    }
    if lo < min || hi > max {
        return Err(format!(
            "{given}: {name} must lie within the fit's bounds [{min}, {max}]"
        ));
    }
    Ok(())
}

/// Checks `--start N,KAPPA` against the fit's bounds.
pub fn check_start((n, kappa): (f64, f64), opts: &IdentifyOptions) -> Result<(), String> {
    let inside = |v: f64, i: usize| v >= opts.lower[i] && v <= opts.upper[i];
    if !inside(n, 0) || !inside(kappa, 1) {
        return Err(format!(
            "--start {},{}: the start must lie within the fit's bounds n in [{}, {}] and \
             kappa in [{}, {}]",
            show(n),
            show(kappa),
            opts.lower[0],
            opts.upper[0],
            opts.lower[1],
            opts.upper[1]
        ));
    }
    Ok(())
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

/// The `--grid` size "NxM": 2 to [`MAX_GRID_SIDE`] values per direction, at most
/// [`MAX_GRID_POINTS`] points.
pub fn parse_grid(s: &str) -> Result<(usize, usize), String> {
    let (a, b) = parse_two::<usize>(s, &['x', 'X'], "\"NxM\"", "a count")?;
    if a < 2 || b < 2 {
        return Err("the grid needs at least 2 points per direction".into());
    }
    if a > MAX_GRID_SIDE || b > MAX_GRID_SIDE || a.saturating_mul(b) > MAX_GRID_POINTS {
        return Err(format!(
            "{a}x{b} is too large: at most {MAX_GRID_SIDE} values per direction and \
             {MAX_GRID_POINTS} points (a 41x41 grid of the shipped data takes seconds; zoom in \
             with --n-range and --kappa-range instead)"
        ));
    }
    Ok((a, b))
}

/// The failure `e` prefixed with the experiment's name and its line in the experiments file
/// `toml` (with hints) where the error chain names an experiment whose simulation failed;
/// other errors unchanged. `law` are the law parameters `(n, κ)` of the solve where the error
/// does not state them.
pub fn name_experiment(e: Box<dyn Error>, toml: &Path, law: Option<[f64; 2]>) -> Box<dyn Error> {
    if e.downcast_ref::<ExperimentFailure>().is_some() {
        return e;
    }
    let Some((name, _)) = rheometer::failure_hints::failed_experiment(e.as_ref()) else {
        return e;
    };
    let loaded = std::fs::read_to_string(toml)
        .ok()
        .and_then(|text| parse_experiments(&text, toml).ok());
    match loaded {
        Some(loaded) => rheometer::failure_hints::name_experiment(e, &loaded, toml, law),
        None => {
            let unlocated = Location {
                path: toml.to_path_buf(),
                line: None,
            };
            Box::new(ExperimentFailure::unlocated(&name, unlocated, e))
        }
    }
}

/// The mesh limit of a landscape: `--max-nodes` (at most [`LANDSCAPE_MAX_NODES`], the cap of
/// the landscape's solves) or that cap.
pub fn landscape_max_nodes(max_nodes: Option<usize>) -> Result<usize, String> {
    match max_nodes {
        None => Ok(LANDSCAPE_MAX_NODES),
        Some(m) if m <= LANDSCAPE_MAX_NODES => Ok(m),
        Some(m) => Err(format!(
            "--max-nodes {m}: the landscape caps its meshes at {LANDSCAPE_MAX_NODES} nodes \
             (points that need more are marked missing); give at most {LANDSCAPE_MAX_NODES}"
        )),
    }
}

/// The estimate of a landscape's run time, from its sample rows (computed and timed exactly as
/// the landscape computes its rows, [`Rheometer::landscape_sample`](rheometer::rheometer::Rheometer::landscape_sample); the run keeps them):
/// "landscape: 441 points on 2 threads, about 16 s (measured on 3 of its 21 rows, 1.5 s in
/// all: about 0.65 s per row of 21 points)". `grid` is (n values, κ values), `sample_s` the
/// wall time the sample took.
pub fn landscape_estimate(sample: &LandscapeSample, grid: (usize, usize), sample_s: f64) -> String {
    let threads = rayon::current_num_threads().clamp(1, grid.1.max(1));
    let t = sample_s + sample.remaining_s(threads);
    let about = if t < 90.0 {
        format!("{t:.0} s")
    } else if t < 5400.0 {
        format!("{:.0} min", t / 60.0)
    } else {
        format!("{:.1} h", t / 3600.0)
    };
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
