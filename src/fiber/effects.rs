//! Candidate effects: named contributions a user's model may lack, each with a **strength
//! parameter** whose neutral value 0 switches it off exactly and which is a model parameter of
//! the [`FiberModel`](crate::fiber::FiberModel) (so derivatives with respect to it are exact,
//! through the dual numbers).
//!
//! | name | strength (unit) | enters as | neutral |
//! |---|---|---|---|
//! | `strain_thinning` | `1 − n` (-) | Carreau-type law with power index `n = 1 − s` | Newtonian |
//! | `radiation` | emissivity `ε` (-) | heat loss `π d ε σ (T⁴ − T_air⁴)` | 0 |
//! | `air_coflow` | amplitude `V` (m/s) | air speed `v_air = V exp(−(L − s)/ℓ)`, `ℓ` = 0.1 m | 0 |
//! | `air_temperature_profile` | excess `ΔT` (K) | `T_air(s) = T_air + ΔT exp(−s/ℓ)`, `ℓ` = 0.05 m | 0 |
//! | `inlet_velocity` | relative error `δ` (-) | inlet condition `u(0) = (1 + δ) u_in` | 0 |
//! | `nusselt_scale` | `s` (-) | Nusselt law `𝒩 → (1 + s) 𝒩` | 0 |
//! | user term | its own factor (-) | `strength ×` the user's [`FiberTerm`] | 0 |
//!
//! **Strain thinning.** The user's Newtonian model is the Carreau-type law at `n = 1` (where
//! `κ` has no effect). The strength is `s = 1 − n`; its derivative at `s = 0` is
//! `−∂μ_e/∂n = −½ μ_e0 ln(1 + De² (μ_e0 ε̇/K̃)²)`, which depends on the stress scale `K = e^κ`
//! left undetermined by the Newtonian fit: the linearised score uses `κ` =
//! [`STRAIN_THINNING_REFERENCE_KAPPA`]; a refit frees both `n` and `κ` (two parameters in the
//! information criterion).
//!
//! The CLI parses a setting as `name` (strength fitted) or `name=value` (fixed), see
//! [`EffectSetting`].

use crate::fiber::contributions::{Balance, FiberTerm, Physics, Strength};
use crate::fiber::error::FiberError;
use std::fmt;
use std::str::FromStr;
use std::sync::Arc;

/// Default decay length `ℓ` \[m\] of the aspirator co-flow `V exp(−(L − s)/ℓ)`.
pub const DEFAULT_COFLOW_DECAY_LENGTH: f64 = 0.1;

/// Default decay length `ℓ` \[m\] of the warm-air profile `ΔT exp(−s/ℓ)`.
pub const DEFAULT_WARM_AIR_DECAY_LENGTH: f64 = 0.05;

/// `κ = ln(K / 1 Pa)` \[-\] at which the strain-thinning direction of a Newtonian model is taken
/// (the middle of the default κ range (7, 20)).
pub const STRAIN_THINNING_REFERENCE_KAPPA: f64 = 13.5;

/// A user-written effect: a [`FiberTerm`] (SI force or heat per length, written once generically
/// over dual numbers) multiplied by its own strength parameter (neutral 0, bounds
/// `bounds`, default `(−10, 10)`).
#[derive(Clone)]
pub struct UserEffect {
    name: &'static str,
    balance: Balance,
    bounds: (f64, f64),
    add: Arc<dyn Fn(Physics) -> Physics + Send + Sync>,
}

impl UserEffect {
    /// The term `term` in `balance`, named `name` (its strength parameter has the same name).
    pub fn new<T: FiberTerm + Clone + 'static>(
        name: &'static str,
        balance: Balance,
        term: T,
    ) -> Self {
        UserEffect {
            name,
            balance,
            bounds: (-10.0, 10.0),
            add: Arc::new(move |p: Physics| p.with_custom(name, balance, term.clone())),
        }
    }

    /// Sets the bounds of the strength in fits.
    pub fn with_bounds(mut self, lower: f64, upper: f64) -> Self {
        self.bounds = (lower, upper);
        self
    }

    /// The balance the term enters.
    pub fn balance(&self) -> Balance {
        self.balance
    }
}

