//! `rheometer`: simulate fiber spinning and identify the Carreau-type elongational viscosity
//! from your own TOML + CSV measurements.

use clap::{Parser, Subcommand, ValueEnum};
use diffbvp::fiber::diagnostics::compare::{FigureFormat, MissingTakeUp};
use diffbvp::fiber::diagnostics::diagnose::{DiagnoseOptions, ResidualProfiles};
use diffbvp::fiber::diagnostics::report::save_residual_figure;
use diffbvp::fiber::effects::{EffectSetting, LawChoice, ModelSpec};
use diffbvp::fiber::failure_hints::ExperimentFailure;
use diffbvp::fiber::figures::{self, ExperimentView, ModelCurves, View};
use diffbvp::fiber::flow_curve_figure::save_flow_curve_figure;
use diffbvp::fiber::input::{load_experiments_with, LoadedExperiments};
use diffbvp::fiber::output::{
    check_output_dir, create_dir, ensure_not_input, profiles_csv, write_atomically, write_profiles,
    write_text,
};
use diffbvp::fiber::rheometer::{
    Estimator, FitSummary, IdentifyOptions, LandscapeRun, PointStatus, Rheometer,
};
use diffbvp::fiber::workflow::{self, CompareRequest, FitRequest, FitRun};
use diffbvp::fiber::{FiberSolution, SimulateOptions};
use indicatif::{ProgressBar, ProgressStyle};
use std::error::Error;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// `println!` that never panics: a closed stdout (e.g. `rheometer ... | head`) is ignored,
/// any other write error (e.g. `> /dev/full`) is remembered and makes the program exit 1 at the
/// end (see [`out_line`]).
macro_rules! outln {
    ($($arg:tt)*) => {{
        $crate::out_line(format_args!($($arg)*));
    }};
}

/// The first error writing to stdout other than a closed pipe.
static STDOUT_ERROR: std::sync::OnceLock<String> = std::sync::OnceLock::new();

/// Set by the first SIGINT: `simulate` and `landscape` stop between experiments or grid points,
/// keep and mark what they finished, and exit with code 130; the other commands end at once
/// (code 130, no temporary left). A second SIGINT ends the program at once.
pub static INTERRUPTED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Whether SIGINT was received (see [`INTERRUPTED`]).
pub fn interrupted() -> bool {
    INTERRUPTED.load(std::sync::atomic::Ordering::SeqCst)
}

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

/// Exit code after SIGINT (128 + 2, the shell's convention).
const EXIT_INTERRUPTED: u8 = 130;

/// Writes one line to stdout; remembers the first failure other than a closed pipe.
pub fn out_line(args: std::fmt::Arguments<'_>) {
    use std::io::Write as _;
    let mut o = std::io::stdout().lock();
    if let Err(e) = o.write_fmt(args).and_then(|()| o.write_all(b"\n")) {
        note_stdout_error(&e);
    }
}

fn note_stdout_error(e: &std::io::Error) {
    if e.kind() != std::io::ErrorKind::BrokenPipe {
        let _ = STDOUT_ERROR.set(e.to_string());
    }
}

/// Writes one line to stderr, ignoring failures (`2>/dev/full` must not panic).
pub fn err_line(s: &str) {
    use std::io::Write as _;
    let mut e = std::io::stderr().lock();
    let _ = e.write_all(s.as_bytes()).and_then(|()| e.write_all(b"\n"));
}

/// SIGINT handling for the commands that stop cleanly.
#[cfg(unix)]
mod sigint {
    use std::sync::atomic::Ordering;

    extern "C" fn on_sigint(_: libc::c_int) {
        // async-signal-safe only: an atomic swap, and _exit on the second signal
        if super::INTERRUPTED.swap(true, Ordering::SeqCst) {
            // SAFETY: _exit is async-signal-safe and takes no pointers
            unsafe { libc::_exit(i32::from(super::EXIT_INTERRUPTED)) };
        }
    }

    /// Installs the handler setting [`super::INTERRUPTED`].
    pub fn install() {
        let handler: extern "C" fn(libc::c_int) = on_sigint;
        // SAFETY: the handler only touches an atomic and calls _exit, both async-signal-safe
        unsafe {
            libc::signal(libc::SIGINT, handler as libc::sighandler_t);
        }
    }
}

#[cfg(not(unix))]
mod sigint {
    /// Elsewhere SIGINT keeps its default (the program ends at once).
    pub fn install() {}
}

