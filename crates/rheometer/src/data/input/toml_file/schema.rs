//! The keys of the experiment file's tables and the rules their values obey: required types
//! and signs, plausible ranges, and hints for misspelt or misplaced keys.

/// Largest plausible fiber diameter \[m\]; larger values suggest the file is in millimetres.
pub const MAX_PLAUSIBLE_DIAMETER_M: f64 = 0.02;

/// Smallest plausible fiber diameter \[m\] (1 µm); smaller values are probably a unit error.
pub const MIN_PLAUSIBLE_DIAMETER_M: f64 = 1e-6;

/// Smallest plausible inlet diameter \[m\] (10 µm): the strand leaving a spinneret hole is
/// wider; a smaller value is probably in the wrong unit.
pub const MIN_PLAUSIBLE_INLET_DIAMETER_M: f64 = 1e-5;

/// Largest plausible inlet velocity \[m/s\] of the melt leaving the die, `4 Q/(π ρ d_in²)`
/// (given or derived): extrusion through a spinneret hole is slower than a few m/s (a 0.1 mm
/// hole at 1 g/min gives 2 m/s); a faster one is probably a mass flow in g/s or g/min typed as
/// kg/s.
pub const MAX_PLAUSIBLE_INLET_VELOCITY_M_S: f64 = 5.0;

/// Plausible density of a polymer melt \[kg/m³\], `(min, max)`, checked at the inlet and air
/// temperatures from `[material]`'s density line.
pub const PLAUSIBLE_MELT_DENSITY_KG_M3: (f64, f64) = (300.0, 3500.0);

/// Plausible specific heat capacity of a polymer \[J/(kg K)\], `(min, max)`, checked at the
/// inlet and air temperatures from `[material]`'s heat-capacity line.
pub const PLAUSIBLE_HEAT_CAPACITY_J_KG_K: (f64, f64) = (300.0, 10000.0);

/// Plausible ranges `(key, min, max)` in SI units (the unit is in the key) of the
/// per-experiment quantities of melt spinning and of the ambient gas (air, nitrogen, helium); a
/// value outside is rejected as a probable unit or typing error, also when it was given in
/// another unit (`inlet_temperature_C`, `mass_flow_g_min`: the range applies after conversion).
/// The diameters have their own bounds ([`MIN_PLAUSIBLE_DIAMETER_M`],
/// [`MAX_PLAUSIBLE_DIAMETER_M`], [`MIN_PLAUSIBLE_INLET_DIAMETER_M`]).
pub const PLAUSIBLE_RANGES: &[(&str, f64, f64)] = &[
    ("mass_flow_kg_s", 1e-10, 1.0),
    ("inlet_velocity_m_s", 1e-6, MAX_PLAUSIBLE_INLET_VELOCITY_M_S),
    ("take_up_velocity_m_s", 1e-6, 1e3),
    ("spinline_length_m", 1e-3, 100.0),
    ("inlet_temperature_K", 100.0, 1500.0),
    ("air_temperature_K", 100.0, 1500.0),
    (
        "inlet_diameter_m",
        MIN_PLAUSIBLE_INLET_DIAMETER_M,
        MAX_PLAUSIBLE_DIAMETER_M,
    ),
    ("air_density_kg_m3", 0.01, 100.0),
    ("air_heat_capacity_J_kg_K", 100.0, 20000.0),
    ("air_kinematic_viscosity_m2_s", 1e-7, 1e-2),
    ("air_heat_conductivity_W_m_K", 1e-3, 1.0),
];

/// What a numeric key must satisfy.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(in crate::data::input) enum Rule {
    Finite,
    Positive,
    NonNegative,
    /// Positive and at most [`MAX_PLAUSIBLE_DIAMETER_M`].
    Diameter,
    /// In (0, 1): a relative uncertainty.
    Fraction,
}

/// A unit a quantity may be given in: `SI = value / divisor + offset`. Dividing by an exact
/// integer (1000, 60000) rounds once, so a converted value is the nearest double to the SI
/// value of the decimal as typed, or one unit in the last place from it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(in crate::data::input) struct Unit {
    /// The key suffix (`g_min`) or column-name suffix.
    pub(in crate::data::input) suffix: &'static str,
    /// The unit as printed (`g/min`).
    pub(in crate::data::input) symbol: &'static str,
    /// The unit in words (`grams per minute`).
    pub(in crate::data::input) name: &'static str,
    pub(in crate::data::input) divisor: f64,
    pub(in crate::data::input) offset: f64,
}