impl fmt::Debug for UserEffect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "UserEffect({}, {:?})", self.name, self.balance)
    }
}

/// A candidate effect.
#[derive(Debug, Clone)]
pub enum Effect {
    /// `strain_thinning`: Carreau-type law instead of Newtonian, strength `1 − n` \[-\].
    StrainThinning,
    /// `radiation`: grey-body radiation, strength = emissivity ε \[-\].
    Radiation,
    /// `air_coflow`: aspirator co-flow, strength = amplitude `V` \[m/s\].
    AirCoflow {
        /// Decay length `ℓ` \[m\] (default [`DEFAULT_COFLOW_DECAY_LENGTH`]).
        decay_length: f64,
    },
    /// `air_temperature_profile`: warm air near the nozzle, strength = excess `ΔT` \[K\].
    AirTemperatureProfile {
        /// Decay length `ℓ` \[m\] (default [`DEFAULT_WARM_AIR_DECAY_LENGTH`]).
        decay_length: f64,
    },
    /// `inlet_velocity`: relative inlet-velocity error δ \[-\], `u(0) = (1 + δ) u_in`.
    InletVelocity,
    /// `nusselt_scale`: `𝒩 → (1 + s) 𝒩`, strength `s` \[-\].
    NusseltScale,
    /// A user-written term with its own strength.
    Custom(UserEffect),
}

/// Canonical names of the built-in effects, in [`Effect::builtin`] order.
pub const BUILTIN_NAMES: [&str; 6] = [
    "strain_thinning",
    "radiation",
    "air_coflow",
    "air_temperature_profile",
    "inlet_velocity",
    "nusselt_scale",
];

impl Effect {
    /// The six built-in candidates with default decay lengths.
    pub fn builtin() -> Vec<Effect> {
        vec![
            Effect::StrainThinning,
            Effect::Radiation,
            Effect::AirCoflow {
                decay_length: DEFAULT_COFLOW_DECAY_LENGTH,
            },
            Effect::AirTemperatureProfile {
                decay_length: DEFAULT_WARM_AIR_DECAY_LENGTH,
            },
            Effect::InletVelocity,
            Effect::NusseltScale,
        ]
    }

