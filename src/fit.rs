//! `rheometer fit`.

use crate::*;
use rheometer::report::fit_html::FIT_REPORT_HTML;
use rheometer::workflow::request;

/// Arguments of `rheometer fit`.
#[derive(clap::Args)]
pub struct FitArgs {
    /// The experiments file (TOML).
    pub experiments: PathBuf,
    /// Start point "N,KAPPA" of the Carreau-type law (default: the paper's start heuristic).
    #[arg(long, value_parser = checks::parse_pair, allow_hyphen_values = true)]
    pub start: Option<(f64, f64)>,
    /// The estimator.
    #[arg(long, value_enum, default_value_t = EstimatorArg::Principled)]
    pub estimator: EstimatorArg,
    /// Fit the Newtonian model (n = 1; the same as --model newtonian).
    #[arg(long, conflicts_with_all = ["model", "start"])]
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
    /// Continue from a previous result: FILE is the JSON of `rheometer fit --json` or of
    /// `rheometer diagnose --json` (its final fit: the model with the effects it found). Its
    /// effects join the model (strengths fitted where they were fitted, fitted shapes free),
    /// and the fit starts from its law and strengths; --with adds further effects. The law
    /// is the file's unless --model says otherwise.
    #[arg(long, value_name = "FILE", conflicts_with = "start")]
    pub from: Option<PathBuf>,
    /// The loss of the fit and its soft margin.
    #[command(flatten)]
    pub robust: checks::LossArgs,
    /// BVP tolerance of the fit (1e-12 to 0.1; default: 1e-4, refined until the
    /// discretisation moves no estimate by more than 0.01 standard errors). Given, it is kept
    /// and the shift only reported.
    #[arg(long, allow_hyphen_values = true, value_parser = checks::parse_tol)]
    pub tol: Option<f64>,
    /// Write the result as JSON to FILE.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write the report as a self-contained HTML page to FILE (verdict, law, flow curve,
    /// residuals, experiments, warnings, inputs; it loads nothing from the network).
    #[arg(long)]
    pub html: Option<PathBuf>,
    /// Write the report (text and HTML), the fitted profiles and figures (paper Fig. 2, 3, 5;
    /// with --with also a before/after residual figure) into DIR.
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
        from,
        robust,
        tol,
        json,
        html,
        out,
    } = args;
    let previous = from
        .as_deref()
        .map(|p| previous::read_previous(p, g))
        .transpose()?;
    let mut opts = IdentifyOptions::with_estimator(estimator(est));
    request::given_tol(&mut opts, tol)?;
    robust.apply(&mut opts)?;
    opts.simulate.max_nodes = g.max_nodes.unwrap_or(checks::DEFAULT_MAX_NODES);
    let model = newtonian.then_some(LawChoice::Newtonian).or(model);
    let law = previous::law(model, previous.as_ref());
    let (with, start, start_strengths) = match &previous {
        Some(p) => {
            let start = p.start(law, &opts)?;
            let c = p.joined_with(with)?;
            (c.effects, start, c.starts)
        }
        None => (with, start, Vec::new()),
    };
    request::newtonian_start(law == LawChoice::Newtonian, start)?;
    if let Some(s) = start {
        checks::check_start(s, &opts)?;
    }
    let spec = ModelSpec {
        law,
        effects: with.clone(),
        candidates: Vec::new(),
    };
    spec.validate().map_err(FlagError)?;
    let loaded = load_input(g, &experiments, true, true)?;
    if let Some(p) = &previous {
        p.check_experiments(&loaded, g)?;
    }
    // every output is checked before the fit
    let mut plan = outputs::plan_for(&experiments, &loaded);
    if let Some(p) = &previous {
        plan.input(&p.path);
    }
    if let Some(path) = &json {
        plan.file(path, "--json");
    }
    if let Some(path) = &html {
        plan.file(path, "--html");
    }
    let names = out.as_ref().map(|_| fit_output_names(&loaded, &with, g));
    if let (Some(dir), Some(names)) = (&out, &names) {
        plan.dir(dir, "--out", names.iter().map(|(_, n)| n));
        plan.dir_files(dir, [PARTIAL_NAME]);
    }
    let outputs = outputs::check(&plan, g)?;
    let request = FitRequest {
        model: spec,
        identify: opts,
        start: start.map(|(n, k)| [n, k]),
        start_strengths,
        baseline: out.is_some(),
        newtonian_reference: out.is_some(),
        ..FitRequest::new(IdentifyOptions::default())
    };
    let run = workflow::fit(&loaded, &request)?;
    say_notes(&run, g);
    // the report is the one place of the warnings (stdout); stderr only says where they are
    let rep = run.summary();
    outln!("{}", rep.to_text());
    if rep.has_warnings() {
        g.say(format!(
            "{} warning(s) in the report above ([[Warnings]])",
            rep.warnings.len()
        ));
    }
    let text = to_report_json(ReportKind::Fit, rep)?;
    if let Some(path) = json {
        outputs.write_text(&path, &text)?;
        g.say(format!("wrote {}", path.display()));
    }
    let page = (html.is_some() || out.is_some()).then(|| run.html_report(&loaded).render());
    if let (Some(path), Some(page)) = (html, &page) {
        outputs.write_text(&path, page)?;
        g.say(format!("wrote {}", path.display()));
    }
    if let (Some(dir), Some(names)) = (out, names) {
        let page = page.unwrap_or_default();
        write_fit_outputs(&run, &outputs, &dir, names, (&text, &page), &with, g)?;
    }
    Ok(())
}

