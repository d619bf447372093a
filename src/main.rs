//! `rheometer`: simulate fiber spinning and identify the Carreau-type elongational viscosity
//! from your own TOML + CSV measurements.

use clap::{Parser, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use rheometer::data::input::{
    load_experiments_with, LoadOptions, LoadedExperiments, DEFAULT_MAX_JSON_BYTES,
};
use rheometer::data::take_up::MissingTakeUp;
use rheometer::diagnostics::residual_figure;
use rheometer::diagnostics::Comparison;
use rheometer::diagnostics::{DiagnoseOptions, ResidualProfiles};
use rheometer::fit::{
    DataCheck, Estimator, FarRule, FitSummary, IdentifyOptions, LandscapeRun, PointStatus,
    Rheometer,
};
use rheometer::model::{EffectSetting, LawChoice, ModelSpec};
use rheometer::model::{FiberSolution, SimulateOptions};
use rheometer::report::figures::{self, ExperimentView, ModelCurves, View};
use rheometer::report::flow_curve_figure::flow_curve_figure;
use rheometer::report::output::write_profiles_csv;
use rheometer::report::output_files::{CheckedOutputs, PARTIAL_NAME};
use rheometer::report::plot::FigureFormat;
use rheometer::report::report_json::{to_report_json, ReportKind};
use rheometer::workflow::failure_hints::ExperimentFailure;
use rheometer::workflow::request::{self, Door, Refusal};
use rheometer::workflow::{self, CompareRequest, FitRequest, FitRun};
use std::error::Error;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// `println!` of the report that never panics (see [`streams::out_line`]): a closed pipe
/// (`rheometer ... | head`) is ignored, any other write error (`> /dev/full`, a closed
/// stdout) makes the program exit 1 at the end with a message.
macro_rules! outln {
    ($($arg:tt)*) => {{
        $crate::streams::out_line(format_args!($($arg)*));
    }};
}

pub use signals::{interrupted, EXIT_INTERRUPTED, INTERRUPTED};
pub use streams::err_line;

/// A command stopped by SIGINT after keeping what it finished: reported as
/// `interrupted: MESSAGE`, exit code 130.
#[derive(Debug)]
pub struct Interrupted(pub String);

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl Error for Interrupted {}

/// A malformed or out-of-range flag found after parsing, where the parser cannot judge a
/// value alone (a start outside the fit's bounds, an effect given twice): reported as
/// `error: ...` with exit code 2, like the parser's own usage errors (the rule of the CLI
/// reference). A [`Refusal`] of the library's request rules is one too.
#[derive(Debug)]
pub struct FlagError(pub String);

impl std::fmt::Display for FlagError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl Error for FlagError {}

/// Exit code of a malformed or out-of-range flag (clap's usage errors, [`FlagError`],
/// [`Refusal`]).
const EXIT_USAGE: u8 = 2;

// after the macro, which they use
mod checks;
mod compare;
mod design;
mod diagnose;
mod fit;
mod landscape;
mod outputs;
mod previous;
mod signals;
mod simulate;
mod streams;

#[derive(Parser)]
#[command(
    name = "rheometer",
    version,
    about = "Simulation-based elongational rheometer for Carreau-type polymer melts",
    long_about = "Simulates stationary melt spinning and identifies the Carreau-type elongational \
viscosity (n, kappa = ln K) from fiber diameters measured along the spin line.",
    after_help = "Examples:\n  \
rheometer fit data/pmma7n_synthetic/experiments.toml --json target/fit.json\n  \
rheometer simulate data/pmma7n_synthetic/experiments.toml --take-up-from-data --out target/sim\n  \
rheometer landscape data/pmma7n_synthetic/experiments.toml --grid 21x21 --out target/landscape\n\n\
Input format, outputs and error messages: see the book (mdbook build book)."
)]
struct Cli {
    /// Print nothing but results and errors.
    #[arg(long, global = true, conflicts_with = "verbose")]
    quiet: bool,
    /// Print more detail (solver statistics, iterations).
    #[arg(long, short, global = true)]
    verbose: bool,
    /// Figure format.
    #[arg(long, value_enum, global = true, default_value_t = FormatArg::Png)]
    format: FormatArg,
    /// Largest mesh (nodes) of a BVP solve (50 to 1000000; default 20000, the landscape
    /// 1000). A solve that needs more fails and names this flag.
    #[arg(long, global = true, allow_hyphen_values = true, value_parser = checks::parse_max_nodes)]
    max_nodes: Option<usize>,
    /// Lift the caps on input size (16 MB experiments file, 128 MB and 1,000,000 rows per CSV
    /// file, 64 kB per CSV line, 1000 experiments, 4 GB estimated fit memory). Inputs must
    /// still be regular files.
    #[arg(long, global = true)]
    allow_large_inputs: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum EstimatorArg {
    /// Relative least squares against the raw data, take-up diameters fitted.
    Principled,
    /// The paper's strain-rate-weighted cost against the smoothed data.
    Paper,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum FormatArg {
    /// Bitmap figures.
    Png,
    /// Vector figures.
    Svg,
}

impl FormatArg {
    /// The library's format.
    pub fn format(self) -> FigureFormat {
        match self {
            FormatArg::Png => FigureFormat::Png,
            FormatArg::Svg => FigureFormat::Svg,
        }
    }

    fn ext(self) -> &'static str {
        self.format().extension()
    }
}

#[derive(Subcommand)]
enum Command {
    /// Simulate every experiment and write profiles (CSV) and figures into DIR.
    #[command(after_help = "Examples:\n  \
rheometer simulate data/pmma7n_synthetic/experiments.toml --n 0.8 --kappa 11.71 \
--take-up-from-data --out target/sim\n  \
rheometer simulate data/pmma7n_synthetic/experiments.toml --newtonian --take-up-diameter 1e-4 \
--out target/sim_newtonian\n\n\
Writes DIR/<experiment>_profile.csv with the columns listed in the book's CLI reference, \
DIR/profiles.png (diameter and temperature of all experiments) and, where measurements exist, \
DIR/diameters_vs_data.png (split into diameters_vs_data_1.png, ... beyond 24 experiments). \
DIR/PARTIAL.txt lists finished and missing profiles while the run is incomplete (running, \
failed, or stopped by Ctrl-C: exit code 130); it is removed when every profile is written.")]
    Simulate(simulate::SimulateArgs),
    /// Identify (n, kappa) from the measurements and print an uncertainty report.
    #[command(after_help = "Examples:\n  \
rheometer fit data/pmma7n_synthetic/experiments.toml --json target/fit.json\n  \
rheometer fit data/pmma7n_synthetic/experiments.toml --estimator paper --start 0.5,11.51\n  \
rheometer fit data/pmma7n_synthetic/experiments.toml --out target/fit\n  \
rheometer fit data/pmma7n_synthetic/experiments.toml --newtonian")]
    Fit(fit::FitArgs),
    /// Which physical effect is missing from the model? Ranks the candidate effects by how
    /// much of the misfit each explains (linearised scores, refits, delta BIC).
    ///
    /// Example: rheometer diagnose data/pmma7n_synthetic/experiments.toml --json
    /// target/diagnose.json --out target/diagnose
    Diagnose(diagnose::DiagnoseArgs),
    /// Compute the cost landscape J(n, kappa) on a grid; write it as CSV and heat map.
    #[command(after_help = "Examples:\n  \
rheometer landscape data/pmma7n_synthetic/experiments.toml --grid 41x41 --out target/landscape\n  \
rheometer landscape data/pmma7n_synthetic/experiments.toml --grid 11x11 --n-range 0.6,1 \
--kappa-range 10,14 --estimator principled --out target/landscape_zoom\n\n\
Writes DIR/landscape.csv with the columns n,kappa,cost,status (ok, failed or not_computed),tol \
(the BVP tolerance of the point) and the heat map DIR/landscape.png. Ctrl-C stops it, keeping the finished points (exit code 130).")]
    Landscape(landscape::LandscapeArgs),
    /// Compare the model with the measurements: residuals along the spin line, noise level,
    /// chi2/dof, whiteness and where the misfit is systematic; text, JSON, CSV and figures.
    ///
    /// Example: rheometer compare data/pmma7n_synthetic/experiments.toml --fit target/fit.json
    /// --out target/compare
    Compare(compare::CompareArgs),
    /// Which experiment next: fit, then rank candidate experiments (mass flow x take-up) by
    /// the predicted uncertainty of (n, kappa) after adding each (exact sensitivities).
    #[command(after_help = "Examples:\n  \
rheometer design data/pmma7n_synthetic/experiments.toml --grid 9x9\n  \
rheometer design data/pmma7n_synthetic/experiments.toml --stencil-velocity 0.2,1.6 \
--take-up-diameter 4e-5,2e-4 --criterion a --out target/design\n\n\
Writes DIR/design.txt, DIR/design.json and DIR/design.csv (every candidate: predicted \
standard errors, correlation, criteria, rank, or why the model has no solution there).")]
    Design(design::DesignArgs),
}

/// Options shared by every subcommand.
pub struct Global {
    /// Print nothing but results and errors.
    pub quiet: bool,
    /// Print more detail.
    pub verbose: bool,
    /// Figure format.
    pub format: FormatArg,
    /// `--max-nodes`, if given.
    pub max_nodes: Option<usize>,
    /// `--allow-large-inputs`: no caps on input size.
    pub allow_large_inputs: bool,
}

impl Global {
    /// A progress message on stderr (nothing with `--quiet`).
    pub fn say(&self, s: String) {
        if !self.quiet {
            err_line(&s);
        }
    }

