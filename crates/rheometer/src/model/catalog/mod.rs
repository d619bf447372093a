//! The effects' catalog: **one descriptor per effect** ([`EffectDescriptor`]), the one place
//! that says what an effect is — its name, unit and symbol, its words, category, neutral value,
//! search and physical ranges, shapes, how its strength maps to the model parameter, how many
//! parameters a refit adds, the independent check that tells it apart from a cause with the same
//! signature, the error-budget source it represents, and how it enters the model. Every consumer
//! reads the descriptor: the model ([`Physics`](crate::model::Physics) names its modifiers'
//! strengths and shapes after the descriptors), the fit's parameter layout, `diagnose` (scan,
//! judge, rank, ties, detection limits), the error budget and the reports.
//!
//! Data only: this module imports nothing of the model, so that the physics below and the
//! effects above both read it. The built-in effects live in one file per family
//! (`physics`, `process`, `instrument`, `material`) and in one table, `BUILTIN`; a
//! user-written candidate is a descriptor ([`EffectDescriptor::user`]) and a
//! [`FiberTerm`](crate::model::FiberTerm), joined by
//! [`Effect::user`](crate::model::Effect::user).
//!
//! | name | strength (unit) | enters as | shape parameters (unit, default, bounds) | category | physical range | search range | budget source |
//! |---|---|---|---|---|---|---|---|
//! | `strain_thinning` | `1 − n` (-) | Carreau-type law with power index `n = 1 − s` (a refit frees `n` and `κ`) | – | physics | [0, 1] | [0, 1] | – |
//! | `radiation` | emissivity `ε` (-) | heat loss `π d ε σ (T⁴ − T_air⁴)` | – | physics | [0, 1] | [-0.5, 2] | – |
//! | `air_coflow` | amplitude `V` (m/s) | air speed `v_air = V (1 + r (L − s)/ℓ)^(−1/r)` (aspirator near the take-up; `r = 0`: `V exp(−(L − s)/ℓ)`) | `decay_length` ℓ (m, 0.1, [0.01, min(1.5, 1.5 L)]), `tail` r (-, 0, [0, 1]; not fitted: `diagnose` scans 0 and 0.5) | physics | [-50, 400] | [-100, 600] | – |
//! | `air_coflow_line` | speed `V` (m/s) | air speed `v_air = V / (1 + exp(−(s − s₀)/w))` (co-flow along the line after `s₀`) | `onset` s₀ (m, 0.2, [0, L]), `ramp_width` w (m, 0.02, [0.002, min(0.5, L)]) | physics | [-50, 400] | [-100, 600] | – |
//! | `air_temperature_profile` | excess `ΔT` (K) | `T_air(s) = T_air + ΔT exp(−s/ℓ)` | `decay_length` ℓ (m, 0.05, [0.005, min(1, L)]) | physics | [-50, 400] | [-60, 600] | – |
//! | `nusselt_scale` | `s` (-) | Nusselt law `𝒩 → (1 + s) 𝒩` | – | physics | [-0.5, 1] | [-0.9, 3] | – |
//! | `inlet_diameter` | die swell `δ` (-) | inlet diameter `(1 + δ) d_in` at the same mass flow: `u(0) = u_in/(1 + δ)²` | – | process | [-0.1, 0.6] | [-0.3, 1] | `inlet_diameter_rel` |
//! | `inlet_velocity` | relative error `δ` (-) | `u(0) = (1 + δ) u_in` (same physics as `inlet_diameter`; not a default candidate) | – | process | [-0.6, 0.25] | [-0.7, 1] | `inlet_velocity_rel` |
//! | `die_temperature_offset` | `ΔT` (K) | `T(0) = T_in + ΔT` (and the melt density there) | – | process | [-30, 30] | [-60, 60] | `inlet_temperature_K` |
//! | `mass_flow_scale` | `δ` (-) | true mass flow `(1 + δ) Q` | – | process | [-0.2, 0.2] | [-0.5, 0.5] | `mass_flow_rel` |
//! | `gauge_scale` | `g` (-) | measured diameter `(1 + g) d + o` | – | instrument | [-0.1, 0.1] | [-0.3, 0.3] | `gauge_scale_rel` |
//! | `gauge_offset` | `o` (µm) | measured diameter `(1 + g) d + o` | – | instrument | [-20, 20] | [-50, 50] | `gauge_offset_um` |
//! | `vft_b_offset` | `ΔB` (K) | VFT `B + ΔB`, zero-rate viscosity at `T_o` held (not a default candidate) | – | material | [-400, 400] | [-1000, 1000] | `vft_B_K` |
//! | `vft_t_vf_offset` | `ΔT_VF` (K) | VFT `T_VF + ΔT_VF`, level at `T_o` held (not a default candidate) | – | material | [-30, 15] | [-60, 15] | `vft_T_VF_K` |
//!
//! Every strength is neutral at 0. Every effect but strain thinning carries an
//! [independent check](EffectDescriptor::independent_check) (calibrate the gauge on a wire,
//! photograph the die swell, weigh the extrudate, measure the melt temperature at the die, the
//! air speed or temperature next to the fiber, the fiber temperature with a pyrometer); the
//! error budget's sources are the descriptors' [`budget`](EffectDescriptor::budget) fields.
//!
//! **Adding a built-in effect**: its descriptor in its family's file and in `BUILTIN`, its
//! physics in one file of [`modifiers`](crate::model::modifiers) with its registry
//! line (the descriptor names its strength and shapes; a term instead for a force or heat flux), a
//! variant of [`Effect`](crate::model::Effect) returning the descriptor, and a row above
//! (a unit test checks the table against the descriptors). **Adding your own**: see
//! [`EffectDescriptor::user`].

