//! Any BVP from Python: problems given as expressions ([`diffbvp::expr::ExprBvp`]), solved
//! with the GIL released, no Python callback per point; their solutions' interpolant, forward
//! sensitivities and adjoint gradients. The scipy-compatible front end (`diffbvp.solve_bvp`)
//! is Python (python/diffbvp/bvp.py); this layer only checks shapes, converts and calls the
//! toolkit.

use crate::errors::{diffbvp_error, input_error};
use diffbvp::expr::{ExprBuilder, ExprBvp, ExprError};
use diffbvp::least_squares::{self, BvpResiduals, BvpRun, FitOptions, ParamMap, Termination};
use diffbvp::mesh::MeshOptions;
use diffbvp::sensitivity::{adjoint_gradient, integral_adjoint, PointFunction, Sensitivities};
use diffbvp::DualNum;
use diffbvp::{Bvp, BvpError, Guess, Solution, SolveOptions, Solver};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use std::sync::Arc;

fn expr_error(e: ExprError) -> PyErr {
    input_error(e.to_string())
}

/// A problem given as expressions (see `diffbvp.ExprProblem` in the stubs): `fun` has one
/// expression per state, `bc` one per boundary residual (`n + k`), `unknowns` names the `k`
/// unknown parameters, `params` the fixed model parameters, `constants` named values.
#[pyclass(module = "diffbvp._native", frozen)]
pub struct ExprProblem {
    bvp: Arc<ExprBvp>,
    builder: ExprBuilder,
    fun: Vec<String>,
    bc: Vec<String>,
}

#[pymethods]
impl ExprProblem {
    #[new]
    #[pyo3(signature = (fun, bc, unknowns, params, constants, singular=None))]
    fn new(
        fun: Vec<String>,
        bc: Vec<String>,
        unknowns: Vec<String>,
        params: Vec<String>,
        constants: Vec<(String, f64)>,
        singular: Option<Vec<f64>>,
    ) -> PyResult<Self> {
        let u: Vec<&str> = unknowns.iter().map(String::as_str).collect();
        let q: Vec<&str> = params.iter().map(String::as_str).collect();
        let mut builder = ExprBvp::builder().unknowns(&u).params(&q);
        for (name, v) in &constants {
            builder = builder.constant(name, *v);
        }
        if let Some(s) = singular {
            builder = builder.singular_term(s);
        }
        let f: Vec<&str> = fun.iter().map(String::as_str).collect();
        let b: Vec<&str> = bc.iter().map(String::as_str).collect();
        let bvp = builder.clone().build(&f, &b).map_err(expr_error)?;
        Ok(ExprProblem {
            bvp: Arc::new(bvp),
            builder,
            fun,
            bc,
        })
    }

    /// Number of states.
    #[getter]
    fn n(&self) -> usize {
        self.bvp.dim()
    }

    /// Number of unknown parameters.
    #[getter]
    fn k(&self) -> usize {
        self.bvp.num_unknowns()
    }

    /// Number of model parameters.
    #[getter]
    fn q(&self) -> usize {
        self.bvp.num_params()
    }

    /// The right-hand side's expressions.
    #[getter]
    fn fun(&self) -> Vec<String> {
        self.fun.clone()
    }

    /// The boundary conditions' expressions.
    #[getter]
    fn bc(&self) -> Vec<String> {
        self.bc.clone()
    }

