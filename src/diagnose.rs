//! `rheometer diagnose`.

use crate::*;
use rheometer::workflow::request;

/// Arguments of `rheometer diagnose`.
#[derive(clap::Args)]
pub struct DiagnoseArgs {
    /// The experiments file (TOML).
    pub experiments: PathBuf,
    /// The viscosity law of your model: carreau or newtonian (default: carreau, or the law
    /// of --from).
    #[arg(long)]
    pub model: Option<LawChoice>,
    /// Effects already in your model (fitted or "=VALUE" fixed, shapes fixed after colons as
    /// in "air_coflow:decay_length=0.2"); repeatable.
    #[arg(long = "with", value_name = "EFFECT[=VALUE][:SHAPE=VALUE]")]
    pub with: Vec<EffectSetting>,
    /// Continue from a previous result: FILE is the JSON of `rheometer fit --json` or of
    /// `rheometer diagnose --json` (its final fit). Its effects are in your model (strengths
    /// fitted where they were fitted, fitted shapes free), your model's fit starts from its
    /// law and strengths, and the search looks for what is still missing; --with adds further
    /// effects. The law is the file's unless --model says otherwise.
    #[arg(long, value_name = "FILE")]
    pub from: Option<PathBuf>,
    /// How many candidates (best linearised score first) get the global search and refits
    /// (default: all).
    #[arg(long, allow_hyphen_values = true, value_parser = checks::parse_refit_top)]
    pub refit_top: Option<usize>,
    /// The loss of your model's fit and its soft margin: a robust loss weights the points
    /// for every fit of the diagnosis (default: least squares with the gross outliers of the
    /// noise model left out).
    #[command(flatten)]
    pub robust: checks::LossArgs,
    /// BVP tolerance of the fits (1e-12 to 0.1; default 1e-4, matched to the noise).
    #[arg(long, allow_hyphen_values = true, value_parser = checks::parse_tol)]
    pub tol: Option<f64>,
    /// Write the diagnosis as JSON to FILE.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Output directory (report, JSON, before/after residual figure and J profiles; without
    /// it only the report is printed).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Runs `rheometer diagnose`.
pub fn run(args: DiagnoseArgs, g: &Global) -> Result<(), Box<dyn Error>> {
    let DiagnoseArgs {
        experiments,
        model,
        with,
        from,
        refit_top,
        robust,
        tol,
        json,
        out,
    } = args;
    let previous = from
        .as_deref()
        .map(|p| previous::read_previous(p, g))
        .transpose()?;
    let law = previous::law(model, previous.as_ref());
    let mut opts = DiagnoseOptions::default();
    let effects = match &previous {
        Some(p) => {
            opts.start = p.start(law, &opts.identify)?.map(|(n, k)| [n, k]);
            let c = p.joined_with(with)?;
            opts.start_strengths = c.starts;
            c.effects
        }
        None => with,
    };
    let loaded = load_input(g, &experiments, true, true)?;
    if let Some(p) = &previous {
        p.check_experiments(&loaded, g)?;
    }
    let spec = ModelSpec {
        law,
        effects,
        candidates: Vec::new(),
    };
    spec.validate().map_err(FlagError)?;
    // every output is checked before the work starts, against the inputs and each other
    let ext = g.format.ext();
    let names = vec![
        ("report".to_string(), "diagnosis.txt".to_string()),
        ("json".to_string(), "diagnosis.json".to_string()),
        (
            "figure".to_string(),
            format!("residuals_before_after.{ext}"),
        ),
        ("figure".to_string(), format!("j_profiles.{ext}")),
    ];
    let mut plan = outputs::plan_for(&experiments, &loaded);
    if let Some(p) = &previous {
        plan.input(&p.path);
    }
    if let Some(path) = &json {
        plan.file(path, "--json");
    }
    if let Some(dir) = &out {
        plan.dir(dir, "--out", names.iter().map(|(_, n)| n));
        plan.dir_files(dir, [PARTIAL_NAME]);
    }
    let outputs = outputs::check(&plan, g)?;
    if let Some(k) = refit_top {
        opts.refit_top = k;
    }
    robust.apply(&mut opts.identify)?;
    opts.identify.simulate.max_nodes = g.max_nodes.unwrap_or(checks::DEFAULT_MAX_NODES);
    request::given_tol(&mut opts.identify, tol)?;
    let spinner = spinner(g, "fitting your model and scoring the candidate effects");
    let run = workflow::diagnose(&loaded, &spec, &opts);
    spinner.finish_and_clear();
    let run = run?;
    let text = run.diagnosis.to_text();
    outln!("{text}");
    let js = to_report_json(ReportKind::Diagnosis, &run.diagnosis.json())?;
    if let Some(path) = json {
        outputs.write_text(&path, &js)?;
        g.say(format!("wrote {}", path.display()));
    }
    let Some(out) = out else {
        g.say("no --out: the report and figures were not written to files".into());
        return Ok(());
    };
    let mut dir = outputs::DirWriter::begin(&outputs, &out, "rheometer diagnose", "files", names)?;
    dir.text("diagnosis.txt", &text)?;
    dir.text("diagnosis.json", &js)?;
    let fig = dir.path(&format!("residuals_before_after.{ext}"));
    dir.rendered(|_| run.residual_figure(&fig).map(|f| vec![f]))?;
    let prof = dir.path(&format!("j_profiles.{ext}"));
    dir.rendered(|_| run.profile_figure(&prof).map(|f| vec![f]))?;
    dir.finish()?;
    g.say(format!(
        "wrote the report, {} and {} to {}",
        fig.display(),
        prof.display(),
        out.display()
    ));
    Ok(())
}

/// A spinner saying `message` on a terminal (hidden under `--quiet`; indicatif draws nothing
/// when stderr is not a terminal).
fn spinner(g: &Global, message: &'static str) -> ProgressBar {
    if g.quiet {
        return ProgressBar::hidden();
    }
    let b = ProgressBar::new_spinner();
    b.set_message(message);
    b.enable_steady_tick(std::time::Duration::from_millis(120));
    b
}