pub(crate) mod descriptor;
pub(crate) mod instrument;
pub(crate) mod material;
pub(crate) mod physics;
pub(crate) mod process;

pub(crate) use descriptor::BudgetSource;
pub(crate) use descriptor::EffectId;
pub(crate) use descriptor::GaugeColumn;
pub(crate) use descriptor::Install;
pub use descriptor::{Category, EffectDescriptor, Scope, ShapeParameter};
pub(crate) use instrument::GAUGE_OFFSET;
pub(crate) use instrument::GAUGE_SCALE;
pub(crate) use material::VFT_B_OFFSET;
pub(crate) use material::VFT_T_VF_OFFSET;
pub(crate) use physics::AIR_COFLOW;
pub(crate) use physics::AIR_COFLOW_LINE;
pub(crate) use physics::AIR_TEMPERATURE_PROFILE;
pub(crate) use physics::COFLOW_DECAY;
pub(crate) use physics::COFLOW_LINE_ONSET;
pub(crate) use physics::COFLOW_LINE_RAMP;
pub(crate) use physics::NUSSELT_SCALE;
pub(crate) use physics::RADIATION;
pub(crate) use physics::STRAIN_THINNING;
pub use physics::STRAIN_THINNING_REFERENCE_KAPPA;
pub(crate) use physics::WARM_AIR_DECAY;
pub(crate) use process::DIE_TEMPERATURE_OFFSET;
pub(crate) use process::INLET_DIAMETER;
pub(crate) use process::INLET_VELOCITY;
pub(crate) use process::MASS_FLOW_SCALE;

/// Every built-in effect, in the canonical order of reports and of
/// [`Effect::all`](crate::model::Effect::all): physics, process, instrument, material.
pub(crate) const BUILTIN: [&EffectDescriptor; 14] = [
    &STRAIN_THINNING,
    &RADIATION,
    &AIR_COFLOW,
    &AIR_COFLOW_LINE,
    &AIR_TEMPERATURE_PROFILE,
    &NUSSELT_SCALE,
    &INLET_DIAMETER,
    &INLET_VELOCITY,
    &DIE_TEMPERATURE_OFFSET,
    &MASS_FLOW_SCALE,
    &GAUGE_SCALE,
    &GAUGE_OFFSET,
    &VFT_B_OFFSET,
    &VFT_T_VF_OFFSET,
];

