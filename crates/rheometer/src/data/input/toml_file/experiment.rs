//! One `[[experiment]]` table (backed by `[defaults]`): its keys in whichever units they are
//! given, converted to SI, and the plausibility checks of the experiment alone (temperatures
//! against the material, the inlet velocity from mass flow and inlet diameter, the take-up
//! against the inlet, the name as a file name).

use std::f64::consts::PI;
use std::path::Path;

use super::schema::{
    keys_of, Quantity, Unit, AIR_TEMPERATURE, EXPERIMENT, EXPERIMENT_TABLES, INLET_DIAMETER,
    INLET_TEMPERATURE, INLET_VELOCITY, MASS_FLOW_Q, MAX_PLAUSIBLE_DIAMETER_M,
    MAX_PLAUSIBLE_INLET_VELOCITY_M_S, MIN_PLAUSIBLE_INLET_DIAMETER_M,
    PLAUSIBLE_HEAT_CAPACITY_J_KG_K, PLAUSIBLE_MELT_DENSITY_KG_M3, SPINLINE_LENGTH,
    STENCIL_VELOCITY, STRING_KEYS, TAKE_UP_DIAMETER, TAKE_UP_PRESSURE, TAKE_UP_VELOCITY,
};
use super::spanned::{Field, Tab};
use crate::data::input::error::{readable, short, sig, InputError, InputWarning, Location};
use crate::data::input::loaded::ExperimentDetails;
use crate::data::input::source::is_stdin_like;
use crate::model::setup::{Experiment, Inlet, Material, TakeUp};

/// Longest experiment name \[bytes\]: the 255-byte file-name limit of common file systems minus
/// the longest suffix of an output file named after the experiment (`_fitted_profile.csv`).
pub const MAX_NAME_BYTES: usize = 255 - "_fitted_profile.csv".len();

/// Largest plausible zero-shear viscosity of the melt at the inlet \[Pa s\]: 1e12 Pa s is the
/// conventional viscosity of a glass at its glass transition; above it the polymer is not a melt.
pub const MAX_INLET_VISCOSITY_PA_S: f64 = 1e12;

/// Largest plausible draw ratio `u_out/u_in = (d_in/d_out)²` \[-\].
pub const MAX_DRAW_RATIO: f64 = 1e6;

/// Where the keys of one experiment are, for the checks that need its data too.
#[derive(Debug, Clone)]
pub(in crate::data::input) struct Located {
    /// The table's name for messages (`[[experiment]] #2 "v0p27_p2"`).
    pub(in crate::data::input) table: String,
    pub(in crate::data::input) name: Location,
    pub(in crate::data::input) name_text: String,
    /// The `data` key.
    pub(in crate::data::input) data: Option<Location>,
    /// The spin-line length key, and how it reads in a message.
    pub(in crate::data::input) spinline: (Location, String),
    /// The inlet key (diameter or velocity), and how it reads in a message.
    pub(in crate::data::input) inlet: (Location, String),
    /// Warnings on this experiment's keys.
    pub(in crate::data::input) warnings: Vec<InputWarning>,
}

/// Where the material lines are, for errors about their values at an experiment's temperatures.
pub(in crate::data::input) struct MaterialAt {
    /// The `density_slope_kg_m3_K` key.
    pub(in crate::data::input) density: Location,
    /// The `heat_capacity_slope_J_kg_K2` key.
    pub(in crate::data::input) heat_capacity: Location,
}

/// An experiment table backed by `[defaults]`.
struct Scope<'s, 'a> {
    table: &'s Tab<'a>,
    defaults: Option<&'s Tab<'a>>,
}

/// A resolved key: SI value, the field it came from, its unit.
type Got<'a> = (f64, Field<'a>, Unit);

