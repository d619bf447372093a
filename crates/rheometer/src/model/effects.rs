//! Candidate effects: named contributions a user's model may lack, each with a **strength
//! parameter** whose neutral value 0 switches it off exactly and which is a model parameter of
//! the [`FiberModel`](crate::model::FiberModel) (so derivatives with respect to it are exact,
//! through the dual numbers). Some have **shape parameters** (decay lengths, an onset position),
//! model parameters too, fitted together with the strength unless fixed.
//!
//! What each effect is — name, unit, category, neutral value, search and physical range,
//! shapes, how the strength maps to the model parameter, remedy, error-budget source, how it
//! enters the model — is its **descriptor** ([`EffectDescriptor`]), one per effect, in
//! [`crate::model::catalog`] (the table of the built-in effects is there). An
//! [`Effect`] is a descriptor plus the settings of one use (its fixed shape values; for a
//! user-written effect, its term): every method below reads the descriptor.
//!
//! Each effect has a [`Category`]: missing **physics**, a **process** condition that differs
//! from the nominal one, an **instrument** (diameter gauge) error, or **material** data (the VFT
//! law) off. Each has a *physical range* ([`Effect::physical_range`], what real spinning lines
//! do) and a wider *search range* ([`Effect::bounds`]) so that a best fit outside physics can be
//! seen and reported ([`Effect::judge`]).
//!
//! **Sign conventions.** `die_temperature_offset = +10 K` means the melt leaves the die 10 K
//! *hotter* than the nominal inlet temperature of the experiment file. `gauge_scale = 0.03`
//! means the gauge reads 3% high. `mass_flow_scale = 0.05`: the true mass flow is 5% above the
//! nominal one. A positive co-flow speed blows along the spinning direction (towards the
//! take-up); the air may be faster than the fiber: the drag then pulls the fiber forward and the
//! Nusselt law uses the magnitude of the relative speed.
//!
//! **Process conditions.** `die_temperature_offset`, `mass_flow_scale` and `inlet_diameter` are
//! exactly the model of the experiment file with the inlet temperature, mass flow or inlet
//! diameter changed (the inlet velocity follows from `4 Q/(π ρ(T(0)) d²)` when the file gives the
//! inlet diameter; with an inlet velocity in the file, the mass flow and temperature change the
//! diameter instead). **Instrument** effects do not enter the boundary-value problem, only the
//! predicted measurement.
//!
//! **Effects in the law.** The user's Newtonian model is the Carreau-type law at `n = 1` (where
//! `κ` has no effect). Strain thinning lives in the law (`Install::Law`): its strength is
//! `s = 1 − n`, the linearised score takes its direction at the descriptor's reference `κ`
//! ([`STRAIN_THINNING_REFERENCE_KAPPA`]), and a refit frees both `n` and `κ`
//! ([`EffectDescriptor::fit_parameters`] = 2 in the information criterion).
//!
//! **Settings on the command line** ([`EffectSetting`]): `name` (strength fitted, shapes fitted
//! with it), `name=value` (strength fixed, shapes fixed at their defaults) and, after a colon,
//! shape parameters fixed at a value: `air_coflow:decay_length=0.2` (strength fitted, ℓ fixed),
//! `air_coflow=40:decay_length=0.2` (both fixed), `air_coflow_line:onset=0.3:ramp_width=0.05`.
//! A shape parameter `name.shape` is a model parameter, e.g. `air_coflow.decay_length` \[m\].
//!
//! **The co-flow's tail.** Air drawn towards an aspirator slows with the distance `z = L − s`
//! from it algebraically, not exponentially (as the flow towards a sink, `∝ z⁻²`, or along a
//! jet, `∝ z⁻¹`), and a slow co-flow far upstream still pulls on the slow fiber there. The tail
//! `r` spans these: `(1 + r z/ℓ)^(−1/r)` decays like `z^(−1/r)` far away and is the exponential at
//! `r = 0`. It is a discrete choice of `diagnose` (both 0 and 0.5 are scanned and the better
//! variant refined with `r` held), not a fitted parameter; `fit --with air_coflow:tail=0.5`
//! fixes it.
//!
//! **Your own effect** is one descriptor and one term ([`Effect::user`]): the term (a
//! [`FiberTerm`], SI force or heat per length) is multiplied by the strength, and the descriptor
//! gives it a name, unit, ranges, category and remedy; `diagnose` then scans, refits, ranks and
//! reports it like a built-in one.

use crate::error::FiberError;
use crate::model::catalog::{self, EffectId, Install};
use crate::model::contributions::{Balance, FiberTerm, Physics, Strength};
use std::fmt;
use std::str::FromStr;
use std::sync::Arc;

pub use crate::model::catalog::{
    Category, EffectDescriptor, ShapeParameter, ALL_NAMES, STRAIN_THINNING_REFERENCE_KAPPA,
};
#[cfg(test)]
use crate::model::catalog::{COFLOW_DECAY, WARM_AIR_DECAY};

