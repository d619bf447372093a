//! The problem classes of issue 63 against closed forms the code does not use: singular
//! problems `y' = S y / x + f` (Emden's equation, the first-order catalyst pellet) and
//! multipoint problems (two-layer diffusion with continuity and with a jump).

use crate::common::{Emden, Pellet, ReactingLayer, LAYER_XI};
use diffbvp::continuation::{continuation, ContinuationOptions};
use diffbvp::mesh::linspace;
use diffbvp::sensitivity::{adjoint_gradient, PointFunction, Sensitivities};
use diffbvp::{solve, Bvp, BvpError, DualNum, Guess, SolveOptions, Solver};

fn emden_exact(x: f64) -> f64 {
    (1.0 + x * x / 3.0).powf(-0.5)
}

/// y = sinh(φx) / (x sinh φ) and dy/dφ (x > 0).
fn pellet_exact(x: f64, phi: f64) -> (f64, f64) {
    let (s, c) = (phi.sinh(), phi.cosh());
    let y = (phi * x).sinh() / (x * s);
    let dy = (x * (phi * x).cosh() * s - (phi * x).sinh() * c) / (x * s * s);
    (y, dy)
}

/// η = 3 (φ coth φ − 1) / φ² and dη/dφ.
fn effectiveness(phi: f64) -> (f64, f64) {
    let coth = 1.0 / phi.tanh();
    let csch2 = 1.0 / (phi.sinh() * phi.sinh());
    let eta = 3.0 * (phi * coth - 1.0) / (phi * phi);
    let deta =
        3.0 * ((coth - phi * csch2) * phi * phi - 2.0 * phi * (phi * coth - 1.0)) / phi.powi(4);
    (eta, deta)
}

/// η = 3 y'(1) / φ² as a point function of the state at x = 1.
struct Eta;

impl PointFunction for Eta {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, _i: usize, _x: f64, y: &[D], p: &[D]) -> D {
        y[1] * 3.0 / (p[0] * p[0])
    }
}

fn tight(tol: f64) -> SolveOptions {
    let mut o = SolveOptions::with_tol(tol);
    o.bc_tol = Some(1e-10);
    o
}

#[test]
fn emden_matches_its_closed_form_at_every_tolerance() {
    let guess = Guess::constant(linspace(0.0, 1.0, 5), &[1.0, 0.0]);
    for (tol, bound) in [(1e-3, 2e-4), (1e-5, 2e-6), (1e-8, 2e-9)] {
        let s = solve(&Emden { regular_bc: true }, &[], &guess, &tight(tol)).unwrap();
        let err = (0..=100)
            .map(|j| j as f64 / 100.0)
            .map(|x| (s.eval(x)[0] - emden_exact(x)).abs())
            .fold(0.0f64, f64::max);
        assert!(
            err < bound,
            "tol {tol:e}: max error {err:e} with {} nodes",
            s.nodes()
        );
        // the slope at 0 is (I - S)^-1 f(0): y''(0) = -y(0)^5 / 3
        let yp0 = s.eval_derivative(0.0);
        assert!(yp0[0].abs() < 1e-12);
        assert!((yp0[1] + s.y[0].powi(5) / 3.0).abs() < 1e-12);
    }
}

#[test]
fn pellet_values_and_forward_sensitivities_match_closed_forms() {
    let phi = 3.0;
    let guess = Guess::constant(linspace(0.0, 1.0, 5), &[0.5, 0.0]);
    let s = solve(&Pellet, &[phi], &guess, &tight(1e-8)).unwrap();
    let sens = Sensitivities::compute(&Pellet, &s).unwrap();
    for x in [0.1, 0.3, 0.5, 0.8, 1.0] {
        let (y, dy) = pellet_exact(x, phi);
        assert!((s.eval(x)[0] - y).abs() < 1e-6 * y.abs(), "y({x})");
        let got = sens.at(x)[0];
        assert!(
            (got - dy).abs() < 1e-6 * dy.abs().max(1e-3),
            "dy/dphi({x}): {got} vs {dy}"
        );
    }
    // x = 0: y(0) = φ / sinh φ, dy(0)/dφ = (sinh φ − φ cosh φ) / sinh² φ
    let dy0 = (phi.sinh() - phi * phi.cosh()) / phi.sinh().powi(2);
    assert!((sens.at(0.0)[0] - dy0).abs() < 1e-6 * dy0.abs());
    assert!((s.y[0] - phi / phi.sinh()).abs() < 1e-6 * s.y[0]);
}

