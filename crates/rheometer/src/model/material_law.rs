//! Elongational viscosity laws `μ_e(T, ε̇; p)` in dimensionless form.
//!
//! A law sees the dimensionless temperature `T̃ = T/T_o`, the dimensionless zero-rate
//! elongational viscosity `μ̃_e0(T̃) = Tr μ_s0(T)/μ_o` (VFT, computed by the model from the
//! [`Material`](super::setup::Material)), the dimensionless strain rate `ε̇̃ = ε̇ L_o/u_o`, the
//! Deborah number `De = μ_o u_o/(K_o L_o)` and its parameters `p` (as dual numbers, so
//! derivatives with respect to them are exact). It returns `μ̃_e = μ_e/μ_o`.
//!
//! The strain-rate formulation needs `∂_T μ_e` and `∂_ε̇ μ_e`; `viscosity_with_partials_shifted` gets
//! them by nested dual numbers (one pass with [`DenseDual<D, Const<2>>`](diffbvp::dense_dual::DenseDual) over the caller's `D`,
//! seeded in `T` and `ε̇`), so a law is written once, without hand-coded derivatives, and the
//! derivatives of the right-hand side with respect to the states and the law parameters stay
//! exact. Laws must be strictly monotone in the strain rate
//! (`∂_ε̇ (μ_e ε̇) > 0`) and smooth at `ε̇ = 0` (the stress-free start has `ε̇ ≡ 0`): write powers of
//! `1 + x²` as `exp(a ln(1 + x²))`, never `powf`/`sqrt` of a quantity that can be 0.
//!
//! The laws and the viscosity helpers are `#[inline(always)]`: they must fuse with the
//! model's right-hand side in every dual-number instance; `#[inline]` alone is not enough,
//! because with `codegen-units = 1` LLVM may keep `mu_e` out of line and slow the fiber's
//! solves.

use diffbvp::dense_dual::DenseDual;
use nalgebra::Const;
use num_dual::DualNum;

/// Largest number of law parameters supported by [`viscosity_with_partials_shifted`].
pub(crate) const MAX_LAW_PARAMS: usize = 8;

/// Inputs of a viscosity law at one point, dimensionless.
#[derive(Debug, Clone, Copy)]
pub struct LawInputs<D> {
    /// Temperature `T̃ = T/T_o` \[-\].
    pub t: D,
    /// Zero-rate elongational viscosity `μ̃_e0(T̃)` \[-\].
    pub mu0: D,
    /// `μ̃_e0 = mu0_factor · exp(mu0_exponent)` \[-\]: the exponent of the VFT law, for laws
    /// that multiply `μ̃_e0` by exponentials and can fold them into one (one `exp` fewer per
    /// point, see [`CarreauLike`]).
    pub mu0_exponent: D,
    /// The constant factor of `μ̃_e0 = mu0_factor · exp(mu0_exponent)` \[-\].
    pub mu0_factor: f64,
    /// Strain rate `ε̇̃` \[-\].
    pub rate: D,
    /// Deborah number `De` \[-\].
    pub de: f64,
}

impl<D: DualNum<Primitive = f64> + Copy> LawInputs<D> {
    /// `De μ̃_e0 ε̇̃ / K̃` with `K̃ = exp(κ)/K_o` (`stress_scale` = `K_o` \[Pa\]) \[-\]: the
    /// reduced strain rate of the Carreau-type laws, with `μ̃_e0 e^(−κ)` as one exponential,
    /// `mu0_factor · exp(mu0_exponent − κ)`.
    #[inline(always)]
    pub fn reduced_rate(&self, kappa: D, stress_scale: f64) -> D {
        (self.mu0_exponent - kappa).exp() * self.rate * (self.mu0_factor * self.de * stress_scale)
    }

    /// `μ̃_e0 exp(g)` \[-\] as one exponential, `mu0_factor · exp(mu0_exponent + g)`.
    #[inline(always)]
    pub fn mu0_times_exp(&self, g: D) -> D {
        (self.mu0_exponent + g).exp() * self.mu0_factor
    }
}

