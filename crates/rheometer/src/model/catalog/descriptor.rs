//! What an effect *is*: [`EffectDescriptor`] and the parts it is made of (its category, shape
//! parameters, how its strength maps to the model parameter, how it enters the model, and the
//! error-budget source it represents). Data only: nothing here evaluates the physics.

use crate::model::setup::Experiment;
use serde::{Deserialize, Serialize};
use std::fmt;

/// What kind of cause an effect is (JSON: `"physics"`, `"process"`, `"instrument"`,
/// `"material"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Category {
    /// Physics missing from the model (a term or an environment profile).
    Physics,
    /// A process condition (die temperature, mass flow, inlet diameter) off its nominal value.
    Process,
    /// The diameter gauge reads wrong (scale or offset).
    Instrument,
    /// Material data of the model (the VFT law of the zero-rate viscosity) off.
    Material,
}

impl Category {
    /// Lower-case name (`"physics"`, `"process"`, `"instrument"`, `"material"`).
    pub fn name(&self) -> &'static str {
        match self {
            Category::Physics => "physics",
            Category::Process => "process",
            Category::Instrument => "instrument",
            Category::Material => "material",
        }
    }
}

impl fmt::Display for Category {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Which values `diagnose`'s global search gives a shape parameter (each a variant of the
/// effect scanned on its own; the refinement then frees the fitted shapes again).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ShapeScan {
    /// Not scanned: held at its default.
    Default,
    /// A discrete choice among these values (the co-flow's tail: 0 and 0.5), in the shape's
    /// unit.
    Choices(&'static [f64]),
    /// These multiples of the default (decay lengths: 0.4, 1, 2.5).
    OfDefault(&'static [f64]),
    /// These fractions of the spin-line length (an onset at 30, 50 and 70 % of the line).
    OfLength(&'static [f64]),
}

impl ShapeScan {
    /// The values for a shape with default `default` on a line of length `length` \[m\]
    /// (unclamped; the caller clamps them to the shape's bounds).
    pub fn values(&self, default: f64, length: f64) -> Vec<f64> {
        match *self {
            ShapeScan::Default => vec![default],
            ShapeScan::Choices(v) => v.to_vec(),
            ShapeScan::OfDefault(f) => f.iter().map(|f| f * default).collect(),
            ShapeScan::OfLength(f) => f.iter().map(|f| f * length).collect(),
        }
    }
}

/// A shape parameter of an effect (decay length, onset position, ...): a model parameter named
/// [`model_param`](Self::model_param), in SI units.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ShapeParameter {
    /// Name in settings (`decay_length`, `onset`, `ramp_width`).
    pub name: &'static str,
    /// Name of the model parameter (`"<effect>.<name>"`, e.g. `"air_coflow.decay_length"`).
    pub model_param: &'static str,
    /// Unit (`"m"`).
    pub unit: &'static str,
    /// Default (start) value.
    pub default: f64,
    /// Bounds of the value in fits (before [`bounds_for_length`](Self::bounds_for_length)).
    pub bounds: (f64, f64),
    /// Upper bound at most this multiple of the spin-line length `L` (`None`: no such limit).
    pub max_per_length: Option<f64>,
    /// Whether it is fitted with the strength when not fixed (`false`: fixed at its default
    /// unless given).
    pub fitted_with_strength: bool,
    /// Whether `diagnose`'s global search scans it across its range as variants of the effect
    /// (`false`: the scan holds it at its default and only the refinement fits it; the same as
    /// [`scan`](Self::scan) not being `ShapeScan::Default`).
    pub scanned: bool,
    /// The values the global search gives it.
    #[serde(skip)]
    pub scan: ShapeScan,
    /// What it is, in words.
    pub describe: &'static str,
}

impl ShapeParameter {
    /// The bounds for a spin line of length `length` \[m\]: the upper bound limited to
    /// `max_per_length · L` (never below the lower bound).
    pub fn bounds_for_length(&self, length: f64) -> (f64, f64) {
        let (lo, hi) = self.bounds;
        match self.max_per_length {
            Some(f) if length.is_finite() && length > 0.0 => (lo, hi.min(f * length).max(lo)),
            _ => (lo, hi),
        }
    }
}

/// How an effect's strength `s` becomes its model parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StrengthMap {
    /// The parameter is the strength.
    Identity,
    /// The parameter is `1 − s` (strain thinning: the law's `n = 1 − s`).
    OneMinus,
    /// The parameter is `1 + s` (a scale factor: the Nusselt law's `(1 + s) 𝒩`).
    OnePlus,
}

impl StrengthMap {
    /// The model parameter for strength `s`.
    pub const fn param_value(self, s: f64) -> f64 {
        match self {
            StrengthMap::Identity => s,
            StrengthMap::OneMinus => 1.0 - s,
            StrengthMap::OnePlus => 1.0 + s,
        }
    }

