//! Momentum and energy balances as sums of **named contributions**.
//!
//! The dimensionless balances (paper eq. `num_c`) are
//!
//! ```text
//! N' = Q ε̇ − c Σ_k F_k,            T' = c/(c_p Q) Σ_k H_k,
//! ```
//!
//! where each `F_k` is an external force per length along the spinning direction (in units of
//! `f_o = Q_o u_o/L_o`; gravity is positive, drag in still air negative) and each `H_k` a heat
//! gain per length (in units of `h_o = c_p,o Q_o T_o/L_o`; cooling is negative). Every
//! contribution is a [`Term`]: a name, the balance it enters, a [`Strength`] multiplying it
//! (neutral `Fixed(1.0)`; `Parameter` makes the strength a model parameter in `p`, so the solution
//! can be differentiated and continued in it), and its physics written once generically over
//! dual numbers.
//!
//! Built in ([`Physics::paper`] switches on the first four, as the paper's model):
//! gravity, Stokes air drag, convective cooling (pluggable [`NusseltLaw`]), viscous heating;
//! off by default: grey-body radiation ([`Physics::with_radiation`]).
//! Users add their own SI terms with [`Physics::with_custom`] (a [`FiberTerm`]).
//!
//! The other built-in effects change the model without a term of their own: a warm-air
//! profile ([`Physics::with_warm_air`]), an aspirator co-flow ([`Physics::with_coflow`]) and a
//! co-flow along the line ([`Physics::with_line_coflow`]), whose decay lengths and onset may be
//! model parameters too ([`Physics::set_strength`] with `"air_coflow.decay_length"` etc.);
//! process parameters (inlet velocity and diameter, die temperature offset, mass-flow scale,
//! [`Physics::process_planned`]) change the boundary conditions and the mass flow; instrument
//! parameters (gauge scale and offset, [`Physics::gauge_reading_planned`]) only the predicted
//! measurement; material parameters the VFT law. Each is a small type in its own file of
//! [`modifiers`], registered there by one line, its strength and shapes named by its descriptor
//! ([`catalog`](super::catalog)); [`Physics`] holds the ones it has, in registry order.
//!
//! The strengths that are candidate effects are named by the effects' descriptors: the
//! radiation term, the convection term's factor `nusselt_scale`, and the modifiers' strengths
//! and shapes; [`Physics::enable`] switches on the part that carries an effect.

use super::catalog::{EffectId, NUSSELT_SCALE, RADIATION};
use super::setup::Air;
use crate::error::FiberError;
use diffbvp::dyn_dual::{eval_dyn, DualScalarFn, DynDualScalarFn};
use modifiers::{AirProfile, InletFactors, Part};
use num_dual::DualNum;
use std::f64::consts::PI;

pub(crate) mod modifiers;

/// Stefan–Boltzmann constant σ [W/(m² K⁴)].
pub const STEFAN_BOLTZMANN: f64 = 5.670374419e-8;

/// Which balance a term enters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Balance {
    /// A force per length \[N/m\] in the momentum balance.
    Momentum,
    /// A heat gain per length \[W/m\] in the energy balance.
    Energy,
}

/// The factor multiplying a term (or an environment profile's amplitude).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Strength {
    /// Switched off (factor 0, no parameter).
    Off,
    /// A fixed factor (1.0 = as modelled).
    Fixed(f64),
    /// A model parameter in `p` (its default value given here): differentiable and continuable.
    Parameter(f64),
}

/// Nusselt function `𝒩(Re_τ, Re², Pr)` of the heat-transfer coefficient `α = λ_*/d 𝒩`
/// (dimensionless inputs: tangential Reynolds number `Re_τ = d v_rel,τ/ν_*` (signed), the square
/// of the Reynolds number of the relative speed and the Prandtl number).
///
/// The Prandtl number is constant along the fiber, so a law may preprocess it once:
/// [`prandtl_argument`](NusseltLaw::prandtl_argument) maps `Pr` to the value handed to
/// [`nusselt`](NusseltLaw::nusselt) on every evaluation (default: `Pr` itself).
pub trait NusseltLaw: Send + Sync {
    /// Evaluates `𝒩` \[-\]; `pr_arg` is [`prandtl_argument`](NusseltLaw::prandtl_argument)`(Pr)`.
    fn nusselt<D: DualNum<Primitive = f64> + Copy>(&self, re_tau: D, re_sq: D, pr_arg: f64) -> D;

    /// Preprocessing of the (constant) Prandtl number, done once per model.
    fn prandtl_argument(&self, pr: f64) -> f64 {
        pr
    }

    /// `𝒩` with an extra regularisation `extra_sq` (≥ 0, dimensionless) of the Reynolds
    /// number and the inclination dependence where the relative speed changes sign, used with an
    /// air co-flow (see `COFLOW_INCLINATION_REGULARISATION`); it is exactly 0 in still air.
    /// Default: ignores `extra_sq`.
    fn nusselt_regularised<D: DualNum<Primitive = f64> + Copy>(
        &self,
        re_tau: D,
        re_sq: D,
        pr_arg: f64,
        extra_sq: D,
    ) -> D {
        let _ = extra_sq;
        self.nusselt(re_tau, re_sq, pr_arg)
    }
}

/// Extra regularisation `ε_c` \[-\] with an air co-flow, of the default Nusselt law's
/// inclination factor, `1 − ½ Re_τ²/(Re² + ε_i² + ε_c² w²/(1 + w²))`, and of its Reynolds
/// number, `Re_ε = √(Re² + ε_r² + ε_c² w²/(1 + w²))`, with
/// `w = v_air/`[`COFLOW_REGULARISATION_SPEED`]. Where the air overtakes the fiber the relative
/// speed changes sign: the unregularised inclination factor jumps from ½ to 1 and back within
/// `|Re| ≲ 1e-3`, and `Nu_CB ∝ Re_ε^½` has a cusp there of width `ε_r` = 1e-3. Both are layers
/// of ~1e-5 m the collocation cannot resolve cheaply: with the cusp at `ε_r`, a solve whose
/// crossing point moved refined its mesh many times, down to intervals of a few µm. `ε_c`
/// widens both layers, so that such solves stay cheap. In still air (`v_air = 0`,
/// also a co-flow of strength 0) the term vanishes identically, with zero derivative, so the
/// base model is reproduced exactly. Elsewhere it changes the inclination factor (½ for the
/// tangential flow along the fiber) by `≲ ε_c²/Re²` relative (0.25% at `Re = 1`) and `Re_ε^½`
/// by `≲ ε_c²/(4 Re²)` (0.06%).
pub(crate) const COFLOW_INCLINATION_REGULARISATION: f64 = 0.05;

/// Air speed scale \[m/s\] of the co-flow regularisation weight `w` (see
/// [`COFLOW_INCLINATION_REGULARISATION`]).
pub(crate) const COFLOW_REGULARISATION_SPEED: f64 = 0.01;

