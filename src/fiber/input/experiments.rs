//! Building the experiments from the TOML tables: the material, `[defaults]` and each
//! `[[experiment]]`, with the plausibility checks of every experiment; loading a whole data set
//! (TOML and its CSV files).

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use toml::de::DeTable;

use super::error::{InputError, Location};
use super::measurements::{load_measurements, DEFAULT_MIN_POINTS};
use super::read_text;
use super::schema::{
    names, rule_of, Rule, EXPERIMENT_NUMBERS, EXPERIMENT_TABLES, MATERIAL_NUMBERS,
    MAX_PLAUSIBLE_DIAMETER_M, MIN_PLAUSIBLE_DIAMETER_M, STRING_KEYS, TOP_KEYS,
};
use super::spanned::{toml_error, Doc, Field, Tab};
use super::uncertainty::uncertainty_table;
use crate::fiber::setup::{Air, Experiment, ExperimentSet, Inlet, Material, TakeUp};
use crate::fiber::uncertainty::Uncertainties;

/// Largest plausible zero-shear viscosity of the melt at the inlet \[Pa s\]: 1e12 Pa s is the
/// conventional viscosity of a glass at its glass transition; above it the polymer is not a melt.
pub const MAX_INLET_VISCOSITY_PA_S: f64 = 1e12;

/// Largest plausible draw ratio `u_out/u_in = (d_in/d_out)²` \[-\].
pub const MAX_DRAW_RATIO: f64 = 1e6;

/// Descriptive information on an experiment that is not part of the model input.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ExperimentDetails {
    /// Stencil velocity of the extruder \[mm/s\] (`stencil_velocity_mm_s`), if given.
    pub stencil_velocity_mm_s: Option<f64>,
    /// Take-up (aspirator) pressure \[bar\] (`take_up_pressure_bar`), if given.
    pub take_up_pressure_bar: Option<f64>,
    /// The measurement CSV file (resolved against the TOML file's directory), if given.
    pub data: Option<PathBuf>,
    /// 1-based line of the experiment's `name` key in the TOML file, if known (for messages
    /// that name the experiment).
    pub line: Option<usize>,
}

/// An experiment set together with per-experiment details (same order as the experiments).
#[derive(Debug, Clone, PartialEq)]
pub struct LoadedExperiments {
    /// The model input (measurements are `None` when parsed without reading CSV files).
    pub set: ExperimentSet,
    /// Descriptive metadata and data-file paths.
    pub details: Vec<ExperimentDetails>,
    /// Declared standard uncertainties (`[uncertainty]` and the experiments' own tables; empty
    /// when nothing is declared).
    pub uncertainty: Uncertainties,
}

/// Loads a TOML experiment file and the CSV files it refers to, requiring at least
/// [`DEFAULT_MIN_POINTS`] measurements per file.
pub fn load_experiments(path: &Path) -> Result<ExperimentSet, InputError> {
    load_experiments_with(path, DEFAULT_MIN_POINTS).map(|loaded| loaded.set)
}

/// Loads a TOML experiment file and its CSV files, requiring at least `min_points` rows per
/// CSV file, and returns the set with the experiments' metadata.
pub fn load_experiments_with(
    path: &Path,
    min_points: usize,
) -> Result<LoadedExperiments, InputError> {
    let text = read_text(path)?;
    let mut loaded = parse_experiments(&text, path)?;
    let doc = Doc::new(path, &text);
    for (i, details) in loaded.details.iter().enumerate() {
        let Some(data) = &details.data else { continue };
        let experiment = &loaded.set.experiments[i];
        let measured =
            load_measurements(data, experiment.spinline_length, min_points).map_err(|cause| {
                InputError::Data {
                    at: doc.data_key_location(i),
                    experiment: experiment.name.clone(),
                    cause: Box::new(cause),
                }
            })?;
        loaded.set.measurements[i] = Some(measured);
    }
    Ok(loaded)
}