    /// `f(x, y, p)` at the columns of `y` (`n × m`), `p` = unknowns then model parameters;
    /// returns `n × m`.
    fn rhs<'py>(
        &self,
        py: Python<'py>,
        x: Vec<f64>,
        y: PyReadonlyArray2<'py, f64>,
        p: Vec<f64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (n, m) = shape(&y, self.bvp.dim(), x.len(), "y")?;
        check_p(&p, self.bvp.num_unknowns() + self.bvp.num_params())?;
        let ya = y.as_array();
        let mut out = vec![0.0; n * m];
        let (mut yi, mut fi) = (vec![0.0; n], vec![0.0; n]);
        for (j, &xj) in x.iter().enumerate() {
            for (c, v) in yi.iter_mut().enumerate() {
                *v = ya[[c, j]];
            }
            self.bvp.eval_rhs(xj, &yi, &p, &mut fi);
            for (c, v) in fi.iter().enumerate() {
                out[c * m + j] = *v;
            }
        }
        crate::convert::array2(py, &out, n, m)
    }

    /// Solves from the guess `x` (m), `y` (`n × m`), `unknowns` (k) at the model parameters
    /// `params` (q), with the GIL released. Returns `(status, message, solution or None)`:
    /// status 0 converged, 1 node limit or no convergence, 2 singular Jacobian, 3 boundary
    /// tolerance not met. Bad input and non-finite values raise `InputError` / `EvaluationError`.
    #[pyo3(signature = (x, y, unknowns, params, tol, bc_tol, max_nodes, verbose, scipy_mesh))]
    #[allow(clippy::too_many_arguments)]
    fn solve(
        &self,
        py: Python<'_>,
        x: Vec<f64>,
        y: PyReadonlyArray2<'_, f64>,
        unknowns: Vec<f64>,
        params: Vec<f64>,
        tol: f64,
        bc_tol: Option<f64>,
        max_nodes: usize,
        verbose: u8,
        scipy_mesh: bool,
    ) -> PyResult<(i32, String, Option<BvpSolution>)> {
        let guess = self.guess(x, &y, unknowns)?;
        if params.len() != self.bvp.num_params() {
            return Err(input_error(format!(
                "params: the problem has {} model parameters, got {} values",
                self.bvp.num_params(),
                params.len()
            )));
        }
        let options = SolveOptions {
            tol,
            bc_tol,
            max_nodes,
            verbose,
            // scipy's contract: nodes are only added (1 or 2 per interval above tol)
            coarsen: !scipy_mesh,
            mesh: if scipy_mesh {
                MeshOptions::scipy()
            } else {
                MeshOptions::default()
            },
            ..SolveOptions::default()
        };
        let bvp = self.bvp.clone();
        let out = py.detach(move || {
            let mut solver = Solver::new(bvp.as_ref(), options);
            solver.solve(&params, &guess)
        });
        match out {
            Ok(sol) => Ok((
                0,
                "The algorithm converged to the desired accuracy.".into(),
                Some(BvpSolution {
                    bvp: self.bvp.clone(),
                    builder: self.builder.clone(),
                    sol: Arc::new(sol),
                }),
            )),
            Err(e) => {
                let status = match &e {
                    BvpError::MaxNodesExceeded { .. } => 1,
                    BvpError::SingularJacobian { .. } => 2,
                    BvpError::ToleranceNotMet {
                        max_residual,
                        tol,
                        max_bc_residual,
                        bc_tol,
                        ..
                    } if max_residual <= tol && max_bc_residual > bc_tol => 3,
                    BvpError::NonFinite { what, component, x } => {
                        let text = if what.contains("boundary") {
                            self.bc
                                .get(*component)
                                .map(|s| format!(" (bc[{component}] = \"{s}\")"))
                        } else {
                            self.fun
                                .get(*component)
                                .map(|s| format!(" (fun[{component}] = \"{s}\")"))
                        };
                        return Err(diffbvp_error(
                            py,
                            "EvaluationError",
                            format!(
                                "{e}{}; a division by zero, the log or sqrt of a negative \
                                 number, or an overflow at x = {x:e}: check the expression and \
                                 the guess there",
                                text.unwrap_or_default()
                            ),
                        ));
                    }
                    BvpError::InvalidInput(_) => return Err(input_error(e.to_string())),
                    _ => 1,
                };
                Ok((status, e.to_string(), None))
            }
        }
    }

    /// Fits the model parameters `fit` (indices into `params`, start values there) to the
    /// observations `data_y ≈ y_component(data_x)`, residuals `(y − data) / sigma`, within
    /// `[lower, upper]`, by the toolkit's bounded trust-region least squares with the Jacobian
    /// exact from forward sensitivities, each solve warm-started from the last accepted one,
    /// with the GIL released. Returns `(p, cost, residuals, jacobian (N × P row-major),
    /// termination, success, iterations, accepted steps, solution at p)`.
    #[pyo3(signature = (x, y, unknowns, params, fit, lower, upper, data_x, data_y, sigma,
                        component, tol, max_nodes, xtol, ftol, max_iterations))]
    #[allow(clippy::too_many_arguments)]
    fn fit(
        &self,
        py: Python<'_>,
        x: Vec<f64>,
        y: PyReadonlyArray2<'_, f64>,
        unknowns: Vec<f64>,
        params: Vec<f64>,
        fit: Vec<usize>,
        lower: Vec<f64>,
        upper: Vec<f64>,
        data_x: PyReadonlyArray1<'_, f64>,
        data_y: PyReadonlyArray1<'_, f64>,
        sigma: PyReadonlyArray1<'_, f64>,
        component: usize,
        tol: f64,
        max_nodes: usize,
        xtol: f64,
        ftol: f64,
        max_iterations: usize,
    ) -> PyResult<FitOutput> {
        let guess = self.guess(x, &y, unknowns)?;
        let (n, q) = (self.bvp.dim(), self.bvp.num_params());
        if params.len() != q || component >= n {
            return Err(input_error(format!(
                "fit: {} model parameter values for {q}, component {component} of {n} states",
                params.len()
            )));
        }
        if fit.is_empty()
            || fit.iter().any(|&j| j >= q)
            || lower.len() != fit.len()
            || upper.len() != fit.len()
        {
            return Err(input_error(format!(
                "fit: the fitted parameters {fit:?} must be indices below {q}, with one lower \
                 and one upper bound each"
            )));
        }
        // the same cap as a data set's measurement rows (the loader's, one limit for both),
        // checked on the arrays' lengths before anything is copied
        let cap = rheometer::data::input::DEFAULT_MAX_ROWS_PER_FILE;
        if data_x.len() > cap {
            return Err(input_error(format!(
                "data_x: {} observations, more than {cap}; thin the data",
                data_x.len()
            )));
        }
        if data_y.len() != data_x.len() || sigma.len() != data_x.len() {
            return Err(input_error(format!(
                "fit: {} points, {} values and {} sigmas; they must match",
                data_x.len(),
                data_y.len(),
                sigma.len()
            )));
        }
        let copy = |a: &PyReadonlyArray1<'_, f64>| a.as_array().to_vec();
        let (data_x, data_y, sigma) = (copy(&data_x), copy(&data_y), copy(&sigma));
        let bvp = self.bvp.clone();
        let options = SolveOptions {
            tol,
            max_nodes,
            ..SolveOptions::default()
        };
        // Ctrl-C sets the fit's cancellation flag (checked before every model evaluation)
        let out = crate::run::interruptible(py, move |cancel| -> Result<_, String> {
            let mut solver = Solver::new(bvp.as_ref(), options);
            let start = solver
                .solve(&params, &guess)
                .map_err(|e| format!("the solve at the start values failed: {e}"))?;
            let p0: Vec<f64> = fit.iter().map(|&j| params[j]).collect();
            let map = fit
                .iter()
                .enumerate()
                .fold(ParamMap::new(params), |m, (i, &j)| m.link(j, i));
            let misfit = Misfit {
                component,
                data: data_y,
                sigma,
            };
            let run = BvpRun::new(solver, start, data_x, misfit, map).map_err(|e| e.to_string())?;
            let mut problem = BvpResiduals::new(fit.len())
                .with_run(run)
                .map_err(|e| e.to_string())?;
            let mut opts = FitOptions::with_bounds(lower, upper);
            opts.xtol = xtol;
            opts.ftol = ftol;
            opts.max_iterations = max_iterations;
            opts.cancel = Some(cancel);
            let result = least_squares::fit(&mut problem, &p0, &opts).map_err(|e| e.to_string())?;
            let sol = problem.runs()[0].accepted().clone();
            Ok((result, sol))
        });
        let (result, sol) =
            out?.map_err(|m| diffbvp_error(py, "EvaluationError", format!("fit_bvp: {m}")))?;
        let success = matches!(
            result.termination,
            Termination::Gradient
                | Termination::Step
                | Termination::CostChange
                | Termination::RelativeOffset
                | Termination::NoiseFloor
        );
        Ok((
            result.p.clone(),
            result.cost,
            result.residuals.clone(),
            result.dense_jacobian(),
            result.termination.to_string(),
            success,
            result.iterations,
            result.accepted_steps,
            BvpSolution {
                bvp: self.bvp.clone(),
                builder: self.builder.clone(),
                sol: Arc::new(sol),
            },
        ))
    }
}