/// Default Nusselt law of `docs/model-closure.md` (an assumption; the paper's law is not public):
/// `𝒩 = (1 − ½ Re_τ²/(Re² + ε_i²)) Nu_CB(Re_ε, Pr)`, `Re_ε = √(Re² + ε_r²)`, with the
/// Churchill–Bernstein cross-flow correlation
/// `Nu_CB = 0.3 + 0.62 Re^½ Pr^⅓ [1 + (0.4/Pr)^⅔]^(−¼) [1 + (Re/282000)^(5/8)]^(4/5)`.
/// In still air `𝒩 = ½ Nu_CB`.
///
/// `ε_r = ε_i = 1e-3` reproduces the reference. With an air co-flow the relative speed changes sign
/// and the inclination factor jumps from ½ to 1 and back within `|Re| ≲ ε_i`; a larger
/// `inclination_regularisation` (e.g. 0.05) smooths that layer (a documented modelling choice).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InclinedChurchillBernstein {
    /// `ε_r` in `Re_ε = √(Re² + ε_r²)` \[-\].
    pub re_regularisation: f64,
    /// `ε_i` in the inclination factor \[-\].
    pub inclination_regularisation: f64,
}

impl Default for InclinedChurchillBernstein {
    fn default() -> Self {
        InclinedChurchillBernstein {
            re_regularisation: 1e-3,
            inclination_regularisation: 1e-3,
        }
    }
}

impl NusseltLaw for InclinedChurchillBernstein {
    /// `0.62 Pr^⅓ [1 + (0.4/Pr)^⅔]^(−¼)`.
    fn prandtl_argument(&self, pr: f64) -> f64 {
        0.62 * pr.cbrt() * (1.0 + (0.4 / pr).powf(2.0 / 3.0)).powf(-0.25)
    }

    #[inline]
    fn nusselt<D: DualNum<Primitive = f64> + Copy>(&self, re_tau: D, re_sq: D, pr_arg: f64) -> D {
        self.nusselt_regularised(re_tau, re_sq, pr_arg, D::zero())
    }

    #[inline]
    fn nusselt_regularised<D: DualNum<Primitive = f64> + Copy>(
        &self,
        re_tau: D,
        re_sq: D,
        pr_arg: f64,
        extra_sq: D,
    ) -> D {
        let re_eps2 = re_sq + self.re_regularisation * self.re_regularisation + extra_sq;
        let inc2 =
            re_sq + self.inclination_regularisation * self.inclination_regularisation + extra_sq;
        let inclination = -(re_tau * re_tau / inc2) * 0.5 + 1.0;
        // Re_ε^½ (Re_ε² > 0); (Re_ε/282000)^(5/8) = Re_ε^½ Re_ε^⅛ / 282000^(5/8), by square roots
        let sqrt_re = re_eps2.sqrt().sqrt();
        let re_58 = sqrt_re * sqrt_re.sqrt().sqrt() * CB_REYNOLDS_SCALE_POW;
        // [1 + (Re_ε/282000)^(5/8)]^(4/5)
        inclination * (sqrt_re * pr_arg * one_plus_pow_four_fifths(re_58) + 0.3)
    }
}

/// `282000^(−5/8)` \[-\]: the Reynolds-number scale of the Churchill–Bernstein correlation's
/// last factor, `(Re/282000)^(5/8) = Re^(5/8) · 282000^(−5/8)` (a literal: `powf` is not a
/// `const fn`, and the right-hand side must not evaluate it at every point).
const CB_REYNOLDS_SCALE_POW: f64 = 3.922_783_205_509_214_5e-4;

/// Below this `|x|` [`one_plus_pow_four_fifths`] sums the binomial series (its remainder after
/// the `x⁸` term is below `0.0037 |x|⁹ < 2·10⁻¹⁸`): `x = (Re/282000)^(5/8) < 0.02` for
/// `Re < 536`, which holds all along a melt-spinning line.
const FOUR_FIFTHS_SERIES_LIMIT: f64 = 0.02;

/// The binomial coefficients `C(4/5, k)`, `k = 1…8` (exact decimals).
const FOUR_FIFTHS_BINOMIAL: [f64; 8] = [
    0.8,
    -0.08,
    0.032,
    -0.0176,
    0.011264,
    -0.0078848,
    0.00585728,
    -0.004539392,
];

/// `(1 + x)^(4/5)` for `x >= 0`: the binomial series (Horner) for `|x| <`
/// [`FOUR_FIFTHS_SERIES_LIMIT`], else `exp(⅘ ln(1 + x))`. The series replaces an `exp` and a
/// `log1p` at every point of the right-hand side (both with dual numbers, the same rules apply
/// to every slope); value and derivative agree with the closed form to `~1e-15` relative.
#[inline]
fn one_plus_pow_four_fifths<D: DualNum<Primitive = f64> + Copy>(x: D) -> D {
    if x.re().abs() < FOUR_FIFTHS_SERIES_LIMIT {
        let mut q = D::from(FOUR_FIFTHS_BINOMIAL[7]);
        for &c in FOUR_FIFTHS_BINOMIAL[..7].iter().rev() {
            q = q * x + c;
        }
        q * x + 1.0
    } else {
        (x.ln_1p() * 0.8).exp()
    }
}

/// Local state in SI units, as seen by user terms ([`FiberTerm`]).
#[derive(Debug, Clone, Copy)]
pub struct SiState<D> {
    /// Position `s` \[m\].
    pub s: f64,
    /// Fiber speed `u` \[m/s\].
    pub velocity: D,
    /// Axial force `N` \[N\].
    pub force: D,
    /// Fiber temperature `T` \[K\].
    pub temperature: D,
    /// Strain rate `ε̇` \[1/s\].
    pub strain_rate: D,
    /// Fiber diameter `d` \[m\].
    pub diameter: D,
    /// Polymer density `ρ(T)` \[kg/m³\].
    pub density: D,
    /// Polymer specific heat `c_p(T)` [J/(kg K)].
    pub heat_capacity: D,
    /// Air temperature at `s` \[K\].
    pub air_temperature: D,
    /// Air speed along the fiber at `s` \[m/s\].
    pub air_velocity: D,
}

/// A user contribution in SI: a force per length \[N/m\] (momentum) or heat gain per length \[W/m\]
/// (energy), written once generically. Register it with [`Physics::with_custom`].
pub trait FiberTerm: Send + Sync {
    /// The term's value at the local state.
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, st: &SiState<D>) -> D;
}

const SI_ARGS: usize = 9;

struct UserTerm<T>(T);

impl<T: FiberTerm> DualScalarFn for UserTerm<T> {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, a: &[D]) -> D {
        let st = SiState {
            s: x,
            velocity: a[0],
            force: a[1],
            temperature: a[2],
            strain_rate: a[3],
            diameter: a[4],
            density: a[5],
            heat_capacity: a[6],
            air_temperature: a[7],
            air_velocity: a[8],
        };
        self.0.eval(&st)
    }
}