    /// A user-written effect (see [`UserEffect::new`]).
    pub fn custom<T: FiberTerm + Clone + 'static>(
        name: &'static str,
        balance: Balance,
        term: T,
    ) -> Self {
        Effect::Custom(UserEffect::new(name, balance, term))
    }

    /// Canonical name (CLI, JSON, docs).
    pub fn name(&self) -> &'static str {
        match self {
            Effect::StrainThinning => "strain_thinning",
            Effect::Radiation => "radiation",
            Effect::AirCoflow { .. } => "air_coflow",
            Effect::AirTemperatureProfile { .. } => "air_temperature_profile",
            Effect::InletVelocity => "inlet_velocity",
            Effect::NusseltScale => "nusselt_scale",
            Effect::Custom(u) => u.name,
        }
    }

    /// Unit of the strength, for reports.
    pub fn unit(&self) -> &'static str {
        match self {
            Effect::AirCoflow { .. } => "m/s",
            Effect::AirTemperatureProfile { .. } => "K",
            _ => "-",
        }
    }

    /// What the strength is, in words.
    pub fn describe(&self) -> &'static str {
        match self {
            Effect::StrainThinning => "strain thinning (Carreau-type law), strength 1 - n",
            Effect::Radiation => "thermal radiation, strength = emissivity",
            Effect::AirCoflow { .. } => {
                "aspirator air co-flow near the take-up, strength = air speed amplitude"
            }
            Effect::AirTemperatureProfile { .. } => {
                "warm air near the nozzle, strength = air temperature excess"
            }
            Effect::InletVelocity => "inlet-velocity (die-swell) error, strength = relative error",
            Effect::NusseltScale => "scale on the Nusselt law, strength s in (1 + s) Nu",
            Effect::Custom(_) => "user-written contribution, strength = its factor",
        }
    }

    /// Neutral strength (the effect is absent): 0 for every effect.
    pub fn neutral(&self) -> f64 {
        0.0
    }

    /// Bounds of the strength in fits.
    pub fn bounds(&self) -> (f64, f64) {
        match self {
            Effect::StrainThinning => (0.0, 1.0),
            Effect::Radiation => (-1.0, 2.0),
            Effect::AirCoflow { .. } => (-5.0, 10.0),
            Effect::AirTemperatureProfile { .. } => (-15.0, 300.0),
            Effect::InletVelocity => (-0.5, 1.0),
            Effect::NusseltScale => (-0.9, 3.0),
            Effect::Custom(u) => u.bounds,
        }
    }

    /// Name of the model parameter (in [`FiberModel::param_names`](crate::fiber::FiberModel::param_names))
    /// that carries the strength.
    pub fn model_param(&self) -> &'static str {
        match self {
            Effect::StrainThinning => "n",
            // one name per effect: the strength parameter carries the effect's name
            _ => self.name(),
        }
    }

    /// Model-parameter value for a strength (`1 − s` for `strain_thinning`, `1 + s` for
    /// `nusselt_scale`, `s` otherwise).
    pub fn param_value(&self, strength: f64) -> f64 {
        match self {
            Effect::StrainThinning => 1.0 - strength,
            Effect::NusseltScale => 1.0 + strength,
            _ => strength,
        }
    }

    /// Strength for a model-parameter value (inverse of [`param_value`](Self::param_value)).
    pub fn strength_of(&self, param: f64) -> f64 {
        match self {
            Effect::StrainThinning => 1.0 - param,
            Effect::NusseltScale => param - 1.0,
            _ => param,
        }
    }

    /// `d(model parameter)/d(strength)`: ±1.
    pub fn param_per_strength(&self) -> f64 {
        match self {
            Effect::StrainThinning => -1.0,
            _ => 1.0,
        }
    }

    /// Adds the effect to `physics` at its neutral strength, as a model parameter (nothing for
    /// `strain_thinning`, which lives in the law). Errors if the strength cannot be named in
    /// `physics` (a user effect whose term does not carry its name).
    pub fn apply(&self, physics: Physics) -> Result<Physics, FiberError> {
        let par = Strength::Parameter(self.param_value(self.neutral()));
        let added = match self {
            Effect::StrainThinning => return Ok(physics),
            Effect::Radiation => physics.with_radiation(1.0),
            Effect::AirCoflow { decay_length } => physics.with_coflow(1.0, *decay_length),
            Effect::AirTemperatureProfile { decay_length } => {
                physics.with_warm_air(1.0, *decay_length)
            }
            Effect::InletVelocity => physics,
            Effect::NusseltScale => physics,
            Effect::Custom(u) => (u.add)(physics),
        };
        // a user effect whose name is taken by another strength is refused by
        // `ModelSpec::validate`; here a missing strength is an error, not a panic
        added.strength(self.model_param(), par)
    }
}

