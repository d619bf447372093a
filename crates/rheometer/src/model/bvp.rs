//! The strain-rate formulation of the stationary fiber model (paper eq. `num_c`) as a [`Bvp`].
//!
//! States (dimensionless): `y = (ũ, Ñ, T̃, ε̇̃)` on `s̃ ∈ [0, L̃]`, `L̃ = L/L_o`:
//!
//! ```text
//! u' = ε̇
//! N' = f_N = Q ε̇ − c Σ F_k
//! T' = f_T = c/(c_p Q) Σ H_k
//! ε̇' = [Re_c/Q (ρ N ε̇ + ρ u f_N + u N ∂_Tρ f_T) − ε̇ ∂_Tμ_e f_T] / (μ_e + ε̇ ∂_ε̇μ_e)
//! ```
//!
//! with `Re_c = c Re + (1 − c) Re_0`, and boundary conditions `u(0) = u_in`, `T(0) = T_in`, the
//! constitutive equation `Re_c/Q ρ(T_in) u_in N(0) = ε̇(0) μ_e(T_in, ε̇(0))` at the nozzle, and the
//! take-up `d(L) = c d_out + (1 − c) d(u_in, ρ(T_in))` (written relative, `d(L)/d_target − 1`) or
//! `u(L) = c u_out + (1 − c) u_in` (written `u(L)/u_target − 1`). `F_k`, `H_k` are the named
//! contributions of [`Physics`].
//!
//! **Parameter layout** (`p`, all fixed model parameters, none unknown):
//! `p = [c, law parameters (e.g. n, κ), strength parameters ([`Physics::strength_parameters`]),
//! take_up_factor]`. The last one, `φ` (neutral value 1), multiplies the prescribed take-up
//! diameter or speed: `d(L) = c φ d_out + (1 − c) d_in`. It makes the take-up condition a
//! differentiable parameter, so a fit can treat the take-up diameter as a nuisance parameter.
//! At `c = 0` the stress-free isothermal fiber `u ≡ u_in, N ≡ 0, T ≡ T_in, ε̇ ≡ 0` solves the
//! problem for every law parameter.

use super::contributions::{
    Balance, Coefficients, InclinedChurchillBernstein, LocalState, NusseltLaw, Physics,
    ProcessFactors, StrengthPlan,
};
use super::material_law::{
    viscosity, viscosity_shifted, viscosity_with_partials_shifted, VftShift, ViscosityLaw,
    ZeroRateViscosity,
};
use super::scaling::Scaling;
use super::setup::{Air, Experiment, Inlet, Material, TakeUp};
use crate::error::FiberError;
use diffbvp::problem::Bvp;
use num_dual::DualNum;
use std::f64::consts::PI;

/// Take-up condition in dimensionless form.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DimensionlessTakeUp {
    /// `d̃(L) = c d̃_out + (1 − c) d̃_in`.
    Diameter {
        /// `d̃_out` \[-\].
        d_out: f64,
        /// `d̃(ũ_in, ρ̃(T̃_in))` \[-\].
        d_in: f64,
    },
    /// `ũ(L) = c ũ_out + (1 − c) ũ_in`.
    Velocity {
        /// `ũ_out` \[-\].
        u_out: f64,
    },
}

/// The fiber model for one experiment: a [`Bvp`] with 4 states and
/// `1 + law.num_params() + physics.num_strength_params()` model parameters.
#[derive(Debug)]
pub struct FiberModel<L: ViscosityLaw, H: NusseltLaw = InclinedChurchillBernstein> {
    /// The elongational viscosity law.
    pub law: L,
    /// The contributions to the balances. Their strengths (off, fixed or which model parameter)
    /// are resolved once at construction ([`Physics::plan`]); build a new model to change them.
    pub physics: Physics<H>,
    /// The non-dimensionalisation.
    pub scaling: Scaling,
    /// The polymer (SI).
    pub material: Material,
    /// The air (SI).
    pub air: Air,
    /// The experiment (SI).
    pub experiment: Experiment,
    zero: ZeroRateViscosity,
    co: Coefficients,
    rho_a: f64,
    rho_b: f64,
    cp_a: f64,
    cp_b: f64,
    u_in: f64,
    t_in: f64,
    inlet_is_diameter: bool,
    re0: f64,
    take_up: DimensionlessTakeUp,
    params: ParamLayout,
    // the strengths of `physics` resolved at construction (the right-hand side reads them)
    plan: StrengthPlan,
    // whether the mass-flow scale is on (resolved at construction)
    mass_flow_scaled: bool,
}

