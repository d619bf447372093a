//! `rheometer compare`.

use crate::*;

/// Arguments of `rheometer compare`.
#[derive(clap::Args)]
pub struct CompareArgs {
    /// The experiments file (TOML).
    pub experiments: PathBuf,
    /// Parameters (n, kappa and take-up factors) from the JSON written by `rheometer fit --json`.
    #[arg(long, conflicts_with_all = ["n", "kappa", "newtonian"])]
    pub fit: Option<PathBuf>,
    /// Power index n of the Carreau-type law (without --fit; n >= 0, 1 is Newtonian).
    #[arg(long, allow_hyphen_values = true, value_parser = checks::parse_n)]
    pub n: Option<f64>,
    /// kappa = ln(K / 1 Pa) of the Carreau-type law (without --fit; |kappa| <= 700).
    #[arg(long, allow_hyphen_values = true, value_parser = checks::parse_kappa)]
    pub kappa: Option<f64>,
    /// Use the Newtonian law (n = 1; not with --n).
    #[arg(long, conflicts_with = "n")]
    pub newtonian: bool,
    /// Take the take-up diameter d_fit(L) from the smoothed measurements where the TOML has
    /// none (implied by --fit, which was fitted that way).
    #[arg(long)]
    pub take_up_from_data: bool,
    /// An effect in the model with its strength, "EFFECT=VALUE" (repeatable; "EFFECT" alone
    /// takes the strength from --fit), shape parameters after colons
    /// ("air_coflow=40:decay_length=0.2"): radiation, air_coflow, air_coflow_line,
    /// air_temperature_profile, nusselt_scale, inlet_diameter, inlet_velocity,
    /// die_temperature_offset, mass_flow_scale, gauge_scale, gauge_offset, vft_b_offset,
    /// vft_t_vf_offset. Effects in the fit
    /// file are included automatically (with their fitted shapes).
    #[arg(long = "with", value_name = "EFFECT[=VALUE][:SHAPE=VALUE]")]
    pub with: Vec<EffectSetting>,
    /// Relative measurement uncertainty (overrides the TOML's relative_uncertainty; default:
    /// the TOML's, else estimated from the data; in (0, 1)).
    #[arg(long, allow_hyphen_values = true, value_parser = checks::parse_fraction)]
    pub relative_uncertainty: Option<f64>,
    /// BVP tolerance of the simulations (1e-12 to 0.1; default 1e-6).
    #[arg(long, allow_hyphen_values = true, value_parser = checks::parse_tol)]
    pub tol: Option<f64>,
    /// Output directory (created; input files are never overwritten).
    #[arg(long)]
    pub out: PathBuf,
}

/// Runs `rheometer compare`.
pub fn run(args: CompareArgs, g: &Global) -> Result<(), Box<dyn Error>> {
    let CompareArgs {
        experiments,
        fit,
        n,
        kappa,
        newtonian,
        take_up_from_data,
        relative_uncertainty,
        with,
        tol,
        out,
    } = args;
    let loaded = load_input(g, &experiments, take_up_from_data, true)?;
    // every output is checked before the simulations, against the inputs and the fit file
    let mut plan = outputs::plan_for(&experiments, &loaded);
    if let Some(f) = &fit {
        plan.input(f);
    }
    let k = loaded.set.experiments.len();
    let names: Vec<(String, String)> = Comparison::file_names(k, g.format.format())
        .into_iter()
        .map(|n| {
            let label = if n.ends_with(".txt") || n.ends_with(".json") || n.ends_with(".csv") {
                "table"
            } else {
                "figure"
            };
            (label.to_string(), n)
        })
        .collect();
    plan.dir(&out, "--out", names.iter().map(|(_, n)| n));
    plan.dir_files(&out, [PARTIAL_NAME]);
    let outputs = outputs::check(&plan, g)?;
    let mut request = match &fit {
        Some(path) => {
            let rep = read_fit_file(g, path, "--fit")?;
            warn_other_data(g, &rep, &loaded, &format!("--fit {}", path.display()));
            for w in &rep.warnings {
                g.warn(format!(
                    "the fit in {} carries a warning: [{}] {}",
                    path.display(),
                    w.code.name(),
                    w.message
                ));
            }
            g.say(format!(
                "model from {}: n = {}, kappa = {} ({} estimator)",
                path.display(),
                rep.n.value,
                rep.kappa.value,
                rep.estimator.name()
            ));
            CompareRequest::of_fit(rep, &path.display().to_string())
        }
        None => {
            let kappa = kappa.ok_or(
                "give the parameters: --fit FIT.json (from `rheometer fit --json`) or --kappa K \
                 with --n N or --newtonian",
            )?;
            let n = if newtonian {
                1.0
            } else {
                n.ok_or("give --n N (or --newtonian) together with --kappa")?
            };
            let mut r = CompareRequest::at([n, kappa]);
            if take_up_from_data {
                r.missing_take_up = MissingTakeUp::FromData;
            }
            r
        }
    };
    request.with = with;
    request.relative_uncertainty = relative_uncertainty;
    request.simulate.max_nodes = g.max_nodes.unwrap_or(checks::DEFAULT_MAX_NODES);
    if let Some(t) = tol {
        request.simulate.tol = t;
    }
    for (e, v) in request.effects()? {
        g.say(format!("model includes {} = {v} {}", e.name(), e.unit()));
    }
    let t0 = std::time::Instant::now();
    let cmp = workflow::compare(&loaded, &request)
        .map_err(|e| checks::name_experiment(Box::new(e), &experiments, Some(request.law)))?;
    let mut dir = outputs::DirWriter::begin(&outputs, &out, "rheometer compare", "files", names)?;
    let written = dir.rendered(|d| cmp.files(d, g.format.format()))?;
    dir.finish()?;
    outln!("{}", cmp.to_text());
    g.say(format!(
        "compared {} experiments in {:.1} s; wrote {} files to {}",
        loaded.set.experiments.len(),
        t0.elapsed().as_secs_f64(),
        written.len(),
        out.display()
    ));
    Ok(())
}
