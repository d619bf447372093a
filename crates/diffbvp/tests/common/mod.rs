//! Test problems with exact solutions shared by several integration tests (and by
//! `benches/solver.rs`).
#![allow(dead_code)]

use diffbvp::{Bvp, DualNum};

/// y'' = y on [0, 1], y(0) = 1, y(1) = 0.
pub struct Exp;
impl Bvp for Exp {
    fn dim(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], _p: &[D], f: &mut [D]) {
        f[0] = y[1];
        f[1] = y[0];
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        r[0] = ya[0] - 1.0;
        r[1] = yb[0];
    }
}
pub fn exp_exact(x: f64) -> f64 {
    ((-x).exp() - (x - 2.0).exp()) / (1.0 - (-2.0f64).exp())
}

/// Bratu y'' + k e^y = 0, y(0) = y(1) = 0.
pub struct Bratu {
    pub k: f64,
}
impl Bvp for Bratu {
    fn dim(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], _p: &[D], f: &mut [D]) {
        f[0] = y[1];
        f[1] = -y[0].exp() * self.k;
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        r[0] = ya[0];
        r[1] = yb[0];
    }
}
/// Bratu's problem y'' + k e^y = 0, y(0) = y(1) = 0, with `k` the model parameter `p[0]`
/// (for solvers, paths and fits that vary it).
pub struct BratuInK;
impl Bvp for BratuInK {
    fn dim(&self) -> usize {
        2
    }
    fn num_params(&self) -> usize {
        1
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], p: &[D], f: &mut [D]) {
        f[0] = y[1];
        f[1] = -y[0].exp() * p[0];
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        r[0] = ya[0];
        r[1] = yb[0];
    }
}

/// Exact Bratu solution for the branch parameter θ (θ = √(2k) cosh(θ/4)).
pub fn bratu_exact(theta: f64, x: f64) -> f64 {
    -2.0 * (((x - 0.5) * theta / 2.0).cosh() / (theta / 4.0).cosh()).ln()
}

/// Shock layer ε y'' + x y' = -ε π² cos(πx) - πx sin(πx), y(-1) = -2, y(1) = 0.
pub struct Shock {
    pub eps: f64,
}
impl Bvp for Shock {
    fn dim(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, y: &[D], _p: &[D], f: &mut [D]) {
        let pi = std::f64::consts::PI;
        f[0] = y[1];
        f[1] = (y[1] * (-x) - self.eps * pi * pi * (pi * x).cos() - pi * x * (pi * x).sin())
            / self.eps;
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        r[0] = ya[0] + 2.0;
        r[1] = yb[0];
    }
}
pub fn shock_exact(eps: f64, x: f64) -> f64 {
    (std::f64::consts::PI * x).cos() + erf(x / (2.0 * eps).sqrt()) / erf(1.0 / (2.0 * eps).sqrt())
}

/// erf with ~1e-16 accuracy (series for small |x|, continued fraction for large).
pub fn erf(x: f64) -> f64 {
    if x == 0.0 {
        return 0.0;
    }
    if x < 0.0 {
        return -erf(-x);
    }
    if x < 3.0 {
        // Taylor series
        let mut sum = x;
        let mut term = x;
        let x2 = x * x;
        let mut k = 0.0;
        loop {
            k += 1.0;
            term *= -x2 / k;
            let add = term / (2.0 * k + 1.0);
            sum += add;
            if add.abs() <= 1e-17 * sum.abs() || add == 0.0 {
                break;
            }
        }
        2.0 / std::f64::consts::PI.sqrt() * sum
    } else {
        // erfc continued fraction (Lentz)
        let mut f = 0.0;
        for k in (1..60).rev() {
            f = (k as f64 / 2.0) / (x + f);
        }
        1.0 - (-x * x).exp() / std::f64::consts::PI.sqrt() / (x + f)
    }
}

/// y'' = -p² y, y(a) = y(b) = 0, y'(a) = p; p unknown (an eigenvalue problem).
pub struct SturmLiouville;
impl Bvp for SturmLiouville {
    fn dim(&self) -> usize {
        2
    }
    fn num_unknowns(&self) -> usize {
        1
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], p: &[D], f: &mut [D]) {
        f[0] = y[1];
        f[1] = -p[0] * p[0] * y[0];
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], p: &[D], r: &mut [D]) {
        r[0] = ya[0];
        r[1] = yb[0];
        r[2] = ya[1] - p[0];
    }
}

/// Coupled Troesch (4 states): y1'' = μ sinh(μ y1) + y3, y3'' = y3 − y1, y1(0) = 0, y1(1) = b,
/// y3(0) = y3(1) = 0; model parameters (μ, b) (scipy's peer uses μ = 5, b = 1).
pub struct CoupledTroesch;
impl Bvp for CoupledTroesch {
    fn dim(&self) -> usize {
        4
    }
    fn num_params(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], p: &[D], f: &mut [D]) {
        f[0] = y[1];
        f[1] = (y[0] * p[0]).sinh() * p[0] + y[2];
        f[2] = y[3];
        f[3] = y[2] - y[0];
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], p: &[D], r: &mut [D]) {
        r[0] = ya[0];
        r[1] = yb[0] - p[1];
        r[2] = ya[2];
        r[3] = yb[2];
    }
}

