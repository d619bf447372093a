//! The problem classes of issue 63 against closed forms the code does not use: singular
//! problems `y' = S y / x + f` (Emden's equation, the first-order catalyst pellet) and
//! multipoint problems (two-layer diffusion with continuity and with a jump).

use diffbvp::continuation::{continuation, ContinuationOptions};
use diffbvp::mesh::linspace;
use diffbvp::sensitivity::{adjoint_gradient, PointFunction, Sensitivities};
use diffbvp::{solve, Bvp, BvpError, DualNum, Guess, SolveOptions, Solver};

/// Emden's equation y'' + (2/x) y' + y^5 = 0, y'(0) = 0, y(1) = sqrt(3/4) (scipy's test
/// problem); `regular_bc: false` replaces y'(0) = 0 by y(0) = 1.1, which the regularity
/// condition contradicts.
struct Emden {
    regular_bc: bool,
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

fn emden_exact(x: f64) -> f64 {
    (1.0 + x * x / 3.0).powf(-0.5)
}

/// The first-order reaction in a spherical catalyst pellet y'' + (2/x) y' = φ² y, y'(0) = 0,
/// y(1) = 1, with the Thiele modulus φ the model parameter.
struct Pellet;

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