    /// A warning on stderr (`warning: ...`), printed even with `--quiet`.
    pub fn warn(&self, s: String) {
        err_line(&format!("warning: {s}"));
    }
}

/// Loads the experiments file and its CSV files (at least 4 rows each) under the input caps
/// (lifted by `--allow-large-inputs`), and prints the loader's warnings once.
/// `take_up_from_data`: whether experiments without a take-up condition will use `d_fit(L)`
/// of their data (then a spin line far beyond the measured range is refused);
/// `require_data`: whether every experiment must name a data file.
pub fn load_input(
    g: &Global,
    path: &Path,
    take_up_from_data: bool,
    require_data: bool,
) -> Result<LoadedExperiments, Box<dyn Error>> {
    let base = LoadOptions {
        take_up_from_data,
        require_data,
        ..LoadOptions::with_min_points(4)
    };
    let options = request::load_options(base, g.allow_large_inputs);
    let loaded = load_experiments_with(path, &options).map_err(|e| {
        if e.exceeded_limit().is_some() {
            request::input_message(&e, Door::Cli).into()
        } else {
            Box::<dyn Error>::from(e)
        }
    })?;
    for w in &loaded.warnings {
        g.warn(w.to_string());
    }
    Ok(loaded)
}

fn estimator(e: EstimatorArg) -> Estimator {
    match e {
        EstimatorArg::Principled => Estimator::Principled,
        EstimatorArg::Paper => Estimator::Paper,
    }
}

fn profiles_of(rh: &Rheometer, sols: &[diffbvp::Solution]) -> ResidualProfiles {
    sols.iter()
        .enumerate()
        .map(|(k, s)| {
            (
                rh.experiments[k].name.clone(),
                rh.measurements[k]
                    .positions
                    .iter()
                    .copied()
                    .zip(rh.relative_residuals(k, s))
                    .collect(),
            )
        })
        .collect()
}

fn linspace(a: f64, b: f64, m: usize) -> Vec<f64> {
    diffbvp::mesh::linspace(a, b, m)
}

/// Reads the fit of a report file given by `flag` (`--from`, `--fit`; `-` is standard
/// input): a fit report or a diagnosis' final fit, through the library's one bounded, strict
/// reader, capped at [`DEFAULT_MAX_JSON_BYTES`] unless `--allow-large-inputs`.
pub fn read_fit_file(g: &Global, path: &Path, flag: &str) -> Result<FitSummary, Box<dyn Error>> {
    let max = if g.allow_large_inputs {
        u64::MAX
    } else {
        DEFAULT_MAX_JSON_BYTES
    };
    Ok(FitSummary::read_file(
        path,
        max,
        flag,
        &[ReportKind::Fit, ReportKind::Diagnosis],
    )?)
}

/// Warns when the fit read from `flag FILE` was not made on the data of `loaded`: other
/// numbers under the same experiment names (its data digest differs). A warning, not a
/// refusal: a fit is legitimately compared with new data, or continued on edited data.
pub fn warn_other_data(g: &Global, fit: &FitSummary, loaded: &LoadedExperiments, source: &str) {
    let data = loaded
        .set
        .experiments
        .iter()
        .zip(&loaded.set.measurements)
        .filter_map(|(e, m)| m.as_ref().map(|m| (e, m)));
    if let DataCheck::Differs(message) = fit.check_data(data, source) {
        g.warn(message);
    }
}

fn run(cli: Cli) -> Result<(), Box<dyn Error>> {
    // the parser's conflict misses the two on different levels (`--verbose fit ... --quiet`)
    if cli.quiet && cli.verbose {
        return Err(Box::new(FlagError(
            "the argument '--quiet' cannot be used with '--verbose': give one of them".into(),
        )));
    }
    let g = Global {
        quiet: cli.quiet,
        verbose: cli.verbose,
        format: cli.format,
        max_nodes: cli.max_nodes,
        allow_large_inputs: cli.allow_large_inputs,
    };
    let toml = match &cli.command {
        Command::Simulate(a) => a.experiments.clone(),
        Command::Fit(a) => a.experiments.clone(),
        Command::Diagnose(a) => a.experiments.clone(),
        Command::Landscape(a) => a.experiments.clone(),
        Command::Compare(a) => a.experiments.clone(),
        Command::Design(a) => a.experiments.clone(),
    };
    match cli.command {
        Command::Simulate(a) => simulate::run(a, &g),
        Command::Fit(a) => fit::run(a, &g),
        Command::Diagnose(a) => diagnose::run(a, &g),
        Command::Landscape(a) => landscape::run(a, &g),
        Command::Compare(a) => compare::run(a, &g),
        Command::Design(a) => design::run(a, &g),
    }
    // a failed simulation names its experiment and TOML line, with likely causes
    .map_err(|e| checks::name_experiment(e, &toml, None))
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            // usage errors on stderr (exit 2), --help and --version on stdout (exit 0)
            if let Err(w) = e.print() {
                if !e.use_stderr() {
                    streams::note_stdout_error(&w);
                }
            }
            if let Some(note) = negative_number_note() {
                err_line(&note);
            }
            return match streams::finish_stdout() {
                Err(()) => ExitCode::FAILURE,
                Ok(()) => ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(1)),
            };
        }
    };
    if let Err(e) = bounded_environment() {
        err_line(&format!("error: {e}"));
        return ExitCode::FAILURE;
    }
    // `simulate` and `landscape` stop cleanly after SIGINT (they check the flag between
    // experiments or grid points); the other commands, and every command after SIGTERM or
    // SIGHUP, end at once, without leaving a temporary of a write in progress behind
    if matches!(cli.command, Command::Simulate(_) | Command::Landscape(_)) {
        signals::install(signals::INTERRUPT_GRACE);
    } else {
        signals::install(std::time::Duration::ZERO);
    }
    let result = run(cli);
    let stdout_ok = streams::finish_stdout();
    match result {
        Ok(()) if stdout_ok.is_ok() => ExitCode::SUCCESS,
        Ok(()) => ExitCode::FAILURE,
        Err(e) => {
            if let Some(i) = e.downcast_ref::<Interrupted>() {
                err_line(&format!("{}: {i}", signals::stopped_by()));
                return ExitCode::from(signals::exit_code());
            }
            report_error(e.as_ref());
            if e.downcast_ref::<FlagError>().is_some() || e.downcast_ref::<Refusal>().is_some() {
                return ExitCode::from(EXIT_USAGE);
            }
            ExitCode::FAILURE
        }
    }
}