impl ExprProblem {
    /// The guess of `x`, `y` (`n × m`, checked) and the unknowns (checked), node-major.
    fn guess(
        &self,
        x: Vec<f64>,
        y: &PyReadonlyArray2<'_, f64>,
        unknowns: Vec<f64>,
    ) -> PyResult<Guess> {
        let (n, m) = shape(y, self.bvp.dim(), x.len(), "y")?;
        check_p(&unknowns, self.bvp.num_unknowns())?;
        let ya = y.as_array();
        let mut g = vec![0.0; n * m];
        for (j, row) in g.chunks_exact_mut(n).enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v = ya[[c, j]];
            }
        }
        Ok(Guess { x, y: g, unknowns })
    }
}

fn shape(
    y: &PyReadonlyArray2<'_, f64>,
    n: usize,
    m: usize,
    what: &str,
) -> PyResult<(usize, usize)> {
    let s = y.shape();
    if s[0] != n || s[1] != m {
        return Err(input_error(format!(
            "{what}: expected shape ({n}, {m}) (states × nodes), got ({}, {})",
            s[0], s[1]
        )));
    }
    Ok((n, m))
}

fn check_p(p: &[f64], k: usize) -> PyResult<()> {
    if p.len() != k {
        return Err(input_error(format!(
            "p: the problem has {k} parameters here, got {} values",
            p.len()
        )));
    }
    Ok(())
}