impl<'a> Scope<'_, 'a> {
    fn optional(&self, q: &Quantity) -> Result<Option<Got<'a>>, InputError> {
        let found = match self.table.quantity(q)? {
            Some(found) => Some(found),
            None => match self.defaults {
                Some(d) => d.quantity(q)?,
                None => None,
            },
        };
        match found {
            Some((field, unit)) => Ok(Some((field.quantity(q, &unit)?, field, unit))),
            None => Ok(None),
        }
    }

    fn required(&self, q: &Quantity) -> Result<Got<'a>, InputError> {
        let hint = if q.units.len() > 1 {
            format!(
                " (give it here or in [defaults]; in any of its units: {})",
                q.spellings()
            )
        } else {
            " (give it here or in [defaults])".to_string()
        };
        self.optional(q)?
            .ok_or_else(|| self.table.missing(&q.si_key(), &hint))
    }

    /// One of two mutually exclusive quantities, resolved as a pair: the experiment table
    /// first, then `[defaults]`. Returns `(first_quantity_given, value)`.
    fn either(&self, a: &Quantity, b: &Quantity) -> Result<Option<(bool, Got<'a>)>, InputError> {
        for tab in std::iter::once(self.table).chain(self.defaults) {
            match (tab.quantity(a)?, tab.quantity(b)?) {
                (Some((fa, _)), Some((fb, _))) => {
                    return Err(fb.inconsistent(format!(
                        "give either `{}` or `{}`, not both",
                        fa.key, fb.key
                    )))
                }
                (Some((f, u)), None) => return Ok(Some((true, (f.quantity(a, &u)?, f, u)))),
                (None, Some((f, u))) => return Ok(Some((false, (f.quantity(b, &u)?, f, u)))),
                (None, None) => {}
            }
        }
        Ok(None)
    }
}

/// Names the table `tab` by its experiment's name (if readable), so that every message about
/// it (unknown keys, its uncertainty table) names the experiment.
pub(in crate::data::input) fn name_table(tab: &mut Tab<'_>) {
    if let Some(name) = tab
        .get("name")
        .and_then(|f| f.string().ok().map(str::to_string))
    {
        tab.name = format!("{} \"{}\"", tab.name, short(&name, 40));
    }
}

/// Parses one `[[experiment]]` table (named by [`name_table`]); also returns where its keys
/// are.
pub(in crate::data::input) fn experiment(
    tab: Tab<'_>,
    defaults: Option<&Tab<'_>>,
    material: &Material,
    material_at: &MaterialAt,
) -> Result<(Experiment, ExperimentDetails, Located), InputError> {
    let allowed: Vec<String> = STRING_KEYS
        .iter()
        .chain(EXPERIMENT_TABLES)
        .map(|k| k.to_string())
        .chain(keys_of(EXPERIMENT))
        .collect();
    tab.check_keys(&allowed)?;
    let name_field = tab.get("name").ok_or_else(|| tab.missing("name", ""))?;
    let name = name_field.string()?.to_string();
    check_name(&name, &name_field)?;
    let scope = Scope {
        table: &tab,
        defaults,
    };
    let mass_flow = scope.required(&MASS_FLOW_Q)?;
    let spinline = scope.required(&SPINLINE_LENGTH)?;
    let t_in = scope.required(&INLET_TEMPERATURE)?;
    let t_air = scope.required(&AIR_TEMPERATURE)?;
    let table = tab.name.as_str();
    let mut warnings = Vec::new();
    temperatures(table, material, &t_in, &t_air, &mut warnings)?;
    material_at_temperatures(table, material, material_at, &[&t_in, &t_air])?;

    let (inlet_is_diameter, inlet_got) = scope
        .either(&INLET_DIAMETER, &INLET_VELOCITY)?
        .ok_or_else(|| InputError::Inconsistent {
            at: tab.doc.at_line(tab.line),
            table: tab.name.clone(),
            message: format!(
                "missing inlet condition: give the inlet diameter ({}) or the inlet velocity \
                 ({}), here or in [defaults]",
                INLET_DIAMETER.spellings(),
                INLET_VELOCITY.spellings()
            ),
        })?;
    let (d_in, u_in) = inlet(
        table,
        material,
        t_in.0,
        &mass_flow,
        inlet_is_diameter,
        &inlet_got,
    )?;
    let derived = format!(
        " (derived from `{}` and `{}`)",
        mass_flow.1.key, inlet_got.1.key
    );
    let take_up = take_up(table, &scope, (inlet_is_diameter, &derived), d_in, u_in)?;
    let data = data_path(&tab)?;
    let metadata = |q: &Quantity| scope.optional(q).map(|v| v.map(|(x, _, _)| x));
    let details = ExperimentDetails {
        stencil_velocity_mm_s: metadata(&STENCIL_VELOCITY)?,
        take_up_pressure_bar: metadata(&TAKE_UP_PRESSURE)?,
        data,
        line: None,
    };
    let located = Located {
        table: tab.name.clone(),
        name: name_field.at(),
        name_text: name.clone(),
        data: tab.get("data").map(|f| f.at()),
        spinline: (spinline.1.at(), spinline.1.shown()),
        inlet: (inlet_got.1.at(), inlet_got.1.shown()),
        warnings,
    };
    let experiment = Experiment {
        name,
        mass_flow: mass_flow.0,
        inlet: if inlet_is_diameter {
            Inlet::Diameter(inlet_got.0)
        } else {
            Inlet::Velocity(inlet_got.0)
        },
        inlet_temperature: t_in.0,
        air_temperature: t_air.0,
        spinline_length: spinline.0,
        take_up,
    };
    Ok((experiment, details, located))
}