impl Effect {
    /// Adds the effect to `physics` at `strength` (in the effect's unit, see
    /// [`unit`](Self::unit)) — e.g. a fitted strength from a fit report. Errors for
    /// `strain_thinning`, which is not a term of the physics but the law's `n = 1 − strength`.
    pub fn apply_at(&self, physics: Physics, strength: f64) -> Result<Physics, String> {
        if matches!(self, Effect::StrainThinning) {
            return Err(
                "strain_thinning is the viscosity law's n = 1 - strength; set n instead".into(),
            );
        }
        let (lo, hi) = self.bounds();
        if !(strength.is_finite() && strength >= lo && strength <= hi) {
            return Err(format!(
                "{} = {strength} is outside its admissible range [{lo}, {hi}] {}",
                self.name(),
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
    fn from_str(s: &str) -> Result<Self, String> {
        let s = s.trim();
        Effect::builtin()
            .into_iter()
            .find(|e| e.name() == s)
            .ok_or_else(|| {
                format!(
                    "unknown effect \"{s}\"; the candidates are {}",
                    BUILTIN_NAMES.join(", ")
                )
            })
    }
}

/// An effect in a model: its strength fitted (`value: None`) or fixed.
#[derive(Debug, Clone)]
pub struct EffectSetting {
    /// The effect.
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

impl FromStr for EffectSetting {
    type Err = String;
    /// `name` (fitted) or `name=value` (fixed), e.g. `radiation=0.9`.
    fn from_str(s: &str) -> Result<Self, String> {
        let (name, value) = match s.split_once('=') {
            Some((n, v)) => {
                let x: f64 = v
                    .trim()
                    .parse()
                    .map_err(|_| format!("\"{v}\" is not a number (in \"{s}\")"))?;
                if !x.is_finite() {
                    return Err(format!("the strength in \"{s}\" is not finite"));
                }
                (n, Some(x))
            }
            None => (s, None),
        };
        let effect: Effect = name.parse()?;
        if let Some(x) = value {
            let (lo, hi) = effect.bounds();
            if x < lo || x > hi {
                return Err(format!(
                    "{} = {x} is outside its admissible range [{lo}, {hi}] {}",
                    effect.name(),
                    effect.unit()
                ));
            }
        }
        Ok(EffectSetting { effect, value })
    }
}

/// The viscosity law of a user's model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LawChoice {
    /// Newtonian (`n = 1`); strain thinning is a candidate.
    Newtonian,
    /// The paper's Carreau-type law with `(n, κ)` fitted.
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

    /// Whether an effect named `name` is in the model or a candidate.
    pub fn contains(&self, name: &str) -> bool {
        self.effects.iter().any(|e| e.effect.name() == name)
            || self.candidates.iter().any(|e| e.name() == name)
    }

    /// Adds `effects` as neutral candidates, skipping those already present (and
    /// `strain_thinning` for a Carreau law, which has it).
    pub fn with_candidates(mut self, effects: &[Effect]) -> Self {
        for e in effects {
            if self.contains(e.name())
                || (self.law == LawChoice::Carreau && matches!(e, Effect::StrainThinning))
            {
                continue;
            }
            self.candidates.push(e.clone());
        }
        self
    }

    /// Checks for duplicate effects and `strain_thinning` in a Carreau model.
    pub fn validate(&self) -> Result<(), String> {
        let mut names: Vec<&str> = Vec::new();
        for e in self
            .effects
            .iter()
            .map(|s| &s.effect)
            .chain(self.candidates.iter())
        {
            if names.contains(&e.name()) {
                return Err(format!("effect {} given twice", e.name()));
            }
            if let Effect::Custom(u) = e {
                let paper = Physics::paper();
                let taken = BUILTIN_NAMES.contains(&u.name)
                    || paper.terms.iter().any(|t| t.name == u.name)
                    || paper
                        .strength_parameters()
                        .iter()
                        .any(|(n, _)| *n == u.name)
                    || ["n", "kappa"].contains(&u.name);
                if taken {
                    return Err(format!(
                        "user effect \"{}\": the name is taken by a built-in term or effect; \
                         choose another",
                        u.name
                    ));
                }
            }
            if self.law == LawChoice::Carreau && matches!(e, Effect::StrainThinning) {
                return Err(
                    "strain_thinning is already part of the Carreau model (use --model newtonian)"
                        .into(),
                );
            }
            names.push(e.name());
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
