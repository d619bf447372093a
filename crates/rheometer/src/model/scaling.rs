//! Non-dimensionalisation of the fiber model (paper Sec. 2, general form; Appendix A, Table 2).
//!
//! Every quantity `x` is written `x = x_o x̃` with a reference value `x_o`. The paper's choices:
//! `L_o = s_o`, `N_o = Q_o u_o`, `f_o = Q_o u_o / L_o` (force per length; the appendix prints
//! `Q_o/(L_o u_o)`, a typo with wrong units), `A_o = Q_o/(ρ_o u_o)`, `d_o = √A_o`, `K_o` (stress
//! scale of the Carreau parameter `K`), `λ_o = μ_o/K_o`. Heat per length is measured in
//! `h_o = c_p,o Q_o T_o / L_o`.
//!
//! The heat-transfer reference `α_o` enters only through `St` and `Nu_*`, and the model uses
//! only their ratio `St/Nu_* = λ_*,o L_o/(c_p,o Q_o)`, which does not contain `α_o`: results do not
//! depend on it.

use std::f64::consts::PI;

/// Reference values `x_o` of the non-dimensionalisation, SI units. Defaults: paper Table 2.
#[derive(Debug, Clone, PartialEq)]
pub struct ReferenceValues {
    /// Mass flow `Q_o` \[kg/s\].
    pub mass_flow: f64,
    /// Length `L_o = s_o` \[m\].
    pub length: f64,
    /// Velocity `u_o` \[m/s\].
    pub velocity: f64,
    /// Temperature `T_o` \[K\].
    pub temperature: f64,
    /// Polymer density `ρ_o` \[kg/m³\].
    pub density: f64,
    /// Polymer specific heat capacity `c_p,o` [J/(kg K)].
    pub heat_capacity: f64,
    /// Dynamic (elongational) viscosity `μ_o` \[Pa s\].
    pub viscosity: f64,
    /// Heat-transfer coefficient `α_o` [W/(m² K)] (results do not depend on it).
    pub heat_transfer: f64,
    /// Air density `ρ_*,o` \[kg/m³\].
    pub air_density: f64,
    /// Air specific heat capacity `c_p,*,o` [J/(kg K)].
    pub air_heat_capacity: f64,
    /// Air kinematic viscosity `ν_*,o` \[m²/s\].
    pub air_kinematic_viscosity: f64,
    /// Air heat conductivity `λ_*,o` [W/(m K)].
    pub air_heat_conductivity: f64,
    /// Stress scale `K_o` of the Carreau parameter `K` \[Pa\].
    pub stress: f64,
    /// Gravitational acceleration `g` \[m/s²\] (a model constant, merged into `Fr`).
    pub gravity: f64,
}

impl Default for ReferenceValues {
    /// Paper Table 2 (`K_o = 1 Pa`, `g = 9.81 m/s²`).
    fn default() -> Self {
        ReferenceValues {
            mass_flow: 3.08e-5,
            length: 0.51,
            velocity: 0.0283,
            temperature: 513.15,
            density: 1.077e3,
            heat_capacity: 2.2903e3,
            viscosity: 1.4865e3,
            heat_transfer: 12.762,
            air_density: 1.0,
            air_heat_capacity: 1000.0,
            air_kinematic_viscosity: 2e-5,
            air_heat_conductivity: 0.031,
            stress: 1.0,
            gravity: 9.81,
        }
    }
}

/// Regularised tangential Stokes resistance coefficient of a slender fiber
/// `r_τ,S^δ = 2π/ln(4/δ) + (π/2)/ln²(4/δ)` \[-\] at slenderness `δ` \[-\] (Marheineke & Wegener 2011).
pub fn stokes_tangential_resistance(delta: f64) -> f64 {
    let l = (4.0 / delta).ln();
    2.0 * PI / l + 0.5 * PI / (l * l)
}

/// Slenderness `δ = 1e-3` used by the paper for the drag coefficient \[-\].
pub(crate) const PAPER_SLENDERNESS: f64 = 1e-3;

/// Reference values and the derived dimensionless numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct Scaling {
    /// The reference values.
    pub reference: ReferenceValues,
    /// Reynolds number `Re = ρ_o u_o L_o/μ_o` \[-\].
    pub re: f64,
    /// Froude number `Fr = u_o/√(g L_o)` \[-\].
    pub fr: f64,
    /// Eckert number `Ec = u_o²/(c_p,o T_o)` \[-\].
    pub ec: f64,
    /// Stanton number `St = α_o d_o L_o/(c_p,o Q_o)` \[-\].
    pub st: f64,
    /// Deborah number `De = λ_o u_o/L_o`, `λ_o = μ_o/K_o` \[-\].
    pub de: f64,
    /// Air drag number `A_* = ρ_*,o d_o u_o²/f_o` \[-\].
    pub a_star: f64,
    /// Air Reynolds number `Re_* = d_o u_o/ν_*,o` \[-\].
    pub re_star: f64,
    /// Nusselt number `Nu_* = α_o d_o/λ_*,o` \[-\].
    pub nu_star: f64,
    /// Prandtl number `Pr_* = c_p,*,o ρ_*,o ν_*,o/λ_*,o` \[-\].
    pub pr_star: f64,
}