/// Where each model parameter sits in `p = [c, law parameters..., strengths..., φ]`
/// ([`FiberModel::param_layout`]): plain index arithmetic, no lookups (the right-hand side
/// decodes `p` with it on every evaluation).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ParamLayout {
    n_law: usize,
    n_strength: usize,
}

impl ParamLayout {
    /// Index of the continuation parameter `c` (0: the stress-free fiber, 1: the model).
    pub const CONTINUATION: usize = 0;

    /// The layout for a law with `n_law` parameters and `n_strength` strength parameters.
    pub fn new(n_law: usize, n_strength: usize) -> Self {
        ParamLayout { n_law, n_strength }
    }

    /// Index of the continuation parameter `c`.
    #[inline]
    pub fn continuation(&self) -> usize {
        Self::CONTINUATION
    }

    /// Indices of the viscosity law's parameters.
    #[inline]
    pub fn law(&self) -> std::ops::Range<usize> {
        1..1 + self.n_law
    }

    /// Index of the law's parameter number `k` (for the Carreau-type law
    /// [`CarreauLike::N`](crate::model::CarreauLike::N) is `n`,
    /// [`CarreauLike::KAPPA`](crate::model::CarreauLike::KAPPA) is `κ`).
    #[inline]
    pub fn law_param(&self, k: usize) -> usize {
        debug_assert!(k < self.n_law, "law parameter {k} of {}", self.n_law);
        1 + k
    }

    /// Indices of the strength parameters (in [`Physics::strength_parameters`] order).
    #[inline]
    pub fn strengths(&self) -> std::ops::Range<usize> {
        1 + self.n_law..1 + self.n_law + self.n_strength
    }

    /// Index of the take-up factor `φ` (the last parameter).
    #[inline]
    pub fn take_up_factor(&self) -> usize {
        1 + self.n_law + self.n_strength
    }

    /// Number of model parameters.
    #[inline]
    pub fn len(&self) -> usize {
        2 + self.n_law + self.n_strength
    }

    /// Always `false` (`c` and `φ` are always there).
    pub fn is_empty(&self) -> bool {
        false
    }
}

fn positive(name: &str, v: f64) -> Result<f64, FiberError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(FiberError::InvalidInput(format!(
            "{name} must be positive and finite, got {v}"
        )))
    }
}

fn finite(name: &str, v: f64) -> Result<f64, FiberError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(FiberError::InvalidInput(format!(
            "{name} is not finite ({v})"
        )))
    }
}

impl<L: ViscosityLaw, H: NusseltLaw> FiberModel<L, H> {
    /// Builds the model with the paper's scaling (Table 2). Validates the inputs.
    pub fn new(
        material: &Material,
        air: &Air,
        experiment: &Experiment,
        law: L,
        physics: Physics<H>,
    ) -> Result<Self, FiberError> {
        Self::with_scaling(material, air, experiment, law, physics, Scaling::default())
    }

    /// Builds the model with a user scaling.
    pub fn with_scaling(
        material: &Material,
        air: &Air,
        experiment: &Experiment,
        law: L,
        physics: Physics<H>,
        scaling: Scaling,
    ) -> Result<Self, FiberError> {
        let e = experiment;
        let [q, length, t_in, t_air] =
            Self::checked_inputs(material, air, e, physics.slenderness, &scaling)?;
        let r = &scaling.reference;
        let (u_in_si, d_in_si) = Self::inlet_velocity_and_diameter(e, q, material.density(t_in))?;
        let take_up = Self::dimensionless_take_up(e, u_in_si, d_in_si, &scaling)?;
        let mut co = Coefficients::new(&scaling, air, physics.slenderness, q, t_air, length);
        co.pr_arg = physics.nusselt.prandtl_argument(co.pr);
        let zero = ZeroRateViscosity {
            a: material.trouton * material.vft_mu_c / r.viscosity,
            b: material.vft_b / r.temperature,
            t_vf: material.vft_t_vf / r.temperature,
        };
        let params = ParamLayout::new(law.num_params(), physics.num_strength_params());
        let plan = physics.plan();
        let mass_flow_scaled = !matches!(
            physics.strength_of(super::catalog::MASS_FLOW_SCALE.id()),
            super::contributions::Strength::Off
        );
        Ok(FiberModel {
            law,
            rho_a: material.density_slope * r.temperature / r.density,
            rho_b: material.density_intercept / r.density,
            cp_a: material.heat_capacity_slope * r.temperature / r.heat_capacity,
            cp_b: material.heat_capacity_intercept / r.heat_capacity,
            u_in: u_in_si / r.velocity,
            t_in: t_in / r.temperature,
            inlet_is_diameter: matches!(e.inlet, Inlet::Diameter(_)),
            re0: scaling.re,
            take_up,
            zero,
            co,
            physics,
            material: material.clone(),
            air: air.clone(),
            experiment: experiment.clone(),
            scaling,
            params,
            plan,
            mass_flow_scaled,
        })
    }