// after the macro, which they use
mod checks;
mod compare;
mod design;
mod diagnose;
mod fit;
mod landscape;
mod simulate;

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
    #[arg(long, global = true)]
    quiet: bool,
    /// Print more detail (solver statistics, iterations).
    #[arg(long, short, global = true)]
    verbose: bool,
    /// Figure format.
    #[arg(long, value_enum, global = true, default_value_t = FormatArg::Png)]
    format: FormatArg,
    /// Largest mesh (nodes) of a BVP solve (50 to 1000000; default 20000, the landscape
    /// 1000). A solve that needs more fails and names this flag.
    #[arg(long, global = true, value_parser = checks::parse_max_nodes)]
    max_nodes: Option<usize>,
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
Writes DIR/landscape.csv with the columns n,kappa,cost,status (ok, failed or not_computed) \
and the heat map DIR/landscape.png. Ctrl-C stops it, keeping the finished points (exit code 130).")]
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

fn inputs_of(path: &Path, loaded: &LoadedExperiments) -> Vec<PathBuf> {
    let mut v = vec![path.to_path_buf()];
    v.extend(loaded.details.iter().filter_map(|d| d.data.clone()));
    v
}

fn estimator(e: EstimatorArg) -> Estimator {
    match e {
        EstimatorArg::Principled => Estimator::Principled,
        EstimatorArg::Paper => Estimator::Paper,
    }
}

fn write_json(path: &Path, text: &str, inputs: &[PathBuf]) -> Result<(), Box<dyn Error>> {
    if let Some(parent) = path.parent() {
        if !parent.as_os_str().is_empty() {
            create_dir(parent)?;
        }
    }
    write_text(path, text, inputs)?;
    Ok(())
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

fn read_fit(path: &Path) -> Result<FitSummary, Box<dyn Error>> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read the fit file {}: {e}", path.display()))?;
    Ok(FitSummary::from_json(&text, &path.display().to_string())?)
}

fn run(cli: Cli) -> Result<(), Box<dyn Error>> {
    let g = Global {
        quiet: cli.quiet,
        verbose: cli.verbose,
        format: cli.format,
        max_nodes: cli.max_nodes,
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
                    note_stdout_error(&w);
                }
            }
            return match finish_stdout() {
                Err(()) => ExitCode::FAILURE,
                Ok(()) => ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(1)),
            };
        }
    };
    // `simulate` and `landscape` stop cleanly (they check the flag between experiments or grid
    // points); the other commands end at once, without leaving a temporary of a write in
    // progress behind
    sigint::install();
    if matches!(cli.command, Command::Simulate(_) | Command::Landscape(_)) {
        interrupt_watchdog(INTERRUPT_GRACE);
    } else {
        interrupt_watchdog(std::time::Duration::ZERO);
    }
    let result = run(cli);
    let stdout_ok = finish_stdout();
    match result {
        Ok(()) if stdout_ok.is_ok() => ExitCode::SUCCESS,
        Ok(()) => ExitCode::FAILURE,
        Err(e) => {
            if let Some(i) = e.downcast_ref::<Interrupted>() {
                err_line(&format!("interrupted: {i}"));
                return ExitCode::from(EXIT_INTERRUPTED);
            }
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
                    eprintln!("  hint: {h}");
                }
            }
            ExitCode::FAILURE
        }
    }
}

/// Grace period after SIGINT before the program is ended regardless (a single solve that
/// does not check the flag); outputs are written atomically and `simulate` keeps its
/// `PARTIAL.txt` manifest up to date, so ending here loses no finished file.
const INTERRUPT_GRACE: std::time::Duration = std::time::Duration::from_millis(1500);

/// Starts a thread that ends the program `grace` after SIGINT (within 25 ms of it for a zero
/// grace), after removing the temporaries of writes in progress.
fn interrupt_watchdog(grace: std::time::Duration) {
    std::thread::spawn(move || {
        while !interrupted() {
            std::thread::sleep(std::time::Duration::from_millis(25));
        }
        std::thread::sleep(grace);
        diffbvp::fiber::output::remove_pending_temporaries();
        err_line("interrupted: stopped before the current step finished; finished files are kept");
        std::process::exit(i32::from(EXIT_INTERRUPTED));
    });
}

/// Flushes stdout; reports (on stderr) the first stdout write error other than a closed pipe.
fn finish_stdout() -> Result<(), ()> {
    use std::io::Write as _;
    if let Err(e) = std::io::stdout().flush() {
        note_stdout_error(&e);
    }
    match STDOUT_ERROR.get() {
        Some(e) => {
            err_line(&format!("error: cannot write to standard output: {e}"));
            Err(())
        }
        None => Ok(()),
    }
}