impl Unit {
    /// The SI value of `value` given in this unit.
    pub(in crate::data::input) fn to_si(self, value: f64) -> f64 {
        if self.offset != 0.0 {
            value + self.offset
        } else if self.divisor == 1.0 {
            value
        } else {
            value / self.divisor
        }
    }

    /// `si` (in the SI unit) expressed in this unit.
    pub(in crate::data::input) fn of_si(self, si: f64) -> f64 {
        (si - self.offset) * self.divisor
    }
}

const fn si(suffix: &'static str, symbol: &'static str) -> Unit {
    Unit {
        suffix,
        symbol,
        name: symbol,
        divisor: 1.0,
        offset: 0.0,
    }
}

const fn per(suffix: &'static str, symbol: &'static str, name: &'static str, divisor: f64) -> Unit {
    Unit {
        suffix,
        symbol,
        name,
        divisor,
        offset: 0.0,
    }
}

/// Mass flow: kg/s (SI), g/s, g/min, g/h, kg/h.
pub(in crate::data::input) const MASS_FLOW: &[Unit] = &[
    Unit {
        name: "kg/s",
        ..si("kg_s", "kg/s")
    },
    per("g_s", "g/s", "g/s", 1e3),
    per("g_min", "g/min", "g/min", 6e4),
    per("g_h", "g/h", "g/h", 3.6e6),
    per("kg_h", "kg/h", "kg/h", 3.6e3),
];
/// Metres, the SI length.
const METRE: Unit = Unit {
    name: "metres",
    ..si("m", "m")
};
/// Diameters: m (SI), mm, µm.
pub(in crate::data::input) const DIAMETER: &[Unit] = &[
    METRE,
    per("mm", "mm", "millimetres", 1e3),
    per("um", "µm", "micrometres", 1e6),
];
/// Lengths along the spin line: m (SI), cm, mm.
pub(in crate::data::input) const LENGTH: &[Unit] = &[
    METRE,
    per("cm", "cm", "centimetres", 1e2),
    per("mm", "mm", "millimetres", 1e3),
];
/// Speeds: m/s (SI), mm/s, m/min.
pub(in crate::data::input) const VELOCITY: &[Unit] = &[
    si("m_s", "m/s"),
    per("mm_s", "mm/s", "mm/s", 1e3),
    per("m_min", "m/min", "m/min", 60.0),
];
/// Temperatures: K (SI), °C.
pub(in crate::data::input) const TEMPERATURE: &[Unit] = &[
    Unit {
        name: "kelvin",
        ..si("K", "K")
    },
    Unit {
        suffix: "C",
        symbol: "°C",
        name: "degrees Celsius",
        divisor: 1.0,
        offset: 273.15,
    },
];

/// A numeric key of the experiment file: its stem, the rule its SI value obeys, and the units
/// it may be given in (the first is the unit stored; the key is `stem_suffix`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(in crate::data::input) struct Quantity {
    pub(in crate::data::input) stem: &'static str,
    pub(in crate::data::input) rule: Rule,
    pub(in crate::data::input) units: &'static [Unit],
}

impl Quantity {
    /// The key of this quantity in `unit`.
    pub(in crate::data::input) fn key(&self, unit: &Unit) -> String {
        if unit.suffix.is_empty() {
            self.stem.to_string()
        } else {
            format!("{}_{}", self.stem, unit.suffix)
        }
    }

    /// The key in the stored unit (`mass_flow_kg_s`).
    pub(in crate::data::input) fn si_key(&self) -> String {
        self.key(&self.units[0])
    }