    /// The model's inputs checked: the experiment's mass flow, spin-line length and temperatures
    /// (above the Vogel temperature), the material and air properties, the `slenderness` and the
    /// reference values of `scaling`; `[mass flow, length, inlet and air temperatures]`, or an
    /// error naming the first input out of range.
    fn checked_inputs(
        material: &Material,
        air: &Air,
        e: &Experiment,
        slenderness: f64,
        scaling: &Scaling,
    ) -> Result<[f64; 4], FiberError> {
        let q = positive("mass flow", e.mass_flow)?;
        let length = positive("spin-line length", e.spinline_length)?;
        let t_in = positive("inlet temperature", e.inlet_temperature)?;
        let t_air = positive("air temperature", e.air_temperature)?;
        finite("density slope", material.density_slope)?;
        finite("density intercept", material.density_intercept)?;
        finite("heat capacity slope", material.heat_capacity_slope)?;
        finite("heat capacity intercept", material.heat_capacity_intercept)?;
        positive("VFT mu_c", material.vft_mu_c)?;
        finite("VFT B", material.vft_b)?;
        finite("VFT T_VF", material.vft_t_vf)?;
        positive("Trouton ratio", material.trouton)?;
        positive("air density", air.density)?;
        positive("air heat capacity", air.heat_capacity)?;
        positive("air kinematic viscosity", air.kinematic_viscosity)?;
        positive("air heat conductivity", air.heat_conductivity)?;
        if t_in <= material.vft_t_vf || t_air <= material.vft_t_vf {
            return Err(FiberError::InvalidInput(format!(
                "inlet ({t_in} K) and air ({t_air} K) temperatures must exceed the Vogel temperature {} K",
                material.vft_t_vf
            )));
        }
        for (what, t) in [("inlet", t_in), ("air", t_air)] {
            positive(
                &format!("density at the {what} temperature"),
                material.density(t),
            )?;
            positive(
                &format!("heat capacity at the {what} temperature"),
                material.heat_capacity(t),
            )?;
        }
        positive("slenderness", slenderness)?;
        let r = &scaling.reference;
        for (name, v) in [
            ("reference mass flow", r.mass_flow),
            ("reference length", r.length),
            ("reference velocity", r.velocity),
            ("reference temperature", r.temperature),
            ("reference density", r.density),
            ("reference heat capacity", r.heat_capacity),
            ("reference viscosity", r.viscosity),
            ("reference heat transfer", r.heat_transfer),
            ("reference air density", r.air_density),
            ("reference air heat capacity", r.air_heat_capacity),
            (
                "reference air kinematic viscosity",
                r.air_kinematic_viscosity,
            ),
            ("reference air heat conductivity", r.air_heat_conductivity),
            ("reference stress", r.stress),
            ("gravity", r.gravity),
        ] {
            positive(name, v)?;
        }
        Ok([q, length, t_in, t_air])
    }