/// A user-written effect: a [`FiberTerm`] (SI force or heat per length, written once generically
/// over dual numbers) multiplied by its own strength parameter, described by its
/// [`EffectDescriptor`] (default [`EffectDescriptor::user`]: dimensionless, neutral 0, search
/// and physical range `(−10, 10)`).
#[derive(Clone)]
pub struct UserEffect {
    descriptor: Arc<EffectDescriptor>,
    balance: Balance,
    add: Arc<dyn Fn(Physics) -> Physics + Send + Sync>,
}

impl UserEffect {
    /// The term `term` in `balance`, named `name` (its strength parameter has the same name),
    /// with the default descriptor [`EffectDescriptor::user`]`(name)`.
    pub fn new<T: FiberTerm + Clone + 'static>(
        name: &'static str,
        balance: Balance,
        term: T,
    ) -> Self {
        Self::described(EffectDescriptor::user(name), balance, term)
    }

    /// The term `term` in `balance` described by `descriptor` (its name names the term and the
    /// strength parameter; [`ModelSpec::validate`] checks the descriptor).
    pub fn described<T: FiberTerm + Clone + 'static>(
        descriptor: EffectDescriptor,
        balance: Balance,
        term: T,
    ) -> Self {
        let name = descriptor.name;
        UserEffect {
            descriptor: Arc::new(EffectDescriptor {
                install: Install::UserTerm,
                ..descriptor
            }),
            balance,
            add: Arc::new(move |p: Physics| p.with_custom(name, balance, term.clone())),
        }
    }

    /// Sets the bounds of the strength in fits (its search range; the physical range too).
    pub fn with_bounds(mut self, lower: f64, upper: f64) -> Self {
        let d = Arc::make_mut(&mut self.descriptor);
        d.search_range = (lower, upper);
        d.physical_range = (lower, upper);
        self
    }

    /// The balance the term enters.
    pub fn balance(&self) -> Balance {
        self.balance
    }

    /// Its descriptor.
    pub fn descriptor(&self) -> &EffectDescriptor {
        &self.descriptor
    }
}

impl fmt::Debug for UserEffect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "UserEffect({}, {:?})",
            self.descriptor.name, self.balance
        )
    }
}

/// A candidate effect: a built-in one (its descriptor in `crate::model::catalog`)
/// or a user-written one. Shape parameters are `Option<f64>`: `None` fits them with the
/// strength (or keeps the default where the shape is not fitted, see
/// [`ShapeParameter::fitted_with_strength`]), `Some(v)` fixes them at `v`.
#[derive(Debug, Clone)]
pub enum Effect {
    /// `strain_thinning`: Carreau-type law instead of Newtonian, strength `1 − n` \[-\].
    StrainThinning,
    /// `radiation`: grey-body radiation, strength = emissivity ε \[-\].
    Radiation,
    /// `air_coflow`: aspirator co-flow near the take-up, strength = amplitude `V` \[m/s\].
    AirCoflow {
        /// Decay length `ℓ` \[m\] fixed, or `None` (fitted, start `DEFAULT_COFLOW_DECAY_LENGTH`).
        decay_length: Option<f64>,
        /// Tail `r` \[-\] of the decay `(1 + r z/ℓ)^(−1/r)` fixed, or `None` (0, the
        /// exponential; not fitted: `diagnose` scans 0 and 0.5, the fit keeps the better).
        tail: Option<f64>,
    },
    /// `air_coflow_line`: co-flow along the line after an onset, strength = speed `V` \[m/s\].
    AirCoflowLine {
        /// Onset `s₀` \[m\] fixed, or `None` (fitted, start `DEFAULT_COFLOW_LINE_ONSET`).
        onset: Option<f64>,
        /// Ramp width `w` \[m\] fixed, or `None` (fitted, start `DEFAULT_COFLOW_LINE_RAMP_WIDTH`;
        /// `diagnose` scans the onset and fits the width only in its refinement).
        ramp_width: Option<f64>,
    },
    /// `air_temperature_profile`: warm air near the nozzle, strength = excess `ΔT` \[K\].
    AirTemperatureProfile {
        /// Decay length `ℓ` \[m\] fixed, or `None` (fitted, start
        /// `DEFAULT_WARM_AIR_DECAY_LENGTH`).
        decay_length: Option<f64>,
    },
    /// `nusselt_scale`: `𝒩 → (1 + s) 𝒩`, strength `s` \[-\].
    NusseltScale,
    /// `inlet_velocity`: relative inlet-velocity error δ \[-\], `u(0) = (1 + δ) u_in` (process).
    InletVelocity,
    /// `inlet_diameter`: die swell δ \[-\], inlet diameter `(1 + δ) d_in` at the same mass flow.
    InletDiameter,
    /// `die_temperature_offset`: `T(0) = T_in + ΔT`, strength ΔT \[K\].
    DieTemperatureOffset,
    /// `mass_flow_scale`: true mass flow `(1 + δ) Q`, strength δ \[-\].
    MassFlowScale,
    /// `gauge_scale`: the gauge reads `(1 + g) d + o`, strength `g` \[-\].
    GaugeScale,
    /// `gauge_offset`: the gauge reads `(1 + g) d + o`, strength `o` \[µm\].
    GaugeOffset,
    /// `vft_b_offset`: VFT parameter `B + ΔB`, the zero-rate viscosity at the reference
    /// temperature `T_o` held, strength ΔB \[K\] (material data; not a default candidate).
    VftBOffset,
    /// `vft_t_vf_offset`: VFT temperature `T_VF + ΔT_VF`, the level at `T_o` held, strength
    /// ΔT_VF \[K\] (material data; not a default candidate).
    VftTvfOffset,
    /// A user-written term with its own strength and descriptor.
    Custom(UserEffect),
}

