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
    /// Use the Newtonian law (n = 1).
    #[arg(long)]
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
        out,
    } = args;
    let loaded = load_input(g, &experiments, take_up_from_data, true)?;
    let inputs = inputs_of(&experiments, &loaded);
    let set = &loaded.set;
    let fit_params = fit.as_ref().map(|p| read_fit(p)).transpose()?;
    let effects = compare_effects(fit_params.as_ref(), &with)?;
    // validated once here; the closure rebuilds the same physics per experiment
    physics_with(&effects)?;
    let physics = || physics_with(&effects).unwrap_or_else(|_| Physics::paper());
    for (e, v) in &effects {
        g.say(format!("model includes {} = {v} {}", e.name(), e.unit()));
    }
    let mut setup = ModelSetup::carreau([0.8, 11.71], &physics);
    setup.simulate.max_nodes = g.max_nodes.unwrap_or(checks::DEFAULT_MAX_NODES);
    let mut fitted = 0;
    if let (Some(path), Some(rep)) = (&fit, fit_params) {
        let names: Vec<String> = set.experiments.iter().map(|e| e.name.clone()).collect();
        rep.check_experiments(&names, &path.display().to_string())?;
        rep.apply(
            &mut setup,
            set.experiments.len(),
            &path.display().to_string(),
        )?;
        fitted = rep.fitted_parameters();
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
            rep.n,
            rep.kappa,
            rep.estimator.name()
        ));
    } else {
        let kappa = kappa.ok_or(
            "give the parameters: --fit FIT.json (from `rheometer fit --json`) or --kappa K \
             with --n N or --newtonian",
        )?;
        let n = if newtonian {
            1.0
        } else {
            n.ok_or("give --n N (or --newtonian) together with --kappa")?
        };
        setup.law_params = [n, kappa];
        if take_up_from_data {
            setup.missing_take_up = MissingTakeUp::FromData;
        }
    }
    let options = CompareOptions {
        relative_uncertainty,
        fitted_parameters: fitted,
        ..Default::default()
    };
    let t0 = std::time::Instant::now();
    let runs = simulate_experiments(set, &setup)
        .map_err(|e| checks::name_experiment(Box::new(e), &experiments, Some(setup.law_params)))?;
    let cmp = compare(&runs, set.relative_uncertainty, &options)?;
    let written = cmp.write(&out, g.format.format(), &inputs)?;
    outln!("{}", cmp.to_text());
    g.say(format!(
        "compared {} experiments in {:.1} s; wrote {} files to {}",
        set.experiments.len(),
        t0.elapsed().as_secs_f64(),
        written.len(),
        out.display()
    ));
    Ok(())
}