/// The physics of a term.
pub enum TermKind {
    /// Gravity `ρ A g`, dimensionless `Q/(Fr² u)`.
    Gravity,
    /// Tangential Stokes drag `μ_* r_τ,S^δ (v_air − u)`.
    AirDrag,
    /// Convective heat loss `−π d α (T − T_air)`, `α = λ_*/d 𝒩`.
    Convection,
    /// Viscous heating `N u'`.
    ViscousHeating,
    /// Grey-body radiation `−π d ε σ (T⁴ − T_air⁴)`.
    Radiation {
        /// Emissivity ε \[-\].
        emissivity: f64,
    },
    /// A user term (SI), see [`FiberTerm`].
    Custom(Box<dyn DynDualScalarFn>),
}

impl std::fmt::Debug for TermKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TermKind::Gravity => write!(f, "Gravity"),
            TermKind::AirDrag => write!(f, "AirDrag"),
            TermKind::Convection => write!(f, "Convection"),
            TermKind::ViscousHeating => write!(f, "ViscousHeating"),
            TermKind::Radiation { emissivity } => write!(f, "Radiation({emissivity})"),
            TermKind::Custom(_) => write!(f, "Custom"),
        }
    }
}

/// A named contribution.
#[derive(Debug)]
pub struct Term {
    /// Name used in reports (and as parameter name of its strength).
    pub name: &'static str,
    /// Which balance it enters.
    pub balance: Balance,
    /// Its factor.
    pub strength: Strength,
    /// Its physics.
    pub kind: TermKind,
}

impl Term {
    /// Name of its strength as a model parameter: the candidate effect's name where the term's
    /// strength is one (`nusselt_scale` for `convection`, its descriptor
    /// `super::catalog::NUSSELT_SCALE`), else the term's name.
    pub fn parameter_name(&self) -> &'static str {
        match self.kind {
            TermKind::Convection => NUSSELT_SCALE.model_param,
            _ => self.name,
        }
    }
}

/// Process and instrument factors of a model evaluation (dual numbers, so that derivatives with
/// respect to the process parameters are exact).
#[derive(Debug, Clone, Copy)]
pub struct ProcessFactors<D> {
    /// Factor on the nominal inlet velocity from `inlet_velocity` and `inlet_diameter`:
    /// `(1 + δ_u)/(1 + δ_d)²` \[-\].
    pub inlet_velocity: D,
    /// Offset of the die temperature `ΔT/T_o` \[-\] (dimensionless).
    pub die_temperature: D,
    /// Factor `1 + δ` on the mass flow \[-\].
    pub mass_flow: D,
    /// Whether the die temperature offset is present (else `die_temperature` is exactly 0).
    pub has_die_temperature: bool,
    /// Whether the mass-flow scale is present (else `mass_flow` is exactly 1).
    pub has_mass_flow: bool,
}

/// The set of contributions: the force and heat terms, the Nusselt law, and the built-in
/// effects that change the air, the inlet, the gauge or the material data (each a modifier
/// registered in `modifiers`, held in registry order, added by its `with_*` builder,
/// [`enable`](Self::enable) or [`set_strength`](Self::set_strength)).
#[derive(Debug)]
pub struct Physics<H: NusseltLaw = InclinedChurchillBernstein> {
    /// Named terms, in evaluation and report order.
    pub terms: Vec<Term>,
    /// The Nusselt law of the convection term.
    pub nusselt: H,
    /// Slenderness `δ` of the drag coefficient \[-\] (paper: 1e-3).
    pub slenderness: f64,
    /// The modifiers, in registry order.
    modifiers: Vec<Part>,
    /// Whether a modifier moves the air.
    air_flow: bool,
}

impl Default for Physics {
    fn default() -> Self {
        Physics::paper()
    }
}

impl Physics {
    /// The paper's model: gravity, air drag, convection (default Nusselt law), viscous heating;
    /// still air at uniform temperature.
    pub fn paper() -> Self {
        Physics::with_nusselt(InclinedChurchillBernstein::default())
    }
}

impl<H: NusseltLaw> Physics<H> {
    /// The paper's set of terms with a user Nusselt law.
    pub fn with_nusselt(nusselt: H) -> Self {
        let t = |name, balance, kind| Term {
            name,
            balance,
            strength: Strength::Fixed(1.0),
            kind,
        };
        Physics {
            terms: vec![
                t("gravity", Balance::Momentum, TermKind::Gravity),
                t("air_drag", Balance::Momentum, TermKind::AirDrag),
                t("convection", Balance::Energy, TermKind::Convection),
                t("viscous_heating", Balance::Energy, TermKind::ViscousHeating),
            ],
            nusselt,
            slenderness: super::scaling::PAPER_SLENDERNESS,
            modifiers: Vec::new(),
            air_flow: false,
        }
    }

    /// Adds grey-body radiation with emissivity `emissivity` \[-\] (term `"radiation"`).
    pub fn with_radiation(mut self, emissivity: f64) -> Self {
        self.terms.push(Term {
            name: RADIATION.model_param,
            balance: Balance::Energy,
            strength: Strength::Fixed(1.0),
            kind: TermKind::Radiation { emissivity },
        });
        self
    }

    /// Whether the air moves (an aspirator co-flow or a co-flow along the line).
    pub fn has_air_flow(&self) -> bool {
        self.air_flow
    }

    /// Puts `part` in registry order, replacing a part of the same kind.
    pub(crate) fn put(&mut self, part: Part) {
        let rank = part.kind.rank();
        match self
            .modifiers
            .binary_search_by_key(&rank, |p| p.kind.rank())
        {
            Ok(i) => self.modifiers[i] = part,
            Err(i) => self.modifiers.insert(i, part),
        }
        self.air_flow = self.modifiers.iter().any(|p| p.kind.moves_air());
    }

    /// The strength of effect `effect`'s strength (its descriptor's
    /// [`model_param`](super::catalog::EffectDescriptor::model_param)): a term's or a
    /// modifier's, `Off` where the physics does not have it.
    pub fn strength_of(&self, effect: EffectId) -> Strength {
        let name = effect.name();
        if let Some(t) = self.terms.iter().find(|t| t.parameter_name() == name) {
            return t.strength;
        }
        self.modifiers
            .iter()
            .find(|p| p.kind.effect().id() == effect)
            .map_or(Strength::Off, |p| p.strengths[0])
    }

