//! Declared standard uncertainties of process conditions, instrument and material data (the
//! `[uncertainty]` table of the experiment file), and the table of the sources (`SOURCES`):
//! each source is the [`budget`](crate::model::catalog::EffectDescriptor::budget) of the effect
//! whose strength represents it, in that effect's descriptor.
//!
//! The data cannot identify these quantities; the
//! [error budget](crate::fit::error_budget()) propagates their uncertainties through
//! the exact sensitivities into `(n, κ, K)` as a systematic uncertainty beside the statistical
//! one.
//!
//! | key | unit | default | scope | effect (strength per unit of the source) |
//! |---|---|---|---|---|
//! | `inlet_temperature_K` | K | 2 K | common | `die_temperature_offset` (1 K/K) |
//! | `mass_flow_rel` | - | 0.01 | per experiment | `mass_flow_scale` (1 per unit) |
//! | `inlet_diameter_rel` | - | 0.02 | common | `inlet_diameter` (1; experiments that give `d_in`) |
//! | `inlet_velocity_rel` | - | 0.04 | common | `inlet_velocity` (1) |
//! | `gauge_scale_rel` | - | 0.01 | common | `gauge_scale` (1), else the measurement model |
//! | `gauge_offset_um` | µm | 1 µm | common | `gauge_offset` (1 µm/µm), else the measurement model |
//! | `vft_B_K` | K | 30 K | common | `vft_b_offset` (1 K/K) |
//! | `vft_T_VF_K` | K | 3 K | common | `vft_t_vf_offset` (1 K/K) |
//!
//! **Defaults** (used for every source not declared; the report says which values are
//! defaults): 2 K for the melt temperature at the die (a thermocouple in the die wall reads the
//! wall, not the melt; a few K is the usual difference), 1 % for the mass flow (a gear pump's
//! throughput weighed over a few minutes), 2 % for the inlet diameter after die swell (read off
//! images of the swollen strand; a 2 % error in `d_in` is a 4 % error of the inlet velocity,
//! hence the 4 % default of `inlet_velocity_rel`), 1 % and 1 µm for the diameter gauge's scale
//! and offset (a laser micrometer calibrated against wire gauges), 30 K (≈ 1 %) for the VFT
//! parameter `B` and 3 K for `T_VF` (the scatter of VFT fits to shear rheometry over a
//! 50–100 K window).
//!
//! **Scope.** A *common* source has one error shared by all experiments (one die thermocouple,
//! one gauge, one die, one material): its contributions from the experiments add before
//! squaring. A *per-experiment* source has an independent error in each experiment (each run's
//! throughput is weighed on its own): its contributions add in squares. An experiment may
//! override the data set's value of any source (its own `uncertainty` sub-table); for a common
//! source the override scales that experiment's share of the one shared error.
//!
//! `inlet_diameter_rel` applies to the experiments that give `inlet_diameter_m`,
//! `inlet_velocity_rel` to those that give `inlet_velocity_m_s`.
//!
//! Where no effect of the name exists in the model library, the source's budget entry says
//! "not available"; the gauge's scale and offset have a fallback that needs no effect: the
//! derivative of the principled estimator's residual `(d/d_meas − 1)/σ` with respect to a gauge
//! reading `(1 + a) d + b` (exact, from the residual's definition).

use crate::model::catalog::{
    BudgetSource, EffectDescriptor, EffectId, DIE_TEMPERATURE_OFFSET, GAUGE_OFFSET, GAUGE_SCALE,
    INLET_DIAMETER, INLET_VELOCITY, MASS_FLOW_SCALE, VFT_B_OFFSET, VFT_T_VF_OFFSET,
};
use crate::model::setup::Experiment;

pub(crate) use crate::model::catalog::GaugeColumn;
pub(crate) use crate::model::catalog::Scope;