/// Checks the environment before any work: every `DIFFBVP_*` variable valid (else an error
/// naming it and its range), and the thread pool built with the size `RAYON_NUM_THREADS`
/// asks for, clamped to a number this machine can run (with a warning); a pool that cannot be
/// built (threads refused by a memory or process limit) is an error, not a panic.
fn bounded_environment() -> Result<(), String> {
    rheometer::environment::check_diffbvp_variables(std::env::vars_os())?;
    if let Some(w) = memory_limit_note() {
        err_line(&format!("warning: {w}"));
    }
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    let value = std::env::var_os("RAYON_NUM_THREADS").map(|v| v.to_string_lossy().into_owned());
    let (threads, warning) = rheometer::environment::thread_count(value.as_deref(), cores);
    if let Some(w) = warning {
        err_line(&format!("warning: {w}"));
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build_global()
        .map_err(|e| {
            format!(
                "cannot start {threads} worker threads ({e}): a limit on memory or processes \
                 (ulimit -v, ulimit -u, a container's limit) is too tight; lower \
                 RAYON_NUM_THREADS (e.g. RAYON_NUM_THREADS=1) or raise the limit"
            )
        })
}

/// Below this address-space limit (`ulimit -v`) the program warns at start: a fit of the
/// shipped data sets needs several hundred MB of address space (thread stacks included).
#[cfg(unix)]
const LOW_ADDRESS_SPACE_BYTES: libc::rlim_t = 1 << 30;

/// A warning when the address space is limited below [`LOW_ADDRESS_SPACE_BYTES`]: the program
/// may then end with "memory allocation failed" (an abort the program cannot turn into a
/// message), so the limit is named before the work.
fn memory_limit_note() -> Option<String> {
    #[cfg(unix)]
    {
        let mut lim = libc::rlimit {
            rlim_cur: 0,
            rlim_max: 0,
        };
        // SAFETY: getrlimit writes the struct it is given and nothing else
        let ok = unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut lim) } == 0;
        let cur = lim.rlim_cur;
        if ok && cur != libc::RLIM_INFINITY && cur < LOW_ADDRESS_SPACE_BYTES {
            return Some(format!(
                "the address space of this process is limited to {} MB (ulimit -v); a fit may \
                 need more and would then end with \"memory allocation failed\"; raise the \
                 limit (ulimit -v unlimited) if it does",
                cur >> 20
            ));
        }
    }
    None
}

/// A note for `--n -- -0.1` (clap reads `--` as the value and `-0.1` as flags): negative
/// numbers are values as they are.
fn negative_number_note() -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.windows(3)
        .find(|w| {
            w[0].starts_with("--")
                && w[1] == "--"
                && w[2].starts_with('-')
                && w[2].parse::<f64>().is_ok()
        })
        .map(|w| {
            format!(
                "note: negative numbers need no \"--\": write {} {} (or {}={})",
                w[0], w[2], w[0], w[2]
            )
        })
}

/// Prints `error: ...`, the causes not already quoted, and the hints of a failed experiment.
fn report_error(e: &(dyn Error + 'static)) {
    let mut printed = e.to_string();
    err_line(&format!("error: {printed}"));
    let mut src = e.source();
    while let Some(s) = src {
        // messages that already quote their cause are not repeated
        let text = s.to_string();
        if !printed.contains(&text) {
            err_line(&format!("  caused by: {text}"));
        }
        printed = text;
        src = s.source();
    }
    if let Some(f) = e.downcast_ref::<ExperimentFailure>() {
        for h in &f.hints {
            err_line(&format!("  hint: {h}"));
        }
    }
}
