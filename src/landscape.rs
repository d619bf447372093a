//! `rheometer landscape`.

use crate::*;
use rheometer::workflow::request::Arg;

/// Arguments of `rheometer landscape`.
#[derive(clap::Args)]
pub struct LandscapeArgs {
    /// The experiments file (TOML).
    pub experiments: PathBuf,
    /// Grid size "NxM" (n values x kappa values).
    #[arg(long, default_value = "41x41", allow_hyphen_values = true, value_parser = checks::parse_grid)]
    pub grid: (usize, usize),
    /// Range of n "MIN,MAX" (within the fit's bounds [0, 1]).
    #[arg(long, default_value = "0,1", value_parser = checks::parse_pair, allow_hyphen_values = true)]
    pub n_range: (f64, f64),
    /// Range of kappa "MIN,MAX" (within the fit's bounds [7, 20]).
    #[arg(long, default_value = "9,16", value_parser = checks::parse_pair, allow_hyphen_values = true)]
    pub kappa_range: (f64, f64),
    /// The estimator whose cost is mapped (default: the paper's, as in its Fig. 4).
    #[arg(long, value_enum, default_value_t = EstimatorArg::Paper)]
    pub estimator: EstimatorArg,
    /// BVP tolerance of the landscape solves (1e-12 to 0.1; a picture: fits solve at 1e-4 and
    /// check the discretisation).
    #[arg(long, default_value_t = 1e-4, allow_hyphen_values = true, value_parser = checks::parse_tol)]
    pub tol: f64,
    /// Solve every point at --tol. Default: a point whose row neighbour's cost is more than
    /// twice its row's lowest is solved at ten times --tol (at most 1e-3; its cost to a few
    /// 1e-4 relative), the minimum and the costs near it at --tol; the CSV's column tol says
    /// which.
    #[arg(long)]
    pub uniform_tol: bool,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
}

/// Runs `rheometer landscape`.
pub fn run(args: LandscapeArgs, g: &Global) -> Result<(), Box<dyn Error>> {
    let LandscapeArgs {
        experiments,
        grid,
        n_range,
        kappa_range,
        estimator: est,
        tol,
        uniform_tol,
        out,
    } = args;
    let mut opts = IdentifyOptions::with_estimator(estimator(est));
    // sizes and ranges before any work
    checks::check_range(Arg::NRange, "n", n_range, [opts.lower[0], opts.upper[0]])?;
    checks::check_range(
        Arg::KappaRange,
        "kappa",
        kappa_range,
        [opts.lower[1], opts.upper[1]],
    )?;
    opts.simulate.tol = tol;
    opts.simulate.max_nodes = checks::landscape_max_nodes(g.max_nodes)?;
    let loaded = load_input(g, &experiments, true, true)?;
    let names = vec![
        ("table".to_string(), "landscape.csv".to_string()),
        (
            "figure".to_string(),
            format!("landscape.{}", g.format.ext()),
        ),
    ];
    let mut plan = outputs::plan_for(&experiments, &loaded);
    plan.dir(&out, "--out", names.iter().map(|(_, n)| n));
    plan.dir_files(&out, [PARTIAL_NAME]);
    let outputs = outputs::check(&plan, g)?;
    let rh = Rheometer::new(&loaded.set)?;
    let ns = linspace(n_range.0, n_range.1, grid.0);
    let ks = linspace(kappa_range.0, kappa_range.1, grid.1);
    let t0 = std::time::Instant::now();
    // a few rows first, timed: the estimate comes from the real work, and the run keeps them
    let far = if uniform_tol {
        FarRule::uniform()
    } else {
        FarRule::for_tol(tol)
    };
    let sample = rh.landscape_sample(&ns, &ks, &opts, far, &INTERRUPTED)?;
    if !g.quiet {
        g.say(checks::landscape_estimate(
            &sample,
            grid,
            t0.elapsed().as_secs_f64(),
        ));
    }
    let bar = progress_bar(g, grid.0 * grid.1);
    let run = rh.landscape_from(sample, |d| bar.set_position(d as u64), &INTERRUPTED)?;
    bar.finish_and_clear();
    let mut dir = outputs::DirWriter::begin(&outputs, &out, "rheometer landscape", "files", names)?;
    let path = dir.path("landscape.csv");
    dir.write("landscape.csv", |w| write_landscape_csv(w, &run))?;
    let total = run.status.len();
    let failed = run.failed();
    if run.cancelled {
        return Err(Interrupted(format!(
            "finished {} of {total} grid points ({} computed, {failed} failed); {} keeps \
             them, the {} points not computed have status not_computed; no figure written",
            total - run.not_reached(),
            run.count(PointStatus::Computed),
            path.display(),
            run.not_reached()
        ))
        .into());
    }
    let l = run.landscape;
    say_failures(g, failed, total, n_range, kappa_range);
    let mut markers = Vec::new();
    if let Some((n, k, c)) = l.minimum() {
        outln!("grid minimum: n = {n:.4}, kappa = {k:.4}, J = {c:.6e}");
        markers.push((n, k, "grid minimum".to_string()));
    }
    let fig = dir.path(&format!("landscape.{}", g.format.ext()));
    let title = format!("J(n, κ), {} estimator", opts.estimator.name());
    dir.rendered(|_| figures::landscape_map(&fig, &l, &title, &markers).map(|f| vec![f]))?;
    dir.finish()?;
    g.say(format!(
        "{} points in {:.1} s; wrote {}",
        grid.0 * grid.1,
        t0.elapsed().as_secs_f64(),
        path.display()
    ));
    Ok(())
}