/// Nonlinear oscillator with an unknown frequency λ (an eigenvalue problem, k = 1) and model
/// parameters in f and g: y'' = -λ² y - a y³, y(0) = y(1) = 0, y'(0) = b (λ depends on the
/// amplitude); p = (λ, a, b).
pub struct Oscillator;
impl Bvp for Oscillator {
    fn dim(&self) -> usize {
        2
    }
    fn num_unknowns(&self) -> usize {
        1
    }
    fn num_params(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], p: &[D], f: &mut [D]) {
        f[0] = y[1];
        f[1] = -p[0] * p[0] * y[0] - p[1] * y[0].powi(3);
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], p: &[D], r: &mut [D]) {
        r[0] = ya[0];
        r[1] = yb[0];
        r[2] = ya[1] - p[2];
    }
}

/// Which oscillatory equation [`Oscillatory`] is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OscillatoryKind {
    /// ε² y'' + y = 0, y(0) = 1, y(1) = 0 (exact: cos(x/ε) − cot(1/ε) sin(x/ε)).
    Linear,
    /// ε² y'' + sin y = 0, y(0) = 0.5, y(1) = 0 (a pendulum; nonlinear).
    Pendulum,
    /// ε² y'' + (1 + x) y = 0, y(0) = 1, y(1) = 0 (the frequency rises by √2 across [0, 1]).
    Airy,
}

/// An oscillatory family on [0, 1] with 1/(2π ε) periods (16 for ε = 0.01); the problems of
/// benches/peers/scipy_oscillatory.py. State (y, y').
pub struct Oscillatory {
    pub kind: OscillatoryKind,
    pub eps: f64,
}
impl Bvp for Oscillatory {
    fn dim(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, y: &[D], _p: &[D], f: &mut [D]) {
        let e2 = self.eps * self.eps;
        f[0] = y[1];
        f[1] = match self.kind {
            OscillatoryKind::Linear => -y[0] / e2,
            OscillatoryKind::Pendulum => -y[0].sin() / e2,
            OscillatoryKind::Airy => -y[0] * ((1.0 + x) / e2),
        };
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        let left = if self.kind == OscillatoryKind::Pendulum {
            0.5
        } else {
            1.0
        };
        r[0] = ya[0] - left;
        r[1] = yb[0];
    }
}

/// Exact solution of [`OscillatoryKind::Linear`].
pub fn oscillatory_linear_exact(eps: f64, x: f64) -> f64 {
    let w = 1.0 / eps;
    (w * x).cos() - (w * x).sin() / w.tan()
}

/// Emden's equation y'' + (2/x) y' + y^5 = 0, y'(0) = 0, y(1) = sqrt(3/4) (scipy's test
/// problem); `regular_bc: false` replaces y'(0) = 0 by y(0) = 1.1, which the regularity
/// condition contradicts.
pub struct Emden {
    /// y'(0) = 0 (else y(0) = 1.1).
    pub regular_bc: bool,
}

impl Bvp for Emden {
    fn dim(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], _p: &[D], f: &mut [D]) {
        f[0] = y[1];
        f[1] = -y[0].powi(5);
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        r[0] = if self.regular_bc { ya[1] } else { ya[0] - 1.1 };
        r[1] = yb[0] - 0.75f64.sqrt();
    }
    fn singular_term(&self) -> Option<Vec<f64>> {
        Some(vec![0.0, 0.0, 0.0, -2.0])
    }
}

/// The first-order reaction in a spherical catalyst pellet y'' + (2/x) y' = φ² y, y'(0) = 0,
/// y(1) = 1, with the Thiele modulus φ the model parameter.
pub struct Pellet;

impl Bvp for Pellet {
    fn dim(&self) -> usize {
        2
    }
    fn num_params(&self) -> usize {
        1
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], p: &[D], f: &mut [D]) {
        f[0] = y[1];
        f[1] = p[0] * p[0] * y[0];
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        r[0] = ya[1];
        r[1] = yb[0] - 1.0;
    }
    fn singular_term(&self) -> Option<Vec<f64>> {
        Some(vec![0.0, 0.0, 0.0, -2.0])
    }
}

/// The interface of [`ReactingLayer`].
pub const LAYER_XI: f64 = 0.4;

/// A reacting layer [0, ξ] (u'' = φ² u) behind an inert diffusion layer [ξ, 1] (u'' = 0),
/// u'(0) = 0, u(1) = 1, u and u' continuous at ξ = [`LAYER_XI`]; φ is the model parameter.
/// Without `multipoint` the same equations on one interval (the region from x).
pub struct ReactingLayer {
    /// Two regions joined at ξ (else one interval).
    pub multipoint: bool,
}

impl Bvp for ReactingLayer {
    fn dim(&self) -> usize {
        2
    }
    fn num_params(&self) -> usize {
        1
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, y: &[D], p: &[D], f: &mut [D]) {
        self.rhs_in_region(usize::from(x > LAYER_XI), x, y, p, f);
    }
    fn rhs_in_region<D: DualNum<Primitive = f64> + Copy>(
        &self,
        region: usize,
        _x: f64,
        y: &[D],
        p: &[D],
        f: &mut [D],
    ) {
        f[0] = y[1];
        f[1] = if region == 0 {
            p[0] * p[0] * y[0]
        } else {
            D::zero()
        };
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        r[0] = ya[1];
        r[1] = yb[0] - 1.0;
    }
    fn interfaces(&self) -> &[f64] {
        if self.multipoint {
            &[LAYER_XI]
        } else {
            &[]
        }
    }
}
