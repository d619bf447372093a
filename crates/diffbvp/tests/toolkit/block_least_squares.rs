//! Block-arrow least squares: a problem that declares shared and per-block local parameters is
//! fitted through the Schur complement, and lands where the dense driver lands (estimates,
//! covariance, standard errors; linear and robust losses, active bounds), for closed-form
//! residuals and for BVP runs.

use diffbvp::least_squares::{
    fit, BlockJacobian, BlockStructure, BvpResiduals, BvpRun, FitOptions, FitResult, Jacobian,
    LeastSquaresProblem, Loss, ParamMap,
};
use diffbvp::mesh::linspace;
use diffbvp::sensitivity::PointFunction;
use diffbvp::{Bvp, DualNum, Guess, SolveOptions, Solver};
use std::sync::Arc;

/// `M` decay curves `y = a_k e^{−λ x} + c` sharing the rate `λ` and the offset `c`, each with
/// its own amplitude `a_k`: parameters `[λ, c, a_1..a_M]`, 12 points per curve, data with
/// deterministic "noise" and a few outliers.
struct Decays {
    data: Vec<Vec<f64>>,
    xs: Vec<f64>,
    blocks: bool,
}

impl Decays {
    fn new(m: usize, blocks: bool) -> Self {
        let xs: Vec<f64> = (0..12).map(|i| 0.25 * i as f64).collect();
        let data = (0..m)
            .map(|k| {
                let a = 1.0 + 0.37 * k as f64;
                xs.iter()
                    .enumerate()
                    .map(|(i, &x)| {
                        let noise = 0.01 * (((7 * i + 3 * k) % 11) as f64 - 5.0);
                        let outlier = if (i + k) % 17 == 0 { 0.5 } else { 0.0 };
                        a * (-0.8 * x).exp() + 0.2 + noise + outlier
                    })
                    .collect()
            })
            .collect();
        Decays { data, xs, blocks }
    }

    fn structure(&self) -> Arc<BlockStructure> {
        Arc::new(BlockStructure::new(
            2,
            self.data.iter().map(|d| (d.len(), 1)),
        ))
    }
}

impl LeastSquaresProblem for Decays {
    type Error = String;
    fn num_params(&self) -> usize {
        2 + self.data.len()
    }
    fn evaluate(&mut self, p: &[f64]) -> Result<(Vec<f64>, Vec<f64>), String> {
        let (r, j) = self.evaluate_blocks(p);
        Ok((r, j.to_dense()))
    }
    fn evaluate_jacobian(&mut self, p: &[f64]) -> Result<(Vec<f64>, Jacobian), String> {
        if !self.blocks {
            let (r, j) = self.evaluate(p)?;
            return Ok((r, Jacobian::Dense(j)));
        }
        let (r, j) = self.evaluate_blocks(p);
        Ok((r, Jacobian::Blocks(j)))
    }
}

impl Decays {
    fn evaluate_blocks(&self, p: &[f64]) -> (Vec<f64>, BlockJacobian) {
        let mut jac = BlockJacobian::zeros(self.structure());
        let mut r = Vec::new();
        for (k, (sh, lo)) in jac.blocks_mut().into_iter().enumerate() {
            let a = p[2 + k];
            for (i, &x) in self.xs.iter().enumerate() {
                let e = (-p[0] * x).exp();
                r.push(a * e + p[1] - self.data[k][i]);
                sh[2 * i] = -x * a * e;
                sh[2 * i + 1] = 1.0;
                lo[i] = e;
            }
        }
        (r, jac)
    }
}

fn options(m: usize, loss: Loss) -> FitOptions {
    let mut lo = vec![0.0, -1.0];
    let mut hi = vec![5.0, 0.19]; // the offset's upper bound is active
    lo.extend(std::iter::repeat_n(0.0, m));
    hi.extend(std::iter::repeat_n(10.0, m));
    FitOptions {
        loss,
        f_scale: 0.05,
        ..FitOptions::with_bounds(lo, hi)
    }
}