/// A name must be usable as the stem of output file names.
fn check_name(name: &str, field: &Field<'_>) -> Result<(), InputError> {
    let shown = short(name, 60);
    let problem = if name.trim().is_empty() {
        Some("must not be empty".to_string())
    } else if name.contains(['/', '\\']) || name.chars().any(char::is_control) {
        Some("must not contain path separators (/ \\) or control characters".to_string())
    } else if name.trim() != name {
        Some(
            "has leading or trailing spaces: they are invisible in reports and file names, and \
             \"a \" would be another experiment than \"a\"; remove them"
                .to_string(),
        )
    } else if name.len() > MAX_NAME_BYTES {
        Some(format!(
            "is {} bytes long; output files are named after the experiment \
             (`<name>_fitted_profile.csv`) and a file name has at most 255 bytes, so a name may \
             have at most {MAX_NAME_BYTES} bytes: shorten it",
            name.len()
        ))
    } else {
        None
    };
    match problem {
        Some(p) => Err(field.inconsistent(format!("`name` = {shown:?} {p}"))),
        None => Ok(()),
    }
}

/// The hint for a kelvin key holding what is probably a Celsius value.
fn celsius_hint(field: &Field<'_>, unit: &Unit, value_k: f64, ok: impl Fn(f64) -> bool) -> String {
    if unit.offset == 0.0 && value_k < 373.15 && ok(value_k + 273.15) {
        let stem = field.key.strip_suffix("_K").unwrap_or(field.key);
        format!(
            "; if {} is in degrees Celsius, write `{stem}_C = {}` (= {} K)",
            field.raw(),
            field.raw(),
            readable(value_k + 273.15)
        )
    } else {
        String::new()
    }
}

/// The inlet and air temperatures against the material: above the Vogel temperature, a melt
/// at the inlet, density and heat capacity plausible at both.
fn temperatures(
    table: &str,
    material: &Material,
    t_in: &Got<'_>,
    t_air: &Got<'_>,
    warnings: &mut Vec<InputWarning>,
) -> Result<(), InputError> {
    let t_vf = material.vft_t_vf;
    let viscosity_ok = |t: f64| {
        t > t_vf && {
            let mu = material.zero_shear_viscosity(t);
            mu.is_finite() && mu <= MAX_INLET_VISCOSITY_PA_S
        }
    };
    for (got, what, ok) in [
        (t_in, "the VFT viscosity is undefined at and below it", true),
        (
            t_air,
            "the fiber cools towards the air temperature, and the VFT viscosity is undefined at \
             and below T_VF",
            false,
        ),
    ] {
        let (t, field, unit) = got;
        if *t <= t_vf {
            let hint = celsius_hint(
                field,
                unit,
                *t,
                |k| if ok { viscosity_ok(k) } else { k > t_vf },
            );
            return Err(field.invalid_in(
                table,
                field.finite()?,
                format!(
                    "must exceed the Vogel temperature vft_T_VF_K = {} K of [material]: {what}{hint}",
                    readable(t_vf)
                ),
            ));
        }
        if unit.offset != 0.0 && field.finite()? >= 273.15 {
            warnings.push(InputWarning {
                at: field.at(),
                message: format!(
                    "{table}: `{}` = {} °C ({} K) is hot for {}; if the value is in kelvin, \
                     write `{}_K = {}`",
                    field.key,
                    field.raw(),
                    sig(*t),
                    if ok { "a polymer melt" } else { "the air" },
                    field.key.strip_suffix("_C").unwrap_or(field.key),
                    field.raw()
                ),
            });
        }
    }
    let (t, field, unit) = t_in;
    let mu_in = material.zero_shear_viscosity(*t);
    if !(mu_in.is_finite() && mu_in <= MAX_INLET_VISCOSITY_PA_S) {
        let what = if mu_in.is_finite() {
            format!(
                "a zero-shear viscosity of {} Pa s at the inlet, above {} Pa s (a glass, not a \
                 melt)",
                sig(mu_in),
                readable(MAX_INLET_VISCOSITY_PA_S)
            )
        } else {
            "an infinite zero-shear viscosity at the inlet (beyond the floating-point range)"
                .to_string()
        };
        let hint = celsius_hint(field, unit, *t, viscosity_ok);
        return Err(field.invalid_in(
            table,
            field.finite()?,
            format!(
                "the inlet temperature is only {:.4} K above the Vogel temperature vft_T_VF_K = \
                 {} K: the VFT law mu_c exp(B/(T - T_VF)) with vft_mu_c_Pa_s = {} and vft_B_K = \
                 {} of [material] gives {what}{hint}",
                t - t_vf,
                readable(t_vf),
                readable(material.vft_mu_c),
                readable(material.vft_b)
            ),
        ));
    }
    Ok(())
}

