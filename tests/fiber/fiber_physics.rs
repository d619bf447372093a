//! Physics checks of the fiber model: alternative formulations, closed forms, balances, limits.

use diffbvp::{Bvp, DualNum, Guess, ResidualScale, SolveOptions};
use rheometer::model::{Air, Experiment, Material, TakeUp};
use rheometer::{
    model::simulate, model::CarreauLike, model::FiberModel, model::FiberSolution, model::Newtonian,
    model::Physics, model::SimulateOptions, model::Strength, model::ViscosityLaw,
};

fn experiment(take_up: TakeUp) -> Experiment {
    Experiment {
        take_up: Some(take_up),
        ..Experiment::pmma7n_v0p53_p2()
    }
}

fn model<L: ViscosityLaw>(law: L, physics: Physics) -> FiberModel<L> {
    FiberModel::new(
        &Material::pmma7n(),
        &Air::paper(),
        &experiment(TakeUp::Diameter(9e-5)),
        law,
        physics,
    )
    .unwrap()
}

/// The explicit 3-state Newtonian formulation: u' = Re/Q ρ u N / μ_e0(T).
struct ThreeState<'a>(&'a FiberModel<Newtonian>);

impl Bvp for ThreeState<'_> {
    fn dim(&self) -> usize {
        3
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, y: &[D], _p: &[D], f: &mut [D]) {
        let m = self.0;
        let q = m.mass_flow();
        let rho = m.density(y[2]);
        let rate = rho * y[0] * y[1] * (m.scaling.re / q) / m.zero_rate_viscosity().eval(y[2]);
        let st = m.local_state(x, &[y[0], y[1], y[2], rate], &[]);
        let (force, heat) = m.physics.sums(&st, &[], m.coefficients());
        f[0] = rate;
        f[1] = rate * q - force;
        f[2] = heat / (st.cp * q);
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        let m = self.0;
        r[0] = ya[0] - m.inlet_velocity();
        r[1] = ya[2] - m.inlet_temperature();
        let d_out = match m.take_up() {
            rheometer::model::DimensionlessTakeUp::Diameter { d_out, .. } => d_out,
            _ => unreachable!(),
        };
        r[2] = m.diameter(yb[0], m.density(yb[2])) / d_out - 1.0;
    }
}

#[test]
fn newtonian_strain_rate_form_equals_explicit_three_state_form() {
    let m = model(Newtonian, Physics::paper());
    let sol = simulate(&m, &[], &SimulateOptions::with_tol(1e-8)).unwrap();
    let s = &sol.solution;
    let guess = Guess::from_fn(s.x.clone(), 3, |x, y| {
        let v = s.eval(x);
        y.copy_from_slice(&v[..3]);
    });
    let opts = SolveOptions {
        tol: 1e-8,
        scale: ResidualScale::PerComponent(vec![1e2, 1e4, 1.0]),
        ..Default::default()
    };
    let three = diffbvp::solve(&ThreeState(&m), &[], &guess, &opts).unwrap();
    let mut worst = [0.0f64; 3];
    for i in 0..=200 {
        let x = m.length() * i as f64 / 200.0;
        let (a, b) = (s.eval(x), three.eval(x));
        for c in 0..3 {
            worst[c] = worst[c].max(((a[c] - b[c]) / b[c]).abs());
        }
    }
    eprintln!(
        "4-state vs 3-state: max rel dev u {:.2e} N {:.2e} T {:.2e}",
        worst[0], worst[1], worst[2]
    );
    assert!(worst.iter().all(|w| *w < 1e-7), "{worst:?}");
}