fn assert_same(block: &FitResult, dense: &FitResult) {
    let se = dense.standard_errors().unwrap();
    for (i, (a, b)) in block.p.iter().zip(&dense.p).enumerate() {
        assert!(
            (a - b).abs() <= 1e-10 * b.abs().max(1.0) || (a - b).abs() <= 1e-6 * se[i],
            "parameter {i}: {a} vs {b} (se {})",
            se[i]
        );
    }
    let (cb, cd) = (block.covariance().unwrap(), dense.covariance().unwrap());
    let scale = cd.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (a, b) in cb.iter().zip(&cd) {
        assert!((a - b).abs() <= 1e-7 * scale, "{a} vs {b}");
    }
    let sb = block.standard_errors().unwrap();
    for (a, b) in sb.iter().zip(&se) {
        assert!((a - b).abs() <= 1e-7 * b, "{a} vs {b}");
    }
}

#[test]
fn block_fit_is_the_dense_fit_for_every_loss() {
    let m = 7;
    for loss in [Loss::Linear, Loss::SoftL1, Loss::Huber, Loss::Cauchy] {
        let mut p0 = vec![0.3, 0.0];
        p0.extend(std::iter::repeat_n(1.0, m));
        let opts = options(m, loss);
        let block = fit(&mut Decays::new(m, true), &p0, &opts).unwrap();
        let dense = fit(&mut Decays::new(m, false), &p0, &opts).unwrap();
        assert!(block.block_jacobian.is_some() && block.jacobian.is_empty());
        assert!(dense.block_jacobian.is_none());
        assert_eq!(block.dense_jacobian().len(), dense.jacobian.len());
        assert_eq!(block.termination, dense.termination, "{loss}");
        // the offset stops at its upper bound in both
        assert!(
            block.p[1] > 0.189 && block.p[1] <= 0.19,
            "{loss}: {:?}",
            block.p
        );
        assert_same(&block, &dense);
        // the compact covariance's shared block and local variances
        let bc = block.block_covariance().unwrap();
        let full = dense.covariance().unwrap();
        let np = 2 + m;
        let shared = bc.shared();
        for (i, j) in [(0, 0), (0, 1), (1, 1)] {
            let d = full[i * np + j];
            assert!((shared[i * 2 + j] - d).abs() <= 1e-7 * d.abs().max(1e-300));
        }
        assert!(dense.block_covariance().is_none());
    }
}

/// The least-squares response `−(JᵀJ)⁻¹ Jᵀ d` of a block-arrow fit (through the Schur
/// complement) equals the dense fit's, and both equal the response computed here from the
/// dense Jacobian by normal equations.
#[test]
fn linear_response_of_a_block_fit_is_the_dense_one() {
    let m = 7;
    let mut p0 = vec![0.3, 0.0];
    p0.extend(std::iter::repeat_n(1.0, m));
    let opts = options(m, Loss::Linear);
    let block = fit(&mut Decays::new(m, true), &p0, &opts).unwrap();
    let dense = fit(&mut Decays::new(m, false), &p0, &opts).unwrap();
    let (nr, np) = (block.residuals.len(), block.p.len());
    let d: Vec<f64> = (0..nr).map(|i| (0.7 * i as f64).sin()).collect();
    let j = nalgebra::DMatrix::from_row_slice(nr, np, &block.dense_jacobian());
    let direct = -(j.transpose() * &j).try_inverse().unwrap()
        * (j.transpose() * nalgebra::DVector::from_column_slice(&d));
    let via_block = block.linear_response(&d).unwrap();
    let via_dense = dense.linear_response(&d).unwrap();
    let scale = direct.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    for i in 0..np {
        assert!(
            (via_block[i] - direct[i]).abs() <= 1e-8 * scale,
            "{i}: {via_block:?} vs {direct}"
        );
        assert!(
            (via_dense[i] - direct[i]).abs() <= 1e-6 * scale,
            "{i}: {via_dense:?} vs {direct}"
        );
    }
    // the shared rows alone
    for (fit, tol) in [(&block, 1e-8), (&dense, 1e-6)] {
        let map = fit.linear_response_map().unwrap();
        let shared = map.apply_shared(&d, 2).unwrap();
        assert_eq!(shared.len(), 2);
        for i in 0..2 {
            assert!(
                (shared[i] - direct[i]).abs() <= tol * scale,
                "{i}: {shared:?}"
            );
        }
    }
    // a change of the wrong length is refused
    assert!(block.linear_response(&d[1..]).is_none());
    assert!(dense.linear_response(&d[1..]).is_none());
}