/// An elongational viscosity law, strictly monotone in the strain rate.
pub trait ViscosityLaw: Send + Sync {
    /// Names of the parameters, in order (e.g. `["n", "kappa"]`).
    fn param_names(&self) -> &'static [&'static str];

    /// Number of parameters.
    fn num_params(&self) -> usize {
        self.param_names().len()
    }

    /// Whether `p` is admissible (e.g. `n ≥ 0`); used to validate user input.
    fn check_params(&self, p: &[f64]) -> Result<(), String> {
        if p.len() != self.num_params() {
            return Err(format!(
                "the law expects {} parameters {:?}, got {}",
                self.num_params(),
                self.param_names(),
                p.len()
            ));
        }
        if let Some(v) = p.iter().find(|v| !v.is_finite()) {
            return Err(format!("law parameter {v} is not finite"));
        }
        Ok(())
    }

    /// Dimensionless elongational viscosity `μ̃_e`.
    fn mu_e<D: DualNum<Primitive = f64> + Copy>(&self, x: &LawInputs<D>, p: &[D]) -> D;
}

/// Dimensionless VFT zero-rate elongational viscosity
/// `μ̃_e0(T̃) = a exp(b/(T̃ − t_VF))` with `a = Tr μ_c/μ_o`, `b = B/T_o`, `t_VF = T_VF/T_o`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ZeroRateViscosity {
    /// `Tr μ_c/μ_o` \[-\].
    pub a: f64,
    /// `B/T_o` \[-\].
    pub b: f64,
    /// `T_VF/T_o` \[-\].
    pub t_vf: f64,
}

impl ZeroRateViscosity {
    /// Evaluates `μ̃_e0(T̃)`.
    #[inline(always)]
    pub fn eval<D: DualNum<Primitive = f64> + Copy>(&self, t: D) -> D {
        self.exponent(t).exp() * self.a
    }

    /// The exponent `b/(T̃ − t_VF)` of `μ̃_e0(T̃) = a exp(b/(T̃ − t_VF))` \[-\].
    #[inline(always)]
    pub fn exponent<D: DualNum<Primitive = f64> + Copy>(&self, t: D) -> D {
        (t - self.t_vf).recip() * self.b
    }

    /// `μ̃_e0(T̃)` with the VFT parameters shifted, `b' = b + db` (`db = ΔB/T_o`) and
    /// `t'_VF = t_VF + dt_vf` (`dt_vf = ΔT_VF/T_o`), **the level at `T̃ = 1` (`T = T_o`) held**:
    /// `a exp(b/(1 − t_VF)) exp(b'/(T̃ − t'_VF) − b'/(1 − t'_VF))`. A VFT fit to shear rheometry
    /// over the processing window pins the viscosity near the window and leaves the temperature
    /// dependence (`B`, `T_VF`, strongly correlated with `μ_c`) uncertain; shifting `B` at fixed
    /// `μ_c` would instead change the level by `exp(ΔB/(T − T_VF))` (13 % for 30 K at 513 K),
    /// which no rheometry leaves open. Equals [`eval`](Self::eval) at `db = dt_vf = 0` up to
    /// rounding.
    #[inline(always)]
    pub fn eval_shifted<D: DualNum<Primitive = f64> + Copy>(&self, t: D, db: D, dt_vf: D) -> D {
        self.exponent_shifted(t, db, dt_vf).exp() * self.a
    }

    /// The exponent of [`eval_shifted`](Self::eval_shifted):
    /// `b/(1 − t_VF) + b'/(T̃ − t'_VF) − b'/(1 − t'_VF)` \[-\] (times `a` after `exp`).
    #[inline(always)]
    pub fn exponent_shifted<D: DualNum<Primitive = f64> + Copy>(&self, t: D, db: D, dt_vf: D) -> D {
        let b = db + self.b;
        let t_vf = dt_vf + self.t_vf;
        let level = self.b / (1.0 - self.t_vf);
        (t - t_vf).recip() * b - (-t_vf + 1.0).recip() * b + level
    }