impl Effect {
    /// Every built-in effect ([`ALL_NAMES`], the order of `catalog::BUILTIN`), shapes not
    /// fixed.
    pub fn all() -> Vec<Effect> {
        vec![
            Effect::StrainThinning,
            Effect::Radiation,
            Effect::AirCoflow {
                decay_length: None,
                tail: None,
            },
            Effect::AirCoflowLine {
                onset: None,
                ramp_width: None,
            },
            Effect::AirTemperatureProfile { decay_length: None },
            Effect::NusseltScale,
            Effect::InletDiameter,
            Effect::InletVelocity,
            Effect::DieTemperatureOffset,
            Effect::MassFlowScale,
            Effect::GaugeScale,
            Effect::GaugeOffset,
            Effect::VftBOffset,
            Effect::VftTvfOffset,
        ]
    }

    /// The built-in candidates of `diagnose` (shapes fitted): physics, then process conditions,
    /// then the instrument (`BUILTIN_NAMES`: the descriptors'
    /// [`default_candidate`](EffectDescriptor::default_candidate)).
    pub fn builtin() -> Vec<Effect> {
        Self::all()
            .into_iter()
            .filter(|e| e.descriptor().default_candidate)
            .collect()
    }

    /// A user-written effect with the default descriptor (see [`UserEffect::new`]).
    pub fn custom<T: FiberTerm + Clone + 'static>(
        name: &'static str,
        balance: Balance,
        term: T,
    ) -> Self {
        Effect::Custom(UserEffect::new(name, balance, term))
    }

    /// A user-written candidate: one descriptor (name, unit, ranges, category, remedy, ...) and
    /// one term, multiplied by the strength (see [`UserEffect::described`]).
    pub fn user<T: FiberTerm + Clone + 'static>(
        descriptor: EffectDescriptor,
        balance: Balance,
        term: T,
    ) -> Self {
        Effect::Custom(UserEffect::described(descriptor, balance, term))
    }

    /// What the effect is: its descriptor.
    pub fn descriptor(&self) -> &EffectDescriptor {
        match self {
            Effect::StrainThinning => &catalog::STRAIN_THINNING,
            Effect::Radiation => &catalog::RADIATION,
            Effect::AirCoflow { .. } => &catalog::AIR_COFLOW,
            Effect::AirCoflowLine { .. } => &catalog::AIR_COFLOW_LINE,
            Effect::AirTemperatureProfile { .. } => &catalog::AIR_TEMPERATURE_PROFILE,
            Effect::NusseltScale => &catalog::NUSSELT_SCALE,
            Effect::InletVelocity => &catalog::INLET_VELOCITY,
            Effect::InletDiameter => &catalog::INLET_DIAMETER,
            Effect::DieTemperatureOffset => &catalog::DIE_TEMPERATURE_OFFSET,
            Effect::MassFlowScale => &catalog::MASS_FLOW_SCALE,
            Effect::GaugeScale => &catalog::GAUGE_SCALE,
            Effect::GaugeOffset => &catalog::GAUGE_OFFSET,
            Effect::VftBOffset => &catalog::VFT_B_OFFSET,
            Effect::VftTvfOffset => &catalog::VFT_T_VF_OFFSET,
            Effect::Custom(u) => &u.descriptor,
        }
    }

    /// Its identity (compare effects by it, not by name).
    pub fn id(&self) -> EffectId {
        self.descriptor().id()
    }

    /// The effect among `effects` whose name is `name` (a name read from a record or the
    /// command line, parsed into the effect it names).
    pub fn find<'a>(effects: &'a [Effect], name: &str) -> Option<&'a Effect> {
        Self::position(effects, name).map(|i| &effects[i])
    }

    /// The index of the effect among `effects` whose name is `name` (see [`find`](Self::find)).
    pub fn position(effects: &[Effect], name: &str) -> Option<usize> {
        effects.iter().position(|e| e.id().name() == name)
    }

    /// Canonical name (CLI, JSON, docs).
    pub fn name(&self) -> &'static str {
        self.descriptor().name
    }

    /// Unit of the strength, for reports.
    pub fn unit(&self) -> &'static str {
        self.descriptor().unit
    }

    /// Symbol of the strength in messages (`ε`, `V`, `ΔT`, ...).
    pub fn symbol(&self) -> &'static str {
        self.descriptor().symbol
    }

    /// What the strength is, in words.
    pub fn describe(&self) -> &'static str {
        self.descriptor().describe
    }

    /// Physics missing, process condition off, instrument error, or material data off.
    pub fn category(&self) -> Category {
        self.descriptor().category
    }

    /// Neutral strength (the effect is absent): 0 for every built-in effect.
    pub fn neutral(&self) -> f64 {
        self.descriptor().neutral
    }

    /// Search range of the strength in fits (wider than the
    /// [`physical_range`](Self::physical_range), so that a best fit outside physics shows).
    pub fn bounds(&self) -> (f64, f64) {
        self.descriptor().search_range
    }

    /// Range of the strength that real spinning lines show (in the strength's unit).
    pub fn physical_range(&self) -> (f64, f64) {
        self.descriptor().physical_range
    }

    /// A measurement outside the diameter data that tells this cause apart from another one
    /// with the same signature (`None` for strain thinning and user effects without one).
    pub fn independent_check(&self) -> Option<&'static str> {
        self.descriptor().independent_check
    }

    /// Whether the effect lives in the viscosity law (strain thinning), not in the physics.
    pub fn installs_in_law(&self) -> bool {
        self.descriptor().installs_in_law()
    }

    /// Parameters a refit with this effect adds to the model without it: the strength's
    /// [`fit_parameters`](EffectDescriptor::fit_parameters) (2 for strain thinning: `n` and
    /// `κ`) plus its free shapes ([`free_shapes`](Self::free_shapes)).
    pub fn extra_parameters(&self) -> usize {
        self.descriptor().fit_parameters + self.free_shapes().len()
    }

    /// Whether `value` (a strength in the effect's unit) is physical, in words: `None` inside
    /// the [`physical_range`](Self::physical_range), else e.g. `"radiation would need ε = 2 > 1:
    /// not physical"`. A non-finite value is never physical.
    pub fn judge(&self, value: f64) -> Option<String> {
        let (lo, hi) = self.physical_range();
        let unit = match self.unit() {
            "-" => String::new(),
            u => format!(" {u}"),
        };
        let what = format!(
            "{} would need {} = {}{unit}",
            self.name(),
            self.symbol(),
            g(value)
        );
        if !value.is_finite() {
            Some(format!("{what}: not a number, not physical"))
        } else if value > hi {
            Some(format!("{what} > {}{unit}: not physical", g(hi)))
        } else if value < lo {
            Some(format!("{what} < {}{unit}: not physical", g(lo)))
        } else {
            None
        }
    }

    /// The effect's shape parameters (empty for most).
    pub fn shape_parameters(&self) -> Vec<ShapeParameter> {
        self.descriptor().shapes.to_vec()
    }

    /// The values the settings fix, in [`shape_parameters`](Self::shape_parameters) order (the
    /// variant's fields).
    fn fixed_shapes(&self) -> Vec<Option<f64>> {
        match self {
            Effect::AirCoflow { decay_length, tail } => vec![*decay_length, *tail],
            Effect::AirCoflowLine { onset, ramp_width } => vec![*onset, *ramp_width],
            Effect::AirTemperatureProfile { decay_length } => vec![*decay_length],
            _ => Vec::new(),
        }
    }

    /// The variant's fields of the fixed shape values, in
    /// [`shape_parameters`](Self::shape_parameters) order.
    fn fixed_shapes_mut(&mut self) -> Vec<&mut Option<f64>> {
        match self {
            Effect::AirCoflow { decay_length, tail } => vec![decay_length, tail],
            Effect::AirCoflowLine { onset, ramp_width } => vec![onset, ramp_width],
            Effect::AirTemperatureProfile { decay_length } => vec![decay_length],
            _ => Vec::new(),
        }
    }

    /// Each shape parameter with its fixed value (`None`: not fixed), in
    /// [`shape_parameters`](Self::shape_parameters) order.
    pub fn shape_settings(&self) -> Vec<(ShapeParameter, Option<f64>)> {
        self.descriptor()
            .shapes
            .iter()
            .copied()
            .zip(self.fixed_shapes())
            .collect()
    }

    /// The shape parameters a fit frees with the strength (not fixed and
    /// [`fitted_with_strength`](ShapeParameter::fitted_with_strength)).
    pub fn free_shapes(&self) -> Vec<ShapeParameter> {
        self.shape_settings()
            .into_iter()
            .filter(|(s, v)| v.is_none() && s.fitted_with_strength)
            .map(|(s, _)| s)
            .collect()
    }

    /// The value of every shape parameter in the model (fixed value or default).
    pub fn shape_values(&self) -> Vec<(ShapeParameter, f64)> {
        self.shape_settings()
            .into_iter()
            .map(|(s, v)| (s, v.unwrap_or(s.default)))
            .collect()
    }

    /// The effect with shape parameter `name` fixed at `value` (must lie within its bounds);
    /// errors name the shape parameter.
    pub fn with_shape(mut self, name: &str, value: f64) -> Result<Effect, String> {
        let shapes = self.descriptor().shapes;
        let Some(i) = shapes.iter().position(|s| s.name == name) else {
            return Err(if shapes.is_empty() {
                format!("{} has no shape parameters (got \"{name}\")", self.name())
            } else {
                format!(
                    "{} has no shape parameter \"{name}\"; its shape parameters are {}",
                    self.name(),
                    shapes.iter().map(|s| s.name).collect::<Vec<_>>().join(", ")
                )
            });
        };
        let sp = shapes[i];
        let (lo, hi) = sp.bounds;
        if !(value.is_finite() && value >= lo && value <= hi) {
            let unit = match sp.unit {
                "-" => String::new(),
                u => format!(" {u}"),
            };
            return Err(format!(
                "{}:{name} = {} is outside its admissible range [{lo}, {hi}]{unit}",
                self.name(),
                crate::report::format::show(value)
            ));
        }
        let name_of = self.name();
        match self.fixed_shapes_mut().into_iter().nth(i) {
            Some(slot) => *slot = Some(value),
            None => return Err(format!("{name_of} has no shape parameter \"{name}\"")),
        }
        Ok(self)
    }

    /// Name of the model parameter that carries the strength (in
    /// [`FiberModel::param_names`](crate::model::FiberModel::param_names)).
    pub fn model_param(&self) -> &'static str {
        self.descriptor().model_param
    }

    /// Model-parameter value for a strength (`1 − s` for `strain_thinning`, `1 + s` for
    /// `nusselt_scale`, `s` otherwise: the descriptor's `StrengthMap`).
    pub fn param_value(&self, strength: f64) -> f64 {
        self.descriptor().param_value(strength)
    }

    /// Strength for a model-parameter value (inverse of [`param_value`](Self::param_value)).
    pub fn strength_of(&self, param: f64) -> f64 {
        self.descriptor().strength_of(param)
    }

    /// `d(model parameter)/d(strength)`: ±1.
    pub fn param_per_strength(&self) -> f64 {
        self.descriptor().map.param_per_strength()
    }

    /// Adds the effect to `physics` at its neutral strength, as a model parameter (nothing for
    /// an effect that lives in the law), with its shape parameters as model parameters at their
    /// fixed or default values: the built-in part switched on by
    /// [`Physics::enable`](crate::model::Physics::enable), or the user's term. Errors if the
    /// strength cannot be named in `physics` (a user effect whose term does not carry its name).
    pub fn apply(&self, physics: Physics) -> Result<Physics, FiberError> {
        let d = self.descriptor();
        let par = Strength::Parameter(self.param_value(self.neutral()));
        let added = match (self, d.install) {
            (_, Install::Law { .. }) => return Ok(physics),
            (Effect::Custom(u), _) => (u.add)(physics),
            (_, _) => physics.enable(d.model_param)?,
        };
        // a user effect whose name is taken by another strength is refused by
        // `ModelSpec::validate`; here a missing strength is an error, not a panic
        let mut p = added.strength(self.model_param(), par)?;
        for (s, v) in self.shape_values() {
            p.set_strength(s.model_param, Strength::Parameter(v))?;
        }
        Ok(p)
    }
}

