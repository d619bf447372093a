//! Boundary value problems written as text: an expression language whose trees the solver
//! evaluates generically over dual numbers (feature `expr`).
//!
//! A problem read from a file, typed at a prompt or lowered from SymPy by the Python package
//! needs no compiled code: [`ExprBvp`] parses one expression per right-hand-side component and
//! per boundary condition and implements [`Bvp`], so every Jacobian — in the states, the unknown
//! parameters and the model parameters — is exact, from the same dual numbers as a hand-written
//! problem's.
//!
//! ## The language
//!
//! * numbers (`2`, `0.5`, `1e-3`), `+ - * /`, powers `a**b` or `a^b` (right-associative; `-a**2`
//!   is `-(a**2)`; an integer exponent uses `powi`, a constant one `powf`);
//! * in a right-hand side: `x` and the states `y[0]`, …, `y[n-1]`; in a boundary condition: the
//!   states at the ends `ya[i]` and `yb[i]`;
//! * the parameters `p[0]`, … — the unknown parameters first (solved for, as scipy's `p`), then
//!   the fixed model parameters — or their names;
//! * named constants (values fixed at parsing) and `pi`;
//! * `exp`, `log` (= `ln`), `sqrt`, `sin`, `cos`, `tan`, `sinh`, `cosh`, `tanh`, `asin`, `acos`,
//!   `atan`, `asinh`, `acosh`, `atanh`, `abs`, `atan2(a, b)`, `min(a, b)`, `max(a, b)`,
//!   `pow(a, b)`;
//! * comparisons `<`, `<=`, `>`, `>=` (1 or 0) and `where(condition, a, b)`: `a` where the
//!   condition is nonzero, else `b`, each branch with its own exact derivative (piecewise
//!   smooth, as SymPy's `Piecewise`).
//!
//! A parse error ([`ExprError`]) names the expression (`fun[1]`, `bc[0]`), the position and the
//! offending symbol, and lists the symbols known there. A division by zero or a logarithm of a
//! negative number during a solve gives a non-finite value, which the solver reports as
//! [`BvpError::NonFinite`](crate::BvpError::NonFinite) with the component and the position.
//!
//! ```
//! use diffbvp::expr::ExprBvp;
//! use diffbvp::mesh::linspace;
//! use diffbvp::{solve, Guess, SolveOptions};
//!
//! // Bratu's problem y'' + k e^y = 0, y(0) = y(1) = 0, with k a model parameter
//! let bratu = ExprBvp::builder()
//!     .params(&["k"])
//!     .build(&["y[1]", "-k*exp(y[0])"], &["ya[0]", "yb[0]"])?;
//! let guess = Guess::constant(linspace(0.0, 1.0, 5), &[0.0, 0.0]);
//! let s = solve(&bratu, &[1.0], &guess, &SolveOptions::with_tol(1e-6))?;
//! assert!((s.eval(0.5)[0] - 0.1405392144).abs() < 1e-6);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod parse;
mod tree;

use crate::problem::Bvp;
use crate::sensitivity::{IntegralFunction, PointFunction};
use num_dual::DualNum;
use parse::{Parser, Place, Symbols};
use std::fmt;
use tree::{Node, Vars};

/// An expression that did not parse, or a problem whose expressions do not fit together.
#[derive(Debug, Clone, PartialEq)]
pub struct ExprError {
    /// Which expression: `fun[1]`, `bc[0]`, `functional`, `integrand`, `endpoint`, or
    /// `problem` for a whole-problem
    /// mismatch (counts, names).
    pub what: String,
    /// The expression's text (empty for a whole-problem mismatch).
    pub expression: String,
    /// Byte offset of the error in `expression`.
    pub position: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for ExprError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.expression.is_empty() {
            return write!(f, "{}: {}", self.what, self.message);
        }
        // the column in characters, for the caret under the expression
        let col = self.expression[..self.position.min(self.expression.len())]
            .chars()
            .count();
        write!(
            f,
            "{} = \"{}\": {} (at position {})\n    {}\n    {}^",
            self.what,
            self.expression,
            self.message,
            col,
            self.expression,
            " ".repeat(col)
        )
    }
}

impl std::error::Error for ExprError {}

fn problem_error(message: String) -> ExprError {
    ExprError {
        what: "problem".into(),
        expression: String::new(),
        position: 0,
        message,
    }
}

/// One parsed expression.
#[derive(Debug, Clone, PartialEq)]
struct Expr {
    node: Node,
}

/// Names and values an [`ExprBvp`] or an [`ExprFunction`] is parsed against
/// ([`ExprBvp::builder`]).
#[derive(Debug, Clone, Default)]
pub struct ExprBuilder {
    unknowns: Vec<String>,
    params: Vec<String>,
    constants: Vec<(String, f64)>,
    singular: Option<Vec<f64>>,
}

const RESERVED: &[&str] = &[
    "x", "y", "ya", "yb", "p", "pi", "exp", "log", "ln", "sqrt", "sin", "cos", "tan", "sinh",
    "cosh", "tanh", "asin", "acos", "atan", "asinh", "acosh", "atanh", "abs", "atan2", "min",
    "max", "pow", "where",
];