#[test]
fn pellet_effectiveness_gradient_from_forward_and_adjoint_matches_closed_form() {
    for phi in [0.5, 3.0, 10.0] {
        let guess = Guess::constant(linspace(0.0, 1.0, 5), &[0.5, 0.0]);
        let s = solve(&Pellet, &[phi], &guess, &tight(1e-8)).unwrap();
        let (eta, deta) = effectiveness(phi);
        let (value, grad) = adjoint_gradient(&Pellet, &s, &[1.0], &[1.0], &Eta).unwrap();
        assert!(
            (value - eta).abs() < 1e-6 * eta,
            "phi {phi}: eta {value} vs {eta}"
        );
        assert!(
            (grad[0] - deta).abs() < 1e-6 * deta.abs(),
            "phi {phi}: adjoint {} vs {deta}",
            grad[0]
        );
        let sens = Sensitivities::compute(&Pellet, &s).unwrap();
        let (dslope, slope) = (sens.at(1.0)[1], s.eval(1.0)[1]);
        let forward = 3.0 * dslope / (phi * phi) - 6.0 * slope / phi.powi(3);
        assert!(
            (forward - deta).abs() < 1e-6 * deta.abs(),
            "phi {phi}: forward {forward} vs {deta}"
        );
    }
}

#[test]
fn pellet_continuation_in_the_thiele_modulus_reaches_the_closed_form() {
    let guess = Guess::constant(linspace(0.0, 1.0, 5), &[0.5, 0.0]);
    let mut solver = Solver::new(&Pellet, tight(1e-6));
    let start = solver.solve(&[1.0], &guess).unwrap();
    let path = continuation(
        &mut solver,
        &start,
        0,
        20.0,
        &ContinuationOptions::default(),
    )
    .unwrap();
    let s = &path.solution;
    assert_eq!(s.params, vec![20.0]);
    for x in [0.2, 0.6, 0.9, 1.0] {
        let (y, _) = pellet_exact(x, 20.0);
        assert!((s.eval(x)[0] - y).abs() < 1e-5 * y.max(1e-3), "y({x})");
    }
}

#[test]
fn structured_and_sparse_elimination_agree_on_a_singular_problem() {
    use diffbvp::LinearSolverKind;
    let guess = Guess::constant(linspace(0.0, 1.0, 5), &[0.5, 0.0]);
    let mut results = Vec::new();
    for kind in [LinearSolverKind::Structured, LinearSolverKind::SparseLu] {
        let mut o = tight(1e-6);
        o.linear_solver = kind;
        o.factor_at_solution = true;
        let s = solve(&Pellet, &[3.0], &guess, &o).unwrap();
        assert_eq!(s.factorization().map(|f| f.kind()), Some(kind));
        results.push(s);
    }
    // the pivoting differs: the meshes and values agree to round-off
    assert_eq!(results[0].nodes(), results[1].nodes());
    for (a, b) in results[0].x.iter().zip(&results[1].x) {
        assert!((a - b).abs() < 1e-12);
    }
    for (a, b) in results[0].y.iter().zip(&results[1].y) {
        assert!((a - b).abs() < 1e-10);
    }
}

#[test]
fn violated_regularity_conditions_are_named() {
    let guess = Guess::constant(linspace(0.0, 1.0, 5), &[1.0, 0.0]);
    // boundary conditions that do not impose S y(0) = 0
    let e = solve(&Emden { regular_bc: false }, &[], &guess, &tight(1e-4)).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, BvpError::InvalidInput(_)), "{msg}");
    assert!(msg.contains("S y(0) = 0"), "{msg}");
    // an interval not starting at 0
    let shifted = Guess::constant(linspace(0.5, 1.0, 5), &[1.0, 0.0]);
    let msg = solve(&Emden { regular_bc: true }, &[], &shifted, &tight(1e-4))
        .unwrap_err()
        .to_string();
    assert!(msg.contains("a = 0") && msg.contains("0.5"), "{msg}");

    struct Bad(Vec<f64>);
    impl Bvp for Bad {
        fn dim(&self) -> usize {
            2
        }
        fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], _p: &[D], f: &mut [D]) {
            f[0] = y[1];
            f[1] = -y[0];
        }
        fn bc<D: DualNum<Primitive = f64> + Copy>(
            &self,
            ya: &[D],
            yb: &[D],
            _p: &[D],
            r: &mut [D],
        ) {
            r[0] = ya[1];
            r[1] = yb[0] - 1.0;
        }
        fn singular_term(&self) -> Option<Vec<f64>> {
            Some(self.0.clone())
        }
    }
    let msg = solve(&Bad(vec![0.0; 3]), &[], &guess, &tight(1e-4))
        .unwrap_err()
        .to_string();
    assert!(msg.contains("2 x 2"), "{msg}");
    let msg = solve(&Bad(vec![0.0, 0.0, 0.0, 1.0]), &[], &guess, &tight(1e-4))
        .unwrap_err()
        .to_string();
    assert!(msg.contains("I - S is singular"), "{msg}");
}