/// A number in short form for messages.
fn g(v: f64) -> String {
    if v == v.trunc() && v.abs() < 1e6 {
        format!("{v}")
    } else {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

impl Effect {
    /// Adds the effect to `physics` at `strength` (in the effect's unit, see
    /// [`unit`](Self::unit)) — e.g. a fitted strength from a fit report — with its shape
    /// parameters at their fixed or default values. Errors for an effect that lives in the law
    /// (`strain_thinning`, the law's `n = 1 − strength`), and for a strength outside the search
    /// range [`bounds`](Self::bounds).
    pub fn apply_at(&self, physics: Physics, strength: f64) -> Result<Physics, String> {
        let d = self.descriptor();
        if d.installs_in_law() {
            return Err(format!(
                "{} is the viscosity law's {} = {}; set {} instead",
                d.name,
                d.model_param,
                d.map.words(),
                d.model_param
            ));
        }
        let (lo, hi) = self.bounds();
        if !(strength.is_finite() && strength >= lo && strength <= hi) {
            return Err(format!(
                "{} = {} is outside its admissible range [{lo}, {hi}] {}",
                self.name(),
                crate::report::format::show(strength),
                self.unit()
            ));
        }
        let par = Strength::Parameter(self.param_value(strength));
        self.apply(physics)
            .and_then(|p| p.strength(self.model_param(), par))
            .map_err(|e| e.to_string())
    }
}

/// The paper's physics plus `effects` at the given strengths (e.g. the effects of a fit
/// report); errors name an effect whose strength is inadmissible.
pub fn physics_with(effects: &[(Effect, f64)]) -> Result<Physics, String> {
    effects
        .iter()
        .try_fold(Physics::paper(), |p, (e, v)| e.apply_at(p, *v))
}

impl FromStr for Effect {
    type Err = String;
    /// A built-in effect by name ([`ALL_NAMES`]), shapes not fixed.
    fn from_str(s: &str) -> Result<Self, String> {
        let s = s.trim();
        let all = Effect::all();
        Effect::find(&all, s).cloned().ok_or_else(|| {
            format!(
                "unknown effect \"{s}\"; the candidates are {}",
                ALL_NAMES.join(", ")
            )
        })
    }
}

/// An effect in a model: its strength fitted (`value: None`) or fixed.
#[derive(Debug, Clone)]
pub struct EffectSetting {
    /// The effect (its fixed shape parameters included).
    pub effect: Effect,
    /// Fixed strength, or `None` to fit it.
    pub value: Option<f64>,
}

impl EffectSetting {
    /// The effect with its strength fitted.
    pub fn fitted(effect: Effect) -> Self {
        EffectSetting {
            effect,
            value: None,
        }
    }

    /// The effect with a fixed strength.
    pub fn fixed(effect: Effect, value: f64) -> Self {
        EffectSetting {
            effect,
            value: Some(value),
        }
    }
}

fn parse_number(token: &str, what: &str, whole: &str) -> Result<f64, String> {
    let x: f64 = token
        .trim()
        .parse()
        .map_err(|_| format!("\"{token}\" is not a number (in \"{whole}\")"))?;
    if !x.is_finite() {
        return Err(format!("the {what} in \"{whole}\" is not finite"));
    }
    Ok(x)
}

impl FromStr for EffectSetting {
    type Err = String;
    /// `name` (fitted) or `name=value` (fixed), e.g. `radiation=0.9`, optionally followed by
    /// shape parameters fixed at values, each after a colon: `air_coflow:decay_length=0.2`,
    /// `air_coflow=40:decay_length=0.2`. Errors name the bad token.
    fn from_str(s: &str) -> Result<Self, String> {
        let mut tokens = s.split(':');
        let head = tokens.next().unwrap_or_default();
        let (name, value) = match head.split_once('=') {
            Some((n, v)) => (n, Some(parse_number(v, "strength", s)?)),
            None => (head, None),
        };
        let mut effect: Effect = name.parse()?;
        if let Some(x) = value {
            let (lo, hi) = effect.bounds();
            if x < lo || x > hi {
                return Err(format!(
                    "{} = {} is outside its admissible range [{lo}, {hi}] {}",
                    effect.name(),
                    crate::report::format::show(x),
                    effect.unit()
                ));
            }
        }
        for token in tokens {
            let Some((shape, v)) = token.split_once('=') else {
                return Err(format!(
                    "\"{token}\" in \"{s}\": give a shape parameter as SHAPE=VALUE \
                     (e.g. {}:decay_length=0.2)",
                    effect.name()
                ));
            };
            let x = parse_number(v, shape.trim(), s)?;
            effect = effect
                .with_shape(shape.trim(), x)
                .map_err(|e| format!("\"{token}\" in \"{s}\": {e}"))?;
        }
        Ok(EffectSetting { effect, value })
    }
}

/// `(n, κ)` \[-\] of a Newtonian model (the law without strain thinning): `n = 1`, and the `κ`
/// at which the strain-thinning direction is taken — the reference of the effect that lives in
/// the law (`Install::Law` of `catalog::STRAIN_THINNING`).
pub const NEWTONIAN_LAW: [f64; 2] = match catalog::STRAIN_THINNING.install {
    Install::Law { reference } => reference,
    _ => panic!("strain thinning lives in the law"),
};

/// The viscosity law of a user's model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LawChoice {
    /// Newtonian (`n = 1`); strain thinning is a candidate.
    Newtonian,
    /// The paper's Carreau-type law with `(n, κ)` fitted.
    #[default]
    Carreau,
}

impl FromStr for LawChoice {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim() {
            "newtonian" => Ok(LawChoice::Newtonian),
            "carreau" => Ok(LawChoice::Carreau),
            o => Err(format!(
                "unknown model \"{o}\"; expected newtonian or carreau"
            )),
        }
    }
}