    /// The strength for model parameter `p` (inverse of [`param_value`](Self::param_value)).
    pub const fn strength_of(self, p: f64) -> f64 {
        match self {
            StrengthMap::Identity => p,
            StrengthMap::OneMinus => 1.0 - p,
            StrengthMap::OnePlus => p - 1.0,
        }
    }

    /// `d(parameter)/d(strength)`: ±1.
    pub const fn param_per_strength(self) -> f64 {
        match self {
            StrengthMap::OneMinus => -1.0,
            _ => 1.0,
        }
    }

    /// The parameter in words (`"strength"`, `"1 - strength"`, `"1 + strength"`).
    pub const fn words(self) -> &'static str {
        match self {
            StrengthMap::Identity => "strength",
            StrengthMap::OneMinus => "1 - strength",
            StrengthMap::OnePlus => "1 + strength",
        }
    }
}

/// How an effect enters the model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Install {
    /// In the viscosity law, not in the physics: the strength sets the law's parameter
    /// ([`EffectDescriptor::model_param`], strain thinning's `n = 1 − s`), and a refit frees the
    /// law's other parameters with it. `reference` is the law's `(n, κ)` without the effect (a
    /// Newtonian model: `n = 1`, and the `κ` at which the effect's direction is taken, since at
    /// `n = 1` it has no effect of its own).
    Law {
        /// `(n, κ)` of the law without the effect \[-\].
        reference: [f64; 2],
    },
    /// A built-in part of [`Physics`](crate::model::Physics) carrying the strength named
    /// [`EffectDescriptor::model_param`] (a term such as radiation, the convection term's
    /// factor, an air profile, a process or instrument parameter), switched on at unit
    /// amplitude by [`Physics::enable`](crate::model::Physics::enable).
    Physics,
    /// The user's [`FiberTerm`](crate::model::FiberTerm) times the strength (carried by
    /// [`UserEffect`](crate::model::UserEffect)).
    UserTerm,
}

/// Whether a source's error is shared by all experiments or independent per experiment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Scope {
    /// One error shared by every experiment (contributions add before squaring).
    Common,
    /// An independent error per experiment (contributions add in squares).
    PerExperiment,
}

/// A derivative that needs no effect: the measurement model of the diameter gauge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GaugeColumn {
    /// The gauge reads `(1 + a) d`: `∂r/∂a = d_model/(σ d_meas)`.
    Scale,
    /// The gauge reads `d + b` (`b` in µm): `∂r/∂b = 10⁻⁶/(σ d_meas)` with `d_meas` in m.
    OffsetMicrometre,
}