    /// The exponent of [`eval_with`](Self::eval_with) (`μ̃_e0 = a exp(·)`) \[-\].
    #[inline(always)]
    pub fn exponent_with<D: DualNum<Primitive = f64> + Copy>(&self, t: D, shift: VftShift<D>) -> D {
        match shift {
            None => self.exponent(t),
            Some([db, dt_vf]) => self.exponent_shifted(t, db, dt_vf),
        }
    }
}

/// Shifts `(ΔB/T_o, ΔT_VF/T_o)` of the VFT parameters (dimensionless; see
/// [`ZeroRateViscosity::eval_shifted`]); `None`: the nominal VFT law.
pub(crate) type VftShift<D> = Option<[D; 2]>;

impl ZeroRateViscosity {
    /// `μ̃_e0(T̃)`, with the VFT parameters shifted when `shift` is given
    /// ([`eval`](Self::eval) or [`eval_shifted`](Self::eval_shifted)).
    #[inline(always)]
    pub fn eval_with<D: DualNum<Primitive = f64> + Copy>(&self, t: D, shift: VftShift<D>) -> D {
        self.exponent_with(t, shift).exp() * self.a
    }

    /// The [`LawInputs`] at `t` (VFT shifted by `shift`), strain rate `rate` and Deborah number
    /// `de`: `μ̃_e0` and its exponent from one evaluation (a law that uses only the exponent
    /// leaves `mu0` unused, and the compiler drops its `exp` after inlining).
    #[inline(always)]
    pub fn law_inputs<D: DualNum<Primitive = f64> + Copy>(
        &self,
        t: D,
        shift: VftShift<D>,
        rate: D,
        de: f64,
    ) -> LawInputs<D> {
        let mu0_exponent = self.exponent_with(t, shift);
        LawInputs {
            t,
            mu0: mu0_exponent.exp() * self.a,
            rate,
            de,
            mu0_exponent,
            mu0_factor: self.a,
        }
    }
}

/// Newtonian law `μ_e = μ_e0(T)` (no parameters).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Newtonian;

impl ViscosityLaw for Newtonian {
    fn param_names(&self) -> &'static [&'static str] {
        &[]
    }
    #[inline(always)]
    fn mu_e<D: DualNum<Primitive = f64> + Copy>(&self, x: &LawInputs<D>, _p: &[D]) -> D {
        x.mu0
    }
}

/// The paper's Carreau-type law (eq. CarreauLikeLaw), parameters `p = (n, κ)`, `K = exp(κ)` \[Pa\]:
/// `μ_e = μ_e0 (1 + De² (μ_e0 ε̇/K̃)²)^((n−1)/2)` with `K̃ = K/K_o` (dimensionless form).
/// Newtonian for `n → 1` or `κ → ∞`. Monotone for `n ≥ 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CarreauLike {
    /// Stress scale `K_o` \[Pa\] of the non-dimensionalisation (`K̃ = exp(κ)/K_o`); 1 Pa in the
    /// paper.
    pub stress_scale: f64,
}

impl CarreauLike {
    /// Position of the power index `n` among the law's parameters.
    pub const N: usize = 0;
    /// Position of `κ = ln(K / 1 Pa)` among the law's parameters.
    pub const KAPPA: usize = 1;

    /// The law with `K_o = 1 Pa` (paper Table 2).
    pub fn new() -> Self {
        CarreauLike { stress_scale: 1.0 }
    }
}

impl Default for CarreauLike {
    /// `K_o = 1 Pa`.
    fn default() -> Self {
        CarreauLike::new()
    }
}