/// A model for the rheometer: the law, the effects it has (fitted or fixed) and the candidates
/// carried along at neutral strength (present as parameters so that sensitivities with respect
/// to them come with every solve, but neither fitted nor changing the model).
#[derive(Debug, Clone)]
pub struct ModelSpec {
    /// The viscosity law.
    pub law: LawChoice,
    /// Effects in the model.
    pub effects: Vec<EffectSetting>,
    /// Candidates at neutral strength.
    pub candidates: Vec<Effect>,
}

impl Default for ModelSpec {
    /// The paper's model: Carreau-type law, no extra effects.
    fn default() -> Self {
        ModelSpec {
            law: LawChoice::Carreau,
            effects: Vec::new(),
            candidates: Vec::new(),
        }
    }
}

impl ModelSpec {
    /// The paper's physics with `law`.
    pub fn new(law: LawChoice) -> Self {
        ModelSpec {
            law,
            ..Default::default()
        }
    }

    /// Adds an effect (fitted or fixed).
    pub fn with(mut self, setting: EffectSetting) -> Self {
        self.effects.push(setting);
        self
    }

    /// Whether the effect `id` is in the model or a candidate.
    pub fn contains(&self, id: EffectId) -> bool {
        self.effects.iter().any(|e| e.effect.id() == id)
            || self.candidates.iter().any(|e| e.id() == id)
    }