impl Default for Scaling {
    fn default() -> Self {
        Scaling::new(ReferenceValues::default())
    }
}

impl Scaling {
    /// Derives the dimensionless numbers from reference values.
    pub fn new(reference: ReferenceValues) -> Self {
        let r = &reference;
        let d_o = (r.mass_flow / (r.density * r.velocity)).sqrt();
        let f_o = r.mass_flow * r.velocity / r.length;
        let re = r.density * r.velocity * r.length / r.viscosity;
        let fr = r.velocity / (r.gravity * r.length).sqrt();
        let ec = r.velocity * r.velocity / (r.heat_capacity * r.temperature);
        let st = r.heat_transfer * d_o * r.length / (r.heat_capacity * r.mass_flow);
        let de = r.viscosity / r.stress * r.velocity / r.length;
        let a_star = r.air_density * d_o * r.velocity * r.velocity / f_o;
        let re_star = d_o * r.velocity / r.air_kinematic_viscosity;
        let nu_star = r.heat_transfer * d_o / r.air_heat_conductivity;
        let pr_star = r.air_heat_capacity * r.air_density * r.air_kinematic_viscosity
            / r.air_heat_conductivity;
        Scaling {
            reference,
            re,
            fr,
            ec,
            st,
            de,
            a_star,
            re_star,
            nu_star,
            pr_star,
        }
    }

    /// Reference area `A_o = Q_o/(ρ_o u_o)` \[m²\].
    pub fn area(&self) -> f64 {
        let r = &self.reference;
        r.mass_flow / (r.density * r.velocity)
    }

    /// Reference diameter `d_o = √A_o` \[m\].
    pub fn diameter(&self) -> f64 {
        self.area().sqrt()
    }

    /// Reference force `N_o = Q_o u_o` \[N\].
    pub fn force(&self) -> f64 {
        self.reference.mass_flow * self.reference.velocity
    }

    /// Reference force per length `f_o = Q_o u_o/L_o` \[N/m\].
    pub fn force_per_length(&self) -> f64 {
        self.force() / self.reference.length
    }

    /// Reference heat flow per length `h_o = c_p,o Q_o T_o/L_o` \[W/m\].
    pub fn heat_per_length(&self) -> f64 {
        let r = &self.reference;
        r.heat_capacity * r.mass_flow * r.temperature / r.length
    }

    /// Reference strain rate `u_o/L_o` \[1/s\].
    pub fn strain_rate(&self) -> f64 {
        self.reference.velocity / self.reference.length
    }

    /// `1/Fr²` \[-\], the gravity coefficient.
    pub fn inv_fr2(&self) -> f64 {
        1.0 / (self.fr * self.fr)
    }

    /// `St/Nu_*` \[-\], the coefficient of the convective heat loss (independent of `α_o`).
    pub fn st_over_nu(&self) -> f64 {
        self.st / self.nu_star
    }

    /// Dimensionless air-drag factor `(A_*/Re_*) r_τ,S^δ` \[-\] for the reference air
    /// (`f̃_air = factor · ρ̃_* ν̃_* (ṽ_air − ũ)`).
    pub fn drag_factor(&self, delta: f64) -> f64 {
        self.a_star / self.re_star * stokes_tangential_resistance(delta)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Relative agreement to the printed significant digits.
    fn close(v: f64, printed: f64, digits: i32) {
        let exponent = printed.abs().log10().floor() as i32;
        let tol = 0.5 * 10f64.powi(exponent - (digits - 1));
        assert!((v - printed).abs() <= tol, "{v} vs {printed} (±{tol:e})");
    }

    #[test]
    fn table2_numbers_match_model_closure() {
        let s = Scaling::default();
        close(s.re, 0.010457, 5);
        close(s.fr, 0.012652, 5);
        close(s.inv_fr2(), 6246.9, 5);
        close(s.ec, 6.8145e-10, 5);
        close(s.st, 0.092751, 5);
        close(s.de, 82.486, 5);
        close(s.drag_factor(PAPER_SLENDERNESS), 0.25844, 5);
        close(s.a_star, 0.47106, 5);
        close(s.re_star, 1.42243, 6);
        close(s.nu_star, 0.41384, 5);
        close(s.pr_star, 0.64516, 5);
        close(s.st_over_nu(), 0.22412, 5);
        close(s.area(), 1.010529e-6, 7);
        close(s.diameter(), 1.005250e-3, 7);
        close(stokes_tangential_resistance(1e-3), 0.780388, 6);
    }

    #[test]
    fn st_over_nu_does_not_depend_on_alpha() {
        let a = Scaling::default();
        let b = Scaling::new(ReferenceValues {
            heat_transfer: 99.0,
            ..Default::default()
        });
        assert!((a.st_over_nu() - b.st_over_nu()).abs() < 1e-15 * a.st_over_nu());
        assert!((a.st - b.st).abs() > 0.1);
    }
}