// ---------------------------------------------------------------- multipoint problems

/// Steady conduction with a uniform source g = 1 through two layers [0, ξ] and [ξ, 1] of
/// conductivities k1, k2 (model parameters 0 and 1) with a contact resistance Rc (parameter 2):
/// T' = −q / k_r, q' = g; T(0) = 1, T(1) = 0; at ξ the flux is continuous and the temperature
/// jumps, T(ξ⁺) = T(ξ⁻) − Rc q(ξ).
struct Layers;

const XI: f64 = 0.4;
const SOURCE: f64 = 1.0;

impl Bvp for Layers {
    fn dim(&self) -> usize {
        2
    }
    fn num_params(&self) -> usize {
        3
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, y: &[D], p: &[D], f: &mut [D]) {
        self.rhs_in_region(usize::from(x > XI), x, y, p, f);
    }
    fn rhs_in_region<D: DualNum<Primitive = f64> + Copy>(
        &self,
        region: usize,
        _x: f64,
        y: &[D],
        p: &[D],
        f: &mut [D],
    ) {
        f[0] = -y[1] / p[region];
        f[1] = D::from(SOURCE);
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        r[0] = ya[0] - 1.0;
        r[1] = yb[0];
    }
    fn interfaces(&self) -> &[f64] {
        &[XI]
    }
    fn interface_conditions<D: DualNum<Primitive = f64> + Copy>(
        &self,
        _index: usize,
        left: &[D],
        right: &[D],
        p: &[D],
        r: &mut [D],
    ) {
        r[0] = right[0] - left[0] + p[2] * left[1];
        r[1] = right[1] - left[1];
    }
}

/// The closed form of [`Layers`]: (T, q) at x (the right limit at ξ), generic so that dual
/// numbers give its exact parameter derivatives.
fn layers_exact<D: DualNum<Primitive = f64> + Copy>(x: f64, p: [D; 3]) -> [D; 2] {
    layers_side(x, p, false)
}

/// [`layers_exact`] with the left limit at ξ if `left`.
fn layers_side<D: DualNum<Primitive = f64> + Copy>(x: f64, p: [D; 3], left: bool) -> [D; 2] {
    let [k1, k2, rc] = p;
    let g = SOURCE;
    let q0 = (-(k1.recip() * (g * XI * XI / 2.0))
        - k2.recip() * (g * (1.0 - XI * XI) / 2.0)
        - rc * (g * XI)
        + 1.0)
        / (k1.recip() * XI + k2.recip() * (1.0 - XI) + rc);
    let q = q0 + g * x;
    if x < XI || (left && x == XI) {
        [-(q0 * x + g * x * x / 2.0) / k1 + 1.0, q]
    } else {
        let t_xi = -(q0 * XI + g * XI * XI / 2.0) / k1 + 1.0 - rc * (q0 + g * XI);
        [t_xi - (q0 * (x - XI) + g * (x * x - XI * XI) / 2.0) / k2, q]
    }
}