/// The error-budget source an effect represents: a process condition, instrument property or
/// material datum the diameters cannot identify, with a declared or default standard
/// uncertainty (see [`uncertainty`](crate::data::uncertainty)).
#[derive(Debug, Clone, Copy)]
pub struct BudgetSource {
    /// Key in the `[uncertainty]` table (the unit is in the name: `_K`, `_rel`, `_um`).
    pub key: &'static str,
    /// Unit of the declared standard uncertainty (`"K"`, `"-"` for relative, `"µm"`).
    pub unit: &'static str,
    /// What the source is, in words (for sentences: "per K of {what}").
    pub what: &'static str,
    /// The unit used in sentences and its size in the declared unit (`("%", 0.01)` for
    /// relative sources, `("K", 1)` for temperatures).
    pub word_unit: (&'static str, f64),
    /// Default standard uncertainty, in `unit`.
    pub default: f64,
    /// Largest plausible standard uncertainty, in `unit` (a larger value is refused).
    pub max: f64,
    /// Common to all experiments or independent per experiment.
    pub scope: Scope,
    /// Strength of the effect per unit of the source, for experiment `e` (`None`: the source
    /// does not apply to `e`).
    pub per_unit: fn(&Experiment) -> Option<f64>,
    /// A derivative that needs no effect, used when the effect does not exist.
    pub fallback: Option<GaugeColumn>,
    /// What to measure or fit, for the budget's warning.
    pub remedy: &'static str,
}

/// `Some(1.0)`: one unit of strength per unit of the source, in every experiment.
pub fn one_per_unit(_: &Experiment) -> Option<f64> {
    Some(1.0)
}

/// One effect, described in one place: everything the model, the fit, the diagnosis (scan,
/// judge, ranking, ties, detection limits), the error budget and the reports need to know of
/// it. The built-in effects are the constants of `catalog` (see its table); a
/// user-written candidate is a descriptor made with [`EffectDescriptor::user`] plus a
/// [`FiberTerm`](crate::model::FiberTerm) ([`Effect::user`](crate::model::Effect::user)).
#[derive(Debug, Clone, Copy)]
pub struct EffectDescriptor {
    /// Canonical name (CLI, JSON, reports); also the name of its strength parameter unless the
    /// effect lives in the law.
    pub name: &'static str,
    /// Name of the model parameter that carries the strength (`"n"` for strain thinning, else
    /// the effect's name).
    pub model_param: &'static str,
    /// Unit of the strength (`"-"` dimensionless, `"K"`, `"m/s"`, `"µm"`, ...).
    pub unit: &'static str,
    /// Symbol of the strength in messages (`ε`, `V`, `ΔT`, ...).
    pub symbol: &'static str,
    /// What the strength is, in words.
    pub describe: &'static str,
    /// Physics, process, instrument or material.
    pub category: Category,
    /// Strength at which the effect is absent (in its unit).
    pub neutral: f64,
    /// Range of the strength in fits (in its unit): wider than the physical range, so that a
    /// best fit outside physics shows.
    pub search_range: (f64, f64),
    /// Range of the strength real spinning lines show (in its unit).
    pub physical_range: (f64, f64),
    /// Shape parameters (decay lengths, an onset), each a model parameter.
    pub shapes: &'static [ShapeParameter],
    /// How the strength becomes the model parameter.
    pub map: StrengthMap,
    /// Parameters a refit adds for the strength itself, before its free shapes (1; strain
    /// thinning 2: `n` and `κ`, which is undetermined in the model without it).
    pub fit_parameters: usize,
    /// A measurement outside these diameter data that tells this cause apart from another one
    /// with the same signature: calibrate the gauge, weigh the throughput, measure the air
    /// speed or temperature or the fiber temperature along the line (`None`: the material law
    /// itself, or a user effect without one; data at other conditions decide).
    pub independent_check: Option<&'static str>,
    /// The error-budget source it represents (`None`: not a budget source).
    pub budget: Option<BudgetSource>,
    /// How it enters the model.
    pub install: Install,
    /// Whether `diagnose` tries it by default (built-in effects only).
    pub default_candidate: bool,
}

/// The identity of an effect, handed out by its descriptor ([`EffectDescriptor::id`]): two
/// effects are the same effect exactly when their ids are equal (the catalog and
/// [`ModelSpec::validate`](crate::model::ModelSpec::validate) keep names unique). Compare
/// ids, not names; a name from input becomes an id where it is parsed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct EffectId(&'static str);

impl EffectId {
    /// The effect's canonical name (CLI, JSON, reports).
    pub const fn name(self) -> &'static str {
        self.0
    }
}

impl fmt::Display for EffectId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.0)
    }
}

impl EffectDescriptor {
    /// A user-written effect named `name`: the strength (neutral 0, dimensionless, search and
    /// physical range `(−10, 10)`) multiplies the user's term; missing physics; no shapes,
    /// check or budget source. Refine it with the `with_*` methods or struct-update syntax
    /// (all fields are public):
    ///
    /// ```
    /// use rheometer::model::{Category, EffectDescriptor};
    /// const GUIDE_DRAG: EffectDescriptor = EffectDescriptor::user("guide_drag")
    ///     .with_unit("mN", "F")
    ///     .with_description("friction of a thread guide at s = 0.2 m, strength = its force")
    ///     .with_category(Category::Process)
    ///     .with_ranges((-2.0, 10.0), (0.0, 5.0))
    ///     .with_independent_check("measure the tension above and below the guide");
    /// assert!(GUIDE_DRAG.validate().is_ok());
    /// ```
    pub const fn user(name: &'static str) -> Self {
        EffectDescriptor {
            name,
            model_param: name,
            unit: "-",
            symbol: "factor",
            describe: "user-written contribution, strength = its factor",
            category: Category::Physics,
            neutral: 0.0,
            search_range: (-10.0, 10.0),
            physical_range: (-10.0, 10.0),
            shapes: &[],
            map: StrengthMap::Identity,
            fit_parameters: 1,
            independent_check: None,
            budget: None,
            install: Install::UserTerm,
            default_candidate: false,
        }
    }

    /// The fields the built-in effects share (a default candidate, a part of
    /// [`Physics`](crate::model::Physics), strength = parameter, neutral 0, no shapes, no
    /// independent check or budget source); each built-in constant overrides the rest.
    pub(crate) const fn builtin(name: &'static str, category: Category) -> Self {
        EffectDescriptor {
            name,
            model_param: name,
            unit: "-",
            symbol: "",
            describe: "",
            category,
            neutral: 0.0,
            search_range: (0.0, 0.0),
            physical_range: (0.0, 0.0),
            shapes: &[],
            map: StrengthMap::Identity,
            fit_parameters: 1,
            independent_check: None,
            budget: None,
            install: Install::Physics,
            default_candidate: true,
        }
    }