/// What the fit says on stderr beside its report: the start heuristic's start and the parts
/// that were not computed.
fn say_notes(run: &FitRun, g: &Global) {
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
}

/// The files `fit --out` writes, as `(label, name)`: the report, the JSON, the fitted
/// profiles, the figures (paged beyond 24 experiments) and, with `--with`, the before/after
/// residual figure.
fn fit_output_names(
    loaded: &LoadedExperiments,
    with: &[EffectSetting],
    g: &Global,
) -> Vec<(String, String)> {
    let ext = g.format.ext();
    let mut v = vec![
        ("report".to_string(), "fit_report.txt".to_string()),
        ("report".to_string(), FIT_REPORT_HTML.to_string()),
        ("json".to_string(), "fit.json".to_string()),
    ];
    for e in &loaded.set.experiments {
        v.push((e.name.clone(), format!("{}_fitted_profile.csv", e.name)));
    }
    if !with.is_empty() {
        v.push(("figure".into(), format!("residuals_before_after.{ext}")));
    }
    v.push(("table".into(), "flow_curve.csv".to_string()));
    v.push(("json".into(), "flow_curve.json".to_string()));
    v.push(("figure".into(), format!("flow_curve.{ext}")));
    let k = loaded.set.experiments.len();
    for n in figures::identification_figure_names(ext, k) {
        v.push(("figure".into(), n));
    }
    v
}

/// The reports, JSON, fitted profiles and figures of a fit into `dir` (the files of
/// `names`; `(json, html)` the JSON and the HTML page), marked incomplete until the last is
/// written.
fn write_fit_outputs(
    run: &FitRun,
    outputs: &CheckedOutputs,
    dir: &Path,
    names: Vec<(String, String)>,
    (json, html): (&str, &str),
    with: &[EffectSetting],
    g: &Global,
) -> Result<(), Box<dyn Error>> {
    let (rh, id) = (&run.rheometer, &run.identification);
    let mut w = outputs::DirWriter::begin(outputs, dir, "rheometer fit", "files", names)?;
    w.text("fit_report.txt", &run.summary().to_text())?;
    w.text("fit.json", json)?;
    w.text(FIT_REPORT_HTML, html)?;
    for (k, sol) in id.solutions.iter().enumerate() {
        let fs = FiberSolution {
            solution: sol.clone(),
        };
        let prof = fs.uniform_profiles(&rh.models[k], 101);
        let name = format!("{}_fitted_profile.csv", rh.experiments[k].name);
        w.write(&name, |out| write_profiles_csv(out, &prof))?;
    }
    if let Some(id0) = &run.baseline {
        let names: Vec<String> = with.iter().map(|w| w.effect.name().to_string()).collect();
        let label = names.join(" + ");
        let before = profiles_of(rh, &id0.solutions);
        let after = profiles_of(rh, &id.solutions);
        let fig = w.path(&format!("residuals_before_after.{}", g.format.ext()));
        w.rendered(|_| residual_figure(&fig, &before, Some((&label, &after))).map(|f| vec![f]))?;
        outln!(
            "RMS relative residual: {:.4} % without {label}, {:.4} % with it ({})",
            100.0 * id0.rms(),
            100.0 * id.rms(),
            fig.display()
        );
    }
    if let Some(curve) = &run.summary().flow_curve {
        w.text("flow_curve.csv", &curve.to_csv())?;
        w.text(
            "flow_curve.json",
            &to_report_json(ReportKind::FlowCurve, curve)?,
        )?;
        let fig = w.path(&format!("flow_curve.{}", g.format.ext()));
        w.rendered(|_| flow_curve_figure(&fig, curve).map(|f| vec![f]))?;
    }
    let newtonian = run.newtonian.as_deref().unwrap_or_default();
    let written =
        w.rendered(|dir| figures::identification_figures(rh, id, newtonian, dir, g.format.ext()))?;
    w.finish()?;
    for p in written {
        g.say(format!("wrote {}", p.display()));
    }
    g.say(format!(
        "wrote the report and fitted profiles to {}",
        dir.display()
    ));
    Ok(())
}