    /// The inlet velocity and diameter \[SI\] of `e` (one given, the other from the mass flow `q`
    /// and the melt density `rho_in` at the inlet), each refused where it overflows or underflows.
    fn inlet_velocity_and_diameter(
        e: &Experiment,
        q: f64,
        rho_in: f64,
    ) -> Result<(f64, f64), FiberError> {
        let u_in_si = match e.inlet {
            Inlet::Diameter(d) => {
                let d = positive("inlet diameter", d)?;
                4.0 * q / (PI * rho_in * d * d)
            }
            Inlet::Velocity(u) => positive("inlet velocity", u)?,
        };
        // derived values that overflow or underflow (e.g. a mass flow of 1e308 kg/s) are refused
        // here, not reported later as a consequence ("inlet diameter 0 m")
        let u_in_si = positive(
            &format!("inlet velocity 4 Q/(π ρ d²) from the mass flow Q = {q:e} kg/s"),
            u_in_si,
        )?;
        let d_in_si = positive(
            &format!(
                "inlet diameter from the mass flow {q:e} kg/s and the inlet velocity {u_in_si:e} m/s"
            ),
            2.0 * (q / (PI * rho_in * u_in_si)).sqrt(),
        )?;
        Ok((u_in_si, d_in_si))
    }

    /// The take-up condition of `e` in the model's units: a diameter below the inlet diameter
    /// `d_in_si`, or a velocity above the inlet velocity `u_in_si`.
    fn dimensionless_take_up(
        e: &Experiment,
        u_in_si: f64,
        d_in_si: f64,
        scaling: &Scaling,
    ) -> Result<DimensionlessTakeUp, FiberError> {
        let r = &scaling.reference;
        let take_up = match e.take_up {
            None => return Err(FiberError::MissingTakeUp(e.name.clone())),
            Some(TakeUp::Diameter(d)) => {
                let d = positive("take-up diameter", d)?;
                if d >= d_in_si {
                    return Err(FiberError::InvalidInput(format!(
                        "take-up diameter {d} m must be smaller than the inlet diameter {d_in_si} m"
                    )));
                }
                DimensionlessTakeUp::Diameter {
                    d_out: d / scaling.diameter(),
                    d_in: d_in_si / scaling.diameter(),
                }
            }
            Some(TakeUp::Velocity(u)) => {
                let u = positive("take-up velocity", u)?;
                if u <= u_in_si {
                    return Err(FiberError::InvalidInput(format!(
                        "take-up velocity {u} m/s must exceed the inlet velocity {u_in_si} m/s"
                    )));
                }
                DimensionlessTakeUp::Velocity {
                    u_out: u / r.velocity,
                }
            }
        };
        Ok(take_up)
    }

    /// Sets the initial Reynolds number `Re_0` of the continuation (default `Re`).
    pub fn with_initial_reynolds(mut self, re0: f64) -> Self {
        self.re0 = re0;
        self
    }

