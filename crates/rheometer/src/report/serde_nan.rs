//! Reading numbers that JSON writes as `null` when they are `NaN` (no standard error, no valid
//! interval), so that a written report reads back.

use serde::{Deserialize, Deserializer};

/// `null` → `NaN`.
pub fn f64<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// `[null, null]` → `[NaN, NaN]`.
pub fn pair<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 2], D::Error> {
    let [a, b] = <[Option<f64>; 2]>::deserialize(d)?;
    Ok([a.unwrap_or(f64::NAN), b.unwrap_or(f64::NAN)])
}

/// `NaN`, the default of a number a report written before it existed lacks.
pub fn nan() -> f64 {
    f64::NAN
}