/// Names of the descriptors in `table` (those that are default candidates if
/// `candidates_only`), in table order; `N` must be their number (checked at compile time).
const fn names<const N: usize>(
    table: &[&EffectDescriptor],
    candidates_only: bool,
) -> [&'static str; N] {
    let mut out = [""; N];
    let (mut i, mut k) = (0, 0);
    while i < table.len() {
        if !candidates_only || table[i].default_candidate {
            assert!(k < N, "more names than the array holds");
            out[k] = table[i].name;
            k += 1;
        }
        i += 1;
    }
    assert!(k == N, "fewer names than the array holds");
    out
}

/// Every built-in effect name (`BUILTIN` order).
pub const ALL_NAMES: [&str; 14] = names(&BUILTIN, false);

/// The names of the default candidates of `diagnose` (`BUILTIN` order).
pub const BUILTIN_NAMES: [&str; 11] = names(&BUILTIN, true);

/// The built-in descriptor named `name`.
pub fn builtin(name: &str) -> Option<&'static EffectDescriptor> {
    BUILTIN.iter().copied().find(|d| d.name == name)
}

#[cfg(test)]
mod tests {
    use super::descriptor::ShapeScan;
    use super::*;

    #[test]
    fn every_builtin_descriptor_is_consistent() {
        for d in BUILTIN {
            d.validate().unwrap();
            // a scanned shape has scan values and vice versa
            for s in d.shapes {
                assert_eq!(s.scanned, s.scan != ShapeScan::Default, "{}", s.model_param);
            }
            // every effect but the material law itself has an independent check
            assert_eq!(
                d.independent_check.is_some(),
                d.name != "strain_thinning",
                "{}",
                d.name
            );
            if let Some(b) = &d.budget {
                assert!(d.category != Category::Physics, "{}", d.name);
                assert!(b.default > 0.0 && b.default <= b.max, "{}", b.key);
            }
        }
        let mut names = ALL_NAMES.to_vec();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), ALL_NAMES.len(), "duplicate names");
        assert_eq!(builtin("radiation").map(|d| d.symbol), Some("ε"));
        assert!(builtin("nonsense").is_none());
    }

    /// The module documentation's table says what the descriptors say (name, unit, category,
    /// physical and search range, budget key), row by row.
    #[test]
    fn the_documented_table_is_the_descriptors() {
        let rows: Vec<Vec<String>> = include_str!("mod.rs")
            .lines()
            .filter_map(|l| l.strip_prefix("//! | `"))
            .map(|l| {
                format!("`{l}")
                    .split(" | ")
                    .map(|c| c.trim().trim_end_matches('|').trim().to_string())
                    .collect()
            })
            .collect();
        assert_eq!(rows.len(), BUILTIN.len());
        let range = |r: (f64, f64)| format!("[{}, {}]", r.0, r.1);
        for (row, d) in rows.iter().zip(BUILTIN) {
            assert_eq!(row[0], format!("`{}`", d.name));
            assert!(row[1].ends_with(&format!("({})", d.unit)), "{}", row[1]);
            assert_eq!(row[4], d.category.name(), "{}", d.name);
            assert_eq!(row[5], range(d.physical_range), "{}", d.name);
            assert_eq!(row[6], range(d.search_range), "{}", d.name);
            let key = d.budget.map_or("–".to_string(), |b| format!("`{}`", b.key));
            assert_eq!(row[7], key, "{}", d.name);
            for s in d.shapes {
                assert!(row[3].contains(&format!("`{}`", s.name)), "{}", d.name);
            }
        }
    }
}