    /// Its identity.
    pub const fn id(&self) -> EffectId {
        EffectId(self.name)
    }

    /// With the strength's unit and its symbol in messages.
    pub const fn with_unit(mut self, unit: &'static str, symbol: &'static str) -> Self {
        self.unit = unit;
        self.symbol = symbol;
        self
    }

    /// With what the strength is, in words.
    pub const fn with_description(mut self, describe: &'static str) -> Self {
        self.describe = describe;
        self
    }

    /// With its category.
    pub const fn with_category(mut self, category: Category) -> Self {
        self.category = category;
        self
    }

    /// With its search range and physical range (in the strength's unit).
    pub const fn with_ranges(mut self, search: (f64, f64), physical: (f64, f64)) -> Self {
        self.search_range = search;
        self.physical_range = physical;
        self
    }

    /// With the measurement that tells it apart from a cause of the same signature.
    pub const fn with_independent_check(mut self, check: &'static str) -> Self {
        self.independent_check = Some(check);
        self
    }

    /// With the error-budget source it represents (its declared uncertainty is the source's
    /// default: the `[uncertainty]` table of an experiment file knows only the built-in keys).
    pub const fn with_budget(mut self, budget: BudgetSource) -> Self {
        self.budget = Some(budget);
        self
    }

    /// The model parameter for strength `s` (`StrengthMap::param_value`).
    pub const fn param_value(&self, s: f64) -> f64 {
        self.map.param_value(s)
    }

    /// The strength for model parameter `p`.
    pub const fn strength_of(&self, p: f64) -> f64 {
        self.map.strength_of(p)
    }

    /// Whether the effect lives in the viscosity law (`Install::Law`).
    pub const fn installs_in_law(&self) -> bool {
        matches!(self.install, Install::Law { .. })
    }

    /// Checks that the descriptor is consistent: a name (no `.`, which separates shape
    /// parameters), finite ranges with the neutral value inside the physical range inside the
    /// search range, shapes named after the effect with their defaults inside their bounds, at
    /// least one fit parameter, a budget source with `0 < default <= max`; a user term has no
    /// shapes (its term cannot read them), carries its strength under its own name and
    /// vanishes at the neutral strength. Errors name the effect and the field.
    pub fn validate(&self) -> Result<(), String> {
        let n = self.name;
        let bad = |what: String| Err(format!("effect \"{n}\": {what}"));
        if n.is_empty() || n.contains('.') || n.contains(char::is_whitespace) {
            return bad("a name must be non-empty, without '.' or spaces".into());
        }
        let (slo, shi) = self.search_range;
        let (plo, phi) = self.physical_range;
        let finite = [slo, shi, plo, phi, self.neutral]
            .iter()
            .all(|v| v.is_finite());
        if !(finite && slo <= plo && plo <= phi && phi <= shi) {
            return bad(format!(
                "the physical range [{plo}, {phi}] must lie inside the search range [{slo}, \
                 {shi}] (finite)"
            ));
        }
        if !(plo..=phi).contains(&self.neutral) {
            return bad(format!(
                "the neutral strength {} lies outside the physical range [{plo}, {phi}]",
                self.neutral
            ));
        }
        if self.fit_parameters == 0 {
            return bad("a refit adds at least one parameter (fit_parameters >= 1)".into());
        }
        for s in self.shapes {
            let prefix = s.model_param.strip_suffix(s.name);
            if prefix != Some(&format!("{n}.")[..]) {
                return bad(format!(
                    "shape \"{}\" must be the model parameter \"{n}.{}\"",
                    s.name, s.name
                ));
            }
            if !(s.bounds.0 <= s.default && s.default <= s.bounds.1) {
                return bad(format!(
                    "shape {}: default {} outside its bounds",
                    s.name, s.default
                ));
            }
        }
        if let Some(b) = &self.budget {
            if !(b.default > 0.0 && b.default <= b.max) {
                return bad(format!(
                    "budget source {}: need 0 < default ({}) <= max ({})",
                    b.key, b.default, b.max
                ));
            }
        }
        if let Install::UserTerm = self.install {
            if !self.shapes.is_empty() {
                return bad("a user term has no shape parameters (fix them in the term)".into());
            }
            if self.model_param != n {
                return bad(format!(
                    "a user term's strength is the parameter \"{n}\", not \"{}\"",
                    self.model_param
                ));
            }
            if self.param_value(self.neutral) != 0.0 {
                return bad(format!(
                    "the term's factor {} = {} at the neutral strength {} must be 0 (the \
                     effect absent)",
                    self.map.words(),
                    self.param_value(self.neutral),
                    self.neutral
                ));
            }
        }
        Ok(())
    }
}