/// `y' = −λ y`, `y(0) = a`: model parameters `(λ, a)`.
struct Decay;
impl Bvp for Decay {
    fn dim(&self) -> usize {
        1
    }
    fn num_params(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], p: &[D], f: &mut [D]) {
        f[0] = -p[0] * y[0];
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], _yb: &[D], p: &[D], r: &mut [D]) {
        r[0] = ya[0] - p[1];
    }
}

struct Misfit(Vec<f64>);
impl PointFunction for Misfit {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, j: usize, _x: f64, y: &[D], _p: &[D]) -> D {
        y[0] - self.0[j]
    }
}

/// `m` BVP runs sharing `λ` (fit parameter 0), each with its own start value `a_k` (fit
/// parameter `1 + k`).
fn bvp_runs(m: usize, declare: bool) -> BvpResiduals<'static, Decay, Misfit> {
    let mut problem = BvpResiduals::new(1 + m);
    for k in 0..m {
        let xs: Vec<f64> = (1..=10).map(|i| 0.1 * i as f64).collect();
        let a = 1.0 + 0.5 * k as f64;
        let data = xs
            .iter()
            .enumerate()
            .map(|(i, x)| a * (-1.3 * x).exp() * (1.0 + 0.01 * (((3 * i + k) % 7) as f64 - 3.0)))
            .collect();
        let map = ParamMap::new(vec![0.0; 2]).link(0, 0).link(1, 1 + k);
        let mut solver = Solver::new(&Decay, SolveOptions::with_tol(1e-9));
        let sol = solver
            .solve(&[1.0, 1.0], &Guess::constant(linspace(0.0, 1.0, 6), &[1.0]))
            .unwrap();
        let run = BvpRun::new(solver, sol, xs, Misfit(data), map).unwrap();
        problem.push(run).unwrap();
    }
    if declare {
        problem.declare_blocks(Some(1)).unwrap();
    }
    problem
}

#[test]
fn bvp_runs_declare_their_blocks() {
    let m = 4;
    let mut p0 = vec![1.0];
    p0.extend(std::iter::repeat_n(1.0, m));
    let opts = FitOptions::with_bounds(vec![0.0; 1 + m], vec![5.0; 1 + m]);
    let mut blocked = bvp_runs(m, true);
    let st = blocked.block_structure().unwrap().clone();
    assert_eq!(
        (st.num_shared(), st.num_blocks(), st.num_params()),
        (1, m, 1 + m)
    );
    let block = fit(&mut blocked, &p0, &opts).unwrap();
    let dense = fit(&mut bvp_runs(m, false), &p0, &opts).unwrap();
    assert!(block.block_jacobian.is_some());
    assert_same(&block, &dense);
    assert!((block.p[0] - 1.3).abs() < 0.02, "{:?}", block.p);
    // the block Jacobian is the dense one
    let (_, jb) = blocked.evaluate_jacobian(&block.p).unwrap();
    let (_, jd) = blocked.evaluate(&block.p).unwrap();
    assert_eq!(jb.to_dense(), jd);
}

#[test]
fn a_structure_the_runs_do_not_have_is_refused() {
    let m = 3;
    let mut problem = bvp_runs(m, false);
    // with no shared parameter, the rate λ would belong to run 0 and run 1
    let err = problem.declare_blocks(Some(0)).unwrap_err().to_string();
    assert!(err.contains("run 1"), "{err}");
    assert!(problem.declare_blocks(Some(9)).is_err());
    assert!(problem.block_structure().is_none());
    // a run linking to another run's parameter after the declaration
    let mut problem = bvp_runs(m, true);
    let mut solver = Solver::new(&Decay, SolveOptions::with_tol(1e-6));
    let sol = solver
        .solve(&[1.0, 1.0], &Guess::constant(linspace(0.0, 1.0, 4), &[1.0]))
        .unwrap();
    let map = ParamMap::new(vec![0.0; 2]).link(0, 0).link(1, 1);
    let run = BvpRun::new(solver, sol, vec![0.5], Misfit(vec![1.0]), map).unwrap();
    let err = problem.push(run).unwrap_err().to_string();
    assert!(err.contains("run 3"), "{err}");
    assert_eq!(problem.len(), m);
}
