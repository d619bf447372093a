//! Building the experiments from the TOML tables: the material, `[defaults]` and each
//! `[[experiment]]` (see `experiment`), and loading a whole data set (TOML and its CSV files,
//! with the checks that need both: see `cross_checks`).

use std::path::Path;

use toml::de::DeTable;

use super::cross_checks::{
    check_experiment_memory, cross_check, data_error, shared_data_files, with_link_hint,
};
use super::csv_file::measurements::read_measurements;
use super::csv_file::row_budget::FitBudget;
use super::error::{short, InputError};
use super::loaded::LoadedExperiments;
use super::options::{show_count, Limit, LoadOptions};
use super::source::read_toml;
use super::toml_file::experiment::{experiment, name_table, Located, MaterialAt};
use super::toml_file::schema::{keys_of, material_quantity, Rule, EXPERIMENT, MATERIAL, TOP_KEYS};
use super::toml_file::spanned::{toml_error, Doc, Tab};
use super::toml_file::uncertainty::uncertainty_table;
use crate::data::uncertainty::Uncertainties;
use crate::model::setup::{Air, ExperimentSet, Material};

/// Loads a TOML experiment file and the CSV files it refers to with the default
/// [`LoadOptions`] (at least `DEFAULT_MIN_POINTS` measurements per file).
pub fn load_experiments(path: &Path) -> Result<ExperimentSet, InputError> {
    load_experiments_with(path, &LoadOptions::default()).map(|loaded| loaded.set)
}

/// Loads a TOML experiment file and its CSV files under `options` (caps on sizes, rows and
/// experiments, enforced while reading; the checks that need the TOML and the data together).
pub fn load_experiments_with(
    path: &Path,
    options: &LoadOptions,
) -> Result<LoadedExperiments, InputError> {
    let text = read_toml(path, options.max_toml_bytes)?;
    let (mut loaded, located) = parse(&text, path, options)?;
    if options.require_data {
        loaded.require_data()?;
    }
    check_experiment_memory(&loaded, options)?;
    let mut budget = FitBudget::new(loaded.set.experiments.len(), options);
    for (i, details) in loaded.details.iter().enumerate() {
        let Some(data) = &details.data else { continue };
        let experiment = &loaded.set.experiments[i];
        let measured = read_measurements(data, experiment.spinline_length, options, &mut budget)
            .map_err(|cause| {
                data_error(
                    &located[i],
                    &experiment.name,
                    with_link_hint(path, data, cause),
                )
            })?;
        loaded.set.measurements[i] = Some(measured);
    }
    for (i, located) in located.iter().enumerate() {
        let warning = cross_check(&loaded, i, located, options)?;
        loaded.warnings.extend(warning);
    }
    let shared = shared_data_files(&loaded, &located);
    loaded.warnings.extend(shared);
    Ok(loaded)
}

/// Parses the TOML text of an experiment file without reading any CSV file (all measurements
/// are `None`). `path` is used in error messages and to resolve the `data` paths.
pub fn parse_experiments(text: &str, path: &Path) -> Result<LoadedExperiments, InputError> {
    parse_experiments_with(text, path, &LoadOptions::default())
}

/// [`parse_experiments`] under `options` (the cap on the number of experiments).
pub fn parse_experiments_with(
    text: &str,
    path: &Path,
    options: &LoadOptions,
) -> Result<LoadedExperiments, InputError> {
    parse(text, path, options).map(|(loaded, _)| loaded)
}