/// One source of systematic error: its key in `[uncertainty]`, its unit, its default and the
/// effect that represents it (the effect descriptor's [`budget`](EffectDescriptor::budget) with
/// the effect's name).
#[derive(Debug, Clone, Copy)]
pub struct Source {
    /// Key in the `[uncertainty]` table (the unit is in the name: `_K`, `_rel`, `_um`).
    pub key: &'static str,
    /// Unit of the declared standard uncertainty (`"K"`, `"-"` for relative, `"µm"`).
    pub unit: &'static str,
    /// What the source is, in words (for sentences: "per K of {what}").
    pub what: &'static str,
    /// The unit used in sentences and its size in the declared unit (`("%", 0.01)` for
    /// relative sources, `("K", 1)` for temperatures).
    pub word_unit: (&'static str, f64),
    /// Default standard uncertainty, in `unit` (see the module documentation).
    pub default: f64,
    /// Largest plausible standard uncertainty, in `unit` (a larger value is refused).
    pub max: f64,
    /// Common to all experiments or independent per experiment.
    pub scope: Scope,
    /// The effect (an [`Effect`](crate::model::Effect)) whose strength represents the
    /// source.
    pub effect: EffectId,
    /// Strength of the effect per unit of the source, for experiment `e` (`None`: the source
    /// does not apply to `e`).
    pub per_unit: fn(&Experiment) -> Option<f64>,
    /// A derivative that needs no effect, used when the effect does not exist.
    pub fallback: Option<GaugeColumn>,
    /// Where to add the missing effect, for the warning (what to measure or fit).
    pub remedy: &'static str,
}

impl Source {
    /// The source `budget` represented by the effect `effect`.
    pub const fn new(effect: EffectId, budget: &BudgetSource) -> Self {
        Source {
            key: budget.key,
            unit: budget.unit,
            what: budget.what,
            word_unit: budget.word_unit,
            default: budget.default,
            max: budget.max,
            scope: budget.scope,
            effect,
            per_unit: budget.per_unit,
            fallback: budget.fallback,
            remedy: budget.remedy,
        }
    }

    /// The source the effect described by `d` represents (`None` if it is not a budget source).
    pub const fn of(d: &EffectDescriptor) -> Option<Self> {
        match &d.budget {
            Some(b) => Some(Source::new(d.id(), b)),
            None => None,
        }
    }

    /// [`of`](Self::of) for a descriptor that is a budget source (a compile-time error for the
    /// built-in table otherwise).
    const fn builtin(d: &EffectDescriptor) -> Self {
        match Source::of(d) {
            Some(s) => s,
            None => panic!("not a budget source"),
        }
    }
}

/// The sources of systematic error of the built-in effects, in the order of the budget's
/// rows: the budget sources of their descriptors (see the module documentation). A new source
/// is a [`budget`](EffectDescriptor::budget) in its effect's descriptor and its row here (a
/// unit test checks that every built-in budget source has exactly one row).
pub(crate) const SOURCES: &[Source] = &[
    Source::builtin(&DIE_TEMPERATURE_OFFSET),
    Source::builtin(&MASS_FLOW_SCALE),
    Source::builtin(&INLET_DIAMETER),
    Source::builtin(&INLET_VELOCITY),
    Source::builtin(&GAUGE_SCALE),
    Source::builtin(&GAUGE_OFFSET),
    Source::builtin(&VFT_B_OFFSET),
    Source::builtin(&VFT_T_VF_OFFSET),
];

/// The keys of [`SOURCES`] (the allowed keys of an `[uncertainty]` table).
pub(crate) fn source_keys() -> Vec<&'static str> {
    SOURCES.iter().map(|s| s.key).collect()
}

/// The source with key `key`.
pub fn source(key: &str) -> Option<&'static Source> {
    SOURCES.iter().find(|s| s.key == key)
}

/// Declared standard uncertainties (in each source's unit): the data set's `[uncertainty]`
/// table and each experiment's overrides. Sources declared nowhere take their default.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Uncertainties {
    /// Declared at the data-set level: `(key, σ)`.
    pub set: Vec<(&'static str, f64)>,
    /// Per experiment (in the order of the experiments; may be empty): `(key, σ)` overriding
    /// the data set's value.
    pub experiments: Vec<Vec<(&'static str, f64)>>,
}

/// Where a standard uncertainty comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Origin {
    /// Declared in the experiment's own `uncertainty` table.
    Experiment,
    /// Declared in the data set's `[uncertainty]` table.
    Declared,
    /// The documented default.
    Default,
}

impl Uncertainties {
    /// No declarations: every source at its default.
    pub fn defaults() -> Self {
        Self::default()
    }