impl ExprBuilder {
    /// Names of the unknown parameters (`p[0..k]`), solved for with the states; their count is
    /// the number `k` of unknowns. An empty name leaves that entry reachable as `p[i]` only.
    pub fn unknowns(mut self, names: &[&str]) -> Self {
        self.unknowns = names.iter().map(|s| s.to_string()).collect();
        self
    }

    /// Names of the fixed model parameters (`p[k..k+q]`), whose values the caller of the solver
    /// supplies; their count is `q`. An empty name leaves the entry reachable as `p[i]` only.
    pub fn params(mut self, names: &[&str]) -> Self {
        self.params = names.iter().map(|s| s.to_string()).collect();
        self
    }

    /// A named constant, replaced by its value at parsing.
    pub fn constant(mut self, name: &str, value: f64) -> Self {
        self.constants.push((name.to_string(), value));
        self
    }

    /// A constant singular term `S` (`n × n`, row-major): the problem becomes
    /// `y' = S y / x + f(x, y, p)` on an interval starting at `0` ([`Bvp::singular_term`]).
    pub fn singular_term(mut self, s: Vec<f64>) -> Self {
        self.singular = Some(s);
        self
    }

    fn names(&self) -> Vec<String> {
        self.unknowns.iter().chain(&self.params).cloned().collect()
    }

    fn check_names(&self) -> Result<(), ExprError> {
        let mut seen: Vec<&str> = Vec::new();
        let all = self
            .unknowns
            .iter()
            .chain(&self.params)
            .chain(self.constants.iter().map(|(n, _)| n));
        for name in all {
            if name.is_empty() {
                continue;
            }
            let ok = name
                .bytes()
                .next()
                .is_some_and(|c| c.is_ascii_alphabetic() || c == b'_')
                && name.bytes().all(|c| c.is_ascii_alphanumeric() || c == b'_');
            if !ok {
                return Err(problem_error(format!(
                    "the name '{name}' is not an identifier (letters, digits and '_', not \
                     starting with a digit)"
                )));
            }
            if RESERVED.contains(&name.as_str()) {
                return Err(problem_error(format!(
                    "the name '{name}' is reserved by the expression language; choose another"
                )));
            }
            if seen.contains(&name.as_str()) {
                return Err(problem_error(format!(
                    "the name '{name}' is given twice (unknowns, parameters and constants \
                     share one namespace)"
                )));
            }
            seen.push(name);
        }
        for (name, v) in &self.constants {
            if !v.is_finite() {
                return Err(problem_error(format!(
                    "the constant '{name}' is not finite ({v})"
                )));
            }
        }
        Ok(())
    }

    fn parse_all(
        &self,
        exprs: &[&str],
        label: &str,
        place: Place,
        n: usize,
    ) -> Result<Vec<Expr>, ExprError> {
        let names = self.names();
        let sym = Symbols {
            n,
            params: &names,
            np: names.len(),
            constants: &self.constants,
        };
        exprs
            .iter()
            .enumerate()
            .map(|(i, src)| {
                let what = format!("{label}[{i}]");
                Parser::new(src, &what, place, &sym)
                    .parse()
                    .map(|node| Expr { node })
            })
            .collect()
    }

    /// Parses the problem: `rhs` gives `n` right-hand-side components (in `x`, `y[i]` and the
    /// parameters), `bc` the `n + k` boundary residuals (in `ya[i]`, `yb[i]` and the
    /// parameters).
    pub fn build(self, rhs: &[&str], bc: &[&str]) -> Result<ExprBvp, ExprError> {
        self.check_names()?;
        let n = rhs.len();
        let k = self.unknowns.len();
        if n == 0 {
            return Err(problem_error(
                "no right-hand side: give one expression per state".into(),
            ));
        }
        if bc.len() != n + k {
            return Err(problem_error(format!(
                "{} boundary conditions for {n} states and {k} unknown parameters: n + k = {} \
                 are needed",
                bc.len(),
                n + k
            )));
        }
        if let Some(s) = &self.singular {
            if s.len() != n * n || s.iter().any(|v| !v.is_finite()) {
                return Err(problem_error(format!(
                    "the singular term S needs {} finite values ({n} × {n}, row-major), got {}",
                    n * n,
                    s.len()
                )));
            }
        }
        let rhs = self.parse_all(rhs, "fun", Place::Rhs, n)?;
        let bc = self.parse_all(bc, "bc", Place::Bc, n)?;
        let sparsity = rhs
            .iter()
            .map(|e| {
                let mut deps = Vec::new();
                e.node.inputs(n, &mut deps);
                deps.sort_unstable();
                deps.dedup();
                deps
            })
            .collect();
        Ok(ExprBvp {
            sparsity,
            n,
            k,
            q: self.params.len(),
            rhs,
            bc,
            names: self.names(),
            singular: self.singular,
        })
    }

