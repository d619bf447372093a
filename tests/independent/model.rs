//! The stationary fiber-spinning model of the paper (Sec. 2, App. A) and `model-closure.md`,
//! written independently of `crates/rheometer/src/**`, dimensional (SI) on the scaled arc length
//! `x = s/L ∈ [0, 1]`, with hidden effects written directly into the balances.
//!
//! States `y = (w, N/N_ref, T/T_ref)` with `u = u_in e^w` [m/s], `N` the tension [N]
//! (`N_ref` = 1e-2 N), `T` [K] (`T_ref` = 100 K). The constitutive law is inverted explicitly
//! (3-state formulation): `σ = N/A = μ_e(T, ε̇) ε̇`, `μ_e = μ_e0(T) (1 + (μ_e0 ε̇/K)²)^((n−1)/2)`,
//! so with `a = μ_e0 ε̇/K`: `σ/K = Φ(a) = a (1 + a²)^((n−1)/2)`, strictly increasing for n > 0.
//! `Φ⁻¹` is solved by Newton in `ln a` in `f64`, and its first derivative is carried through
//! the dual numbers by one Newton correction (exact to first order, which is all the
//! collocation Jacobian needs).
//!
//! Balances per unit length (s along the spin line, downwards):
//! - momentum `N' = Q u' − Q g/u − f_air`, `f_air = μ_* r_τ (v_air(s) − u)` (tangential Stokes
//!   drag, linear in the relative speed, so its sign reverses where the air overtakes the fiber);
//! - energy `c_p Q T' = N u' − π λ_* Nu (T − T_air(s)) − π d ε σ_SB (T⁴ − T_air(s)⁴)`;
//! - `Nu = ι · Nu_CB(Re_ε, Pr)`, `Re = d |v_air − u|/ν_*`, `Re_ε = √(Re² + 1e-6)`, the
//!   inclination factor `ι = 1 − ½ Re²/(Re² + 1e-6)` (closure default) or, for lines with air
//!   flow, `ι = ½` (purely tangential relative flow; the closure's factor differs from ½ only for
//!   |Re| ≲ 1e-3, where it jumps to 1 in a layer of ~1e-7 m — a documented smoother choice).
//!
//! A homotopy parameter `c ∈ [0, 1]` (the only model parameter) multiplies gravity, drag,
//! viscous heating, convective and radiative cooling: at `c = 0` the fiber is isothermal and
//! `u ≈ u_in e^{x ln Dr}`.

use diffbvp::{Bvp, DualNum};
use std::f64::consts::PI;

/// Gravitational acceleration [m/s²].
pub const GRAVITY: f64 = 9.81;
/// Stefan–Boltzmann constant [W/(m² K⁴)].
pub const STEFAN_BOLTZMANN: f64 = 5.670374419e-8;
/// Slenderness of the regularised Stokes drag [-].
pub const SLENDERNESS: f64 = 1e-3;
/// Tension scale of the state [N].
const N_REF: f64 = 1e-2;
/// Temperature scale of the state [K].
const T_REF: f64 = 100.0;

/// Tangential Stokes resistance coefficient `r_τ,S = 2π/ln(4/δ) + (π/2)/ln²(4/δ)` [-].
pub fn stokes_tangential() -> f64 {
    let l = (4.0 / SLENDERNESS).ln();
    2.0 * PI / l + 0.5 * PI / (l * l)
}

/// Polymer and air data (SI).
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// ρ(T) = rho_slope T + rho_intercept [kg/(m³ K)], [kg/m³].
    pub rho_slope: f64,
    /// [kg/m³]
    pub rho_intercept: f64,
    /// c_p(T) = cp_slope T + cp_intercept [J/(kg K²)], [J/(kg K)].
    pub cp_slope: f64,
    /// [J/(kg K)]
    pub cp_intercept: f64,
    /// VFT μ_s0 = mu_c exp(B/(T − T_VF)) [Pa s].
    pub mu_c: f64,
    /// [K]
    pub vft_b: f64,
    /// [K]
    pub vft_t_vf: f64,
    /// Air density [kg/m³].
    pub air_rho: f64,
    /// Air heat capacity [J/(kg K)].
    pub air_cp: f64,
    /// Air kinematic viscosity [m²/s].
    pub air_nu: f64,
    /// Air heat conductivity [W/(m K)].
    pub air_lambda: f64,
}

impl Material {
    /// PMMA7N, paper Table 1.
    pub fn pmma7n() -> Self {
        Material {
            rho_slope: -0.964,
            rho_intercept: 1572.33,
            cp_slope: 3.2,
            cp_intercept: 648.22,
            mu_c: 3.7074e-4,
            vft_b: 3649.0,
            vft_t_vf: 273.15,
            air_rho: 1.0,
            air_cp: 1000.0,
            air_nu: 2e-5,
            air_lambda: 0.031,
        }
    }
    /// Density [kg/m³] at `t` [K].
    pub fn rho(&self, t: f64) -> f64 {
        self.rho_slope * t + self.rho_intercept
    }
    /// Air Prandtl number [-].
    pub fn prandtl(&self) -> f64 {
        self.air_cp * self.air_rho * self.air_nu / self.air_lambda
    }
}