    /// Declares `sigma` (in the source's unit) at the data-set level; errors for an unknown
    /// key or an implausible value.
    pub fn with(mut self, key: &str, sigma: f64) -> Result<Self, String> {
        let s = check(key, sigma)?;
        self.set.retain(|(k, _)| *k != s.key);
        self.set.push((s.key, sigma));
        Ok(self)
    }

    /// The standard uncertainty of source `key` in experiment `k` and where it comes from.
    pub fn sigma(&self, key: &str, k: usize) -> Option<(f64, Origin)> {
        let s = source(key)?;
        let find = |v: &[(&'static str, f64)]| v.iter().find(|(x, _)| *x == s.key).map(|p| p.1);
        if let Some(v) = self.experiments.get(k).and_then(|e| find(e)) {
            return Some((v, Origin::Experiment));
        }
        Some(match find(&self.set) {
            Some(v) => (v, Origin::Declared),
            None => (s.default, Origin::Default),
        })
    }

    /// Whether anything is declared (data set or experiments).
    pub fn any_declared(&self) -> bool {
        !self.set.is_empty() || self.experiments.iter().any(|e| !e.is_empty())
    }
}

/// Checks a declared value: the key is a source, the value finite, positive and at most the
/// source's plausible maximum.
pub fn check(key: &str, sigma: f64) -> Result<&'static Source, String> {
    let s = source(key).ok_or_else(|| {
        format!(
            "unknown uncertainty source `{key}`; expected one of: {}",
            source_keys().join(", ")
        )
    })?;
    if !sigma.is_finite() || sigma <= 0.0 {
        return Err(format!(
            "`{key}` = {sigma}: a standard uncertainty must be positive and finite"
        ));
    }
    if sigma > s.max {
        return Err(format!("`{key}` = {sigma}: {}", implausible(s)));
    }
    Ok(s)
}

/// Why a value above the source's maximum is refused.
pub fn implausible(s: &Source) -> String {
    let rel = if s.unit == "-" {
        " (relative: 0.02 means 2 %)"
    } else {
        ""
    };
    format!(
        "implausibly large for a standard uncertainty of the {} (at most {} {}{rel}); check the \
         unit",
        s.what, s.max, s.unit
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sigma_prefers_experiment_then_set_then_default() {
        let mut u = Uncertainties::defaults()
            .with("mass_flow_rel", 0.03)
            .unwrap();
        u.experiments = vec![vec![], vec![("mass_flow_rel", 0.05)]];
        assert_eq!(u.sigma("mass_flow_rel", 0), Some((0.03, Origin::Declared)));
        assert_eq!(
            u.sigma("mass_flow_rel", 1),
            Some((0.05, Origin::Experiment))
        );
        assert_eq!(
            u.sigma("inlet_temperature_K", 1),
            Some((2.0, Origin::Default))
        );
        assert_eq!(u.sigma("nonsense", 0), None);
        assert!(u.any_declared() && !Uncertainties::defaults().any_declared());
    }

    #[test]
    fn check_refuses_bad_values() {
        assert!(check("inlet_temperature_K", 0.0).is_err());
        assert!(check("inlet_temperature_K", f64::NAN).is_err());
        assert!(check("inlet_temperature_K", 51.0)
            .unwrap_err()
            .contains("implausibly"));
        assert!(check("mass_flow_rel", 2.0).unwrap_err().contains("2 %"));
        assert!(check("mass_flow", 0.1)
            .unwrap_err()
            .contains("mass_flow_rel"));
        for s in SOURCES {
            assert!(s.default > 0.0 && s.default <= s.max, "{}", s.key);
        }
    }

    /// Every built-in budget source has exactly one row, and the keys are unique.
    #[test]
    fn sources_are_the_descriptors_budgets() {
        let mut from_descriptors: Vec<&str> = crate::model::catalog::BUILTIN
            .iter()
            .filter_map(|d| Source::of(d).map(|s| s.effect.name()))
            .collect();
        let mut rows: Vec<&str> = SOURCES.iter().map(|s| s.effect.name()).collect();
        from_descriptors.sort_unstable();
        rows.sort_unstable();
        assert_eq!(rows, from_descriptors);
        let mut keys = source_keys();
        keys.sort_unstable();
        keys.dedup();
        assert_eq!(keys.len(), SOURCES.len());
        assert_eq!(SOURCES[0].key, "inlet_temperature_K");
    }
}