    /// Adds `effects` as neutral candidates, skipping those already present (and those that
    /// live in the law, `strain_thinning`, for a Carreau law, which has it).
    pub fn with_candidates(mut self, effects: &[Effect]) -> Self {
        for e in effects {
            if self.contains(e.id()) || (self.law == LawChoice::Carreau && e.installs_in_law()) {
                continue;
            }
            self.candidates.push(e.clone());
        }
        self
    }

    /// Checks for duplicate effects, an effect of the law (`strain_thinning`) in a Carreau
    /// model, and user effects: a name not taken by a built-in term, strength or effect, and a
    /// consistent descriptor ([`EffectDescriptor::validate`]).
    pub fn validate(&self) -> Result<(), String> {
        let mut ids: Vec<EffectId> = Vec::new();
        for e in self
            .effects
            .iter()
            .map(|s| &s.effect)
            .chain(self.candidates.iter())
        {
            if ids.contains(&e.id()) {
                return Err(format!("effect {} given twice", e.name()));
            }
            if let Effect::Custom(u) = e {
                let name = u.descriptor.name;
                let paper = Physics::paper();
                let taken = ALL_NAMES.contains(&name)
                    || name.contains('.')
                    || paper.terms.iter().any(|t| t.name == name)
                    || paper.strength_parameters().iter().any(|(n, _)| *n == name)
                    || ["n", "kappa"].contains(&name);
                if taken {
                    return Err(format!(
                        "user effect \"{name}\": the name is taken by a built-in term or effect; \
                         choose another"
                    ));
                }
                u.descriptor.validate()?;
            }
            if self.law == LawChoice::Carreau && e.installs_in_law() {
                return Err(format!(
                    "{} is already part of the Carreau model (use --model newtonian)",
                    e.name()
                ));
            }
            ids.push(e.id());
        }
        Ok(())
    }