/// Parses the TOML text of an experiment file without reading any CSV file (all measurements
/// are `None`). `path` is used in error messages and to resolve the `data` paths.
pub fn parse_experiments(text: &str, path: &Path) -> Result<LoadedExperiments, InputError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let root = DeTable::parse(text).map_err(|e| toml_error(path, text, &e))?;
    let doc = Doc::new(path, text);
    let top = Tab {
        doc: &doc,
        name: "the top level".into(),
        table: root.get_ref(),
        line: None,
    };
    top.check_keys(TOP_KEYS)?;
    let relative_uncertainty = match top.get("relative_uncertainty") {
        Some(field) => Some(relative_uncertainty(&field)?),
        None => None,
    };
    let mut uncertainty = Uncertainties::default();
    if let Some(tab) = top.sub_table("uncertainty", "[uncertainty]")? {
        uncertainty.set = uncertainty_table(&tab)?;
    }
    let material_tab = top
        .sub_table("material", "[material]")?
        .ok_or_else(|| top.missing("material", " (the [material] table)"))?;
    let (material, air) = material(&material_tab)?;
    let defaults = top.sub_table("defaults", "[defaults]")?;
    if let Some(defaults) = &defaults {
        defaults.check_keys(&names(EXPERIMENT_NUMBERS))?;
        for (key, rule) in EXPERIMENT_NUMBERS {
            if let Some(field) = defaults.get(key) {
                field.number(*rule)?;
            }
        }
    }
    let tables = top.experiment_tables()?;
    let mut experiments = Vec::with_capacity(tables.len());
    let mut details = Vec::with_capacity(tables.len());
    let mut seen: Vec<(String, Option<usize>)> = Vec::new();
    for tab in tables {
        let label = tab.name.clone();
        let own_name = match tab
            .get("name")
            .and_then(|f| f.string().ok().map(str::to_string))
        {
            Some(name) => format!("{label} \"{name}\" uncertainty table"),
            None => format!("{label} uncertainty table"),
        };
        let own = match tab.sub_table("uncertainty", &own_name)? {
            Some(t) => uncertainty_table(&t)?,
            None => Vec::new(),
        };
        uncertainty.experiments.push(own);
        let (experiment, mut detail, name_at) = experiment(tab, defaults.as_ref(), &material)?;
        detail.line = name_at.line;
        if let Some((_, first)) = seen.iter().find(|(n, _)| *n == experiment.name) {
            let first = first
                .map(|l| format!(" (first defined at line {l})"))
                .unwrap_or_default();
            return Err(InputError::Inconsistent {
                at: name_at,
                table: format!("{label} \"{}\"", experiment.name),
                message: format!("duplicate experiment name \"{}\"{first}", experiment.name),
            });
        }
        seen.push((experiment.name.clone(), name_at.line));
        experiments.push(experiment);
        details.push(detail);
    }
    let measurements = vec![None; experiments.len()];
    Ok(LoadedExperiments {
        set: ExperimentSet {
            material,
            air,
            experiments,
            measurements,
            relative_uncertainty,
        },
        details,
        uncertainty,
    })
}

impl ExperimentSet {
    /// Loads an experiment set from a TOML file and its CSV files (see [`load_experiments`]).
    pub fn load(path: &Path) -> Result<Self, InputError> {
        load_experiments(path)
    }
}

fn relative_uncertainty(field: &Field<'_>) -> Result<f64, InputError> {
    field.number(Rule::Fraction)
}

fn material(tab: &Tab<'_>) -> Result<(Material, Air), InputError> {
    tab.check_keys(&names(MATERIAL_NUMBERS))?;
    let get = |key: &'static str| -> Result<f64, InputError> {
        let rule = rule_of(MATERIAL_NUMBERS, key).unwrap_or(Rule::Finite);
        match tab.get(key) {
            Some(field) => field.number(rule),
            None if key == "trouton_ratio" => Ok(3.0),
            None => Err(tab.missing(key, "")),
        }
    };
    let material = Material {
        density_slope: get("density_slope_kg_m3_K")?,
        density_intercept: get("density_intercept_kg_m3")?,
        heat_capacity_slope: get("heat_capacity_slope_J_kg_K2")?,
        heat_capacity_intercept: get("heat_capacity_intercept_J_kg_K")?,
        vft_mu_c: get("vft_mu_c_Pa_s")?,
        vft_b: get("vft_B_K")?,
        vft_t_vf: get("vft_T_VF_K")?,
        trouton: get("trouton_ratio")?,
    };
    let air = Air {
        density: get("air_density_kg_m3")?,
        heat_capacity: get("air_heat_capacity_J_kg_K")?,
        kinematic_viscosity: get("air_kinematic_viscosity_m2_s")?,
        heat_conductivity: get("air_heat_conductivity_W_m_K")?,
    };
    Ok((material, air))
}

