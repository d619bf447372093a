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
    /// Fit the Newtonian model (n = 1; the same as --model newtonian).
    #[arg(long, conflicts_with = "model")]
    pub newtonian: bool,
    /// The viscosity law of the model: carreau (n, kappa fitted; the default) or newtonian.
    #[arg(long)]
    pub model: Option<LawChoice>,
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
    /// BVP tolerance of the fit (1e-12 to 0.1; default: 1e-4, refined until the
    /// discretisation moves no estimate by more than 0.01 standard errors). Given, it is kept
    /// and the shift only reported.
    #[arg(long, allow_hyphen_values = true, value_parser = checks::parse_tol)]
    pub tol: Option<f64>,
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
        tol,
        json,
        out,
    } = args;
    let mut opts = IdentifyOptions::with_estimator(estimator(est));
    if let Some(t) = tol {
        opts.simulate.tol = t;
        opts.max_discretisation_shift = Some(f64::INFINITY);
    }
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
        for name in [
            "fit.json",
            "fit_report.txt",
            "flow_curve.csv",
            "flow_curve.json",
        ] {
            ensure_not_input(&dir.join(name), &inputs)?;
        }
    }
    let law = match (newtonian, model) {
        (true, _) => LawChoice::Newtonian,
        (false, m) => m.unwrap_or_default(),
    };
    if law == LawChoice::Newtonian && start.is_some() {
        return Err(
            "--start: the Newtonian model (n = 1) has no (n, kappa) to start from; \
                    drop --start or fit the Carreau-type law (--model carreau)"
                .into(),
        );
    }
    let spec = ModelSpec {
        law,
        effects: with.clone(),
        candidates: Vec::new(),
    };
    let request = FitRequest {
        model: spec,
        identify: opts,
        start: start.map(|(n, k)| [n, k]),
        baseline: out.is_some(),
        newtonian_reference: out.is_some(),
        ..FitRequest::new(IdentifyOptions::default())
    };
    let run = workflow::fit(&loaded, &request)?;
    if let Some(sp) = &run.start_heuristic {
        g.say(format!(
            "start heuristic: (n, kappa) = ({}, {})",
            sp.start[0], sp.start[1]
        ));
    }
    for (what, e) in [
        ("error budget", &run.budget_error),
        (
            "profile intervals and likelihood-ratio test",
            &run.profile_error,
        ),
        ("flow curve", &run.flow_curve_error),
    ] {
        if let Some(e) = e {
            g.say(format!("note: {what} not computed: {e}"));
        }
    }
    // the report is the one place of the warnings (stdout); stderr only says where they are
    let rep = run.summary();
    outln!("{}", rep.to_text());
    if rep.has_warnings() {
        g.say(format!(
            "{} warning(s) in the report above ([[Warnings]])",
            rep.warnings.len()
        ));
    }
    let text = serde_json::to_string_pretty(rep)?;
    if let Some(path) = json {
        write_json(&path, &text, &inputs)?;
        g.say(format!("wrote {}", path.display()));
    }
    if let Some(dir) = out {
        write_fit_outputs(&run, &dir, &text, &with, &inputs, g)?;
    }
    Ok(())
}

/// The report, JSON, fitted profiles and figures of a fit into `dir`.
fn write_fit_outputs(
    run: &FitRun,
    dir: &Path,
    json: &str,
    with: &[EffectSetting],
    inputs: &[PathBuf],
    g: &Global,
) -> Result<(), Box<dyn Error>> {
    let (rh, id) = (&run.rheometer, &run.identification);
    create_dir(dir)?;
    if let Some(id0) = &run.baseline {
        let names: Vec<String> = with.iter().map(|w| w.effect.name().to_string()).collect();
        let label = names.join(" + ");
        let before = profiles_of(rh, &id0.solutions);
        let after = profiles_of(rh, &id.solutions);
        let fig = dir.join(format!("residuals_before_after.{}", g.format.ext()));
        ensure_not_input(&fig, inputs)?;
        save_residual_figure(&fig, &before, Some((&label, &after)))?;
        outln!(
            "RMS relative residual: {:.4} % without {label}, {:.4} % with it ({})",
            100.0 * id0.rms(),
            100.0 * id.rms(),
            fig.display()
        );
    }
    write_text(
        &dir.join("fit_report.txt"),
        &run.summary().to_text(),
        inputs,
    )?;
    write_text(&dir.join("fit.json"), json, inputs)?;
    if let Some(curve) = &run.summary().flow_curve {
        write_text(&dir.join("flow_curve.csv"), &curve.to_csv(), inputs)?;
        write_text(
            &dir.join("flow_curve.json"),
            &serde_json::to_string_pretty(curve)?,
            inputs,
        )?;
        let fig = dir.join(format!("flow_curve.{}", g.format.ext()));
        ensure_not_input(&fig, inputs)?;
        save_flow_curve_figure(&fig, curve)?;
        g.say(format!("wrote {}", fig.display()));
    }
    for (k, sol) in id.solutions.iter().enumerate() {
        let model = &rh.models[k];
        let fs = FiberSolution {
            solution: sol.clone(),
        };
        let prof = fs.uniform_profiles(model, 101);
        write_text(
            &dir.join(format!("{}_fitted_profile.csv", rh.experiments[k].name)),
            &profiles_csv(&prof),
            inputs,
        )?;
    }
    let newtonian = run.newtonian.as_deref().unwrap_or_default();
    let written = figures::identification_figures(rh, id, newtonian, dir, g.format.ext(), inputs)?;
    for w in written {
        g.say(format!("wrote {}", w.display()));
    }
    g.say(format!(
        "wrote the report and fitted profiles to {}",
        dir.display()
    ));
    Ok(())
}