#[test]
fn two_layers_with_a_contact_jump_match_the_closed_form_and_its_derivatives() {
    use diffbvp::mesh::{multipoint_linspace, regions};
    use num_dual::Dual64;
    let p = [1.0, 3.0, 0.5];
    let guess = Guess::constant(multipoint_linspace(&[0.0, XI, 1.0], 4), &[0.5, 0.0]);
    let mut o = tight(1e-6);
    o.factor_at_solution = true;
    let s = solve(&Layers, &p, &guess, &o).unwrap();
    // the Newton matrix stays almost block diagonal: the structured elimination factors it
    assert_eq!(
        s.factorization().map(|f| f.kind()),
        Some(diffbvp::LinearSolverKind::Structured)
    );
    let r = regions(&s.x);
    assert_eq!(r.len(), 2);
    // the left limit at ξ is the last node of region 0
    let left = r[0].end - 1;
    let exact_left = layers_side(XI, p, true);
    assert!((s.at_node(left, 0) - exact_left[0]).abs() < 1e-12);
    let sens = Sensitivities::compute(&Layers, &s).unwrap();
    for x in [0.1, 0.3, XI, 0.7, 0.95] {
        let v = layers_exact(x, p);
        let got = s.eval(x);
        assert!(
            (got[0] - v[0]).abs() < 1e-12 && (got[1] - v[1]).abs() < 1e-12,
            "x {x}"
        );
        let d = sens.at(x);
        for j in 0..3 {
            let mut pd = p.map(Dual64::from);
            pd[j] = Dual64::new(p[j], 1.0);
            let e = layers_exact(x, pd);
            for c in 0..2 {
                let want = e[c].eps;
                assert!(
                    (d[c * 3 + j] - want).abs() < 1e-10 * (1.0 + want.abs()),
                    "d y{c}/d p{j} at {x}: {} vs {want}",
                    d[c * 3 + j]
                );
            }
        }
    }
    // the adjoint gradient of T at the jump's left limit plus q(1)
    struct Probe;
    impl PointFunction for Probe {
        fn eval<D: DualNum<Primitive = f64> + Copy>(
            &self,
            i: usize,
            _x: f64,
            y: &[D],
            _p: &[D],
        ) -> D {
            y[i]
        }
    }
    let (value, grad) = adjoint_gradient(&Layers, &s, &[0.2, 1.0], &[1.0, 1.0], &Probe).unwrap();
    let want_v = layers_exact(0.2, p)[0] + layers_exact(1.0, p)[1];
    assert!((value - want_v).abs() < 1e-12);
    for j in 0..3 {
        let mut pd = p.map(Dual64::from);
        pd[j] = Dual64::new(p[j], 1.0);
        let want = layers_exact(0.2, pd)[0].eps + layers_exact(1.0, pd)[1].eps;
        assert!(
            (grad[j] - want).abs() < 1e-10 * (1.0 + want.abs()),
            "dG/dp{j}"
        );
    }
}

/// u(x) of [`ReactingLayer`]: A cosh(φx) in the reacting layer, linear beyond it.
fn reacting_exact<D: DualNum<Primitive = f64> + Copy>(x: f64, phi: D) -> D {
    let (c, s) = ((phi * LAYER_XI).cosh(), (phi * LAYER_XI).sinh());
    let a = (c + phi * s * (1.0 - LAYER_XI)).recip();
    if x <= LAYER_XI {
        a * (phi * x).cosh()
    } else {
        a * (c + phi * s * (x - LAYER_XI))
    }
}

#[test]
fn a_reacting_layer_refines_its_own_region_and_matches_the_closed_form() {
    use diffbvp::mesh::{multipoint_linspace, regions};
    use num_dual::Dual64;
    let phi = 30.0;
    let guess = Guess::constant(multipoint_linspace(&[0.0, LAYER_XI, 1.0], 5), &[0.5, 0.0]);
    let s = solve(
        &ReactingLayer { multipoint: true },
        &[phi],
        &guess,
        &tight(1e-8),
    )
    .unwrap();
    let r = regions(&s.x);
    // the steep layer is refined, the linear region keeps its few nodes
    assert!(r[0].len() > 4 * r[1].len(), "{:?}", r);
    assert!(r[1].len() <= 5, "{:?}", r);
    let sens = Sensitivities::compute(&ReactingLayer { multipoint: true }, &s).unwrap();
    for x in [0.0, 0.2, 0.38, LAYER_XI, 0.6, 1.0] {
        let want = reacting_exact(x, phi);
        assert!((s.eval(x)[0] - want).abs() < 1e-7, "u({x})");
        let dwant = reacting_exact(x, Dual64::new(phi, 1.0)).eps;
        let got = sens.at(x)[0];
        assert!(
            (got - dwant).abs() < 1e-6 * dwant.abs().max(1e-3),
            "du/dphi({x}): {got} vs {dwant}"
        );
    }
}