/// An experiment table backed by `[defaults]`.
struct Scope<'s, 'a> {
    table: &'s Tab<'a>,
    defaults: Option<&'s Tab<'a>>,
}

impl<'a> Scope<'_, 'a> {
    fn get(&self, key: &'a str) -> Option<Field<'a>> {
        self.table
            .get(key)
            .or_else(|| self.defaults.and_then(|d| d.get(key)))
    }

    fn rule(key: &str) -> Rule {
        rule_of(EXPERIMENT_NUMBERS, key).unwrap_or(Rule::Finite)
    }

    fn optional(&self, key: &'a str) -> Result<Option<(f64, Field<'a>)>, InputError> {
        match self.get(key) {
            Some(field) => Ok(Some((field.number(Self::rule(key))?, field))),
            None => Ok(None),
        }
    }

    fn required(&self, key: &'a str) -> Result<(f64, Field<'a>), InputError> {
        let hint = " (give it here or in [defaults])";
        self.optional(key)?
            .ok_or_else(|| self.table.missing(key, hint))
    }

    /// One of two mutually exclusive keys, resolved as a pair: the experiment table first,
    /// then `[defaults]`. Returns `(first_key_given, value, field)`.
    fn either(&self, a: &'a str, b: &'a str) -> Result<Option<(bool, f64, Field<'a>)>, InputError> {
        for tab in std::iter::once(self.table).chain(self.defaults) {
            match (tab.get(a), tab.get(b)) {
                (Some(_), Some(fb)) => {
                    return Err(fb.inconsistent(format!("give either `{a}` or `{b}`, not both")))
                }
                (Some(fa), None) => return Ok(Some((true, fa.number(Self::rule(a))?, fa))),
                (None, Some(fb)) => return Ok(Some((false, fb.number(Self::rule(b))?, fb))),
                (None, None) => {}
            }
        }
        Ok(None)
    }
}