    /// Adds a user term (SI) named `name` to `balance`.
    pub fn with_custom<T: FiberTerm + 'static>(
        mut self,
        name: &'static str,
        balance: Balance,
        term: T,
    ) -> Self {
        self.terms.push(Term {
            name,
            balance,
            strength: Strength::Fixed(1.0),
            kind: TermKind::Custom(Box::new(UserTerm(term))),
        });
        self
    }

    /// Sets the strength named `name`: a term's (by its name or [`Term::parameter_name`], e.g.
    /// `"convection"` or `"nusselt_scale"`) or a modifier's strength or shape, named by its
    /// effect's descriptor: `"air_coflow"`, `"air_coflow.decay_length"` and `"air_coflow.tail"`
    /// (need [`with_coflow`](Self::with_coflow)), `"air_coflow_line"`,
    /// `"air_coflow_line.onset"`, `"air_coflow_line.ramp_width"` (need
    /// [`with_line_coflow`](Self::with_line_coflow)), `"air_temperature_profile"` and
    /// `"air_temperature_profile.decay_length"` (need [`with_warm_air`](Self::with_warm_air)),
    /// a process or instrument parameter (`"inlet_velocity"`, `"inlet_diameter"`,
    /// `"die_temperature_offset"`, `"mass_flow_scale"`, `"gauge_scale"`, `"gauge_offset"`) or a
    /// material-data offset (`"vft_b_offset"`, `"vft_t_vf_offset"`), which setting adds. An
    /// unknown name, or an air profile that is not there, is an error.
    pub fn set_strength(&mut self, name: &str, strength: Strength) -> Result<(), FiberError> {
        if let Some(t) = self
            .terms
            .iter_mut()
            .find(|t| t.name == name || t.parameter_name() == name)
        {
            t.strength = strength;
            return Ok(());
        }
        for p in &mut self.modifiers {
            if let Some((slot, _, _)) = p.slots().find(|s| s.1 == name) {
                p.strengths[slot] = strength;
                return Ok(());
            }
        }
        let registered = modifiers::registered();
        let Some((kind, strengths, added_by)) = registered.iter().find(|(k, s, _)| {
            Part {
                kind: *k,
                strengths: *s,
            }
            .slots()
            .any(|s| s.1 == name)
        }) else {
            let mut known: Vec<&str> = self.terms.iter().map(|t| t.parameter_name()).collect();
            let parts: Vec<Part> = registered
                .iter()
                .map(|(kind, strengths, _)| Part {
                    kind: *kind,
                    strengths: *strengths,
                })
                .collect();
            known.extend(modifiers::slot_order(&parts).iter().map(|s| s.2));
            return Err(FiberError::InvalidInput(format!(
                "unknown strength \"{name}\"; the strengths are {}",
                known.join(", ")
            )));
        };
        if let Some((how, what)) = added_by {
            return Err(FiberError::InvalidInput(format!(
                "strength {name}: the physics has no {what} (add it with {how})"
            )));
        }
        self.put(Part {
            kind: *kind,
            strengths: *strengths,
        });
        self.set_strength(name, strength)
    }

    /// Switches on the built-in part that carries the strength named `name` (an effect's
    /// [`model_param`](super::catalog::EffectDescriptor::model_param)), at unit amplitude with
    /// its shapes at their defaults: the radiation term (emissivity 1) or a modifier that needs
    /// its builder (the aspirator co-flow, the co-flow along the line or the warm-air profile,
    /// speed or excess 1). Nothing changes where the part is there already or always is (a
    /// term's factor such as `nusselt_scale`, a process, instrument or material parameter). Set
    /// the strength afterwards with [`set_strength`](Self::set_strength); an unknown name is an
    /// error.
    pub fn enable(mut self, name: &str) -> Result<Self, FiberError> {
        if self.terms.iter().any(|t| t.parameter_name() == name) {
            return Ok(self);
        }
        if name == RADIATION.model_param {
            return Ok(self.with_radiation(1.0));
        }
        for (kind, strengths, added_by) in modifiers::registered() {
            let part = Part { kind, strengths };
            if !part.slots().any(|s| s.1 == name) {
                continue;
            }
            let present = self.modifiers.iter().any(|p| p.kind.rank() == kind.rank());
            if added_by.is_some() && !present && kind.effect().model_param == name {
                self.put(part);
            }
            return Ok(self);
        }
        Err(FiberError::InvalidInput(format!(
            "no built-in part of the physics carries the strength \"{name}\""
        )))
    }

    /// Builder form of [`set_strength`](Self::set_strength).
    pub fn strength(mut self, name: &str, strength: Strength) -> Result<Self, FiberError> {
        self.set_strength(name, strength)?;
        Ok(self)
    }

    /// Names and default values of the strengths that are model parameters, in `p` order:
    /// terms first (in term order, by [`Term::parameter_name`]), then the modifiers' (named by
    /// the effects' descriptors) in registry order, each modifier's strength and the shapes
    /// fitted with it, then the shapes that are not (`"air_coflow.tail"`).
    pub fn strength_parameters(&self) -> Vec<(&'static str, f64)> {
        let mut v: Vec<(&'static str, f64)> = self
            .terms
            .iter()
            .filter_map(|t| match t.strength {
                Strength::Parameter(d) => Some((t.parameter_name(), d)),
                _ => None,
            })
            .collect();
        for (i, slot, name) in modifiers::slot_order(&self.modifiers) {
            if let Strength::Parameter(d) = self.modifiers[i].strengths[slot] {
                v.push((name, d));
            }
        }
        v
    }
}

/// The reference values that turn dimensionless states into SI ones (`x_SI = x̃ · scale`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SiScales {
    /// `u_o` \[m/s\]: speed (also of the air).
    pub velocity: f64,
    /// `N_o` \[N\]: axial force.
    pub force: f64,
    /// `T_o` \[K\]: temperature (also of the air).
    pub temperature: f64,
    /// `u_o/L_o` \[1/s\]: strain rate.
    pub strain_rate: f64,
    /// `d_o` \[m\]: diameter.
    pub diameter: f64,
    /// `ρ_o` \[kg/m³\]: density.
    pub density: f64,
    /// `c_p,o` \[J/(kg K)\]: heat capacity.
    pub heat_capacity: f64,
    /// `L_o` \[m\]: position along the spin line.
    pub length: f64,
}

/// Dimensionless coefficients of the built-in terms, computed once from the scaling.
#[derive(Debug, Clone, Copy)]
pub struct Coefficients {
    /// Dimensionless mass flow `Q̃` \[-\].
    pub q: f64,
    /// `1/Fr²` \[-\].
    pub inv_fr2: f64,
    /// Drag factor `(A_*/Re_*) r_τ,S ρ̃_* ν̃_*` \[-\].
    pub drag: f64,
    /// Convection factor `π (St/Nu_*) λ̃_*` \[-\].
    pub convection: f64,
    /// `Re_*/ν̃_*` [-]: the air Reynolds number is this times `d̃ ṽ_rel`.
    pub re_air: f64,
    /// Prandtl number of the actual air \[-\].
    pub pr: f64,
    /// The Nusselt law's preprocessed Prandtl argument ([`NusseltLaw::prandtl_argument`]).
    pub pr_arg: f64,
    /// Eckert number \[-\].
    pub ec: f64,
    /// Radiation factor `π σ T_o³ d_o L_o/(c_p,o Q_o)` \[-\] (times ε).
    pub radiation: f64,
    /// Uniform air temperature `T̃_air` \[-\].
    pub t_air: f64,
    /// Dimensionless spin-line length `L̃` \[-\].
    pub length: f64,
    /// SI factors of the states and of `s`.
    pub si: SiScales,
    /// `f_o` \[N/m\].
    pub force_per_length: f64,
    /// `h_o` \[W/m\].
    pub heat_per_length: f64,
}

