//! `rheometer fit`.

use crate::*;

/// Arguments of `rheometer fit`.
#[derive(clap::Args)]
pub struct FitArgs {
    /// The experiments file (TOML).
    pub experiments: PathBuf,
    /// Start point "N,KAPPA" (default: the paper's start heuristic).
    #[arg(long, value_parser = checks::parse_pair, allow_hyphen_values = true)]
    pub start: Option<(f64, f64)>,
    /// The estimator.
    #[arg(long, value_enum, default_value_t = EstimatorArg::Principled)]
    pub estimator: EstimatorArg,
    /// Evaluate the Newtonian model (n = 1) instead of fitting.
    #[arg(long)]
    pub newtonian: bool,
    /// The viscosity law of the model: carreau (n, kappa fitted) or newtonian.
    #[arg(long, default_value = "carreau")]
    pub model: LawChoice,
    /// Add an effect, its strength fitted ("radiation") or fixed ("radiation=0.9"), shape
    /// parameters fixed after colons ("air_coflow=40:decay_length=0.2"); repeatable.
    /// Physics: strain_thinning, radiation, air_coflow, air_coflow_line,
    /// air_temperature_profile, nusselt_scale; process: inlet_diameter, inlet_velocity,
    /// die_temperature_offset, mass_flow_scale; instrument: gauge_scale, gauge_offset;
    /// material data: vft_b_offset, vft_t_vf_offset (K, viscosity at T_o held).
    #[arg(long = "with", value_name = "EFFECT[=VALUE][:SHAPE=VALUE]")]
    pub with: Vec<EffectSetting>,
    /// The loss of the fit: linear (least squares), or a robust loss that down-weights
    /// outliers: soft_l1, huber, cauchy (as in scipy's least_squares; needs the principled
    /// estimator).
    #[arg(long, default_value = "linear", value_parser = diffbvp::least_squares::Loss::parse)]
    pub loss: diffbvp::least_squares::Loss,
    /// Soft margin of a robust loss as a relative residual (e.g. 0.02 for 2 %; default: the
    /// robust noise scale of the data).
    #[arg(long = "f-scale", value_parser = checks::parse_f_scale, allow_hyphen_values = true)]
    pub f_scale: Option<f64>,
    /// Write the result as JSON to FILE.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write the report, the fitted profiles and figures (paper Fig. 2, 3, 5; with --with also
    /// a before/after residual figure) into DIR.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Runs `rheometer fit`.
pub fn run(args: FitArgs, g: &Global) -> Result<(), Box<dyn Error>> {
    let FitArgs {
        experiments,
        start,
        estimator: est,
        newtonian,
        model,
        with,
        loss,
        f_scale,
        json,
        out,
    } = args;
    let mut opts = IdentifyOptions::with_estimator(estimator(est));
    opts.loss = loss;
    opts.f_scale = f_scale;
    opts.simulate.max_nodes = g.max_nodes.unwrap_or(checks::DEFAULT_MAX_NODES);
    if let Some(s) = start {
        checks::check_start(s, &opts)?;
    }
    let loaded = load_input(g, &experiments, true, true)?;
    let inputs = inputs_of(&experiments, &loaded);
    // refuse an output that is an input before spending time on the fit
    if let Some(path) = &json {
        ensure_not_input(path, &inputs)?;
    }
    if let Some(dir) = &out {
        for name in ["fit.json", "fit_report.txt"] {
            ensure_not_input(&dir.join(name), &inputs)?;
        }
    }
    let spec = ModelSpec {
        law: model,
        effects: with.clone(),
        candidates: Vec::new(),
    };
    let rh = Rheometer::with_spec(&loaded.set, spec)?;
    let law_fitted = model == LawChoice::Carreau
        || with
            .iter()
            .any(|w| w.effect.name() == "strain_thinning" && w.value.is_none());
    if newtonian {
        let mut obj = rh.objective([1.0, 20.0], &opts)?;
        let j = obj.cost_at(1.0, 20.0)?;
        outln!(
            "Newtonian model (n = 1): cost J = {j:.6e} ({} estimator)",
            opts.estimator.name()
        );
        return Ok(());
    }
    let start = match start {
        Some((n, k)) => [n, k],
        None if !law_fitted => [1.0, STRAIN_THINNING_REFERENCE_KAPPA],
        None => {
            let sp = rh.start_heuristic(&opts)?;
            g.say(format!(
                "start heuristic: (n, kappa) = ({}, {})",
                sp.start[0], sp.start[1]
            ));
            sp.start
        }
    };
    let id = rh.identify(start, &opts)?;
    // the systematic uncertainty of what the data cannot identify (declared or default
    // uncertainties); a budget that cannot be computed does not fail the fit
    let rep = match error_budget(&rh, &id, &loaded.uncertainty, &opts) {
        Ok(budget) => FitReport::new(&id).with_error_budget(budget),
        Err(e) => {
            g.say(format!("warning: error budget not computed: {e}"));
            FitReport::new(&id)
        }
    };
    outln!("{}", rep.to_text());
    for w in &rep.warnings {
        g.say(format!("warning: {w}"));
    }
    let text = serde_json::to_string_pretty(&rep)?;
    if let Some(path) = json {
        write_json(&path, &text, &inputs)?;
        g.say(format!("wrote {}", path.display()));
    }
    if let Some(dir) = out {
        create_dir(&dir)?;
        if !with.is_empty() {
            // the same fit without the effects, for the before/after comparison
            let rh0 = Rheometer::with_spec(&loaded.set, ModelSpec::new(model))?;
            let s0 = if model == LawChoice::Carreau {
                [id.n, id.kappa]
            } else {
                [1.0, STRAIN_THINNING_REFERENCE_KAPPA]
            };
            let id0 = rh0.identify(s0, &opts)?;
            let names: Vec<String> = with.iter().map(|w| w.effect.name().to_string()).collect();
            let label = names.join(" + ");
            let before = profiles_of(&rh0, &id0.solutions);
            let after = profiles_of(&rh, &id.solutions);
            let fig = dir.join("residuals_before_after.png");
            save_residual_figure(&fig, &before, Some((&label, &after)))?;
            outln!(
                "RMS relative residual: {:.4} % without {label}, {:.4} % with it ({})",
                100.0 * id0.rms_relative_residual,
                100.0 * id.rms_relative_residual,
                fig.display()
            );
        }
        write_text(&dir.join("fit_report.txt"), &rep.to_text(), &inputs)?;
        write_text(&dir.join("fit.json"), &text, &inputs)?;
        for (k, sol) in id.solutions.iter().enumerate() {
            let model = &rh.models[k];
            let fs = FiberSolution {
                solution: sol.clone(),
            };
            let prof = fs.uniform_profiles(model, 101);
            write_text(
                &dir.join(format!("{}_fitted_profile.csv", rh.experiments[k].name)),
                &profiles_csv(&prof),
                &inputs,
            )?;
        }
        let newtonian = rh
            .newtonian_solutions(id.kappa, &opts)
            .map_err(figures::FigureError::Model)?;
        let written =
            figures::identification_figures(&rh, &id, &newtonian, &dir, g.format.ext(), &inputs)?;
        for w in written {
            g.say(format!("wrote {}", w.display()));
        }
        g.say(format!(
            "wrote the report and fitted profiles to {}",
            dir.display()
        ));
    }
    Ok(())
}