/// Density and heat capacity of the material plausible at the experiment's temperatures.
fn material_at_temperatures(
    table: &str,
    material: &Material,
    at: &MaterialAt,
    temperatures: &[&Got<'_>],
) -> Result<(), InputError> {
    for (t, field, _) in temperatures {
        let (rho, cp) = (material.density(*t), material.heat_capacity(*t));
        let (r0, r1) = PLAUSIBLE_MELT_DENSITY_KG_M3;
        let (c0, c1) = PLAUSIBLE_HEAT_CAPACITY_J_KG_K;
        let at_t = format!("at {} K ({} of {table})", readable(*t), field.shown());
        let (location, message) = if !(r0..=r1).contains(&rho) {
            (
                &at.density,
                format!(
                    "the density line (`density_slope_kg_m3_K` = {}, `density_intercept_kg_m3` = \
                     {}) gives ρ = {} kg/m³ {at_t}, outside the {r0} to {r1} kg/m³ of a polymer; \
                     check the slope (kg/(m³ K), typically -0.5 to -1.5) and the intercept \
                     (kg/m³ at 0 K)",
                    readable(material.density_slope),
                    readable(material.density_intercept),
                    sig(rho)
                ),
            )
        } else if !(c0..=c1).contains(&cp) {
            (
                &at.heat_capacity,
                format!(
                    "the heat-capacity line (`heat_capacity_slope_J_kg_K2` = {}, \
                     `heat_capacity_intercept_J_kg_K` = {}) gives c_p = {} J/(kg K) {at_t}, \
                     outside the {c0} to {c1} J/(kg K) of a polymer; check both values",
                    readable(material.heat_capacity_slope),
                    readable(material.heat_capacity_intercept),
                    sig(cp)
                ),
            )
        } else {
            continue;
        };
        return Err(InputError::Inconsistent {
            at: location.clone(),
            table: "[material]".into(),
            message,
        });
    }
    Ok(())
}

/// The inlet diameter and velocity `(d_in, u_in)` \[m, m/s\] from the given one and the mass
/// balance `Q = ρ(T_in) u_in π d_in²/4`, checked for plausibility; a too fast inlet points at
/// the mass flow's unit.
fn inlet(
    table: &str,
    material: &Material,
    t_in: f64,
    mass_flow: &Got<'_>,
    is_diameter: bool,
    given: &Got<'_>,
) -> Result<(f64, f64), InputError> {
    let (q, q_field, _) = mass_flow;
    let (value, field, _) = given;
    let rho = material.density(t_in);
    let (d_in, u_in) = if is_diameter {
        (*value, 4.0 * q / (PI * rho * value * value))
    } else {
        (2.0 * (q / (PI * rho * value)).sqrt(), *value)
    };
    let inputs = format!(
        "{} and {} with ρ(T_in) = {} kg/m³",
        q_field.shown(),
        field.shown(),
        sig(rho)
    );
    if is_diameter && u_in > MAX_PLAUSIBLE_INLET_VELOCITY_M_S && u_in.is_finite() {
        let per_q = u_in / q;
        let units: Vec<String> = MASS_FLOW_Q
            .units
            .iter()
            .filter(|u| q_field.key != MASS_FLOW_Q.key(u))
            .filter(|u| {
                let v = per_q * u.to_si(q_field.finite().unwrap_or(0.0));
                (1e-5..=MAX_PLAUSIBLE_INLET_VELOCITY_M_S).contains(&v)
            })
            .map(|u| {
                format!(
                    "`{} = {}` if it is in {}",
                    MASS_FLOW_Q.key(u),
                    q_field.raw(),
                    u.name
                )
            })
            .collect();
        let diameter_plausible = (1e-4..=5e-3).contains(&d_in);
        let suspect = if diameter_plausible {
            "the mass flow is probably in another unit".to_string()
        } else {
            format!(
                "the mass flow is in another unit, or the inlet diameter ({} mm) is too small",
                sig(d_in * 1e3)
            )
        };
        let write = if units.is_empty() {
            String::new()
        } else {
            format!(": write {}", units.join(", or "))
        };
        return Err(q_field.inconsistent_in(
            table,
            format!(
                "{inputs} give an inlet velocity 4 Q/(π ρ d_in²) = {} m/s, faster than a melt \
                 leaves a spinneret (at most {MAX_PLAUSIBLE_INLET_VELOCITY_M_S} m/s): \
                 {suspect}{write}",
                sig(u_in)
            ),
        ));
    }
    let (derived, v, unit, min, max) = if is_diameter {
        (
            "inlet velocity 4 Q/(π ρ d_in²)",
            u_in,
            "m/s",
            1e-6,
            MAX_PLAUSIBLE_INLET_VELOCITY_M_S,
        )
    } else {
        (
            "inlet diameter 2 √(Q/(π ρ u_in))",
            d_in,
            "m",
            MIN_PLAUSIBLE_INLET_DIAMETER_M,
            MAX_PLAUSIBLE_DIAMETER_M,
        )
    };
    if !(v.is_finite() && v >= min && v <= max) {
        return Err(field.inconsistent_in(
            table,
            format!(
                "{inputs} give an {derived} = {} {unit}, outside the plausible range {} to {} \
                 {unit}; check the units",
                sig(v),
                readable(min),
                readable(max)
            ),
        ));
    }
    Ok((d_in, u_in))
}

/// The take-up condition, if given: a diameter below the inlet diameter or a velocity above
/// the inlet velocity, with a draw ratio of at most [`MAX_DRAW_RATIO`].
fn take_up(
    table: &str,
    scope: &Scope<'_, '_>,
    (inlet_is_diameter, derived): (bool, &str),
    d_in: f64,
    u_in: f64,
) -> Result<Option<TakeUp>, InputError> {
    match scope.either(&TAKE_UP_DIAMETER, &TAKE_UP_VELOCITY)? {
        None => Ok(None),
        Some((true, (d_out, field, _))) => {
            let from = if inlet_is_diameter { "" } else { derived };
            if d_out >= d_in {
                return Err(field.inconsistent_in(
                    table,
                    format!(
                        "take-up diameter {} m must be smaller than the inlet diameter {} m{from}",
                        sig(d_out),
                        sig(d_in)
                    ),
                ));
            }
            let ratio = (d_in / d_out).powi(2);
            if ratio > MAX_DRAW_RATIO {
                return Err(field.inconsistent_in(
                    table,
                    format!(
                        "take-up diameter {} m and inlet diameter {} m{from} give a draw ratio \
                         (d_in/d_out)² = {}, above the plausible {}",
                        sig(d_out),
                        sig(d_in),
                        sig(ratio),
                        readable(MAX_DRAW_RATIO)
                    ),
                ));
            }
            Ok(Some(TakeUp::Diameter(d_out)))
        }
        Some((false, (u_out, field, _))) => {
            let from = if inlet_is_diameter { derived } else { "" };
            if u_out <= u_in {
                return Err(field.inconsistent_in(
                    table,
                    format!(
                        "take-up velocity {} m/s must be larger than the inlet velocity {} \
                         m/s{from}",
                        sig(u_out),
                        sig(u_in)
                    ),
                ));
            }
            let ratio = u_out / u_in;
            if ratio > MAX_DRAW_RATIO {
                return Err(field.inconsistent_in(
                    table,
                    format!(
                        "take-up velocity {} m/s and inlet velocity {} m/s{from} give a draw \
                         ratio u_out/u_in = {}, above the plausible {}",
                        sig(u_out),
                        sig(u_in),
                        sig(ratio),
                        readable(MAX_DRAW_RATIO)
                    ),
                ));
            }
            Ok(Some(TakeUp::Velocity(u_out)))
        }
    }
}

/// The data file, resolved against the experiments file's folder.
fn data_path(tab: &Tab<'_>) -> Result<Option<std::path::PathBuf>, InputError> {
    let Some(field) = tab.get("data") else {
        return Ok(None);
    };
    let file = field.string()?;
    if file.trim().is_empty() {
        return Err(field.inconsistent("`data` must name a CSV file".into()));
    }
    let relative = Path::new(file).is_relative();
    if relative && is_stdin_like(tab.doc.path) {
        return Err(field.inconsistent(format!(
            "`data` = {:?} is a relative path, but the experiments were read from {}, which has \
             no folder to resolve it against: give the data files' absolute paths, or pass the \
             experiments file by its own path",
            short(file, 80),
            tab.doc.path.display()
        )));
    }
    let dir = tab.doc.path.parent().unwrap_or(Path::new(""));
    Ok(Some(dir.join(file)))
}