impl Coefficients {
    /// Coefficients for `air`, mass flow `q_si` \[kg/s\], air temperature `t_air_si` \[K\] and
    /// spin-line length `length_si` \[m\].
    pub fn new(
        scaling: &super::scaling::Scaling,
        air: &Air,
        slenderness: f64,
        q_si: f64,
        t_air_si: f64,
        length_si: f64,
    ) -> Self {
        let r = &scaling.reference;
        let rho_a = air.density / r.air_density;
        let nu_a = air.kinematic_viscosity / r.air_kinematic_viscosity;
        let lam_a = air.heat_conductivity / r.air_heat_conductivity;
        let cp_a = air.heat_capacity / r.air_heat_capacity;
        Coefficients {
            q: q_si / r.mass_flow,
            inv_fr2: scaling.inv_fr2(),
            drag: scaling.drag_factor(slenderness) * rho_a * nu_a,
            convection: PI * scaling.st_over_nu() * lam_a,
            re_air: scaling.re_star / nu_a,
            pr: scaling.pr_star * cp_a * rho_a * nu_a / lam_a,
            pr_arg: scaling.pr_star * cp_a * rho_a * nu_a / lam_a,
            ec: scaling.ec,
            radiation: PI
                * STEFAN_BOLTZMANN
                * r.temperature.powi(3)
                * scaling.diameter()
                * r.length
                / (r.heat_capacity * r.mass_flow),
            t_air: t_air_si / r.temperature,
            length: length_si / r.length,
            si: SiScales {
                velocity: r.velocity,
                force: scaling.force(),
                temperature: r.temperature,
                strain_rate: scaling.strain_rate(),
                diameter: scaling.diameter(),
                density: r.density,
                heat_capacity: r.heat_capacity,
                length: r.length,
            },
            force_per_length: scaling.force_per_length(),
            heat_per_length: scaling.heat_per_length(),
        }
    }
}

/// Local dimensionless state handed to the built-in terms.
#[derive(Debug, Clone, Copy)]
pub struct LocalState<D> {
    /// Position `s̃` \[-\].
    pub s: f64,
    /// `ũ` \[-\].
    pub u: D,
    /// `Ñ` \[-\].
    pub n: D,
    /// `T̃` \[-\].
    pub t: D,
    /// `ε̇̃` \[-\].
    pub rate: D,
    /// `ρ̃(T̃)` \[-\].
    pub rho: D,
    /// `c̃_p(T̃)` \[-\].
    pub cp: D,
    /// `d̃ = 2√(Q̃/(π ρ̃ ũ))` \[-\].
    pub d: D,
    /// Mass flow `Q̃` \[-\] (the nominal one times the mass-flow factor).
    pub q: D,
    /// `T̃_air(s̃)` \[-\].
    pub t_air: D,
    /// `ṽ_air(s̃)` \[-\].
    pub v_air: D,
}

#[inline]
fn strength_value<D: DualNum<Primitive = f64> + Copy>(
    s: &Strength,
    p: &[D],
    k: &mut usize,
) -> Option<D> {
    match *s {
        Strength::Off => None,
        Strength::Fixed(v) => Some(D::from(v)),
        Strength::Parameter(_) => {
            let v = p.get(*k).copied();
            *k += 1;
            Some(v.unwrap_or_else(|| D::from(f64::NAN)))
        }
    }
}

/// Where one strength comes from, resolved once ([`StrengthPlan`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Source {
    /// Switched off.
    Off,
    /// A fixed factor.
    Fixed(f64),
    /// Entry `i` of the strength parameters `sp`.
    Param(usize),
}

impl Source {
    /// The value with strength parameters `sp` (`NaN` where `sp` is too short), as
    /// [`strength_value`] gives it.
    #[inline]
    pub(crate) fn value<D: DualNum<Primitive = f64> + Copy>(self, sp: &[D]) -> Option<D> {
        match self {
            Source::Off => None,
            Source::Fixed(v) => Some(D::from(v)),
            Source::Param(i) => Some(sp.get(i).copied().unwrap_or_else(|| D::from(f64::NAN))),
        }
    }
}

/// The strengths of a [`Physics`] resolved once: for every term and every slot of every
/// modifier whether it is off, a fixed factor or which entry of the strength parameters `sp` it
/// reads. [`FiberModel`](crate::model::FiberModel) builds it at construction so that its right-hand
/// side neither counts the parameterised terms nor looks up the modifiers' slots on every call;
/// the `*_planned` methods of [`Physics`] take it. A plan belongs to the physics it was made
/// from: rebuild it ([`Physics::plan`]) after changing a strength.
#[derive(Debug, Clone, PartialEq)]
pub struct StrengthPlan {
    terms: Vec<Source>,
    modifiers: Vec<[Source; modifiers::SLOTS]>,
}

fn source(s: &Strength, k: &mut usize) -> Source {
    match *s {
        Strength::Off => Source::Off,
        Strength::Fixed(v) => Source::Fixed(v),
        Strength::Parameter(_) => {
            *k += 1;
            Source::Param(*k - 1)
        }
    }
}

impl<H: NusseltLaw> Physics<H> {
    /// The strengths resolved once (see [`StrengthPlan`]).
    pub fn plan(&self) -> StrengthPlan {
        let mut k = 0;
        let terms = self
            .terms
            .iter()
            .map(|t| source(&t.strength, &mut k))
            .collect();
        let mut parts = vec![[Source::Off; modifiers::SLOTS]; self.modifiers.len()];
        for (i, slot, _) in modifiers::slot_order(&self.modifiers) {
            parts[i][slot] = source(&self.modifiers[i].strengths[slot], &mut k);
        }
        StrengthPlan {
            terms,
            modifiers: parts,
        }
    }

    /// Number of strength parameters in `p`.
    pub fn num_strength_params(&self) -> usize {
        self.strength_parameters().len()
    }

    /// The process factors with the strengths resolved by `plan` (made by [`plan`](Self::plan)
    /// from this physics; `temperature_scale` = `T_o` \[K\]): inlet-velocity factor
    /// `(1 + δ_u)/(1 + δ_d)²`, die temperature offset `ΔT/T_o`, mass-flow factor `1 + δ`.
    /// Exactly 1, 0, 1 where the parameters are off.
    #[inline]
    pub fn process_planned<D: DualNum<Primitive = f64> + Copy>(
        &self,
        plan: &StrengthPlan,
        sp: &[D],
        temperature_scale: f64,
    ) -> ProcessFactors<D> {
        let mut f = InletFactors {
            velocity: None,
            die_temperature: None,
            mass_flow: None,
        };
        for (p, src) in self.modifiers.iter().zip(&plan.modifiers) {
            p.kind
                .inlet(Part::values(src, sp), temperature_scale, &mut f);
        }
        ProcessFactors {
            inlet_velocity: f.velocity.unwrap_or(D::one()),
            die_temperature: f.die_temperature.unwrap_or(D::zero()),
            mass_flow: f.mass_flow.unwrap_or(D::one()),
            has_die_temperature: f.die_temperature.is_some(),
            has_mass_flow: f.mass_flow.is_some(),
        }
    }