/// Air speed along the fiber [m/s] (positive: downwards, with the fiber).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AirFlow {
    /// Still air.
    Still,
    /// Aspirator jet near the take-up: `V / (1 + ((L − s)/ℓ)²)` (Lorentzian, not exponential).
    Aspirator {
        /// V [m/s] at the take-up.
        speed: f64,
        /// ℓ [m].
        length: f64,
    },
    /// Co-flow along the line: `V (1 + tanh((s − s₀)/w))/2`.
    Ramp {
        /// V [m/s] far downstream.
        speed: f64,
        /// s₀ [m], the middle of the ramp.
        onset: f64,
        /// w [m].
        width: f64,
    },
}

impl AirFlow {
    /// v_air(s) [m/s] on a line of length `l` [m].
    pub fn speed(&self, s: f64, l: f64) -> f64 {
        match *self {
            AirFlow::Still => 0.0,
            AirFlow::Aspirator { speed, length } => {
                let z = (l - s) / length;
                speed / (1.0 + z * z)
            }
            AirFlow::Ramp {
                speed,
                onset,
                width,
            } => 0.5 * speed * (1.0 + ((s - onset) / width).tanh()),
        }
    }
}

/// Air temperature excess over the ambient [K].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AirHeat {
    /// Uniform ambient air.
    Uniform,
    /// `ΔT / (1 + s/ℓ)²`.
    InverseSquare {
        /// ΔT [K] at the nozzle.
        excess: f64,
        /// ℓ [m].
        length: f64,
    },
    /// `ΔT (1 − s/s_e)` for s < s_e, 0 beyond.
    Linear {
        /// ΔT [K] at the nozzle.
        excess: f64,
        /// s_e [m].
        end: f64,
    },
}

impl AirHeat {
    /// Excess [K] at s [m].
    pub fn excess(&self, s: f64) -> f64 {
        match *self {
            AirHeat::Uniform => 0.0,
            AirHeat::InverseSquare { excess, length } => excess / (1.0 + s / length).powi(2),
            AirHeat::Linear { excess, end } => excess * (1.0 - s / end).max(0.0),
        }
    }
}

/// The viscosity law: Carreau-type `(n, κ)`, K = e^κ Pa; `n = 1` is Newtonian.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Law {
    /// Power index n [-].
    pub n: f64,
    /// κ = ln(K / 1 Pa) [-].
    pub kappa: f64,
}

/// One spin line with its true conditions and hidden effects.
#[derive(Debug, Clone, PartialEq)]
pub struct Line {
    /// Material.
    pub material: Material,
    /// Viscosity law.
    pub law: Law,
    /// True mass flow [kg/s].
    pub mass_flow: f64,
    /// True inlet temperature [K].
    pub inlet_temperature: f64,
    /// Inlet diameter [m] (with the true inlet temperature and mass flow it sets u_in).
    pub inlet_diameter: f64,
    /// Take-up diameter [m].
    pub take_up_diameter: f64,
    /// Spin-line length [m].
    pub length: f64,
    /// Ambient air temperature [K].
    pub air_temperature: f64,
    /// Air flow.
    pub air_flow: AirFlow,
    /// Warm air.
    pub air_heat: AirHeat,
    /// Grey-body emissivity [-] (0: no radiation).
    pub emissivity: f64,
    /// Strain hardening β [-] (0: none): the melt's zero-rate viscosity grows as
    /// `exp(β ε_H)` with the Hencky strain `ε_H = ln(u/u_in)` — an effect outside the
    /// project's candidates.
    pub hardening: f64,
}

impl Line {
    /// Inlet speed u_in = 4Q/(π ρ(T_in) d_in²) [m/s].
    pub fn inlet_speed(&self) -> f64 {
        4.0 * self.mass_flow
            / (PI * self.material.rho(self.inlet_temperature) * self.inlet_diameter.powi(2))
    }
    /// (u [m/s], N [N], T [K]) from a state vector.
    pub fn physical(&self, y: &[f64]) -> (f64, f64, f64) {
        (self.inlet_speed() * y[0].exp(), N_REF * y[1], T_REF * y[2])
    }
    /// Diameter [m] from a state vector.
    pub fn diameter(&self, y: &[f64]) -> f64 {
        let (u, _, t) = self.physical(y);
        2.0 * (self.mass_flow / (PI * self.material.rho(t) * u)).sqrt()
    }
    /// Strain rate ε̇ [1/s] from a state vector.
    pub fn strain_rate(&self, y: &[f64]) -> f64 {
        let mut f = [0.0; 3];
        self.rhs(0.0, y, &[1.0, 1.0], &mut f);
        f[0] * self.inlet_speed() * y[0].exp() / self.length
    }
    /// Initial guess at c = 0: isothermal, exponential speed.
    pub fn guess_state(&self, x: f64, y: &mut [f64]) {
        let m = &self.material;
        let t = self.inlet_temperature;
        let u_out = 4.0 * self.mass_flow / (PI * m.rho(t) * self.take_up_diameter.powi(2));
        let lnd = (u_out / self.inlet_speed()).ln();
        let mu0 = 3.0 * m.mu_c * (m.vft_b / (t - m.vft_t_vf)).exp();
        // Newtonian isothermal: N = 3 μ_s0 A u' = μ0 Q lnd/(ρ L)
        let n = mu0 * self.mass_flow * lnd / (m.rho(t) * self.length);
        y[0] = lnd * x;
        y[1] = n / N_REF;
        y[2] = t / T_REF;
    }
}

