//! Simulated profiles as CSV: the columns of the profile files `simulate` and `fit` write.
//!
//! The files themselves go through the output layer [`crate::report::output_files`]: every
//! output planned and checked against the inputs before the work, regular files written
//! through a temporary renamed into place, special files in place.

use crate::model::simulate::Profiles;
use std::io::Write;

/// CSV header of simulated profiles.
pub(crate) const PROFILE_HEADER: &str =
    "position_m,velocity_m_s,force_N,temperature_K,strain_rate_1_s,diameter_m";

/// The column [`write_profiles_csv`] adds after [`PROFILE_HEADER`]'s for a model with gauge
/// effects: what the gauge reads ([`Profiles::gauge_reading`]).
pub(crate) const GAUGE_READING_COLUMN: &str = "gauge_reading_m";

/// Writes profiles as CSV with `PROFILE_HEADER` to `w`, row by row (no string of the whole
/// table is built); with gauge effects a last column `GAUGE_READING_COLUMN`.
pub fn write_profiles_csv(w: &mut dyn Write, p: &Profiles) -> std::io::Result<()> {
    match &p.gauge_reading {
        Some(_) => writeln!(w, "{PROFILE_HEADER},{GAUGE_READING_COLUMN}")?,
        None => writeln!(w, "{PROFILE_HEADER}")?,
    }
    for i in 0..p.position.len() {
        write!(
            w,
            "{:.6e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e}",
            p.position[i],
            p.velocity[i],
            p.force[i],
            p.temperature[i],
            p.strain_rate[i],
            p.diameter[i]
        )?;
        match &p.gauge_reading {
            Some(g) => writeln!(w, ",{:.10e}", g[i])?,
            None => writeln!(w)?,
        }
    }
    Ok(())
}