    /// Every accepted key.
    pub(in crate::data::input) fn keys(&self) -> impl Iterator<Item = String> + '_ {
        self.units.iter().map(|u| self.key(u))
    }

    /// The unit of `key`, if it is a key of this quantity.
    pub(in crate::data::input) fn unit_of(&self, key: &str) -> Option<&'static Unit> {
        self.units.iter().find(|u| self.key(u) == key)
    }

    /// The accepted keys for a message: `` `mass_flow_kg_s` (kg/s), `mass_flow_g_min` (g/min)``.
    pub(in crate::data::input) fn spellings(&self) -> String {
        self.units
            .iter()
            .map(|u| format!("`{}` ({})", self.key(u), u.symbol))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

const fn q(stem: &'static str, rule: Rule, units: &'static [Unit]) -> Quantity {
    Quantity { stem, rule, units }
}

pub(in crate::data::input) const TOP_KEYS: &[&str] = &[
    "relative_uncertainty",
    "uncertainty",
    "material",
    "defaults",
    "experiment",
];

/// Sub-table keys of an `[[experiment]]` table (its own `uncertainty` overrides).
pub(in crate::data::input) const EXPERIMENT_TABLES: &[&str] = &["uncertainty"];

pub(in crate::data::input) const MATERIAL: &[Quantity] = &[
    q("density_slope", Rule::Finite, &[si("kg_m3_K", "kg/(m³ K)")]),
    q("density_intercept", Rule::Positive, &[si("kg_m3", "kg/m³")]),
    q(
        "heat_capacity_slope",
        Rule::Finite,
        &[si("J_kg_K2", "J/(kg K²)")],
    ),
    q(
        "heat_capacity_intercept",
        Rule::Finite,
        &[si("J_kg_K", "J/(kg K)")],
    ),
    q("vft_mu_c", Rule::Positive, &[si("Pa_s", "Pa s")]),
    q("vft_B", Rule::Positive, &[si("K", "K")]),
    q("vft_T_VF", Rule::NonNegative, TEMPERATURE),
    q("trouton_ratio", Rule::Positive, &[si("", "-")]),
    q("air_density", Rule::Positive, &[si("kg_m3", "kg/m³")]),
    q(
        "air_heat_capacity",
        Rule::Positive,
        &[si("J_kg_K", "J/(kg K)")],
    ),
    q(
        "air_kinematic_viscosity",
        Rule::Positive,
        &[si("m2_s", "m²/s")],
    ),
    q(
        "air_heat_conductivity",
        Rule::Positive,
        &[si("W_m_K", "W/(m K)")],
    ),
];

pub(in crate::data::input) const MASS_FLOW_Q: Quantity = q("mass_flow", Rule::Positive, MASS_FLOW);
pub(in crate::data::input) const INLET_DIAMETER: Quantity =
    q("inlet_diameter", Rule::Diameter, DIAMETER);
pub(in crate::data::input) const INLET_VELOCITY: Quantity =
    q("inlet_velocity", Rule::Positive, VELOCITY);
pub(in crate::data::input) const TAKE_UP_DIAMETER: Quantity =
    q("take_up_diameter", Rule::Diameter, DIAMETER);
pub(in crate::data::input) const TAKE_UP_VELOCITY: Quantity =
    q("take_up_velocity", Rule::Positive, VELOCITY);
pub(in crate::data::input) const SPINLINE_LENGTH: Quantity =
    q("spinline_length", Rule::Positive, LENGTH);
pub(in crate::data::input) const INLET_TEMPERATURE: Quantity =
    q("inlet_temperature", Rule::Positive, TEMPERATURE);
pub(in crate::data::input) const AIR_TEMPERATURE: Quantity =
    q("air_temperature", Rule::Positive, TEMPERATURE);
pub(in crate::data::input) const STENCIL_VELOCITY: Quantity =
    q("stencil_velocity", Rule::Positive, &[si("mm_s", "mm/s")]);
pub(in crate::data::input) const TAKE_UP_PRESSURE: Quantity =
    q("take_up_pressure", Rule::Finite, &[si("bar", "bar")]);

pub(in crate::data::input) const EXPERIMENT: &[Quantity] = &[
    MASS_FLOW_Q,
    INLET_DIAMETER,
    INLET_VELOCITY,
    TAKE_UP_DIAMETER,
    TAKE_UP_VELOCITY,
    SPINLINE_LENGTH,
    INLET_TEMPERATURE,
    AIR_TEMPERATURE,
    STENCIL_VELOCITY,
    TAKE_UP_PRESSURE,
];

/// String-valued keys of an `[[experiment]]` table (not allowed in `[defaults]`).
pub(in crate::data::input) const STRING_KEYS: &[&str] = &["name", "data"];

/// Every key of `quantities`.
pub(in crate::data::input) fn keys_of(quantities: &[Quantity]) -> Vec<String> {
    quantities.iter().flat_map(|q| q.keys()).collect()
}

/// The quantity with the material key `key`.
pub(in crate::data::input) fn material_quantity(stem: &str) -> Option<&'static Quantity> {
    MATERIAL.iter().find(|q| q.stem == stem)
}

/// The quantity of `key` among `quantities`, with its unit.
fn quantity_of<'q>(quantities: &'q [Quantity], key: &str) -> Option<(&'q Quantity, &'static Unit)> {
    quantities
        .iter()
        .find_map(|q| q.unit_of(key).map(|u| (q, u)))
}

