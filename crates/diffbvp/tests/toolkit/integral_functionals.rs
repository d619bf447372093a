//! Integral functionals `G = ∫ g dx + φ`: 4th-order convergence of the value and of `dG/dp` on
//! fixed meshes halved, and the adjoint, the forward route and the closed form agreeing.

use diffbvp::mesh::linspace;
use diffbvp::sensitivity::{
    integral_adjoint, integral_forward, integral_value, IntegralFunction, Sensitivities,
};
use diffbvp::{solve, Bvp, DualNum, Guess, SolveOptions};
use num_dual::Dual64;

/// y'' = k² y, y(0) = 1, y(1) = 0: y = sinh(k(1−x))/sinh(k).
struct Hyper;
impl Bvp for Hyper {
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
        r[0] = ya[0] - 1.0;
        r[1] = yb[0];
    }
}

/// G = ∫₀¹ (y² + k y) dx + y'(0)²/k: states, the parameter and both parts of the functional.
struct Functional;
impl IntegralFunction for Functional {
    fn integrand<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], p: &[D]) -> D {
        y[0] * y[0] + p[0] * y[0]
    }
    fn endpoint<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], _yb: &[D], p: &[D]) -> D {
        ya[1] * ya[1] / p[0]
    }
}

/// The closed form of G(k): ∫ y² = (sinh 2k/(4k) − 1/2)/sinh² k, ∫ y = (cosh k − 1)/(k sinh k),
/// y'(0) = −k coth k.
fn closed_form<D: DualNum<Primitive = f64> + Copy>(k: D) -> D {
    let s = k.sinh();
    let i2 = ((k * 2.0).sinh() / (k * 4.0) - 0.5) / (s * s);
    let i1 = (k.cosh() - 1.0) / (k * s);
    let coth = k.cosh() / s;
    i2 + k * i1 + k * coth * coth
}

const K: f64 = 3.0;

/// (value, adjoint dG/dk, forward dG/dk) on the uniform mesh of `intervals` intervals.
fn on_mesh(intervals: usize) -> (f64, f64, f64, f64) {
    let guess = Guess::constant(linspace(0.0, 1.0, intervals + 1), &[0.5, -1.0]);
    let sol = solve(&Hyper, &[K], &guess, &SolveOptions::fixed_mesh()).unwrap();
    assert_eq!(sol.x.len(), intervals + 1, "the mesh must stay fixed");
    let value = integral_value(&Hyper, &sol, &Functional).unwrap();
    let (v_adj, adjoint) = integral_adjoint(&Hyper, &sol, &Functional).unwrap();
    let sens = Sensitivities::compute(&Hyper, &sol).unwrap();
    let (v_fwd, forward) = integral_forward(&Hyper, &sol, &sens, &Functional).unwrap();
    // the three routes evaluate the same quadrature
    assert!(
        (v_adj - value).abs() <= 1e-14 * value.abs(),
        "{v_adj} {value}"
    );
    assert!(
        (v_fwd - value).abs() <= 1e-14 * value.abs(),
        "{v_fwd} {value}"
    );
    (value, adjoint[0], forward[0], sens.dy.len() as f64)
}

#[test]
fn value_and_gradient_converge_at_fourth_order() {
    let exact = closed_form(Dual64::from_re(K).derivative());
    let (g_exact, dg_exact) = (exact.re, exact.eps);
    let meshes = [8, 16, 32, 64, 128];
    let mut errors = Vec::new();
    for &m in &meshes {
        let (g, adjoint, forward, _) = on_mesh(m);
        // adjoint and forward differentiate the same discrete G: round-off apart
        assert!(
            (adjoint - forward).abs() <= 1e-11 * dg_exact.abs(),
            "{m} intervals: adjoint {adjoint} forward {forward}"
        );
        errors.push(((g - g_exact).abs(), (adjoint - dg_exact).abs()));
        println!(
            "{m:>4} intervals: G error {:.3e}, dG/dk error {:.3e} (adjoint − forward {:.1e})",
            (g - g_exact).abs(),
            (adjoint - dg_exact).abs(),
            (adjoint - forward).abs()
        );
    }
    for w in 1..errors.len() {
        let order_g = (errors[w - 1].0 / errors[w].0).log2();
        let order_d = (errors[w - 1].1 / errors[w].1).log2();
        println!(
            "order {} -> {}: G {order_g:.3}, dG/dk {order_d:.3}",
            meshes[w - 1],
            meshes[w]
        );
        assert!((3.8..4.2).contains(&order_g), "G's order {order_g}");
        assert!((3.8..4.2).contains(&order_d), "dG/dk's order {order_d}");
    }
    // the finest mesh: adjoint, forward and closed form within 1e-6 relative
    let (g, adjoint, forward, _) = on_mesh(128);
    assert!(((g - g_exact) / g_exact).abs() < 1e-6);
    assert!(((adjoint - dg_exact) / dg_exact).abs() < 1e-6);
    assert!(((forward - dg_exact) / dg_exact).abs() < 1e-6);
}

#[test]
fn gradient_matches_differences_of_resolves() {
    // the discrete G's derivative: central differences on one fixed mesh agree to ~h² of the
    // difference step, independent of the quadrature error
    let mesh = linspace(0.0, 1.0, 21);
    let value_at = |k: f64| {
        let sol = solve(
            &Hyper,
            &[k],
            &Guess::constant(mesh.clone(), &[0.5, -1.0]),
            &SolveOptions::fixed_mesh(),
        )
        .unwrap();
        integral_value(&Hyper, &sol, &Functional).unwrap()
    };
    let h = 1e-4;
    let fd = (value_at(K + h) - value_at(K - h)) / (2.0 * h);
    let sol = solve(
        &Hyper,
        &[K],
        &Guess::constant(mesh.clone(), &[0.5, -1.0]),
        &SolveOptions::fixed_mesh(),
    )
    .unwrap();
    let (_, adjoint) = integral_adjoint(&Hyper, &sol, &Functional).unwrap();
    assert!(
        ((adjoint[0] - fd) / fd).abs() < 1e-8,
        "adjoint {} fd {fd}",
        adjoint[0]
    );
}

#[test]
fn sensitivities_of_another_solution_are_refused() {
    let a = solve(
        &Hyper,
        &[K],
        &Guess::constant(linspace(0.0, 1.0, 9), &[0.5, -1.0]),
        &SolveOptions::fixed_mesh(),
    )
    .unwrap();
    let b = solve(
        &Hyper,
        &[K],
        &Guess::constant(linspace(0.0, 1.0, 17), &[0.5, -1.0]),
        &SolveOptions::fixed_mesh(),
    )
    .unwrap();
    let sens = Sensitivities::compute(&Hyper, &b).unwrap();
    let err = integral_forward(&Hyper, &a, &sens, &Functional).unwrap_err();
    assert!(err.to_string().contains("different solution"), "{err}");
}