    /// Names of the model parameters in `p` order: `"c"`, the law's, the strengths',
    /// `"take_up_factor"`.
    pub fn param_names(&self) -> Vec<&'static str> {
        let mut v = vec!["c"];
        v.extend_from_slice(self.law.param_names());
        v.extend(self.physics.strength_parameters().iter().map(|(n, _)| *n));
        v.push("take_up_factor");
        v
    }

    /// Where each parameter sits in `p`.
    #[inline]
    pub fn param_layout(&self) -> ParamLayout {
        self.params
    }

    /// Index of the take-up factor `φ` in `p` (the last parameter;
    /// [`ParamLayout::take_up_factor`]).
    pub fn take_up_factor_index(&self) -> usize {
        self.params.take_up_factor()
    }

    /// Index of the first law parameter in `p` ([`ParamLayout::law`]).
    pub fn law_param_offset(&self) -> usize {
        self.params.law().start
    }

    /// Index of the parameter `name` in `p`.
    pub fn param_index(&self, name: &str) -> Option<usize> {
        self.param_names().iter().position(|n| *n == name)
    }

    /// The full parameter vector `p = [c, law_params, default strengths]`, validated.
    pub fn parameters(&self, c: f64, law_params: &[f64]) -> Result<Vec<f64>, FiberError> {
        self.law
            .check_params(law_params)
            .map_err(FiberError::InvalidInput)?;
        finite("continuation parameter c", c)?;
        let mut p = Vec::with_capacity(self.params.len());
        p.push(c);
        p.extend_from_slice(law_params);
        p.extend(self.physics.strength_parameters().iter().map(|(_, d)| *d));
        p.push(1.0);
        Ok(p)
    }

    /// Checks a full parameter vector (length, finiteness, law admissibility).
    pub fn check_parameters(&self, p: &[f64]) -> Result<(), FiberError> {
        if p.len() != self.params.len() {
            return Err(FiberError::InvalidInput(format!(
                "expected {} model parameters {:?}, got {}",
                self.params.len(),
                self.param_names(),
                p.len()
            )));
        }
        if let Some(v) = p.iter().find(|v| !v.is_finite()) {
            return Err(FiberError::InvalidInput(format!(
                "parameter {v} is not finite"
            )));
        }
        self.law
            .check_params(&p[self.params.law()])
            .map_err(FiberError::InvalidInput)
    }

    /// Dimensionless inlet speed `ũ_in` \[-\].
    pub fn inlet_velocity(&self) -> f64 {
        self.u_in
    }

    /// Dimensionless inlet temperature `T̃_in` \[-\].
    pub fn inlet_temperature(&self) -> f64 {
        self.t_in
    }

    /// Dimensionless spin-line length `L̃` \[-\].
    pub fn length(&self) -> f64 {
        self.co.length
    }

    /// Dimensionless mass flow `Q̃` \[-\].
    pub fn mass_flow(&self) -> f64 {
        self.co.q
    }

    /// The dimensionless coefficients of the contributions.
    pub fn coefficients(&self) -> &Coefficients {
        &self.co
    }

    /// The dimensionless take-up condition.
    pub fn take_up(&self) -> DimensionlessTakeUp {
        self.take_up
    }

    /// The dimensionless zero-rate viscosity `μ̃_e0(T̃)`.
    pub fn zero_rate_viscosity(&self) -> &ZeroRateViscosity {
        &self.zero
    }

    /// `ρ̃(T̃)` \[-\].
    #[inline]
    pub fn density<D: DualNum<Primitive = f64> + Copy>(&self, t: D) -> D {
        t * self.rho_a + self.rho_b
    }

    /// `c̃_p(T̃)` \[-\].
    #[inline]
    pub fn heat_capacity<D: DualNum<Primitive = f64> + Copy>(&self, t: D) -> D {
        t * self.cp_a + self.cp_b
    }

    /// `d̃(ũ, ρ̃) = 2√(Q̃/(π ρ̃ ũ))` \[-\] with the nominal mass flow (see
    /// [`fiber_diameter`](Self::fiber_diameter) for the diameter with a `mass_flow_scale`).
    #[inline]
    pub fn diameter<D: DualNum<Primitive = f64> + Copy>(&self, u: D, rho: D) -> D {
        ((rho * u).recip() * (4.0 * self.co.q / PI)).sqrt()
    }

    /// `d̃ = 2√(Q̃ f_Q/(π ρ̃ ũ))` \[-\] with the mass-flow factor `f_Q` ([`ProcessFactors`]).
    #[inline]
    fn diameter_q<D: DualNum<Primitive = f64> + Copy>(&self, u: D, rho: D, f_q: D) -> D {
        ((rho * u).recip() * f_q * (4.0 * self.co.q / PI)).sqrt()
    }

    /// The true fiber diameter `d̃` \[-\] of the state `y` with the full model parameters `p`
    /// (the mass flow scaled by `mass_flow_scale` where present). Times
    /// [`Scaling::diameter`] gives metres.
    #[inline]
    pub fn fiber_diameter<D: DualNum<Primitive = f64> + Copy>(&self, y: &[D], p: &[D]) -> D {
        let sp = self.strength_slice(p);
        let pf = self
            .physics
            .process_planned(&self.plan, sp, self.scaling.reference.temperature);
        let rho = self.density(y[2]);
        if pf.has_mass_flow {
            self.diameter_q(y[0], rho, pf.mass_flow)
        } else {
            self.diameter(y[0], rho)
        }
    }

    /// The diameter the gauge reads \[-\]: `(1 + g) d̃ + õ` of
    /// [`fiber_diameter`](Self::fiber_diameter) with the gauge parameters (`gauge_scale`,
    /// `gauge_offset`) of `p`; the true diameter where they are absent. This is the predicted
    /// measurement the rheometer's residuals compare with the data.
    #[inline]
    pub fn observed_diameter<D: DualNum<Primitive = f64> + Copy>(&self, y: &[D], p: &[D]) -> D {
        let d = self.fiber_diameter(y, p);
        let sp = self.strength_slice(p);
        self.physics
            .gauge_reading_planned(&self.plan, d, sp, self.scaling.diameter())
    }

    /// Whether the mass flow is scaled (`mass_flow_scale` present in the physics).
    #[inline]
    fn has_mass_flow_scale(&self) -> bool {
        self.mass_flow_scaled
    }

    /// The strength parameters within full parameters `p` (empty if `p` is too short).
    #[inline]
    fn strength_slice<'p, D>(&self, p: &'p [D]) -> &'p [D] {
        let r = self.params.strengths();
        &p[r.start.min(p.len())..r.end.min(p.len())]
    }

    /// The inlet state `(ũ(0), T̃(0))` \[-\] with full parameters `p`: the nominal inlet
    /// velocity and temperature changed by the process parameters (`inlet_velocity`,
    /// `inlet_diameter`, `die_temperature_offset`, `mass_flow_scale`).
    pub fn inlet_state(&self, p: &[f64]) -> (f64, f64) {
        let sp = self.strength_slice(p);
        let (u, t, _) = self.inlet_conditions(sp);
        (u, t)
    }

    /// `(ũ(0), T̃(0), process factors)` with strength parameters `sp`. With an inlet diameter
    /// in the experiment file, `u(0) = 4 Q f_Q/(π ρ(T(0)) d²) · (1 + δ_u)/(1 + δ_d)²`; with an
    /// inlet velocity, `u(0) = u_in (1 + δ_u)/(1 + δ_d)²`.
    #[inline]
    fn inlet_conditions<D: DualNum<Primitive = f64> + Copy>(
        &self,
        sp: &[D],
    ) -> (D, D, ProcessFactors<D>) {
        let pf = self
            .physics
            .process_planned(&self.plan, sp, self.scaling.reference.temperature);
        let mut u = pf.inlet_velocity * self.u_in;
        let t = if pf.has_die_temperature {
            pf.die_temperature + self.t_in
        } else {
            D::from(self.t_in)
        };
        if self.inlet_is_diameter {
            if pf.has_mass_flow {
                u *= pf.mass_flow;
            }
            if pf.has_die_temperature {
                u = u * self.density(self.t_in) / self.density(t);
            }
        }
        (u, t, pf)
    }

    /// Reynolds number of the continuation, `Re_c = c Re + (1 − c) Re_0`.
    #[inline]
    fn re_c<D: DualNum<Primitive = f64> + Copy>(&self, c: D) -> D {
        c * self.scaling.re + (-c + 1.0) * self.re0
    }

    /// The local state at `s̃ = x` for `y = (u, N, T, ε̇)` and strength parameters `sp`.
    #[inline]
    pub fn local_state<D: DualNum<Primitive = f64> + Copy>(
        &self,
        x: f64,
        y: &[D],
        sp: &[D],
    ) -> LocalState<D> {
        let (u, n, t, rate) = (y[0], y[1], y[2], y[3]);
        let rho = self.density(t);
        let (t_air, v_air) = self
            .physics
            .environment_planned(&self.plan, x, sp, &self.co);
        let pf = self
            .physics
            .process_planned(&self.plan, sp, self.scaling.reference.temperature);
        let (d, q) = if pf.has_mass_flow {
            (
                self.diameter_q(u, rho, pf.mass_flow),
                pf.mass_flow * self.co.q,
            )
        } else {
            (self.diameter(u, rho), D::from(self.co.q))
        };
        LocalState {
            s: x,
            u,
            n,
            t,
            rate,
            rho,
            cp: self.heat_capacity(t),
            d,
            q,
            t_air,
            v_air,
        }
    }

    /// Dimensionless `μ̃_e(T̃, ε̇̃)` with law parameters `lp` and the nominal VFT law (no
    /// `vft_b_offset`/`vft_t_vf_offset`; [`viscosity_at`](Self::viscosity_at) applies them).
    pub fn viscosity<D: DualNum<Primitive = f64> + Copy>(&self, t: D, rate: D, lp: &[D]) -> D {
        viscosity(&self.law, &self.zero, self.scaling.de, t, rate, lp)
    }

    /// Dimensionless `μ̃_e(T̃, ε̇̃)` with the full model parameters `p` (law parameters and the
    /// VFT offsets where the physics has them).
    pub fn viscosity_at<D: DualNum<Primitive = f64> + Copy>(&self, t: D, rate: D, p: &[D]) -> D {
        let lp = &p[self.params.law()];
        let sp = &p[self.params.strengths()];
        viscosity_shifted(
            &self.law,
            &self.zero,
            self.vft_shift(sp),
            self.scaling.de,
            t,
            rate,
            lp,
        )
    }

    /// The VFT shift of the strength parameters `sp` (`None` without VFT offsets).
    #[inline]
    fn vft_shift<D: DualNum<Primitive = f64> + Copy>(&self, sp: &[D]) -> VftShift<D> {
        self.physics
            .vft_shift_planned(&self.plan, sp, self.scaling.reference.temperature)
    }

    /// Values of all named terms at `s̃ = x` for `y` and full parameters `p`:
    /// `(name, balance, dimensionless value)` (strength applied, continuation factor `c` not).
    pub fn terms_at(&self, x: f64, y: &[f64], p: &[f64]) -> Vec<(&'static str, Balance, f64)> {
        let strengths = self.params.strengths();
        let sp = &p[strengths.start.min(p.len())..strengths.end.min(p.len())];
        let st = self.local_state(x, y, sp);
        self.physics.report(&st, sp, &self.co)
    }
}