/// Parses one `[[experiment]]` table; also returns the location of its name.
fn experiment(
    mut tab: Tab<'_>,
    defaults: Option<&Tab<'_>>,
    material: &Material,
) -> Result<(Experiment, ExperimentDetails, Location), InputError> {
    // name the table by the experiment's name (if readable) before reporting unknown keys
    if let Some(name) = tab
        .get("name")
        .and_then(|f| f.string().ok().map(str::to_string))
    {
        tab.name = format!("{} \"{name}\"", tab.name);
    }
    tab.check_keys(&[STRING_KEYS, EXPERIMENT_TABLES, &names(EXPERIMENT_NUMBERS)].concat())?;
    let name_field = tab.get("name").ok_or_else(|| tab.missing("name", ""))?;
    let name = name_field.string()?.to_string();
    if name.trim().is_empty() || name.contains(['/', '\\']) || name.chars().any(char::is_control) {
        return Err(name_field.inconsistent(format!(
            "`name` = {name:?} must be non-empty, without path separators or control characters"
        )));
    }
    let name_at = name_field.at();
    let scope = Scope {
        table: &tab,
        defaults,
    };
    let (mass_flow, q_field) = scope.required("mass_flow_kg_s")?;
    let (spinline_length, _) = scope.required("spinline_length_m")?;
    let (inlet_temperature, t_in_field) = scope.required("inlet_temperature_K")?;
    let (air_temperature, t_air_field) = scope.required("air_temperature_K")?;
    let table = tab.name.as_str();

    let t_vf = material.vft_t_vf;
    if inlet_temperature <= t_vf {
        return Err(t_in_field.invalid_in(
            table,
            inlet_temperature,
            format!(
                "must exceed the Vogel temperature vft_T_VF_K = {t_vf} K of [material]: the VFT \
                 viscosity is undefined at and below it"
            ),
        ));
    }
    if air_temperature <= t_vf {
        return Err(t_air_field.invalid_in(
            table,
            air_temperature,
            format!(
                "must exceed the Vogel temperature vft_T_VF_K = {t_vf} K of [material]: the fiber \
                 cools towards the air temperature, and the VFT viscosity is undefined at and \
                 below T_VF"
            ),
        ));
    }
    for (t, field) in [
        (inlet_temperature, &t_in_field),
        (air_temperature, &t_air_field),
    ] {
        let (rho, cp) = (material.density(t), material.heat_capacity(t));
        if !(rho > 0.0 && cp > 0.0) {
            return Err(field.invalid_in(
                table,
                t,
                format!(
                    "[material] gives a non-positive density ({rho} kg/m³) or heat capacity \
                     ({cp} J/(kg K)) at this temperature"
                ),
            ));
        }
    }
    let mu_in = material.zero_shear_viscosity(inlet_temperature);
    if !(mu_in.is_finite() && mu_in <= MAX_INLET_VISCOSITY_PA_S) {
        let what = if mu_in.is_finite() {
            format!(
                "a zero-shear viscosity of {mu_in:.3e} Pa s at the inlet, above \
                 {MAX_INLET_VISCOSITY_PA_S:e} Pa s (a glass, not a melt)"
            )
        } else {
            "an infinite zero-shear viscosity at the inlet (beyond the floating-point range)"
                .to_string()
        };
        return Err(t_in_field.invalid_in(
            table,
            inlet_temperature,
            format!(
                "the inlet temperature is only {:.4} K above the Vogel temperature \
                 vft_T_VF_K = {t_vf} K: the VFT law mu_c exp(B/(T - T_VF)) gives {what}",
                inlet_temperature - t_vf
            ),
        ));
    }

    let (inlet_is_diameter, inlet_value, inlet_field) = scope
        .either("inlet_diameter_m", "inlet_velocity_m_s")?
        .ok_or_else(|| InputError::Inconsistent {
            at: tab.doc.at_line(tab.line),
            table: tab.name.clone(),
            message: "missing inlet condition: give `inlet_diameter_m` or `inlet_velocity_m_s` \
                      (here or in [defaults])"
                .into(),
        })?;
    let inlet = if inlet_is_diameter {
        Inlet::Diameter(inlet_value)
    } else {
        Inlet::Velocity(inlet_value)
    };
    // the other inlet quantity, from the mass balance Q = ρ(T_in) u_in π d_in²/4
    let rho_in = material.density(inlet_temperature);
    let (d_in, u_in) = match inlet {
        Inlet::Diameter(d) => (d, 4.0 * mass_flow / (PI * rho_in * d * d)),
        Inlet::Velocity(u) => (2.0 * (mass_flow / (PI * rho_in * u)).sqrt(), u),
    };
    let (derived, value, unit, min, max) = if inlet_is_diameter {
        ("inlet velocity 4 Q/(π ρ d_in²)", u_in, "m/s", 1e-6, 1e3)
    } else {
        (
            "inlet diameter 2 √(Q/(π ρ u_in))",
            d_in,
            "m",
            MIN_PLAUSIBLE_DIAMETER_M,
            MAX_PLAUSIBLE_DIAMETER_M,
        )
    };
    if !(value.is_finite() && value >= min && value <= max) {
        return Err(inlet_field.inconsistent_in(
            table,
            format!(
                "`mass_flow_kg_s` = {mass_flow} (line {}) and `{}` = {inlet_value} give an {derived} \
                 = {value:.3e} {unit} (with ρ(T_in) = {rho_in:.1} kg/m³), outside the plausible range \
                 {min:e} to {max:e} {unit}",
                q_field.at().line.unwrap_or(0),
                inlet_field.key
            ),
        ));
    }
    let given = |derived_from: &str| {
        if derived_from.is_empty() {
            String::new()
        } else {
            format!(" (derived from `mass_flow_kg_s` and `{derived_from}`)")
        }
    };
    let take_up = match scope.either("take_up_diameter_m", "take_up_velocity_m_s")? {
        None => None,
        Some((true, d_out, field)) => {
            let from = given(if inlet_is_diameter {
                ""
            } else {
                "inlet_velocity_m_s"
            });
            if d_out >= d_in {
                return Err(field.inconsistent_in(
                    table,
                    format!(
                        "take-up diameter {d_out} m must be smaller than the inlet diameter {d_in} m{from}"
                    ),
                ));
            }
            let ratio = (d_in / d_out).powi(2);
            if ratio > MAX_DRAW_RATIO {
                return Err(field.inconsistent_in(
                    table,
                    format!(
                        "take-up diameter {d_out} m and inlet diameter {d_in} m{from} give a draw \
                         ratio (d_in/d_out)² = {ratio:.3e}, above the plausible {MAX_DRAW_RATIO:e}"
                    ),
                ));
            }
            Some(TakeUp::Diameter(d_out))
        }
        Some((false, u_out, field)) => {
            let from = given(if inlet_is_diameter {
                "inlet_diameter_m"
            } else {
                ""
            });
            if u_out <= u_in {
                return Err(field.inconsistent_in(
                    table,
                    format!(
                        "take-up velocity {u_out} m/s must be larger than the inlet velocity {u_in} m/s{from}"
                    ),
                ));
            }
            let ratio = u_out / u_in;
            if ratio > MAX_DRAW_RATIO {
                return Err(field.inconsistent_in(
                    table,
                    format!(
                        "take-up velocity {u_out} m/s and inlet velocity {u_in} m/s{from} give a \
                         draw ratio u_out/u_in = {ratio:.3e}, above the plausible {MAX_DRAW_RATIO:e}"
                    ),
                ));
            }
            Some(TakeUp::Velocity(u_out))
        }
    };

    let metadata = |key| scope.optional(key).map(|v| v.map(|(x, _)| x));
    let data = match tab.get("data") {
        None => None,
        Some(field) => {
            let file = field.string()?;
            if file.trim().is_empty() {
                return Err(field.inconsistent("`data` must name a CSV file".into()));
            }
            let dir = tab.doc.path.parent().unwrap_or(Path::new(""));
            Some(dir.join(file))
        }
    };
    let details = ExperimentDetails {
        stencil_velocity_mm_s: metadata("stencil_velocity_mm_s")?,
        take_up_pressure_bar: metadata("take_up_pressure_bar")?,
        data,
        line: None,
    };
    let experiment = Experiment {
        name,
        mass_flow,
        inlet,
        inlet_temperature,
        air_temperature,
        spinline_length,
        take_up,
    };
    Ok((experiment, details, name_at))
}

