//! Feature `sprs`: the sparse matrices a user takes away hold the same exact values as the
//! dense inspection and the solver's own results (`cargo test -p diffbvp --features sprs`).
#![cfg(feature = "sprs")]

use diffbvp::inspect::discrete_system;
use diffbvp::least_squares::{fit, BvpResiduals, BvpRun, FitOptions, ParamMap};
use diffbvp::mesh::linspace;
use diffbvp::sensitivity::{PointFunction, Sensitivities};
use diffbvp::sparse::{collocation_jacobian, fit_jacobian, param_jacobian, sensitivity_matrix};
use diffbvp::{solve, Bvp, DualNum, Guess, SolveOptions, Solver};

/// y'' = −λ a e^y, y(0) = b, y(1) = 0, y'(0) = 1 with the unknown λ and model parameters
/// (a, b): unknowns and parameters both in the matrices.
struct Eigen;
impl Bvp for Eigen {
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
        f[1] = -p[0] * p[1] * y[0].exp();
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], p: &[D], r: &mut [D]) {
        r[0] = ya[0] - p[2];
        r[1] = yb[0];
        r[2] = ya[1] - 1.0;
    }
}

fn solution() -> diffbvp::Solution {
    let mut guess = Guess::constant(linspace(0.0, 1.0, 7), &[0.2, 0.0]);
    guess.unknowns = vec![1.0];
    solve(&Eigen, &[1.0, 0.2], &guess, &SolveOptions::fixed_mesh()).unwrap()
}

#[test]
fn jacobians_equal_the_dense_inspection() {
    let sol = solution();
    let dense = discrete_system(&Eigen, &sol.params, &Guess::from(&sol)).unwrap();
    let size = dense.size;
    let jac = collocation_jacobian(&Eigen, &sol).unwrap();
    assert_eq!(jac.shape(), (size, size));
    let pj = param_jacobian(&Eigen, &sol).unwrap();
    assert_eq!(pj.shape(), (size, 2));
    let mut worst: f64 = 0.0;
    for r in 0..size {
        for c in 0..size {
            let s = jac.get(r, c).copied().unwrap_or(0.0);
            worst = worst.max((s - dense.jacobian[r * size + c]).abs());
        }
        for j in 0..2 {
            let s = pj.get(r, j).copied().unwrap_or(0.0);
            worst = worst.max((s - dense.param_jacobian[r * 2 + j]).abs());
        }
    }
    assert!(worst < 1e-12, "largest difference {worst:e}");
}

#[test]
fn sensitivity_matrix_holds_the_forward_sensitivities() {
    let sol = solution();
    let sens = Sensitivities::compute(&Eigen, &sol).unwrap();
    let s = sensitivity_matrix(&sens);
    let states = sol.y.len();
    assert_eq!(s.shape(), (states + 1, 2));
    for r in 0..states {
        for j in 0..2 {
            assert_eq!(s.get(r, j).copied().unwrap_or(0.0), sens.dy[r * 2 + j]);
        }
    }
    for j in 0..2 {
        assert_eq!(s.get(states, j).copied().unwrap_or(0.0), sens.d_unknowns[j]);
    }
}

struct Misfit(Vec<f64>);
impl PointFunction for Misfit {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, j: usize, _x: f64, y: &[D], _p: &[D]) -> D {
        y[0] - self.0[j]
    }
}

#[test]
fn fit_jacobian_is_the_fit_results_jacobian() {
    let truth = solution();
    let xs: Vec<f64> = (1..10).map(|i| i as f64 / 10.0).collect();
    let data: Vec<f64> = xs.iter().map(|&x| truth.eval(x)[0]).collect();
    let opts = SolveOptions::fixed_mesh();
    let mut solver = Solver::new(&Eigen, opts);
    let start = [0.8, 0.1];
    let mut guess = Guess::constant(linspace(0.0, 1.0, 7), &[0.2, 0.0]);
    guess.unknowns = vec![1.0];
    let accepted = solver.solve(&start, &guess).unwrap();
    let map = ParamMap::new(vec![0.0; 2]).link(0, 0).link(1, 1);
    let run = BvpRun::new(solver, accepted, xs.clone(), Misfit(data), map).unwrap();
    let mut problem = BvpResiduals::new(2).with_run(run).unwrap();
    let bounds = FitOptions::with_bounds(vec![0.1, -1.0], vec![5.0, 1.0]);
    let result = fit(&mut problem, &start, &bounds).unwrap();
    let j = fit_jacobian(&result);
    assert_eq!(j.shape(), (xs.len(), 2));
    let dense = result.dense_jacobian();
    for r in 0..xs.len() {
        for c in 0..2 {
            assert_eq!(j.get(r, c).copied().unwrap_or(0.0), dense[r * 2 + c]);
        }
    }
}