    /// The shift of the VFT parameters `(ΔB/T_o, ΔT_VF/T_o)` (dimensionless) with the strengths
    /// resolved by `plan` (`temperature_scale` = `T_o` \[K\]); `None` where both are off.
    #[inline]
    pub fn vft_shift_planned<D: DualNum<Primitive = f64> + Copy>(
        &self,
        plan: &StrengthPlan,
        sp: &[D],
        temperature_scale: f64,
    ) -> Option<[D; 2]> {
        let mut shift = [None, None];
        for (p, src) in self.modifiers.iter().zip(&plan.modifiers) {
            p.kind
                .material(Part::values(src, sp), temperature_scale, &mut shift);
        }
        match shift {
            [None, None] => None,
            [b, t] => Some([b.unwrap_or(D::zero()), t.unwrap_or(D::zero())]),
        }
    }

    /// The gauge's reading of a true diameter with the strengths resolved by `plan`:
    /// `(1 + g) d + o` with `d`, the result and `diameter_scale` = `d_o` \[m\] (the offset `o` is
    /// in µm); `d` itself where the gauge parameters are off.
    #[inline]
    pub fn gauge_reading_planned<D: DualNum<Primitive = f64> + Copy>(
        &self,
        plan: &StrengthPlan,
        d: D,
        sp: &[D],
        diameter_scale: f64,
    ) -> D {
        let mut out = d;
        for (p, src) in self.modifiers.iter().zip(&plan.modifiers) {
            p.kind
                .gauge(Part::values(src, sp), diameter_scale, &mut out);
        }
        out
    }

    /// `(T̃_air(s̃), ṽ_air(s̃))` with the strengths resolved by `plan`.
    #[inline]
    pub fn environment_planned<D: DualNum<Primitive = f64> + Copy>(
        &self,
        plan: &StrengthPlan,
        s: f64,
        sp: &[D],
        co: &Coefficients,
    ) -> (D, D) {
        let mut air = AirProfile {
            excess: None,
            speed: None,
        };
        for (p, src) in self.modifiers.iter().zip(&plan.modifiers) {
            p.kind.air(Part::values(src, sp), s, co, &mut air);
        }
        let t = match air.excess {
            Some(e) => e + co.t_air,
            None => D::from(co.t_air),
        };
        (t, air.speed.unwrap_or(D::zero()))
    }
    /// Unscaled dimensionless value of one term (force per length in units of `f_o` or heat
    /// per length in units of `h_o`).
    ///
    /// Out of line on purpose: inlined into the right-hand side's loop over the terms, it makes
    /// that loop slower, in `f64` and in the dense dual passes alike (criterion, `fiber_rhs_*`).
    #[inline(never)]
    pub fn term_value<D: DualNum<Primitive = f64> + Copy>(
        &self,
        term: &Term,
        st: &LocalState<D>,
        co: &Coefficients,
    ) -> D {
        match &term.kind {
            TermKind::Gravity => st.u.recip() * (st.q * co.inv_fr2),
            TermKind::AirDrag => (st.v_air - st.u) * co.drag,
            TermKind::Convection => {
                let re_tau = st.d * (st.v_air - st.u) * co.re_air;
                let nu = match self.has_air_flow() {
                    false => self.nusselt.nusselt(re_tau, re_tau * re_tau, co.pr_arg),
                    true => {
                        let w = st.v_air * (co.si.velocity / COFLOW_REGULARISATION_SPEED);
                        let w2 = w * w;
                        let extra = w2 / (w2 + 1.0)
                            * (COFLOW_INCLINATION_REGULARISATION
                                * COFLOW_INCLINATION_REGULARISATION);
                        self.nusselt
                            .nusselt_regularised(re_tau, re_tau * re_tau, co.pr_arg, extra)
                    }
                };
                -nu * (st.t - st.t_air) * co.convection
            }
            TermKind::ViscousHeating => st.n * st.rate * co.ec,
            TermKind::Radiation { emissivity } => {
                let t2 = st.t * st.t;
                let ta2 = st.t_air * st.t_air;
                -st.d * (t2 * t2 - ta2 * ta2) * (co.radiation * emissivity)
            }
            TermKind::Custom(f) => Self::custom_term_value(f.as_ref(), term.balance, st, co),
        }
    }

    /// The value of a user-written term (dimensionless, as [`term_value`](Self::term_value)):
    /// its SI arguments, [`eval_dyn`], scaled back. Out of line: inlined into the right-hand
    /// side, its argument array made the right-hand side of every model (with or without user
    /// terms) slower.
    #[cold]
    #[inline(never)]
    fn custom_term_value<D: DualNum<Primitive = f64> + Copy>(
        f: &dyn DynDualScalarFn,
        balance: Balance,
        st: &LocalState<D>,
        co: &Coefficients,
    ) -> D {
        let si = &co.si;
        let args = [
            st.u * si.velocity,
            st.n * si.force,
            st.t * si.temperature,
            st.rate * si.strain_rate,
            st.d * si.diameter,
            st.rho * si.density,
            st.cp * si.heat_capacity,
            st.t_air * si.temperature,
            st.v_air * si.velocity,
        ];
        let v = eval_dyn(f, st.s * si.length, &args[..SI_ARGS]);
        let scale = match balance {
            Balance::Momentum => co.force_per_length,
            Balance::Energy => co.heat_per_length,
        };
        v * (1.0 / scale)
    }

    /// `(Σ F_k, Σ H_k)`: total dimensionless force and heat gain per length with strength
    /// parameters `sp`.
    #[inline]
    pub fn sums<D: DualNum<Primitive = f64> + Copy>(
        &self,
        st: &LocalState<D>,
        sp: &[D],
        co: &Coefficients,
    ) -> (D, D) {
        let mut force = D::zero();
        let mut heat = D::zero();
        let mut k = 0;
        for term in &self.terms {
            if let Some(f) = strength_value(&term.strength, sp, &mut k) {
                let v = self.term_value(term, st, co) * f;
                match term.balance {
                    Balance::Momentum => force += v,
                    Balance::Energy => heat += v,
                }
            }
        }
        (force, heat)
    }

    /// [`sums`](Self::sums) with the strengths resolved by `plan` (made by [`plan`](Self::plan)
    /// from this physics: one source per term).
    #[inline]
    pub fn sums_planned<D: DualNum<Primitive = f64> + Copy>(
        &self,
        plan: &StrengthPlan,
        st: &LocalState<D>,
        sp: &[D],
        co: &Coefficients,
    ) -> (D, D) {
        let mut force = D::zero();
        let mut heat = D::zero();
        for (term, src) in self.terms.iter().zip(&plan.terms) {
            if let Some(f) = src.value(sp) {
                let v = self.term_value(term, st, co) * f;
                match term.balance {
                    Balance::Momentum => force += v,
                    Balance::Energy => heat += v,
                }
            }
        }
        (force, heat)
    }