/// The plausible SI range `(min, max)` of quantity `q`, if it has one.
pub(in crate::data::input) fn plausible_range(q: &Quantity) -> Option<(f64, f64)> {
    let key = q.si_key();
    PLAUSIBLE_RANGES
        .iter()
        .find(|(k, _, _)| *k == key)
        .map(|&(_, min, max)| (min, max))
}

/// Where a key belongs, for hints on keys given in the wrong table.
fn home_of(key: &str) -> Option<&'static str> {
    if key == "relative_uncertainty" {
        Some("the top level (before the first [table] header)")
    } else if key == "uncertainty" {
        Some("the top level ([uncertainty]) or an [[experiment]] (its own `uncertainty` table)")
    } else if quantity_of(MATERIAL, key).is_some() {
        Some("[material]")
    } else if STRING_KEYS.contains(&key) {
        Some("[[experiment]] (it cannot be a default)")
    } else if quantity_of(EXPERIMENT, key).is_some() {
        Some("[defaults] or [[experiment]]")
    } else if crate::data::uncertainty::source(key).is_some() {
        Some("[uncertainty] (or an experiment's `uncertainty` table)")
    } else {
        None
    }
}

/// For a key made of a known stem and an unknown unit (`mass_flow_lb_h`), the accepted units.
fn unit_hint(key: &str) -> Option<String> {
    MATERIAL
        .iter()
        .chain(EXPERIMENT)
        .filter(|q| key.len() > q.stem.len() + 1)
        .find(|q| {
            key.get(..q.stem.len() + 1)
                .is_some_and(|head| head.eq_ignore_ascii_case(&format!("{}_", q.stem)))
        })
        .map(|q| {
            format!(
                "; `{}` is given in one of these units: {}",
                q.stem,
                q.spellings()
            )
        })
}

pub(in crate::data::input) fn key_hint(key: &str, allowed: &[&str]) -> String {
    if let Some(home) = home_of(key) {
        return format!("; this key belongs in {home}");
    }
    let lower = key.to_lowercase();
    if let Some(exact) = allowed.iter().find(|a| a.to_lowercase() == lower) {
        return format!("; did you mean `{exact}`? (keys are case-sensitive)");
    }
    if let Some(candidate) = closest(key, allowed) {
        return format!("; did you mean `{candidate}`?");
    }
    if let Some(hint) = unit_hint(key) {
        return hint;
    }
    format!("; expected one of: {}", allowed.join(", "))
}

/// The element of `allowed` closest to `key` (case-insensitive edit distance), if close enough
/// to be a probable typo.
pub(in crate::data::input) fn closest<'a>(key: &str, allowed: &[&'a str]) -> Option<&'a str> {
    let lower = key.to_lowercase();
    allowed
        .iter()
        .map(|a| (levenshtein(&lower, &a.to_lowercase()), *a))
        .min()
        .filter(|(d, _)| *d <= (key.len() / 3).max(2))
        .map(|(_, a)| a)
}

fn levenshtein(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let substitution = diagonal + usize::from(ca != cb);
            diagonal = row[j + 1];
            row[j + 1] = substitution.min(row[j] + 1).min(row[j + 1] + 1);
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levenshtein_distances() {
        assert_eq!(levenshtein("kitten", "sitting"), 3);
        assert_eq!(levenshtein("", "abc"), 3);
        assert_eq!(levenshtein("vft_b_k", "vft_b_k"), 0);
    }

    #[test]
    fn units_convert_to_si() {
        let g_min = MASS_FLOW_Q.unit_of("mass_flow_g_min").unwrap();
        assert_eq!(g_min.to_si(60.0), 1e-3);
        let c = INLET_TEMPERATURE.unit_of("inlet_temperature_C").unwrap();
        assert_eq!(c.to_si(240.0), 513.15);
        assert_eq!(c.of_si(513.15), 240.0);
        assert_eq!(INLET_DIAMETER.si_key(), "inlet_diameter_m");
        assert_eq!(MATERIAL[7].si_key(), "trouton_ratio");
        let hint = key_hint("mass_flow_pounds_per_hour", &["mass_flow_kg_s"]);
        assert!(hint.contains("`mass_flow_g_min` (g/min)"), "{hint}");
        let hint = key_hint("Inlet_Diameter_m", &["inlet_diameter_m"]);
        assert!(hint.contains("case-sensitive"), "{hint}");
    }
}