/// The progress bar of `points` grid points (hidden under `--quiet`).
fn progress_bar(g: &Global, points: usize) -> ProgressBar {
    if g.quiet {
        ProgressBar::hidden()
    } else {
        let b = ProgressBar::new(points as u64);
        b.set_style(
            ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} ({eta} left)")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        b.set_message("landscape");
        b
    }
}

/// What the failed grid points mean: their count, and a warning when most failed (the ranges
/// reach beyond where the model has a solution).
fn say_failures(
    g: &Global,
    failed: usize,
    total: usize,
    n_range: (f64, f64),
    kappa_range: (f64, f64),
) {
    if failed > 0 {
        outln!(
            "{failed} of {total} grid points failed (no solution there; cost NaN, grey in the \
             figure, status failed in the CSV)"
        );
    }
    if 2 * failed > total {
        g.warn(format!(
            "most grid points failed ({failed} of {total}): the ranges --n-range {},{} \
             --kappa-range {},{} reach far beyond where the model has a solution for these \
             experiments; narrow them",
            checks::show(n_range.0),
            checks::show(n_range.1),
            checks::show(kappa_range.0),
            checks::show(kappa_range.1)
        ));
    }
}

/// Writes the landscape as CSV `n,kappa,cost,status,tol`, one row per grid point (`n` varying
/// fastest); status is `ok`, `failed` (cost NaN: no solution) or `not_computed` (interrupted),
/// `tol` the BVP tolerance of the point's cost (NaN where none was computed).
fn write_landscape_csv(w: &mut dyn std::io::Write, run: &LandscapeRun) -> std::io::Result<()> {
    let l = &run.landscape;
    writeln!(w, "n,kappa,cost,status,tol")?;
    for (j, k) in l.kappa.iter().enumerate() {
        for (i, n) in l.n.iter().enumerate() {
            let idx = j * l.n.len() + i;
            let status = match run.status[idx] {
                PointStatus::Computed => "ok",
                PointStatus::Failed => "failed",
                PointStatus::NotReached => "not_computed",
            };
            writeln!(
                w,
                "{},{},{:e},{status},{:e}",
                checks::show(*n),
                checks::show(*k),
                l.cost[idx],
                run.tol[idx]
            )?;
        }
    }
    Ok(())
}
