//! `rheometer diagnose`.

use crate::*;

/// Arguments of `rheometer diagnose`.
#[derive(clap::Args)]
pub struct DiagnoseArgs {
    /// The experiments file (TOML).
    pub experiments: PathBuf,
    /// The viscosity law of your model: carreau or newtonian.
    #[arg(long, default_value = "carreau")]
    pub model: LawChoice,
    /// Effects already in your model (fitted or "=VALUE" fixed, shapes fixed after colons as
    /// in "air_coflow:decay_length=0.2"); repeatable.
    #[arg(long = "with", value_name = "EFFECT[=VALUE][:SHAPE=VALUE]")]
    pub with: Vec<EffectSetting>,
    /// How many candidates (best linearised score first) get the global search and refits
    /// (default: all).
    #[arg(long, allow_hyphen_values = true, value_parser = checks::parse_refit_top)]
    pub refit_top: Option<usize>,
    /// Write the diagnosis as JSON to FILE.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Output directory (report and before/after residual figure).
    #[arg(long)]
    pub out: PathBuf,
}

/// Runs `rheometer diagnose`.
pub fn run(args: DiagnoseArgs, g: &Global) -> Result<(), Box<dyn Error>> {
    let DiagnoseArgs {
        experiments,
        model,
        with,
        refit_top,
        json,
        out,
    } = args;
    let loaded = load_input(g, &experiments, true, true)?;
    let inputs = inputs_of(&experiments, &loaded);
    let spec = ModelSpec {
        law: model,
        effects: with,
        candidates: Vec::new(),
    };
    spec.validate()?;
    let mut opts = DiagnoseOptions::default();
    if let Some(k) = refit_top {
        opts.refit_top = k;
    }
    opts.identify.simulate.max_nodes = g.max_nodes.unwrap_or(checks::DEFAULT_MAX_NODES);
    // a spinner on a terminal (indicatif draws nothing when stderr is not a terminal)
    let spinner = if g.quiet {
        ProgressBar::hidden()
    } else {
        let b = ProgressBar::new_spinner();
        b.set_message("fitting your model and scoring the candidate effects");
        b.enable_steady_tick(std::time::Duration::from_millis(120));
        b
    };
    let run = diagnose(&loaded.set, &spec, &opts);
    spinner.finish_and_clear();
    let run = run?;
    let text = run.diagnosis.to_text();
    outln!("{text}");
    create_dir(&out)?;
    write_text(&out.join("diagnosis.txt"), &text, &inputs)?;
    let js = serde_json::to_string_pretty(&run.diagnosis)?;
    write_text(&out.join("diagnosis.json"), &js, &inputs)?;
    if let Some(path) = json {
        write_json(&path, &js, &inputs)?;
        g.say(format!("wrote {}", path.display()));
    }
    let fig = out.join(format!("residuals_before_after.{}", g.format.ext()));
    ensure_not_input(&fig, &inputs)?;
    run.save_figure(&fig)?;
    let prof = out.join(format!("j_profiles.{}", g.format.ext()));
    ensure_not_input(&prof, &inputs)?;
    run.save_profile_figure(&prof)?;
    g.say(format!(
        "wrote the report, {} and {} to {}",
        fig.display(),
        prof.display(),
        out.display()
    ));
    Ok(())
}