#[cfg(test)]
mod tests {
    use super::*;

    const MATERIAL: &str = r#"
[material]
density_slope_kg_m3_K = -0.964
density_intercept_kg_m3 = 1572.33
heat_capacity_slope_J_kg_K2 = 3.2
heat_capacity_intercept_J_kg_K = 648.22
vft_mu_c_Pa_s = 0.00037074
vft_B_K = 3649.0
vft_T_VF_K = 273.15
air_density_kg_m3 = 1.0
air_heat_capacity_J_kg_K = 1000.0
air_kinematic_viscosity_m2_s = 2e-05
air_heat_conductivity_W_m_K = 0.031

[defaults]
spinline_length_m = 0.51
inlet_temperature_K = 513.15
air_temperature_K = 293
"#;

    fn parse(experiments: &str) -> Result<LoadedExperiments, InputError> {
        let text = format!("{MATERIAL}\n{experiments}");
        parse_experiments(&text, Path::new("dir/exp.toml"))
    }

    fn parse_err(experiments: &str) -> String {
        parse(experiments).unwrap_err().to_string()
    }

    const ONE: &str =
        "[[experiment]]\nname = \"a\"\nmass_flow_kg_s = 3e-5\ninlet_diameter_m = 1e-3\n";

    #[test]
    fn minimal_experiment_parses_with_defaults() {
        let loaded = parse(&format!(
            "{ONE}data = \"a.csv\"\ntake_up_pressure_bar = 2\n"
        ))
        .unwrap();
        let set = &loaded.set;
        assert_eq!(set.material, Material::pmma7n());
        assert_eq!(set.air, Air::paper());
        let e = &set.experiments[0];
        assert_eq!(e.name, "a");
        assert_eq!(e.inlet, Inlet::Diameter(1e-3));
        assert_eq!(e.air_temperature, 293.0);
        assert_eq!(e.take_up, None);
        assert_eq!(set.measurements, vec![None]);
        assert_eq!(set.relative_uncertainty, None);
        assert_eq!(loaded.details[0].data, Some(PathBuf::from("dir/a.csv")));
        assert_eq!(loaded.details[0].take_up_pressure_bar, Some(2.0));
        assert_eq!(loaded.details[0].stencil_velocity_mm_s, None);
    }