/// A converged solution of an [`ExprProblem`], with its derivatives.
#[pyclass(module = "diffbvp._native", frozen)]
pub struct BvpSolution {
    bvp: Arc<ExprBvp>,
    builder: ExprBuilder,
    sol: Arc<Solution>,
}

fn to_py_bvp_error(e: BvpError) -> PyErr {
    Python::attach(|py| match e {
        BvpError::InvalidInput(_) => input_error(e.to_string()),
        _ => diffbvp_error(py, "EvaluationError", e.to_string()),
    })
}

#[pymethods]
impl BvpSolution {
    /// Mesh nodes (m).
    #[getter]
    fn x<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        PyArray1::from_slice(py, &self.sol.x).into_any()
    }

    /// States at the nodes, `n × m`.
    #[getter]
    fn y<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        transposed(py, &self.sol.y, self.sol.nodes(), self.sol.n)
    }

    /// Slopes `f(x_i, y_i, p)` at the nodes, `n × m`.
    #[getter]
    fn yp<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        transposed(py, &self.sol.yp, self.sol.nodes(), self.sol.n)
    }

    /// The unknown parameters found.
    #[getter]
    fn unknowns<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        PyArray1::from_slice(py, &self.sol.unknowns).into_any()
    }

    /// Scaled RMS collocation residual per interval (m − 1).
    #[getter]
    fn rms_residuals<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        PyArray1::from_slice(py, &self.sol.rms_residuals).into_any()
    }

    /// Solve statistics: `(newton_iterations, mesh_refinements, mesh_coarsenings,
    /// max_residual, max_bc_residual)`.
    #[getter]
    fn stats(&self) -> (usize, usize, usize, f64, f64) {
        let s = &self.sol.stats;
        (
            s.newton_iterations,
            s.mesh_refinements,
            s.mesh_coarsenings,
            s.max_residual,
            s.max_bc_residual,
        )
    }

    /// The interpolant (nu = 0) or its derivative (nu = 1) at `xs`, `n × len(xs)`.
    fn eval<'py>(&self, py: Python<'py>, xs: Vec<f64>, nu: u8) -> PyResult<Bound<'py, PyAny>> {
        let n = self.sol.n;
        let mut out = vec![0.0; n * xs.len()];
        let (mut y, mut yp) = (vec![0.0; n], vec![0.0; n]);
        for (j, &x) in xs.iter().enumerate() {
            self.sol
                .try_eval_into(x, &mut y, &mut yp)
                .map_err(|e| input_error(e.to_string()))?;
            let v = if nu == 0 { &y } else { &yp };
            for (c, vc) in v.iter().enumerate() {
                out[c * xs.len() + j] = *vc;
            }
        }
        crate::convert::array2(py, &out, n, xs.len())
    }

    /// Forward sensitivities with respect to the model parameters: `(dy, d_unknowns)` with
    /// `dy[c, j, l] = ∂y_c(xs_j)/∂q_l` (`n × len × q`; at the nodes when `xs` is None) and
    /// `d_unknowns[i, l]` (`k × q`).
    #[pyo3(signature = (xs=None))]
    fn sensitivities<'py>(
        &self,
        py: Python<'py>,
        xs: Option<Vec<f64>>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let (bvp, sol) = (self.bvp.clone(), self.sol.clone());
        let sens = py
            .detach(move || Sensitivities::compute(bvp.as_ref(), &sol))
            .map_err(to_py_bvp_error)?;
        let (n, q, k) = (self.sol.n, self.bvp.num_params(), self.bvp.num_unknowns());
        let pts = xs.unwrap_or_else(|| self.sol.x.clone());
        if let Some(j) = pts.iter().position(|x| !x.is_finite()) {
            return Err(input_error(format!("xs[{j}] is not finite ({})", pts[j])));
        }
        let len = pts.len();
        let mut out = vec![0.0; n * len * q];
        let (mut dy, mut dyp) = (vec![0.0; n * q], vec![0.0; n * q]);
        for (j, &x) in pts.iter().enumerate() {
            sens.at_into(x, &mut dy, &mut dyp);
            for (idx, d) in dy.iter().enumerate() {
                let (c, l) = (idx / q, idx % q);
                out[(c * len + j) * q + l] = *d;
            }
        }
        let a = PyArray1::from_slice(py, &out)
            .reshape([n, len, q])?
            .into_any();
        let b = PyArray1::from_slice(py, &sens.d_unknowns)
            .reshape([k, q])?
            .into_any();
        Ok((a, b))
    }

    /// Value and gradient (model parameters) of `G = Σ_j w_j g(xs_j, y(xs_j), p)`, `g` an
    /// expression in `x`, `y[i]` and the parameters, by the adjoint method.
    fn adjoint_gradient<'py>(
        &self,
        py: Python<'py>,
        functional: String,
        xs: Vec<f64>,
        weights: Vec<f64>,
    ) -> PyResult<(f64, Bound<'py, PyAny>)> {
        let g = self
            .builder
            .function(self.sol.n, &functional)
            .map_err(expr_error)?;
        let (bvp, sol) = (self.bvp.clone(), self.sol.clone());
        let (v, grad) = py
            .detach(move || adjoint_gradient(bvp.as_ref(), &sol, &xs, &weights, &g))
            .map_err(to_py_bvp_error)?;
        Ok((v, PyArray1::from_slice(py, &grad).into_any()))
    }

    /// Value and gradient (model parameters) of the integral functional
    /// `G = ∫ g(x, y, p) dx + φ(ya, yb, p)` by the adjoint method: `integrand` in `x`, `y[i]`
    /// and the parameters, `endpoint` (optional) in `ya[i]`, `yb[i]` and the parameters.
    #[pyo3(signature = (integrand, endpoint=None))]
    fn integral<'py>(
        &self,
        py: Python<'py>,
        integrand: String,
        endpoint: Option<String>,
    ) -> PyResult<(f64, Bound<'py, PyAny>)> {
        let g = self
            .builder
            .integral(self.sol.n, &integrand, endpoint.as_deref())
            .map_err(expr_error)?;
        let (bvp, sol) = (self.bvp.clone(), self.sol.clone());
        let (v, grad) = py
            .detach(move || integral_adjoint(bvp.as_ref(), &sol, &g))
            .map_err(to_py_bvp_error)?;
        Ok((v, PyArray1::from_slice(py, &grad).into_any()))
    }
}

/// What [`ExprProblem::fit`] returns to Python.
type FitOutput = (
    Vec<f64>,
    f64,
    Vec<f64>,
    Vec<f64>,
    String,
    bool,
    usize,
    usize,
    BvpSolution,
);

/// The weighted misfit `(y_c(x_j) − d_j) / σ_j` of one state component at the observations.
struct Misfit {
    component: usize,
    data: Vec<f64>,
    sigma: Vec<f64>,
}

impl PointFunction for Misfit {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, j: usize, _x: f64, y: &[D], _p: &[D]) -> D {
        (y[self.component] - self.data[j]) / self.sigma[j]
    }
}

/// `n × m` from `m × n` row-major.
fn transposed<'py>(py: Python<'py>, v: &[f64], m: usize, n: usize) -> PyResult<Bound<'py, PyAny>> {
    let mut out = vec![0.0; v.len()];
    for (i, row) in v.chunks_exact(n).enumerate() {
        for (c, val) in row.iter().enumerate() {
            out[c * m + i] = *val;
        }
    }
    crate::convert::array2(py, &out, n, m)
}