    /// Value of every term (strength applied) at `st`: `(name, balance, dimensionless value)`.
    pub fn report(
        &self,
        st: &LocalState<f64>,
        sp: &[f64],
        co: &Coefficients,
    ) -> Vec<(&'static str, Balance, f64)> {
        let mut k = 0;
        self.terms
            .iter()
            .map(|term| {
                let v = match strength_value(&term.strength, sp, &mut k) {
                    Some(f) => self.term_value(term, st, co) * f,
                    None => 0.0,
                };
                (term.name, term.balance, v)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use modifiers::coflow_decay;

    /// The Churchill–Bernstein factor `(1 + x)^(4/5)` by its series: value and slope equal to
    /// the closed form (`exp(⅘ log1p x)`, slope `⅘ (1 + x)^(−1/5)`) over the series' range and
    /// across its limit, where the two branches meet: values to 4e-16 relative, slopes to
    /// 2e-15 (the truncated slope series' remainder `9 C(⅘, 9) x⁸` is 1e-15 of `⅘` at the
    /// limit). The literal `282000^(−5/8)` equals `powf`'s value to one unit in the last place.
    #[test]
    fn the_four_fifths_power_series_equals_the_closed_form() {
        use num_dual::Dual64;
        let reference = 282000f64.powf(-0.625);
        assert!((CB_REYNOLDS_SCALE_POW - reference).abs() <= f64::EPSILON * reference);
        let mut worst = (0.0f64, 0.0f64);
        let limit = FOUR_FIFTHS_SERIES_LIMIT;
        let points = (0..=400).map(|i| f64::from(i) / 400.0 * limit * 1.5);
        for x in points.chain([limit * (1.0 - 1e-12), limit, 1e-9, 0.5, 3.0]) {
            let d = one_plus_pow_four_fifths(Dual64::from_re(x).derivative());
            let value = (x.ln_1p() * 0.8).exp();
            let slope = 0.8 * (1.0 + x).powf(-0.2);
            worst.0 = worst.0.max((d.re - value).abs() / value);
            worst.1 = worst.1.max((d.eps - slope).abs() / slope);
        }
        assert!(
            worst.0 < 4e-16 && worst.1 < 2e-15,
            "relative errors {worst:?}"
        );
    }

    /// The co-flow's extra regularisation: none in still air (the base model exactly), at most
    /// the documented relative change at `Re ≥ 1`, and a Nusselt number whose slope in `Re`
    /// stays bounded across the point where the air overtakes the fiber (without it, the
    /// `Re^½` cusp of width 1e-3 makes the slope reach ~10 per unit `Re`).
    #[test]
    fn coflow_regularisation_widens_the_crossing_and_leaves_still_air_alone() {
        use num_dual::Dual64;
        let law = InclinedChurchillBernstein::default();
        let pr = law.prandtl_argument(0.7);
        let eps2 = COFLOW_INCLINATION_REGULARISATION * COFLOW_INCLINATION_REGULARISATION;
        let plain = |re: f64| law.nusselt(re, re * re, pr);
        let coflow = |re: f64| law.nusselt_regularised(re, re * re, pr, eps2);
        for re in [0.0, 1e-4, 0.3, 2.0, 50.0] {
            let still: f64 = law.nusselt_regularised(re, re * re, pr, 0.0);
            assert_eq!(still.to_bits(), plain(re).to_bits(), "Re {re}");
        }
        for re in [1.0, 3.0, 30.0, 300.0] {
            let rel = (coflow(re) / plain(re) - 1.0).abs();
            // inclination factor ≤ ε²/Re², Re_ε^½ ≤ ε²/(4 Re²) (relative)
            assert!(rel <= 1.25 * eps2 / (re * re), "Re {re}: {rel:e}");
        }
        let slope = |f: &dyn Fn(Dual64) -> Dual64, re: f64| f(Dual64::from_re(re).derivative()).eps;
        let max_slope = |f: &dyn Fn(Dual64) -> Dual64| {
            (-400..=400)
                .map(|i| slope(f, f64::from(i) * 2.5e-4))
                .fold(0.0f64, |a, v| a.max(v.abs()))
        };
        let wide = max_slope(&|re| law.nusselt_regularised(re, re * re, pr, Dual64::from(eps2)));
        let narrow = max_slope(&|re| law.nusselt(re, re * re, pr));
        assert!(wide < 3.0, "slope with the co-flow's regularisation {wide}");
        assert!(narrow > 5.0 * wide, "slope without {narrow} against {wide}");
    }

    #[test]
    fn coflow_decay_spans_exponential_and_algebraic_tails() {
        use num_dual::Dual64;
        // the closed form, accurate for small r u too
        let direct = |u: f64, r: f64| (-(r * u).ln_1p() / r).exp();
        for u in [0.0, 0.3, 1.0, 4.0, 25.0] {
            // r = 0: the exponential
            let e: f64 = coflow_decay(u, 0.0);
            assert!(
                (e - (-u).exp()).abs() <= 1e-15 * (-u).exp().max(1e-300),
                "{u}: {e}"
            );
            // both branches against the closed form, on either side of the switch |r u| = 1e-2
            for r in [
                1e-7,
                1e-4,
                0.9e-2 / u.max(1.0),
                1.1e-2 / u.max(1.0),
                0.3,
                0.5,
                1.0,
            ] {
                let v: f64 = coflow_decay(u, r);
                let w = direct(u, r);
                assert!((v - w).abs() <= 1e-12 * w, "u {u} r {r}: {v} vs {w}");
            }
            // the derivative in r at r = 0 (the series branch): u² e^(−u) / 2, and against a
            // central difference of the closed form at r = 0.3 (the logarithm branch)
            let d0 = coflow_decay(Dual64::from_re(u), Dual64::from_re(0.0).derivative()).eps;
            let exact = 0.5 * u * u * (-u).exp();
            assert!(
                (d0 - exact).abs() <= 1e-14 * exact.max(1e-300),
                "{u}: {d0} vs {exact}"
            );
            let d3 = coflow_decay(Dual64::from_re(u), Dual64::from_re(0.3).derivative()).eps;
            let h = 1e-6;
            let fd = (direct(u, 0.3 + h) - direct(u, 0.3 - h)) / (2.0 * h);
            assert!(
                (d3 - fd).abs() <= 1e-7 * fd.abs().max(1e-12),
                "{u}: {d3} vs {fd}"
            );
        }
        // the tails: inverse square at r = 1/2, inverse at r = 1
        let far: f64 = 1e4;
        assert!((coflow_decay(far, 0.5_f64) * (far / 2.0).powi(2) - 1.0).abs() < 1e-3);
        assert!((coflow_decay(far, 1.0_f64) * far - 1.0).abs() < 1e-3);
    }

    /// Every strength slot is named by a built-in descriptor (its strength or a shape), each
    /// descriptor of a part of the physics is switched on by [`Physics::enable`] with its
    /// strength and shapes settable, and nothing else is named.
    #[test]
    fn slots_are_named_by_the_descriptors() {
        use crate::model::catalog::{Install, BUILTIN};
        let mut named: Vec<&str> = Vec::new();
        for d in BUILTIN {
            if d.install != Install::Physics {
                continue;
            }
            let mut p = Physics::paper()
                .enable(d.model_param)
                .and_then(|p| p.strength(d.model_param, Strength::Parameter(0.0)))
                .unwrap_or_else(|e| panic!("{}: {e}", d.name));
            for s in d.shapes {
                p.set_strength(s.model_param, Strength::Parameter(s.default))
                    .unwrap();
                named.push(s.model_param);
            }
            if !p.terms.iter().any(|t| t.parameter_name() == d.model_param) {
                named.push(d.model_param);
            }
            // enabling twice changes nothing
            let n = p.num_strength_params();
            assert_eq!(p.enable(d.model_param).unwrap().num_strength_params(), n);
        }
        named.sort_unstable();
        let registered: Vec<Part> = modifiers::registered()
            .into_iter()
            .map(|(kind, strengths, _)| Part { kind, strengths })
            .filter(|p| p.kind.effect().id() != modifiers::test_effect::UNIFORM_AIR.id())
            .collect();
        let mut slots: Vec<&str> = modifiers::slot_order(&registered)
            .iter()
            .map(|s| s.2)
            .collect();
        slots.sort_unstable();
        assert_eq!(named, slots);
        assert!(Physics::paper().enable("nonsense").is_err());
        let e = Physics::paper()
            .strength("air_coflow.tail", Strength::Fixed(0.5))
            .unwrap_err();
        assert!(e.to_string().contains("with_coflow"), "{e}");
    }

    #[test]
    fn still_air_nusselt_is_half_churchill_bernstein() {
        let law = InclinedChurchillBernstein::default();
        let pr: f64 = 0.64516;
        let re: f64 = 1.7;
        let cb = 0.3
            + 0.62
                * re.sqrt()
                * pr.cbrt()
                * (1.0 + (0.4 / pr).powf(2.0 / 3.0)).powf(-0.25)
                * (1.0 + (re / 282000.0).powf(0.625)).powf(0.8);
        let v = law.nusselt(-re, re * re, law.prandtl_argument(pr));
        assert!((v - 0.5 * cb).abs() < 1e-6 * cb, "{v} {cb}");
        let cross = law.nusselt(0.0, re * re, law.prandtl_argument(pr));
        assert!((cross - cb).abs() < 1e-6 * cb);
    }

    /// The planned evaluation of the modifiers gives the closed forms of the model's equations,
    /// bit for bit, with air profiles, process and instrument parameters mixed and set in any
    /// order; the parameters come in registry order (each strength with its fitted shapes,
    /// then the others); a too short `sp` gives NaN strengths. Terms: planned and plain sums
    /// agree bit for bit.
    #[test]
    fn planned_evaluation_is_the_closed_form() {
        let physics = Physics::paper()
            .with_radiation(0.9)
            .strength("gauge_offset", Strength::Parameter(1.5))
            .and_then(|p| p.strength("mass_flow_scale", Strength::Parameter(-0.02)))
            .map(|p| p.with_warm_air(30.0, 0.05).with_coflow(2.0, 0.1))
            .and_then(|p| p.strength("radiation", Strength::Parameter(0.8)))
            .and_then(|p| p.strength("air_coflow", Strength::Parameter(1.1)))
            .and_then(|p| p.strength("air_coflow.tail", Strength::Parameter(0.2)))
            .and_then(|p| p.strength("air_coflow.decay_length", Strength::Parameter(0.12)))
            .and_then(|p| p.strength("air_temperature_profile", Strength::Fixed(0.7)))
            .and_then(|p| p.strength("inlet_diameter", Strength::Parameter(0.05)))
            .and_then(|p| p.strength("die_temperature_offset", Strength::Parameter(3.0)))
            .and_then(|p| p.strength("gauge_scale", Strength::Fixed(0.01)))
            .unwrap();
        let names: Vec<&str> = physics.strength_parameters().iter().map(|p| p.0).collect();
        assert_eq!(
            names,
            [
                "radiation",
                "air_coflow",
                "air_coflow.decay_length",
                "inlet_diameter",
                "die_temperature_offset",
                "mass_flow_scale",
                "gauge_offset",
                "air_coflow.tail"
            ]
        );
        let plan = physics.plan();
        let n = physics.num_strength_params();
        let sp: Vec<f64> = (0..n).map(|i| 0.3 + 0.1 * i as f64).collect();
        let co = Coefficients::new(
            &super::super::scaling::Scaling::default(),
            &Air::paper(),
            physics.slenderness,
            1e-4,
            300.0,
            1.0,
        );
        let bits = |v: f64| v.to_bits();
        let pf = physics.process_planned(&plan, &sp, 500.0);
        let swell = sp[3] + 1.0;
        assert_eq!(bits(pf.inlet_velocity), bits(1.0 / (swell * swell)));
        assert_eq!(bits(pf.die_temperature), bits(sp[4] * 500f64.recip()));
        assert_eq!(bits(pf.mass_flow), bits(sp[5] + 1.0));
        assert!(pf.has_die_temperature && pf.has_mass_flow);
        assert_eq!(
            bits(physics.gauge_reading_planned(&plan, 0.7, &sp, 1e-4)),
            bits(0.7 * (0.01 + 1.0) + sp[6] * (1e-6 / 1e-4))
        );
        assert_eq!(physics.vft_shift_planned(&plan, &sp, 500.0), None);
        let short = &sp[..n - 2];
        assert!(physics
            .gauge_reading_planned(&plan, 0.7, short, 1e-4)
            .is_nan());
        assert!(physics
            .process_planned(&plan, short, 500.0)
            .mass_flow
            .is_finite());
        assert!(physics
            .process_planned(&plan, &sp[..5], 500.0)
            .mass_flow
            .is_nan());
        for s in [0.0, 0.4, 0.9] {
            let (t, v) = physics.environment_planned(&plan, s, &sp, &co);
            let u = ((co.length - s) * co.si.length) / sp[2];
            let v_closed = sp[1] * coflow_decay(u, sp[7]) * (2.0 / co.si.velocity);
            let warm = 0.7 * ((-s * co.si.length) / 0.05).exp() * (30.0 / co.si.temperature);
            assert_eq!((bits(t), bits(v)), (bits(warm + co.t_air), bits(v_closed)));
            let st = LocalState {
                s,
                u: 2.0,
                n: 5000.0,
                t: 0.9,
                rate: 3.0,
                rho: 1.1,
                cp: 1.2,
                d: 0.4,
                q: 1.0,
                t_air: t,
                v_air: v,
            };
            let (f, h) = physics.sums(&st, &sp, &co);
            let (fp, hp) = physics.sums_planned(&plan, &st, &sp, &co);
            assert_eq!((bits(f), bits(h)), (bits(fp), bits(hp)));
        }
    }
}