    #[test]
    fn relative_uncertainty_at_top_level() {
        let text = format!("relative_uncertainty = 0.015\n{MATERIAL}\n{ONE}");
        let loaded = parse_experiments(&text, Path::new("x.toml")).unwrap();
        assert_eq!(loaded.set.relative_uncertainty, Some(0.015));
        let text = format!("relative_uncertainty = 1.5\n{MATERIAL}\n{ONE}");
        let msg = parse_experiments(&text, Path::new("x.toml"))
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("x.toml:1") && msg.contains("relative_uncertainty"),
            "{msg}"
        );
    }

    #[test]
    fn relative_uncertainty_in_defaults_is_pointed_to_top_level() {
        let text = MATERIAL.replace("[defaults]\n", "[defaults]\nrelative_uncertainty = 0.01\n");
        let msg = parse_experiments(&format!("{text}\n{ONE}"), Path::new("x.toml"))
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("unknown key `relative_uncertainty` in [defaults]"),
            "{msg}"
        );
        assert!(msg.contains("top level"), "{msg}");
    }

    #[test]
    fn typo_gets_suggestion_with_line() {
        let msg = parse_err(&ONE.replace("mass_flow_kg_s", "mass_flow_kgs"));
        assert!(msg.starts_with("dir/exp.toml:"), "{msg}");
        assert!(
            msg.contains("unknown key `mass_flow_kgs` in [[experiment]] #1"),
            "{msg}"
        );
        assert!(msg.contains("did you mean `mass_flow_kg_s`?"), "{msg}");
    }

    #[test]
    fn integers_are_numbers_and_strings_are_not() {
        let loaded = parse(&format!("{ONE}spinline_length_m = 1\n")).unwrap();
        assert_eq!(loaded.set.experiments[0].spinline_length, 1.0);
        // TOML's digit separators, in integers and floats
        let loaded = parse(&format!(
            "{ONE}air_temperature_K = 2_93\nspinline_length_m = 0.5_1\n"
        ))
        .unwrap();
        assert_eq!(loaded.set.experiments[0].air_temperature, 293.0);
        assert_eq!(loaded.set.experiments[0].spinline_length, 0.51);
        let msg = parse_err(&ONE.replace("3e-5", "\"3e-5\""));
        assert!(
            msg.contains("`mass_flow_kg_s` must be a number, found a string"),
            "{msg}"
        );
    }

    #[test]
    fn nan_and_inf_are_rejected() {
        for v in ["nan", "inf", "-inf"] {
            let msg = parse_err(&ONE.replace("3e-5", v));
            assert!(msg.contains("is not a finite number"), "{msg}");
        }
    }

    #[test]
    fn take_up_velocity_must_exceed_inlet_velocity() {
        let exp = ONE.replace("inlet_diameter_m = 1e-3", "inlet_velocity_m_s = 0.02");
        let ok = parse(&format!("{exp}take_up_velocity_m_s = 0.5\n")).unwrap();
        assert_eq!(ok.set.experiments[0].take_up, Some(TakeUp::Velocity(0.5)));
        let msg = parse_err(&format!("{exp}take_up_velocity_m_s = 0.01\n"));
        assert!(
            msg.contains("must be larger than the inlet velocity"),
            "{msg}"
        );
    }

    #[test]
    fn inlet_temperature_below_vogel_temperature() {
        let msg = parse_err(&format!("{ONE}inlet_temperature_K = 260\n"));
        assert!(msg.contains("Vogel temperature"), "{msg}");
    }

    #[test]
    fn bad_names() {
        let msg = parse_err(&ONE.replace("\"a\"", "\"a/b\""));
        assert!(msg.contains("`name`"), "{msg}");
        let msg = parse_err(&ONE.replace("name = \"a\"\n", ""));
        assert!(msg.contains("missing required key `name`"), "{msg}");
    }

    #[test]
    fn experiment_must_be_array_of_tables() {
        let msg = parse_err(&ONE.replace("[[experiment]]", "[experiment]"));
        assert!(msg.contains("array of tables"), "{msg}");
        let msg = parse_err("");
        assert!(msg.contains("missing required key `experiment`"), "{msg}");
    }
}