    /// Parses a point function `g(x, y, p)` for `n` states (the right-hand side's symbols:
    /// `x`, `y[i]`, parameters): a functional for
    /// [`adjoint_gradient`](crate::sensitivity::adjoint_gradient) or a residual for a fit.
    pub fn function(&self, n: usize, expr: &str) -> Result<ExprFunction, ExprError> {
        self.check_names()?;
        let mut e = self.parse_all(&[expr], "functional", Place::Rhs, n)?;
        Ok(ExprFunction { expr: e.remove(0) })
    }
}

impl ExprBuilder {
    /// Parses an integral functional `G = ∫ g(x, y, p) dx + φ(ya, yb, p)` for `n` states:
    /// `integrand` in the right-hand side's symbols (`x`, `y[i]`, parameters), `endpoint`
    /// (optional) in the boundary conditions' (`ya[i]`, `yb[i]`, parameters); for
    /// [`integral_adjoint`](crate::sensitivity::integral_adjoint) and
    /// [`integral_value`](crate::sensitivity::integral_value).
    pub fn integral(
        &self,
        n: usize,
        integrand: &str,
        endpoint: Option<&str>,
    ) -> Result<ExprIntegral, ExprError> {
        self.check_names()?;
        let mut g = self.parse_all(&[integrand], "integrand", Place::Rhs, n)?;
        let endpoint = match endpoint {
            Some(src) => Some(self.parse_all(&[src], "endpoint", Place::Bc, n)?.remove(0)),
            None => None,
        };
        Ok(ExprIntegral {
            integrand: g.remove(0),
            endpoint,
        })
    }
}

/// An integral functional given by expressions ([`ExprBuilder::integral`]).
#[derive(Debug, Clone)]
pub struct ExprIntegral {
    integrand: Expr,
    endpoint: Option<Expr>,
}

impl IntegralFunction for ExprIntegral {
    fn integrand<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, y: &[D], p: &[D]) -> D {
        let v = Vars {
            x,
            y,
            ya: &[],
            yb: &[],
            p,
        };
        self.integrand.node.eval(&v)
    }

    fn endpoint<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], p: &[D]) -> D {
        match &self.endpoint {
            Some(e) => {
                let v = Vars {
                    x: 0.0,
                    y: &[],
                    ya,
                    yb,
                    p,
                };
                e.node.eval(&v)
            }
            None => D::zero(),
        }
    }
}

/// A boundary value problem given by expressions ([module documentation](self)).
#[derive(Debug, Clone)]
pub struct ExprBvp {
    n: usize,
    k: usize,
    q: usize,
    rhs: Vec<Expr>,
    bc: Vec<Expr>,
    names: Vec<String>,
    singular: Option<Vec<f64>>,
    /// The inputs (`[y, p]`) each right-hand-side expression reads ([`Bvp::rhs_sparsity`]).
    sparsity: Vec<Vec<usize>>,
}

impl ExprBvp {
    /// A builder: declare unknowns, model parameters and constants, then
    /// [`build`](ExprBuilder::build).
    pub fn builder() -> ExprBuilder {
        ExprBuilder::default()
    }

    /// A problem without parameters or constants.
    pub fn new(rhs: &[&str], bc: &[&str]) -> Result<Self, ExprError> {
        Self::builder().build(rhs, bc)
    }

    /// The names of `p` (unknowns, then model parameters; empty where none was given).
    pub fn param_names(&self) -> &[String] {
        &self.names
    }

    /// Evaluates the right-hand side at `x`, `y`, `p` in `f64` (for checks and plots).
    pub fn eval_rhs(&self, x: f64, y: &[f64], p: &[f64], f: &mut [f64]) {
        self.rhs(x, y, p, f);
    }
}

impl Bvp for ExprBvp {
    fn dim(&self) -> usize {
        self.n
    }

    fn num_unknowns(&self) -> usize {
        self.k
    }

    fn num_params(&self) -> usize {
        self.q
    }

    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, y: &[D], p: &[D], f: &mut [D]) {
        let v = Vars {
            x,
            y,
            ya: &[],
            yb: &[],
            p,
        };
        for (fi, e) in f.iter_mut().zip(&self.rhs) {
            *fi = e.node.eval(&v);
        }
    }

    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], p: &[D], r: &mut [D]) {
        let v = Vars {
            x: 0.0,
            y: &[],
            ya,
            yb,
            p,
        };
        for (ri, e) in r.iter_mut().zip(&self.bc) {
            *ri = e.node.eval(&v);
        }
    }

    fn singular_term(&self) -> Option<Vec<f64>> {
        self.singular.clone()
    }

    fn rhs_sparsity(&self) -> Option<&[Vec<usize>]> {
        Some(&self.sparsity)
    }
}

/// A point function `g(x, y, p)` given by an expression ([`ExprBuilder::function`]); the same
/// expression at every point (the point's index is not read).
#[derive(Debug, Clone)]
pub struct ExprFunction {
    expr: Expr,
}

impl PointFunction for ExprFunction {
    fn eval<D: DualNum<Primitive = f64> + Copy>(
        &self,
        _index: usize,
        x: f64,
        y: &[D],
        p: &[D],
    ) -> D {
        let v = Vars {
            x,
            y,
            ya: &[],
            yb: &[],
            p,
        };
        self.expr.node.eval(&v)
    }
}