impl<L: ViscosityLaw, H: NusseltLaw> Bvp for FiberModel<L, H> {
    fn dim(&self) -> usize {
        4
    }

    fn num_params(&self) -> usize {
        self.params.len()
    }

    #[inline]
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, y: &[D], p: &[D], f: &mut [D]) {
        let c = p[ParamLayout::CONTINUATION];
        let lp = &p[self.params.law()];
        let sp = &p[self.params.strengths()];
        let st = self.local_state(x, y, sp);
        let (force, heat) = self.physics.sums_planned(&self.plan, &st, sp, &self.co);
        let q = st.q;
        let f_n = st.rate * q - c * force;
        let f_t = c * heat / (st.cp * q);
        let (mu, mu_t, mu_r) = viscosity_with_partials_shifted(
            &self.law,
            &self.zero,
            self.vft_shift(sp),
            self.scaling.de,
            st.t,
            st.rate,
            lp,
        );
        let re_over_q = if self.has_mass_flow_scale() {
            self.re_c(c) / q
        } else {
            self.re_c(c) / self.co.q
        };
        let num = re_over_q
            * (st.rho * st.n * st.rate + st.rho * st.u * f_n + st.u * st.n * f_t * self.rho_a)
            - st.rate * mu_t * f_t;
        f[0] = st.rate;
        f[1] = f_n;
        f[2] = f_t;
        f[3] = num / (mu + st.rate * mu_r);
    }

    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], p: &[D], r: &mut [D]) {
        let c = p[ParamLayout::CONTINUATION];
        let sp = &p[self.params.strengths()];
        // process conditions: u(0) and T(0) off their nominal values, mass flow scaled
        let (u_in, t_in, pf) = self.inlet_conditions(sp);
        let q = pf.mass_flow * self.co.q;
        let rho_in = self.density(t_in);
        r[0] = ya[0] - u_in;
        r[1] = match self.take_up {
            DimensionlessTakeUp::Diameter { d_out, .. } => {
                let phi = p[self.params.take_up_factor()];
                // at c = 0 the target is the stress-free fiber's diameter d(u(0), ρ(T(0)))
                let d_free = self.diameter_q(u_in, rho_in, pf.mass_flow);
                let target = c * phi * d_out + (-c + 1.0) * d_free;
                self.diameter_q(yb[0], self.density(yb[2]), pf.mass_flow) / target - 1.0
            }
            DimensionlessTakeUp::Velocity { u_out } => {
                let phi = p[self.params.take_up_factor()];
                let target = c * phi * u_out + (-c + 1.0) * u_in;
                yb[0] / target - 1.0
            }
        };
        r[2] = ya[2] - t_in;
        let re_over_q = if pf.has_mass_flow {
            self.re_c(c) / q
        } else {
            self.re_c(c) / self.co.q
        };
        r[3] = re_over_q * (ya[1] * (u_in * rho_in)) - ya[3] * self.viscosity_at(t_in, ya[3], p);
    }
}