impl ViscosityLaw for CarreauLike {
    fn param_names(&self) -> &'static [&'static str] {
        &["n", "kappa"]
    }
    fn check_params(&self, p: &[f64]) -> Result<(), String> {
        if p.len() != 2 || !p.iter().all(|v| v.is_finite()) {
            return Err(format!(
                "Carreau-type law needs finite (n, kappa), got {p:?}"
            ));
        }
        if p[0] < 0.0 {
            return Err(format!("power index n = {} must be >= 0", p[0]));
        }
        Ok(())
    }
    #[inline(always)]
    fn mu_e<D: DualNum<Primitive = f64> + Copy>(&self, x: &LawInputs<D>, p: &[D]) -> D {
        let (n, kappa) = (p[0], p[1]);
        // λ ε̇ De = De μ0 ε̇ / K̃; μ0 (1 + w²)^((n−1)/2) with μ0 folded into each exponential
        // (two exp instead of three)
        let w = x.reduced_rate(kappa, self.stress_scale);
        x.mu0_times_exp((n - 1.0) * 0.5 * (w * w).ln_1p())
    }
}

/// Carreau–Yasuda-type law with the same `K`: `μ_e = μ_e0 (1 + |w|^a)^((n−1)/a)`,
/// `w = De μ_e0 ε̇/K̃`, parameters `p = (n, κ)`, fixed Yasuda exponent `a > 1` \[-\]
/// (`a = 2` is [`CarreauLike`]). Monotone for `n ≥ 0`. `|w|^a` is evaluated as
/// `exp(a/2 · ln w²)` away from `w = 0` and as exactly 0 (derivative 0, correct for `a > 1`) at it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CarreauYasuda {
    /// Yasuda exponent `a > 1` \[-\].
    pub a: f64,
    /// Stress scale `K_o` \[Pa\] (1 Pa in the paper).
    pub stress_scale: f64,
}

impl CarreauYasuda {
    /// The law with exponent `a` and `K_o = 1 Pa`.
    pub fn new(a: f64) -> Self {
        CarreauYasuda {
            a,
            stress_scale: 1.0,
        }
    }
}

impl ViscosityLaw for CarreauYasuda {
    fn param_names(&self) -> &'static [&'static str] {
        &["n", "kappa"]
    }
    fn check_params(&self, p: &[f64]) -> Result<(), String> {
        if !(self.a > 1.0 && self.a.is_finite()) {
            return Err(format!("Yasuda exponent a = {} must be > 1", self.a));
        }
        CarreauLike::new().check_params(p)
    }
    #[inline(always)]
    fn mu_e<D: DualNum<Primitive = f64> + Copy>(&self, x: &LawInputs<D>, p: &[D]) -> D {
        let (n, kappa) = (p[0], p[1]);
        let w = x.reduced_rate(kappa, self.stress_scale);
        let w2 = w * w;
        let wa = if w2.re() > 0.0 {
            (w2.ln() * (0.5 * self.a)).exp()
        } else {
            D::zero()
        };
        x.mu0_times_exp((n - 1.0) / self.a * wa.ln_1p())
    }
}

/// `(μ_e, ∂_T μ_e, ∂_ε̇ μ_e)` (all dimensionless) at temperature `t`, strain rate `rate`, law
/// parameters `p` and VFT parameters shifted by `shift`, by nested dual numbers (one pass, two
/// seeds over `D`): `μ_e0` is computed from `zero` on the lifted temperature so that `∂_T`
/// includes the VFT dependence. Exact for every `D`.
#[inline(always)]
pub(crate) fn viscosity_with_partials_shifted<
    L: ViscosityLaw,
    D: DualNum<Primitive = f64> + Copy,
>(
    law: &L,
    zero: &ZeroRateViscosity,
    shift: VftShift<D>,
    de: f64,
    t: D,
    rate: D,
    p: &[D],
) -> (D, D, D) {
    let k = p.len().min(MAX_LAW_PARAMS);
    let mut pl = [DenseDual::<D, Const<2>>::from_re(D::zero()); MAX_LAW_PARAMS];
    for (l, &v) in pl.iter_mut().zip(&p[..k]) {
        *l = DenseDual::from_re(v);
    }
    let pl = &pl[..k];
    let tt = DenseDual::<D, Const<2>>::from_re(t).derivative(0);
    let shift = shift.map(|d| d.map(DenseDual::from_re));
    let x = zero.law_inputs(tt, shift, DenseDual::from_re(rate).derivative(1), de);
    let m = law.mu_e(&x, pl);
    (m.re, m.slope(0), m.slope(1))
}