/// Isothermal Newtonian fiber without gravity and drag: N' = Q u' and Re/Q ρ u N = μ u', so
/// with N = N_0 + Q (u − u_in): u' = a u (b + Q u), a = Re ρ/(Q μ), b = N_0 − Q u_in. For
/// w = 1/u: w' = −a (b w + Q), hence u(s) = 1/((1/u_in + Q/b) e^(−a b s) − Q/b).
#[test]
fn isothermal_newtonian_fiber_matches_riccati_closed_form() {
    let physics = Physics::paper()
        .strength("gravity", Strength::Off)
        .and_then(|p| p.strength("air_drag", Strength::Off))
        .and_then(|p| p.strength("convection", Strength::Off))
        .and_then(|p| p.strength("viscous_heating", Strength::Off))
        .unwrap();
    let u_in_si = 4.0 * 3.08e-5
        / (std::f64::consts::PI * Material::pmma7n().density(513.15) * 1.134e-3f64.powi(2));
    let m = FiberModel::new(
        &Material::pmma7n(),
        &Air::paper(),
        &experiment(TakeUp::Velocity(30.0 * u_in_si)),
        Newtonian,
        physics,
    )
    .unwrap();
    let sol = simulate(&m, &[], &SimulateOptions::with_tol(1e-9)).unwrap();
    let q = m.mass_flow();
    let u_in = m.inlet_velocity();
    let t_in = m.inlet_temperature();
    let a = m.scaling.re * m.density(t_in) / (q * m.zero_rate_viscosity().eval(t_in));
    let l = m.length();
    let u_out = 30.0 * u_in;
    let u_of = |b: f64, s: f64| 1.0 / ((1.0 / u_in + q / b) * (-a * b * s).exp() - q / b);
    // b from u(L) = u_out by bisection (u(L) increases with b)
    let (mut lo, mut hi) = (1e-6, 1e6);
    for _ in 0..200 {
        let mid = (lo * hi).sqrt();
        let v = u_of(mid, l);
        if v.is_finite() && v > 0.0 && v < u_out {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let b = 0.5 * (lo + hi);
    let n0 = b + q * u_in;
    let mut worst = [0.0f64; 2];
    for i in 0..=100 {
        let s = l * i as f64 / 100.0;
        let y = sol.solution.eval(s);
        let u = u_of(b, s);
        let n = n0 + q * (u - u_in);
        worst[0] = worst[0].max((y[0] / u - 1.0).abs());
        worst[1] = worst[1].max((y[1] / n - 1.0).abs());
        assert!((y[2] - t_in).abs() < 1e-14);
    }
    eprintln!("Riccati: max rel dev u {:.2e} N {:.2e}", worst[0], worst[1]);
    assert!(worst[0] < 1e-7 && worst[1] < 1e-7, "{worst:?}");
}

/// Simpson's rule on every mesh interval (nodes and midpoints of the C¹ interpolant) is exact
/// for the Lobatto IIIa collocation solution, so the integrated balances must close to the
/// level of Newton's convergence.
#[test]
fn momentum_and_energy_balances_close() {
    let m = model(CarreauLike::new(), Physics::paper());
    let sol = simulate(&m, &[0.8, 11.71], &SimulateOptions::with_tol(1e-8)).unwrap();
    let s = &sol.solution;
    let q = m.mass_flow();
    let sums = |x: f64| {
        let y = s.eval(x);
        let st = m.local_state(x, &y, &[]);
        let (f, h) = m.physics.sums(&st, &[], m.coefficients());
        (f, h / (st.cp * q))
    };
    let (mut int_f, mut int_h, mut abs_f) = (0.0, 0.0, 0.0);
    for w in s.x.windows(2) {
        let (a, b) = (w[0], w[1]);
        let (fa, ha) = sums(a);
        let (fm, hm) = sums(0.5 * (a + b));
        let (fb, hb) = sums(b);
        int_f += (b - a) / 6.0 * (fa + 4.0 * fm + fb);
        int_h += (b - a) / 6.0 * (ha + 4.0 * hm + hb);
        abs_f += (b - a) / 6.0 * (fa.abs() + 4.0 * fm.abs() + fb.abs());
    }
    let last = s.nodes() - 1;
    // N(L) − N(0) = Q (u(L) − u(0)) − ∫ ΣF
    let mom =
        (s.at_node(last, 1) - s.at_node(0, 1)) - q * (s.at_node(last, 0) - s.at_node(0, 0)) + int_f;
    // T(L) − T(0) = ∫ ΣH/(c_p Q)
    let dt = s.at_node(last, 2) - s.at_node(0, 2);
    let en = dt - int_h;
    eprintln!("momentum balance defect {:.2e} (of ∫|F| = {abs_f:.3e}), energy defect {:.2e} (of ΔT = {dt:.3e})", mom, en);
    assert!(mom.abs() < 1e-10 * abs_f, "momentum defect {mom:e}");
    assert!(en.abs() < 1e-10 * dt.abs(), "energy defect {en:e}");
}

fn diameters<L: ViscosityLaw>(m: &FiberModel<L>, p: &[f64]) -> Vec<f64> {
    let sol: FiberSolution = simulate(m, p, &SimulateOptions::with_tol(1e-8)).unwrap();
    sol.uniform_profiles(m, 52).diameter
}

#[test]
fn carreau_tends_to_newtonian() {
    let newt = diameters(&model(Newtonian, Physics::paper()), &[]);
    let carreau = model(CarreauLike::new(), Physics::paper());
    let dev = |d: &[f64]| {
        d.iter()
            .zip(&newt)
            .fold(0.0f64, |a, (x, y)| a.max((x / y - 1.0).abs()))
    };
    let truth = dev(&diameters(&carreau, &[0.8, 11.71]));
    let n_near_1 = dev(&diameters(&carreau, &[1.0 - 1e-9, 11.71]));
    let kappa_big = dev(&diameters(&carreau, &[0.8, 40.0]));
    eprintln!("max rel diameter deviation from Newtonian: truth {truth:.2e}, n = 1 - 1e-9: {n_near_1:.2e}, kappa = 40: {kappa_big:.2e}");
    assert!(truth > 1e-3);
    assert!(n_near_1 < 1e-8 && kappa_big < 1e-8);
}

/// The physical solution must not depend on the reference values (in particular not on `α_o`).
#[test]
fn profiles_do_not_depend_on_reference_values() {
    use rheometer::model::{ReferenceValues, Scaling};
    let opts = SimulateOptions::with_tol(1e-8);
    let e = experiment(TakeUp::Diameter(9e-5));
    let base = model(CarreauLike::new(), Physics::paper());
    let a = simulate(&base, &[0.8, 11.71], &opts)
        .unwrap()
        .uniform_profiles(&base, 21);
    for reference in [
        ReferenceValues {
            heat_transfer: 50.0,
            ..Default::default()
        },
        ReferenceValues {
            length: 1.0,
            velocity: 0.05,
            temperature: 400.0,
            viscosity: 1e3,
            mass_flow: 1e-5,
            ..Default::default()
        },
    ] {
        let m = FiberModel::with_scaling(
            &Material::pmma7n(),
            &Air::paper(),
            &e,
            CarreauLike { stress_scale: 1.0 },
            Physics::paper(),
            Scaling::new(reference),
        )
        .unwrap();
        let b = simulate(&m, &[0.8, 11.71], &opts)
            .unwrap()
            .uniform_profiles(&m, 21);
        let mut worst = 0.0f64;
        for i in 0..21 {
            worst = worst.max((a.diameter[i] / b.diameter[i] - 1.0).abs());
            worst = worst.max((a.temperature[i] / b.temperature[i] - 1.0).abs());
            worst = worst.max((a.force[i] / b.force[i] - 1.0).abs());
        }
        eprintln!("other reference values: max rel dev {worst:.2e}");
        assert!(worst < 1e-6, "{worst:e}");
    }
}

#[test]
fn fiber_model_refuses_an_overflowing_inlet_velocity() {
    use rheometer::model::{Air, Experiment, Material};
    use rheometer::model::{CarreauLike, FiberModel, Physics};
    let mut e = Experiment::pmma7n_v0p53_p2();
    e.mass_flow = 1e308;
    let result = FiberModel::new(
        &Material::pmma7n(),
        &Air::paper(),
        &e,
        CarreauLike::new(),
        Physics::default(),
    );
    let m = match result {
        Err(e) => e.to_string(),
        Ok(_) => panic!("a mass flow of 1e308 kg/s was accepted"),
    };
    assert!(m.contains("inlet velocity") && m.contains("inf"), "{m}");
    assert!(!m.contains("inlet diameter 0 m"), "{m}");
}