#[test]
fn multipoint_meshes_must_hold_the_interfaces_twice() {
    let msg = solve(
        &ReactingLayer { multipoint: true },
        &[2.0],
        &Guess::constant(linspace(0.0, 1.0, 5), &[0.5, 0.0]),
        &tight(1e-4),
    )
    .unwrap_err()
    .to_string();
    assert!(msg.contains("twice") && msg.contains("0.4"), "{msg}");
}

/// Errors and node counts per tolerance (run with --nocapture for the table of the report).
#[test]
fn errors_shrink_with_the_tolerance() {
    use diffbvp::mesh::multipoint_linspace;
    for tol in [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8] {
        let grid = |f: &dyn Fn(f64) -> f64| {
            (0..=200)
                .map(|j| j as f64 / 200.0)
                .map(f)
                .fold(0.0f64, f64::max)
        };
        let g = Guess::constant(linspace(0.0, 1.0, 5), &[1.0, 0.0]);
        let e = solve(&Emden { regular_bc: true }, &[], &g, &tight(tol)).unwrap();
        let err_e = grid(&|x| (e.eval(x)[0] - emden_exact(x)).abs());
        let g = Guess::constant(linspace(0.0, 1.0, 5), &[0.5, 0.0]);
        let pl = solve(&Pellet, &[3.0], &g, &tight(tol)).unwrap();
        let err_p = grid(&|x| {
            let y = if x == 0.0 {
                3.0 / 3.0f64.sinh()
            } else {
                pellet_exact(x, 3.0).0
            };
            (pl.eval(x)[0] - y).abs()
        });
        let g = Guess::constant(multipoint_linspace(&[0.0, XI, 1.0], 5), &[0.5, 0.0]);
        let rl = solve(
            &ReactingLayer { multipoint: true },
            &[30.0],
            &g,
            &tight(tol),
        )
        .unwrap();
        let err_r = grid(&|x| (rl.eval(x)[0] - reacting_exact(x, 30.0)).abs());
        eprintln!(
            "| {tol:.0e} | {err_e:.1e} | {} | {err_p:.1e} | {} | {err_r:.1e} | {} |",
            e.nodes(),
            pl.nodes(),
            rl.nodes()
        );
        for err in [err_e, err_p, err_r] {
            assert!(err < tol, "tol {tol:e}: error {err:e}");
        }
    }
}

/// r_j = T(x_j) − data_j.
struct TemperatureMisfit {
    data: Vec<f64>,
}

impl PointFunction for TemperatureMisfit {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, j: usize, _x: f64, y: &[D], _p: &[D]) -> D {
        y[0] - self.data[j]
    }
}

#[test]
fn a_least_squares_fit_recovers_the_second_layer_and_the_contact_resistance() {
    use diffbvp::least_squares::{fit, BvpResiduals, BvpRun, FitOptions, ParamMap};
    use diffbvp::mesh::multipoint_linspace;
    let truth = [1.0, 3.0, 0.5];
    // data from the closed form, both sides of the interface
    let xs: Vec<f64> = (1..20).map(|i| i as f64 / 20.0).collect();
    let data = xs.iter().map(|&x| layers_exact(x, truth)[0]).collect();
    let mut solver = Solver::new(&Layers, tight(1e-8));
    let guess = Guess::constant(multipoint_linspace(&[0.0, XI, 1.0], 4), &[0.5, 0.0]);
    let start = [2.0, 0.1];
    let accepted = solver.solve(&[1.0, start[0], start[1]], &guess).unwrap();
    let map = ParamMap::new(vec![1.0, 0.0, 0.0]).link(1, 0).link(2, 1);
    let run = BvpRun::new(solver, accepted, xs, TemperatureMisfit { data }, map).unwrap();
    let mut prob = BvpResiduals::new(2).with_run(run).unwrap();
    let opts = FitOptions::with_bounds(vec![0.1, 0.0], vec![10.0, 2.0]);
    let res = fit(&mut prob, &start, &opts).unwrap();
    assert!((res.p[0] - truth[1]).abs() < 1e-8, "{:?}", res.p);
    assert!((res.p[1] - truth[2]).abs() < 1e-8, "{:?}", res.p);
    assert!(res.cost < 1e-20, "cost {}", res.cost);
}
