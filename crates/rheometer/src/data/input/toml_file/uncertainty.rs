//! Reading the `[uncertainty]` tables: the data set's (top level) and an experiment's own
//! (`[experiment.uncertainty]` after its `[[experiment]]` header, or an inline
//! `uncertainty = { ... }`), declaring standard uncertainties of the sources of
//! [`SOURCES`](crate::data::uncertainty::SOURCES).
//!
//! Every value must be a finite positive number at most the source's plausible maximum; an
//! unknown key is an error naming file, line, table and key, with a suggestion (the source key
//! of a quantity given with its measurement unit, e.g. `mass_flow_kg_s` → `mass_flow_rel`).

use super::schema::{closest, Rule};
use super::spanned::Tab;
use crate::data::input::error::InputError;
use crate::data::uncertainty::{implausible, source, source_keys};

/// Smallest plausible standard uncertainty of a key in micrometres (`gauge_offset_um`) \[µm\]:
/// 1 nm; a smaller value is probably in metres.
const MIN_MICROMETRES: f64 = 1e-3;

/// The hint for an unknown key of an `[uncertainty]` table.
fn hint(key: &str) -> String {
    let keys = source_keys();
    // the same quantity with another unit suffix (`mass_flow_kg_s`, `inlet_temperature_C`)
    let stem = |k: &str| {
        k.rsplit_once('_')
            .map_or(k.to_lowercase(), |(a, _)| a.to_lowercase())
    };
    let same = keys
        .iter()
        .find(|k| stem(k) == stem(key) || stem(k) == key.to_lowercase());
    match same.copied().or_else(|| closest(key, &keys)) {
        Some(k) => {
            let s = source(k).map_or("", |s| s.unit);
            let unit = if s == "-" {
                "a relative standard uncertainty: 0.02 means 2 %".to_string()
            } else {
                format!("a standard uncertainty in {s}")
            };
            format!("; did you mean `{k}` ({unit})?")
        }
        None => format!("; expected one of: {}", keys.join(", ")),
    }
}

/// The declarations of one `[uncertainty]` table, in file order.
pub(in crate::data::input) fn uncertainty_table(
    tab: &Tab<'_>,
) -> Result<Vec<(&'static str, f64)>, InputError> {
    let keys = source_keys();
    tab.check_keys_hinted(&keys, hint)?;
    let mut out = Vec::new();
    for key in keys {
        let Some(field) = tab.get(key) else { continue };
        // `Finite`, not `Positive`: the plausible ranges of the experiment keys of the same name
        // (`inlet_temperature_K`) are for the quantity, not for its uncertainty
        let value = field.number(Rule::Finite)?;
        let Some(s) = source(key) else { continue };
        if value <= 0.0 {
            return Err(field.invalid(value, "must be positive (a standard uncertainty)"));
        }
        if value > s.max {
            return Err(field.invalid(value, implausible(s)));
        }
        if s.unit == "µm" && value < MIN_MICROMETRES {
            return Err(field.invalid(
                value,
                format!(
                    "implausibly small for a standard uncertainty in micrometres (below \
                     {MIN_MICROMETRES} µm = 1 nm, which no gauge resolves): was it given in \
                     metres? then write `{key} = {}`",
                    crate::data::input::error::sig(value * 1e6)
                ),
            ));
        }
        out.push((s.key, value));
    }
    Ok(out)
}