/// `μ̃_e` alone (no derivatives).
#[inline(always)]
pub fn viscosity<L: ViscosityLaw, D: DualNum<Primitive = f64> + Copy>(
    law: &L,
    zero: &ZeroRateViscosity,
    de: f64,
    t: D,
    rate: D,
    p: &[D],
) -> D {
    viscosity_shifted(law, zero, None, de, t, rate, p)
}

/// [`viscosity`] with the VFT parameters shifted by `shift`.
#[inline(always)]
pub(crate) fn viscosity_shifted<L: ViscosityLaw, D: DualNum<Primitive = f64> + Copy>(
    law: &L,
    zero: &ZeroRateViscosity,
    shift: VftShift<D>,
    de: f64,
    t: D,
    rate: D,
    p: &[D],
) -> D {
    law.mu_e(&zero.law_inputs(t, shift, rate, de), p)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn zero() -> ZeroRateViscosity {
        // PMMA7N with Table 2 scaling
        ZeroRateViscosity {
            a: 3.0 * 3.7074e-4 / 1.4865e3,
            b: 3649.0 / 513.15,
            t_vf: 273.15 / 513.15,
        }
    }

    #[test]
    fn shifted_vft_holds_the_level_at_the_reference_temperature() {
        let z = zero();
        for (db, dt) in [(0.0, 0.0), (0.1, 0.0), (0.0, -0.02), (-0.3, 0.01)] {
            let at_ref = z.eval_shifted(1.0f64, db, dt);
            assert!((at_ref / z.eval(1.0f64) - 1.0).abs() < 1e-14, "{db} {dt}");
            // colder: a larger B (or T_VF) raises the viscosity below T_o
            let cold = 0.8f64;
            let ratio = z.eval_shifted(cold, db, dt) / z.eval(cold);
            let expected = (db + z.b) / (cold - z.t_vf - dt)
                - (db + z.b) / (1.0 - z.t_vf - dt)
                - z.b / (cold - z.t_vf)
                + z.b / (1.0 - z.t_vf);
            assert!((ratio.ln() - expected).abs() < 1e-12, "{db} {dt}");
        }
        assert!(z.eval_shifted(0.8f64, 0.1, 0.0) > z.eval(0.8f64));
        assert!(z.eval_shifted(0.8f64, 0.0, 0.01) > z.eval(0.8f64));
    }

    #[test]
    fn zero_rate_viscosity_is_three_at_inlet() {
        assert!((zero().eval(1.0f64) - 3.0).abs() < 1e-3);
    }

    #[test]
    fn partials_match_finite_differences() {
        let z = zero();
        let laws: [&dyn Fn(f64, f64) -> (f64, f64, f64); 2] = [
            &|t, r| {
                viscosity_with_partials_shifted(
                    &CarreauLike::new(),
                    &z,
                    None,
                    82.486,
                    t,
                    r,
                    &[0.8, 11.71],
                )
            },
            &|t, r| {
                viscosity_with_partials_shifted(
                    &CarreauYasuda::new(1.5),
                    &z,
                    None,
                    82.486,
                    t,
                    r,
                    &[0.7, 11.0],
                )
            },
        ];
        for law in laws {
            for &(t, r) in &[(1.0, 0.0), (0.8, 3.0), (0.7, 40.0)] {
                let (m, mt, mr) = law(t, r);
                let h = 1e-6;
                let fdt = (law(t + h, r).0 - law(t - h, r).0) / (2.0 * h);
                let fdr =
                    (law(t, r + h).0 - law(t, (r - h).max(0.0)).0) / (r + h - (r - h).max(0.0));
                assert!(m.is_finite() && mt.is_finite() && mr.is_finite());
                assert!((mt - fdt).abs() <= 1e-6 * (1.0 + fdt.abs()), "{mt} {fdt}");
                if r > 0.0 {
                    assert!((mr - fdr).abs() <= 1e-6 * (1.0 + fdr.abs()), "{mr} {fdr}");
                } else {
                    assert_eq!(mr, 0.0);
                }
            }
        }
    }

    #[test]
    fn carreau_is_strictly_monotone_and_tends_to_newtonian() {
        let z = zero();
        let c = CarreauLike::new();
        let mut last = 0.0;
        for i in 0..200 {
            let r = i as f64 * 0.5;
            let s = viscosity(&c, &z, 82.486, 0.8, r, &[0.3, 11.0]) * r;
            assert!(s > last || i == 0);
            last = s;
        }
        let newt = viscosity::<_, f64>(&Newtonian, &z, 82.486, 0.8, 5.0, &[]);
        let near = viscosity::<_, f64>(&c, &z, 82.486, 0.8, 5.0, &[1.0 - 1e-9, 11.71]);
        assert!((near / newt - 1.0).abs() < 1e-8);
        let stiff = viscosity::<_, f64>(&c, &z, 82.486, 0.8, 5.0, &[0.8, 60.0]);
        assert!((stiff / newt - 1.0).abs() < 1e-12);
    }

    /// The laws evaluate `μ̃_e0` folded into their exponentials ([`LawInputs::reduced_rate`],
    /// [`LawInputs::mu0_times_exp`]); written out as in the paper with `μ̃_e0` itself
    /// (`μ̃_e0 (1 + |De μ̃_e0 ε̇̃ K_o e^(−κ)|^a)^((n−1)/a)`), nominal and VFT-shifted, they agree
    /// to 1e-14 relative over strain rates from 0 to far into the thinning, and `K_o`
    /// enters as a factor of the reduced rate.
    #[test]
    fn the_folded_laws_equal_the_written_out_formula() {
        let z = zero();
        let de = 82.486;
        let written_out = |a: f64, k_o: f64, t: f64, r: f64, p: [f64; 2], shift: VftShift<f64>| {
            let mu0 = z.eval_with(t, shift);
            let w = de * mu0 * r * k_o * (-p[1]).exp();
            mu0 * (1.0 + w.abs().powf(a)).powf((p[0] - 1.0) / a)
        };
        let mut worst = 0.0f64;
        for shift in [None, Some([0.05, -0.01])] {
            for (t, r) in [
                (1.0, 0.0),
                (0.9, 1e-3),
                (0.8, 3.0),
                (0.7, 40.0),
                (0.75, 2e3),
            ] {
                for (p, k_o) in [([0.8, 11.71], 1.0), ([0.3, 9.5], 1.0), ([0.6, 13.0], 2.5)] {
                    let c = CarreauLike { stress_scale: k_o };
                    let y = CarreauYasuda {
                        a: 1.5,
                        stress_scale: k_o,
                    };
                    let mc = viscosity_shifted(&c, &z, shift, de, t, r, &p);
                    let my = viscosity_shifted(&y, &z, shift, de, t, r, &p);
                    worst = worst.max((mc / written_out(2.0, k_o, t, r, p, shift) - 1.0).abs());
                    worst = worst.max((my / written_out(1.5, k_o, t, r, p, shift) - 1.0).abs());
                }
            }
        }
        assert!(worst < 1e-14, "largest relative difference {worst:e}");
    }

    #[test]
    fn yasuda_with_a_two_is_carreau() {
        let z = zero();
        let a = viscosity::<_, f64>(
            &CarreauYasuda::new(2.0),
            &z,
            82.486,
            0.9,
            7.0,
            &[0.8, 11.71],
        );
        let b = viscosity::<_, f64>(&CarreauLike::new(), &z, 82.486, 0.9, 7.0, &[0.8, 11.71]);
        assert!((a / b - 1.0).abs() < 1e-13);
    }
}