/// Φ⁻¹(r) for Φ(a) = a (1 + a²)^((n−1)/2), odd in r, in f64.
fn carreau_inverse(r: f64, n: f64) -> f64 {
    if r == 0.0 || !r.is_finite() {
        return r;
    }
    if r < 0.0 {
        return -carreau_inverse(-r, n);
    }
    let m = 0.5 * (n - 1.0);
    let lr = r.ln();
    let mut t = lr;
    for _ in 0..100 {
        let e = (-2.0 * t.abs()).exp();
        let l1 = if t > 0.0 {
            2.0 * t + e.ln_1p()
        } else {
            e.ln_1p()
        };
        let logistic = if t > 0.0 {
            1.0 / (1.0 + e)
        } else {
            e / (1.0 + e)
        };
        let f = t + m * l1 - lr;
        let fp = 1.0 + 2.0 * m * logistic;
        let dt = f / fp;
        t -= dt;
        if dt.abs() <= 1e-15 * (1.0 + t.abs()) {
            break;
        }
    }
    t.exp()
}

impl Bvp for Line {
    fn dim(&self) -> usize {
        3
    }
    fn num_params(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, y: &[D], p: &[D], f: &mut [D]) {
        let m = &self.material;
        let c = p[0];
        let s = x * self.length;
        let q = self.mass_flow;
        let u = y[0].exp() * self.inlet_speed();
        let tension = y[1] * N_REF;
        let t = y[2] * T_REF;
        let rho = t * m.rho_slope + m.rho_intercept;
        let cp = t * m.cp_slope + m.cp_intercept;
        let area = (rho * u).recip() * q;
        let d = (area * (4.0 / PI)).sqrt();
        let mu0 = ((t - m.vft_t_vf).recip() * m.vft_b).exp()
            * (3.0 * m.mu_c)
            * (y[0] * self.hardening).exp();
        // constitutive law: σ/K = Φ(a), a = μ0 ε̇/K
        let k = self.law.kappa.exp();
        let ratio = tension / area / k;
        let a0 = carreau_inverse(ratio.re(), self.law.n);
        let mm = 0.5 * (self.law.n - 1.0);
        let phi0 = a0 * (1.0 + a0 * a0).powf(mm);
        let dphi0 = (1.0 + a0 * a0).powf(mm - 1.0) * (1.0 + self.law.n * a0 * a0);
        let a = (ratio - phi0) / dphi0 + a0;
        let rate = a * k / mu0;
        // air
        let v_air = p[1] * self.air_flow.speed(s, self.length);
        let t_air = self.air_temperature + self.air_heat.excess(s);
        let v_rel = -u + v_air;
        let drag = v_rel * (m.air_rho * m.air_nu * stokes_tangential());
        let re = d * v_rel / m.air_nu;
        let re2 = re * re;
        let re_eps = (re2 + 1e-6).sqrt();
        let pr = m.prandtl();
        let nu_cb = re_eps.sqrt()
            * (0.62 * pr.powf(1.0 / 3.0) * (1.0 + (0.4 / pr).powf(2.0 / 3.0)).powf(-0.25))
            * ((re_eps / 282000.0).powf(5.0 / 8.0) + 1.0).powf(0.8)
            + 0.3;
        let inclination = if matches!(self.air_flow, AirFlow::Still) {
            -(re2 / (re2 + 1e-6)) * 0.5 + 1.0
        } else {
            D::from(0.5)
        };
        let nusselt = nu_cb * inclination;
        let convection = nusselt * (t - t_air) * (PI * m.air_lambda);
        let t2 = t * t;
        let radiation = d * (t2 * t2 - t_air.powi(4)) * (PI * self.emissivity * STEFAN_BOLTZMANN);
        let dn = rate * q - (c * (u.recip() * (q * GRAVITY) + drag));
        let dt = (c * (tension * rate - convection - radiation)) / (cp * q);
        let l = self.length;
        f[0] = rate / u * l;
        f[1] = dn * (l / N_REF);
        f[2] = dt * (l / T_REF);
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        let m = &self.material;
        let t_l = yb[2] * T_REF;
        let rho_l = t_l * m.rho_slope + m.rho_intercept;
        // u(L) = 4Q/(π ρ(T_L) d_out²)  ⇔  w(1) = ln(4Q/(π ρ d_out² u_in))
        let target = (rho_l * (PI * self.take_up_diameter.powi(2) * self.inlet_speed())
            / (4.0 * self.mass_flow))
            .recip()
            .ln();
        r[0] = ya[0];
        r[1] = ya[2] - self.inlet_temperature / T_REF;
        r[2] = yb[0] - target;
    }
}