    /// The physics: the paper's terms plus every effect and candidate at neutral strength (an
    /// error names a strength that cannot be set; run [`validate`](Self::validate) first).
    pub fn physics(&self) -> Result<Physics, FiberError> {
        self.effects
            .iter()
            .map(|s| &s.effect)
            .chain(self.candidates.iter())
            .try_fold(Physics::paper(), |p, e| e.apply(p))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::catalog::descriptor::StrengthMap;
    use crate::model::catalog::physics::DEFAULT_COFLOW_LINE_RAMP_WIDTH;
    use crate::model::catalog::BUILTIN_NAMES;

    #[test]
    fn search_ranges_contain_physical_ranges_and_neutral() {
        for e in Effect::all() {
            let (lo, hi) = e.bounds();
            let (plo, phi) = e.physical_range();
            assert!(lo <= plo && plo <= phi && phi <= hi, "{}", e.name());
            assert!((plo..=phi).contains(&e.neutral()), "{}", e.name());
            for s in e.shape_parameters() {
                assert!(
                    s.bounds.0 <= s.default && s.default <= s.bounds.1,
                    "{}",
                    s.name
                );
                assert!(s.model_param.starts_with(e.name()));
            }
        }
        assert_eq!(Effect::all().len(), ALL_NAMES.len());
        let names: Vec<&str> = Effect::builtin().iter().map(|e| e.name()).collect();
        assert_eq!(names, BUILTIN_NAMES);
    }

    /// The built-in effects are the catalog's descriptors, in its order, each with as many
    /// fixed-shape fields as its descriptor has shapes; the accessors read the descriptor.
    #[test]
    fn effects_are_the_catalog() {
        let all = Effect::all();
        assert_eq!(all.len(), catalog::BUILTIN.len());
        for (e, d) in all.iter().zip(catalog::BUILTIN) {
            assert!(std::ptr::eq(e.descriptor().name, d.name), "{}", d.name);
            assert_eq!(e.fixed_shapes().len(), d.shapes.len(), "{}", d.name);
            let mut m = e.clone();
            assert_eq!(m.fixed_shapes_mut().len(), d.shapes.len(), "{}", d.name);
            assert_eq!(e.name().parse::<Effect>().map(|x| x.name()), Ok(d.name));
            assert_eq!(
                e.extra_parameters(),
                d.fit_parameters + d.shapes.iter().filter(|s| s.fitted_with_strength).count()
            );
        }
        assert_eq!(Effect::StrainThinning.extra_parameters(), 2);
        assert_eq!(NEWTONIAN_LAW, [1.0, STRAIN_THINNING_REFERENCE_KAPPA]);
        assert_eq!(
            Effect::StrainThinning
                .apply_at(Physics::paper(), 0.2)
                .unwrap_err(),
            "strain_thinning is the viscosity law's n = 1 - strength; set n instead"
        );
    }

    /// A user effect is a descriptor and a term: the descriptor's unit, ranges, category and
    /// check are the effect's; an inconsistent descriptor is refused by the spec.
    #[test]
    fn a_user_descriptor_describes_its_effect() {
        #[derive(Clone)]
        struct Pull;
        impl FiberTerm for Pull {
            fn eval<D: num_dual::DualNum<Primitive = f64> + Copy>(
                &self,
                st: &crate::model::contributions::SiState<D>,
            ) -> D {
                st.force * 0.0 + (-(st.s - 0.2) * (st.s - 0.2) / 1e-3).exp() * 1e-3
            }
        }
        let d = EffectDescriptor::user("mid_pull")
            .with_unit("mN", "F")
            .with_category(Category::Process)
            .with_ranges((-5.0, 5.0), (-2.0, 2.0))
            .with_independent_check("a tensiometer above and below the guide");
        let e = Effect::user(d, Balance::Momentum, Pull);
        assert_eq!((e.name(), e.unit(), e.symbol()), ("mid_pull", "mN", "F"));
        assert_eq!((e.bounds(), e.physical_range()), ((-5.0, 5.0), (-2.0, 2.0)));
        assert_eq!(e.category(), Category::Process);
        assert_eq!(
            e.independent_check(),
            Some("a tensiometer above and below the guide")
        );
        assert_eq!(e.extra_parameters(), 1);
        assert_eq!(
            e.judge(3.0).as_deref(),
            Some("mid_pull would need F = 3 mN > 2 mN: not physical")
        );
        let spec = ModelSpec::default().with_candidates(&[e]);
        spec.validate().unwrap();
        assert!(spec
            .physics()
            .unwrap()
            .strength_parameters()
            .contains(&("mid_pull", 0.0)));
        // a neutral strength outside the physical range, or a factor that does not vanish there
        for bad in [
            EffectDescriptor { neutral: 3.0, ..d },
            EffectDescriptor {
                map: StrengthMap::OnePlus,
                ..d
            },
            EffectDescriptor {
                physical_range: (-6.0, 2.0),
                ..d
            },
        ] {
            let spec =
                ModelSpec::default().with_candidates(&[Effect::user(bad, Balance::Momentum, Pull)]);
            let err = spec.validate().unwrap_err();
            assert!(err.starts_with("effect \"mid_pull\""), "{err}");
        }
    }

    #[test]
    fn judge_words_and_shape_bounds_for_length() {
        assert_eq!(
            Effect::Radiation.judge(2.0).as_deref(),
            Some("radiation would need ε = 2 > 1: not physical")
        );
        assert_eq!(
            Effect::GaugeOffset.judge(-25.0).as_deref(),
            Some("gauge_offset would need o = -25 µm < -20 µm: not physical")
        );
        assert!(Effect::MassFlowScale.judge(0.1).is_none());
        assert_eq!(COFLOW_DECAY.bounds_for_length(0.5), (0.01, 0.75));
        assert_eq!(WARM_AIR_DECAY.bounds_for_length(2.0), (0.005, 1.0));
        assert_eq!(
            COFLOW_DECAY.bounds_for_length(f64::NAN),
            COFLOW_DECAY.bounds
        );
    }

    #[test]
    fn shapes_fixed_by_settings_are_not_freed() {
        let s: EffectSetting = "air_coflow_line:onset=0.25".parse().unwrap();
        // the fixed onset is not fitted; the ramp width (not given) still is
        let free: Vec<_> = s
            .effect
            .free_shapes()
            .iter()
            .map(|f| f.model_param)
            .collect();
        assert_eq!(free, ["air_coflow_line.ramp_width"]);
        let vals: Vec<f64> = s.effect.shape_values().iter().map(|v| v.1).collect();
        assert_eq!(vals, [0.25, DEFAULT_COFLOW_LINE_RAMP_WIDTH]);
        let both: EffectSetting = "air_coflow_line:onset=0.25:ramp_width=0.05"
            .parse()
            .unwrap();
        assert!(both.effect.free_shapes().is_empty());
        let free = Effect::AirCoflow {
            decay_length: None,
            tail: None,
        }
        .free_shapes();
        assert_eq!(free.len(), 1);
        assert_eq!(free[0].model_param, "air_coflow.decay_length");
    }
}
