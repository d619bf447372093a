//! The keys of the experiment file's tables and the rules their values obey: required types
//! and signs, plausible ranges, and hints for misspelt or misplaced keys.

/// Largest plausible fiber diameter \[m\]; larger values suggest the file is in millimetres.
pub const MAX_PLAUSIBLE_DIAMETER_M: f64 = 0.02;

/// Smallest plausible fiber diameter \[m\] (1 µm); smaller values are probably a unit error.
pub const MIN_PLAUSIBLE_DIAMETER_M: f64 = 1e-6;

/// Plausible ranges `(key, min, max)` of the per-experiment quantities of melt spinning (SI, the
/// unit is in the key); a value outside is rejected as a probable unit or typing error. The
/// diameters have their own bounds ([`MIN_PLAUSIBLE_DIAMETER_M`], [`MAX_PLAUSIBLE_DIAMETER_M`]).
pub const PLAUSIBLE_RANGES: &[(&str, f64, f64)] = &[
    ("mass_flow_kg_s", 1e-10, 1.0),
    ("inlet_velocity_m_s", 1e-6, 1e3),
    ("take_up_velocity_m_s", 1e-6, 1e3),
    ("spinline_length_m", 1e-3, 100.0),
    ("inlet_temperature_K", 100.0, 1500.0),
    ("air_temperature_K", 100.0, 1500.0),
];

/// What a numeric key must satisfy.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Rule {
    Finite,
    Positive,
    NonNegative,
    /// Positive and at most [`MAX_PLAUSIBLE_DIAMETER_M`].
    Diameter,
    /// In (0, 1): a relative uncertainty.
    Fraction,
}

pub(super) const TOP_KEYS: &[&str] = &[
    "relative_uncertainty",
    "uncertainty",
    "material",
    "defaults",
    "experiment",
];

/// Sub-table keys of an `[[experiment]]` table (its own `uncertainty` overrides).
pub(super) const EXPERIMENT_TABLES: &[&str] = &["uncertainty"];

pub(super) const MATERIAL_NUMBERS: &[(&str, Rule)] = &[
    ("density_slope_kg_m3_K", Rule::Finite),
    ("density_intercept_kg_m3", Rule::Positive),
    ("heat_capacity_slope_J_kg_K2", Rule::Finite),
    ("heat_capacity_intercept_J_kg_K", Rule::Finite),
    ("vft_mu_c_Pa_s", Rule::Positive),
    ("vft_B_K", Rule::Positive),
    ("vft_T_VF_K", Rule::NonNegative),
    ("trouton_ratio", Rule::Positive),
    ("air_density_kg_m3", Rule::Positive),
    ("air_heat_capacity_J_kg_K", Rule::Positive),
    ("air_kinematic_viscosity_m2_s", Rule::Positive),
    ("air_heat_conductivity_W_m_K", Rule::Positive),
];

pub(super) const EXPERIMENT_NUMBERS: &[(&str, Rule)] = &[
    ("mass_flow_kg_s", Rule::Positive),
    ("inlet_diameter_m", Rule::Diameter),
    ("inlet_velocity_m_s", Rule::Positive),
    ("take_up_diameter_m", Rule::Diameter),
    ("take_up_velocity_m_s", Rule::Positive),
    ("spinline_length_m", Rule::Positive),
    ("inlet_temperature_K", Rule::Positive),
    ("air_temperature_K", Rule::Positive),
    ("stencil_velocity_mm_s", Rule::Positive),
    ("take_up_pressure_bar", Rule::Finite),
];

/// String-valued keys of an `[[experiment]]` table (not allowed in `[defaults]`).
pub(super) const STRING_KEYS: &[&str] = &["name", "data"];

pub(super) fn names(rules: &[(&'static str, Rule)]) -> Vec<&'static str> {
    rules.iter().map(|(k, _)| *k).collect()
}

pub(super) fn rule_of(rules: &[(&str, Rule)], key: &str) -> Option<Rule> {
    rules.iter().find(|(k, _)| *k == key).map(|(_, r)| *r)
}

/// Where a key belongs, for hints on keys given in the wrong table.
fn home_of(key: &str) -> Option<&'static str> {
    if key == "relative_uncertainty" {
        Some("the top level (before the first [table] header)")
    } else if key == "uncertainty" {
        Some("the top level ([uncertainty]) or an [[experiment]] (its own `uncertainty` table)")
    } else if rule_of(MATERIAL_NUMBERS, key).is_some() {
        Some("[material]")
    } else if STRING_KEYS.contains(&key) {
        Some("[[experiment]] (it cannot be a default)")
    } else if rule_of(EXPERIMENT_NUMBERS, key).is_some() {
        Some("[defaults] or [[experiment]]")
    } else if crate::fiber::uncertainty::source(key).is_some() {
        Some("[uncertainty] (or an experiment's `uncertainty` table)")
    } else {
        None
    }
}

pub(super) fn key_hint(key: &str, allowed: &[&str]) -> String {
    if let Some(home) = home_of(key) {
        return format!("; this key belongs in {home}");
    }
    let lower = key.to_lowercase();
    let best = allowed
        .iter()
        .map(|a| (levenshtein(&lower, &a.to_lowercase()), *a))
        .min();
    match best {
        Some((d, candidate)) if d <= (key.len() / 3).max(2) => {
            format!("; did you mean `{candidate}`?")
        }
        _ => format!("; expected one of: {}", allowed.join(", ")),
    }
}

/// The element of `allowed` closest to `key` (case-insensitive edit distance), if close enough
/// to be a probable typo.
pub(super) fn closest<'a>(key: &str, allowed: &[&'a str]) -> Option<&'a str> {
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

/// The unit of a key, from its suffix (`mass_flow_kg_s` → `kg/s`).
pub(super) fn unit_of(key: &str) -> &'static str {
    [("_kg_s", "kg/s"), ("_m_s", "m/s"), ("_m", "m"), ("_K", "K")]
        .iter()
        .find(|(suffix, _)| key.ends_with(suffix))
        .map_or("", |(_, unit)| *unit)
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
}