/// The experiments and where their keys are.
fn parse(
    text: &str,
    path: &Path,
    options: &LoadOptions,
) -> Result<(LoadedExperiments, Vec<Located>), InputError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let root = DeTable::parse(text).map_err(|e| toml_error(path, text, &e))?;
    let doc = Doc::new(path, text);
    let top = Tab {
        doc: &doc,
        name: "the top level".into(),
        table: root.get_ref(),
        line: None,
    };
    top.check_keys(TOP_KEYS)
        .map_err(|e| super::toml_file::syntax::not_experiments(path, text).unwrap_or(e))?;
    let relative_uncertainty = match top.get("relative_uncertainty") {
        Some(field) => Some(field.number(Rule::Fraction)?),
        None => None,
    };
    let mut uncertainty = Uncertainties::default();
    if let Some(tab) = top.sub_table("uncertainty", "[uncertainty]")? {
        uncertainty.set = uncertainty_table(&tab)?;
    }
    let material_tab = top.sub_table("material", "[material]")?.ok_or_else(|| {
        super::toml_file::syntax::not_experiments(path, text)
            .unwrap_or_else(|| top.missing("material", " (the [material] table)"))
    })?;
    let (material, air) = material(&material_tab)?;
    let at = |key: &str| match material_tab.get(key) {
        Some(field) => field.at(),
        None => doc.at_line(material_tab.line),
    };
    let material_at = MaterialAt {
        density: at("density_slope_kg_m3_K"),
        heat_capacity: at("heat_capacity_slope_J_kg_K2"),
    };
    let defaults = top.sub_table("defaults", "[defaults]")?;
    if let Some(defaults) = &defaults {
        defaults.check_keys(&keys_of(EXPERIMENT))?;
        for q in EXPERIMENT {
            if let Some((field, unit)) = defaults.quantity(q)? {
                field.quantity(q, &unit)?;
            }
        }
    }
    let tables = top.experiment_tables()?;
    if tables.len() > options.max_experiments {
        return Err(InputError::Limit {
            at: doc.at_line(tables.get(options.max_experiments).and_then(|t| t.line)),
            limit: Limit::Experiments,
            message: format!(
                "{} [[experiment]] tables, more than the limit of {} (a fit of that many \
                 experiments would take hours); split the data set, or raise the limit `{}` if \
                 this is intended",
                show_count(tables.len() as u64),
                show_count(options.max_experiments as u64),
                Limit::Experiments.option()
            ),
        });
    }
    let mut experiments = Vec::with_capacity(tables.len());
    let mut details = Vec::with_capacity(tables.len());
    let mut located = Vec::with_capacity(tables.len());
    let mut warnings = Vec::new();
    for mut tab in tables {
        name_table(&mut tab);
        let own = match tab.sub_table("uncertainty", &format!("{} uncertainty table", tab.name))? {
            Some(t) => uncertainty_table(&t)?,
            None => Vec::new(),
        };
        uncertainty.experiments.push(own);
        let (experiment, mut detail, at) =
            experiment(tab, defaults.as_ref(), &material, &material_at)?;
        detail.line = at.name.line;
        unique_name(&experiment.name, &at, &located)?;
        warnings.extend(at.warnings.iter().cloned());
        experiments.push(experiment);
        details.push(detail);
        located.push(at);
    }
    let measurements = vec![None; experiments.len()];
    let loaded = LoadedExperiments {
        set: ExperimentSet {
            material,
            air,
            experiments,
            measurements,
            relative_uncertainty,
        },
        details,
        uncertainty,
        warnings,
        path: path.to_path_buf(),
    };
    Ok((loaded, located))
}

/// Refuses a name used before, also when the two differ only in case (the output files would
/// collide on case-insensitive file systems: macOS, Windows).
fn unique_name(name: &str, at: &Located, before: &[Located]) -> Result<(), InputError> {
    let lower = name.to_lowercase();
    let Some(first) = before.iter().find(|b| b.name_text.to_lowercase() == lower) else {
        return Ok(());
    };
    let line = first
        .name
        .line
        .map(|l| format!(" (first defined at line {l})"))
        .unwrap_or_default();
    let message = if first.name_text == name {
        format!("duplicate experiment name \"{}\"{line}", short(name, 60))
    } else {
        format!(
            "experiment name \"{}\" differs from \"{}\"{line} only in upper/lower case: their \
             output files would overwrite each other on macOS and Windows; rename one",
            short(name, 60),
            short(&first.name_text, 60)
        )
    };
    Err(InputError::Inconsistent {
        at: at.name.clone(),
        table: at.table.clone(),
        message,
    })
}

impl ExperimentSet {
    /// Loads an experiment set from a TOML file and its CSV files (see [`load_experiments`]).
    pub fn load(path: &Path) -> Result<Self, InputError> {
        load_experiments(path)
    }
}

fn material(tab: &Tab<'_>) -> Result<(Material, Air), InputError> {
    tab.check_keys(&keys_of(MATERIAL))?;
    let get = |stem: &'static str| -> Result<f64, InputError> {
        let Some(q) = material_quantity(stem) else {
            return Err(tab.missing(stem, ""));
        };
        match tab.quantity(q)? {
            Some((field, unit)) => field.quantity(q, &unit),
            None if stem == "trouton_ratio" => Ok(3.0),
            None => Err(tab.missing(&q.si_key(), "")),
        }
    };
    let material = Material {
        density_slope: get("density_slope")?,
        density_intercept: get("density_intercept")?,
        heat_capacity_slope: get("heat_capacity_slope")?,
        heat_capacity_intercept: get("heat_capacity_intercept")?,
        vft_mu_c: get("vft_mu_c")?,
        vft_b: get("vft_B")?,
        vft_t_vf: get("vft_T_VF")?,
        trouton: get("trouton_ratio")?,
    };
    let air = Air {
        density: get("air_density")?,
        heat_capacity: get("air_heat_capacity")?,
        kinematic_viscosity: get("air_kinematic_viscosity")?,
        heat_conductivity: get("air_heat_conductivity")?,
    };
    Ok((material, air))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::setup::{Inlet, TakeUp};
    use std::path::PathBuf;

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
