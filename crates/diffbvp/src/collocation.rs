//! The discrete collocation system of the 3-stage Lobatto IIIa scheme (bvp4c / `solve_bvp`).
//!
//! On interval `i` with `h_i = x_{i+1} - x_i` the residual is
//!
//! ```text
//! r_i = y_{i+1} - y_i - h_i/6 (f_i + 4 f_{i+1/2} + f_{i+1}),
//! y_{i+1/2} = (y_i + y_{i+1})/2 - h_i/8 (f_{i+1} - f_i),   f_{i+1/2} = f(x_i + h_i/2, y_{i+1/2}, p).
//! ```
//!
//! The unknowns are `Y = (y_0, …, y_{m-1}, p_unknown)`; the equations are the `(m-1) n`
//! collocation residuals followed by the `n + k` boundary residuals. Jacobian blocks come from
//! exact dual-number Jacobians of `f` at the nodes and midpoints and of `g`, combined by the chain
//! rule (Ascher, Mattheij & Russell; Kierzenka & Shampine 2001).

use crate::dual_jacobian::{BcFn, Coloring, DualJacobian, InterfaceFn, RhsFn, Seeds};
use crate::error::BvpError;
use crate::problem::Bvp;
use crate::singular::Singular;

/// Values, residuals and Jacobians of the collocation system on one mesh.
pub(crate) struct Collocation {
    /// Number of states.
    pub n: usize,
    /// Number of unknown parameters.
    pub k: usize,
    /// Number of fixed model parameters.
    pub q: usize,
    /// Mesh.
    pub x: Vec<f64>,
    /// Interval lengths.
    pub h: Vec<f64>,
    /// `f` at the nodes, `m × n` row-major.
    pub f: Vec<f64>,
    /// Midpoint states, `(m-1) × n`.
    pub y_mid: Vec<f64>,
    /// `f` at the midpoints, `(m-1) × n`.
    pub f_mid: Vec<f64>,
    /// Residual vector: `(m-1) n` collocation residuals, then `n + k` boundary residuals.
    pub res: Vec<f64>,
    /// Width of the stored Jacobians' parameter part (`k` for Newton, `k + q` for sensitivities
    /// in all model parameters, `k + model_seeds.len()` in general).
    pub seeded_params: usize,
    /// The model parameters (indices into the `q` model parameters, increasing) whose columns
    /// follow the `k` unknowns' in the Jacobians' parameter part: column `k + s` is model
    /// parameter `model_seeds[s]` (empty for Newton, `0..q` for a full linearisation).
    pub model_seeds: Vec<usize>,
    /// Node Jacobians `∂f/∂(y, p_seeded)`, `m × n × (n + seeded)`.
    pub jn: Vec<f64>,
    /// Midpoint Jacobians, `(m-1) × n × (n + seeded)`.
    pub jm: Vec<f64>,
    /// Boundary Jacobian `∂g/∂(ya, yb, p_seeded)`, `(n+k) × (2n + seeded)`.
    pub jbc: Vec<f64>,
    /// Right-hand-side evaluations in `f64` (one per point).
    pub rhs_evals: usize,
    /// Right-hand-side evaluations with dual numbers (one per point and pass).
    pub jac_evals: usize,
    /// The problem's singular term ([`Bvp::singular_term`]), refreshed by every evaluation.
    pub singular: Option<Singular>,
    /// Region of every node of a multipoint mesh ([`Bvp::interfaces`]; all 0 otherwise): the
    /// number of zero-width intervals (interfaces) before it.
    pub region: Vec<usize>,
    /// Interface Jacobians `∂h_j/∂(left, right, p_seeded)`, `interfaces × n × wb` with the
    /// boundary Jacobian's row width `wb` (and its column layout).
    pub jif: Vec<f64>,
    input: Vec<f64>,
    fbuf: Vec<f64>,
    /// Input indices seeded at a node or midpoint (`[y, p]`) and at the boundary
    /// (`[ya, yb, p]`) for a linearisation in a subset of the model parameters.
    seed_list: Vec<usize>,
    bc_seed_list: Vec<usize>,
    engine: DualJacobian,
    /// The colouring of the node seeds by the problem's [`Bvp::rhs_sparsity`], when it saves
    /// dual passes in the current pass.
    coloring: Coloring,
}

impl Collocation {
    pub(crate) fn new(n: usize, k: usize, q: usize) -> Self {
        Collocation {
            n,
            k,
            q,
            x: Vec::new(),
            h: Vec::new(),
            f: Vec::new(),
            y_mid: Vec::new(),
            f_mid: Vec::new(),
            res: Vec::new(),
            seeded_params: 0,
            model_seeds: Vec::new(),
            jn: Vec::new(),
            jm: Vec::new(),
            jbc: Vec::new(),
            rhs_evals: 0,
            jac_evals: 0,
            singular: None,
            region: Vec::new(),
            jif: Vec::new(),
            input: Vec::new(),
            fbuf: Vec::new(),
            seed_list: Vec::new(),
            bc_seed_list: Vec::new(),
            engine: DualJacobian::default(),
            coloring: Coloring::default(),
        }
    }

    /// Reads the problem's singular term ([`Bvp::singular_term`]) and checks it and the mesh's
    /// start `a = 0`; `D` and `B` are recomputed only when `S` changed.
    pub(crate) fn refresh_singular<P: Bvp>(&mut self, problem: &P) -> Result<(), BvpError> {
        match problem.singular_term() {
            None => self.singular = None,
            Some(s) => {
                let a = self.x.first().copied().unwrap_or(0.0);
                match &self.singular {
                    Some(cached) if cached.is_of(&s) => Singular::check_start(a)?,
                    _ => self.singular = Some(Singular::new(s, self.n, a)?),
                }
            }
        }
        Ok(())
    }

    /// Colours the node seeds by the problem's [`Bvp::rhs_sparsity`] (checked); whether the
    /// node and midpoint Jacobians of this pass are compressed (not with a singular term, nor
    /// when every seeded column needs a colour of its own).
    fn refresh_coloring<P: Bvp>(
        &mut self,
        problem: &P,
        seeds: Seeds<'_>,
    ) -> Result<bool, BvpError> {
        let Some(pattern) = problem.rhs_sparsity() else {
            return Ok(false);
        };
        let inputs = self.n + self.k + self.q;
        if pattern.len() != self.n {
            return Err(BvpError::InvalidInput(format!(
                "rhs_sparsity lists {} components for {} states",
                pattern.len(),
                self.n
            )));
        }
        if let Some((i, &d)) = pattern
            .iter()
            .enumerate()
            .find_map(|(i, deps)| deps.iter().find(|&&d| d >= inputs).map(|d| (i, d)))
        {
            return Err(BvpError::InvalidInput(format!(
                "rhs_sparsity: component {i} lists input {d}, but [y, p] has {inputs} entries \
                 ({} states, {} unknowns, {} model parameters)",
                self.n, self.k, self.q
            )));
        }
        if self.singular.is_some() {
            return Ok(false);
        }
        Ok(self.coloring.build(pattern, seeds, inputs))
    }

    /// The region of every node from the zero-width intervals of the mesh (a multipoint mesh
    /// holds each interface twice).
    fn set_regions(&mut self) {
        self.region.clear();
        let mut r = 0;
        self.region.push(0);
        for &h in &self.h {
            if h == 0.0 {
                r += 1;
            }
            self.region.push(r);
        }
    }

    /// Whether interval `i` is an interface (zero width: its rows are the interface
    /// conditions, not collocation equations).
    #[inline]
    pub(crate) fn is_interface(&self, i: usize) -> bool {
        self.h[i] == 0.0
    }

    /// Number of mesh nodes.
    pub(crate) fn m(&self) -> usize {
        self.x.len()
    }

    /// Installs a new mesh and sizes the buffers (allocation happens here, once per mesh).
    pub(crate) fn set_mesh(&mut self, x: &[f64]) {
        let (n, m) = (self.n, x.len());
        self.x.clear();
        self.x.extend_from_slice(x);
        self.h.clear();
        self.h.extend(x.windows(2).map(|w| w[1] - w[0]));
        self.set_regions();
        self.f.resize(m * n, 0.0);
        self.y_mid.resize((m - 1) * n, 0.0);
        self.f_mid.resize((m - 1) * n, 0.0);
        self.res.resize((m - 1) * n + n + self.k, 0.0);
    }

    /// Sets the node slopes `f` and the midpoint states from node values `y` and their slopes
    /// `yp = f(x_i, y_i, p)` without evaluating `f` (the midpoint formula of
    /// [`residual`](Self::residual), bit for bit). Enough for [`jacobians`](Self::jacobians).
    pub(crate) fn set_midpoints_from_slopes(&mut self, y: &[f64], yp: &[f64]) {
        let (n, m) = (self.n, self.m());
        self.f.clear();
        self.f.extend_from_slice(&yp[..m * n]);
        self.midpoint_states(y);
    }

    /// The Hermite midpoint states `y_{i+1/2} = (y_i + y_{i+1})/2 − h_i (f_{i+1} − f_i)/8` from
    /// the node values `y` and the node slopes in `f`.
    fn midpoint_states(&mut self, y: &[f64]) {
        let (n, m) = (self.n, self.m());
        let len = (m - 1) * n;
        let ys = y[..len].chunks_exact(n).zip(y[n..len + n].chunks_exact(n));
        let fs = self.f[..len]
            .chunks_exact(n)
            .zip(self.f[n..len + n].chunks_exact(n));
        for (((ym, &h), (yi, yj)), (fi, fj)) in self.y_mid[..len]
            .chunks_exact_mut(n)
            .zip(&self.h)
            .zip(ys)
            .zip(fs)
        {
            for c in 0..n {
                ym[c] = 0.5 * (yi[c] + yj[c]) - 0.125 * h * (fj[c] - fi[c]);
            }
        }
    }

    /// A copy of the mesh and the Jacobians (`jn`, `jm`, `jbc`, as last evaluated), without the
    /// value buffers: what [`param_column`](Self::param_column) and the Newton-matrix assembly
    /// read.
    pub(crate) fn jacobian_copy(&self) -> Collocation {
        let mut c = Collocation::new(self.n, self.k, self.q);
        c.x.extend_from_slice(&self.x);
        c.h.extend_from_slice(&self.h);
        c.region.extend_from_slice(&self.region);
        c.jif.extend_from_slice(&self.jif);
        c.seeded_params = self.seeded_params;
        c.model_seeds.clone_from(&self.model_seeds);
        c.jn.extend_from_slice(&self.jn);
        c.jm.extend_from_slice(&self.jm);
        c.jbc.extend_from_slice(&self.jbc);
        c
    }

    /// Evaluates `f` at the nodes and midpoints and the full residual vector.
    pub(crate) fn residual<P: Bvp>(
        &mut self,
        problem: &P,
        y: &[f64],
        p: &[f64],
    ) -> Result<(), BvpError> {
        self.refresh_singular(problem)?;
        let (n, m) = (self.n, self.m());
        for i in 0..m {
            let (yi, fi) = (&y[i * n..(i + 1) * n], &mut self.f[i * n..(i + 1) * n]);
            problem.rhs_in_region(self.region[i], self.x[i], yi, p, fi);
            if let Some(s) = &self.singular {
                s.apply(self.x[i], yi, fi);
            }
        }
        self.rhs_evals += m;
        check_finite(&self.f, n, 1, |i| self.x[i], "right-hand side")?;
        self.midpoint_states(y);
        for i in 0..m - 1 {
            let xm = self.x[i] + 0.5 * self.h[i];
            let (ym, fm) = (
                &self.y_mid[i * n..(i + 1) * n],
                &mut self.f_mid[i * n..(i + 1) * n],
            );
            if self.h[i] == 0.0 {
                // an interface: no collocation equation, no midpoint
                fm.fill(0.0);
                continue;
            }
            problem.rhs_in_region(self.region[i], xm, ym, p, fm);
            if let Some(s) = &self.singular {
                s.apply(xm, ym, fm);
            }
        }
        self.rhs_evals += m - 1;
        check_finite(
            &self.f_mid,
            n,
            1,
            |i| self.x[i] + 0.5 * self.h[i],
            "right-hand side",
        )?;
        self.finish_residual(problem, y, p)
    }

    /// The residual vector from the node and midpoint values of `f` in place, and the boundary
    /// residuals.
    fn finish_residual<P: Bvp>(
        &mut self,
        problem: &P,
        y: &[f64],
        p: &[f64],
    ) -> Result<(), BvpError> {
        let (n, m) = (self.n, self.m());
        let len = (m - 1) * n;
        let ys = y[..len].chunks_exact(n).zip(y[n..len + n].chunks_exact(n));
        let fs = self.f[..len]
            .chunks_exact(n)
            .zip(self.f[n..len + n].chunks_exact(n));
        for ((((r, &h), fm), (yi, yj)), (fi, fj)) in self.res[..len]
            .chunks_exact_mut(n)
            .zip(&self.h)
            .zip(self.f_mid[..len].chunks_exact(n))
            .zip(ys)
            .zip(fs)
        {
            for c in 0..n {
                r[c] = yj[c] - yi[c] - h / 6.0 * (fi[c] + 4.0 * fm[c] + fj[c]);
            }
        }
        let off = len;
        let (res_col, res_bc) = self.res.split_at_mut(off);
        for i in 0..m - 1 {
            if self.h[i] == 0.0 {
                let r = &mut res_col[i * n..(i + 1) * n];
                let (left, right) = (&y[i * n..(i + 1) * n], &y[(i + 1) * n..(i + 2) * n]);
                problem.interface_conditions(self.region[i], left, right, p, r);
                if let Some(c) = r.iter().position(|v| !v.is_finite()) {
                    return Err(BvpError::NonFinite {
                        what: "interface condition",
                        component: c,
                        x: self.x[i],
                    });
                }
            }
        }
        problem.bc(&y[..n], &y[(m - 1) * n..], p, res_bc);
        for (c, v) in res_bc.iter().enumerate() {
            if !v.is_finite() {
                return Err(BvpError::NonFinite {
                    what: "boundary residual",
                    component: c,
                    x: self.x[0],
                });
            }
        }
        Ok(())
    }

    /// [`residual`](Self::residual) and [`jacobians`](Self::jacobians) at `y` in one pass over
    /// the nodes and midpoints: the values of `f` are the real parts of the dual-number
    /// evaluations (no separate `f64` evaluation). For an iterate whose Jacobian will be needed.
    pub(crate) fn residual_and_jacobians<P: Bvp>(
        &mut self,
        problem: &P,
        y: &[f64],
        p: &[f64],
        seeded: usize,
    ) -> Result<(), BvpError> {
        self.dual_pass(problem, y, p, seeded, None, true)?;
        self.finish_residual(problem, y, p)
    }

    /// Evaluates the node, midpoint and boundary Jacobians with respect to `y` and the first
    /// `seeded` parameters. Requires a preceding [`residual`](Self::residual) at the same `y`
    /// (the midpoint states are reused).
    pub(crate) fn jacobians<P: Bvp>(
        &mut self,
        problem: &P,
        y: &[f64],
        p: &[f64],
        seeded: usize,
    ) -> Result<(), BvpError> {
        self.dual_pass(problem, y, p, seeded, None, false)
    }

    /// [`jacobians`](Self::jacobians) with respect to `y`, the `k` unknowns and the model
    /// parameters `model` only (indices into the `q` model parameters, strictly increasing):
    /// the other model parameters are constants of the dual pass, which then needs
    /// `ceil((n + k + model.len()) / 8)` evaluations per point instead of
    /// `ceil((n + k + q) / 8)`. Column `k + s` of the parameter part is `model[s]`.
    pub(crate) fn jacobians_in<P: Bvp>(
        &mut self,
        problem: &P,
        y: &[f64],
        p: &[f64],
        model: &[usize],
    ) -> Result<(), BvpError> {
        debug_assert!(model.windows(2).all(|w| w[0] < w[1]));
        debug_assert!(model.last().is_none_or(|&j| j < self.q));
        if model.len() == self.q {
            // all of them: the plain prefix seeding
            return self.dual_pass(problem, y, p, self.k + self.q, None, false);
        }
        self.dual_pass(problem, y, p, self.k + model.len(), Some(model), false)
    }

    /// The dual-number pass of [`jacobians`](Self::jacobians) (with `model`, of
    /// [`jacobians_in`](Self::jacobians_in)); with `values`, the real parts also set the node
    /// slopes `f`, the midpoint states and `f_mid` (checked finite, as
    /// [`residual`](Self::residual) checks them).
    fn dual_pass<P: Bvp>(
        &mut self,
        problem: &P,
        y: &[f64],
        p: &[f64],
        seeded: usize,
        model: Option<&[usize]>,
        values: bool,
    ) -> Result<(), BvpError> {
        let Some(list) = model else {
            let n = self.n;
            self.seeded_params = seeded;
            self.model_seeds.clear();
            self.model_seeds.extend(0..seeded.saturating_sub(self.k));
            let seeds = (Seeds::First(n + seeded), Seeds::First(2 * n + seeded));
            return self.dual_pass_seeded(problem, y, p, seeds, values);
        };
        self.set_seed_lists(list, true);
        self.dual_pass_listed(problem, y, p, values)
    }

    /// Sets the seeds of a pass in the model parameters `model`: `model_seeds`, and the input
    /// indices at the nodes and midpoints (`[y, p]`) and at the boundary (`[ya, yb, p]`), with
    /// the states and the `k` unknowns in front if `states`.
    fn set_seed_lists(&mut self, model: &[usize], states: bool) {
        let (n, k) = (self.n, self.k);
        self.seeded_params = if states { k + model.len() } else { model.len() };
        self.model_seeds.clear();
        self.model_seeds.extend_from_slice(model);
        self.seed_list.clear();
        self.bc_seed_list.clear();
        if states {
            self.seed_list.extend(0..n + k);
            self.bc_seed_list.extend(0..2 * n + k);
        }
        self.seed_list.extend(model.iter().map(|j| n + k + j));
        self.bc_seed_list
            .extend(model.iter().map(|j| 2 * n + k + j));
    }

    /// [`dual_pass_seeded`](Self::dual_pass_seeded) with the seeds of
    /// [`set_seed_lists`](Self::set_seed_lists).
    fn dual_pass_listed<P: Bvp>(
        &mut self,
        problem: &P,
        y: &[f64],
        p: &[f64],
        values: bool,
    ) -> Result<(), BvpError> {
        let nodes = std::mem::take(&mut self.seed_list);
        let bc = std::mem::take(&mut self.bc_seed_list);
        let seeds = (Seeds::These(&nodes), Seeds::These(&bc));
        let result = self.dual_pass_seeded(problem, y, p, seeds, values);
        self.seed_list = nodes;
        self.bc_seed_list = bc;
        result
    }

    /// The derivatives of `f` (at the nodes and midpoints) and of `g` with respect to the model
    /// parameters `model` only, nothing in the states: `jn`, `jm` are `… × n × s` and `jbc` is
    /// `(n + k) × s` for `s = model.len()`, column `j` model parameter `model[j]`. A
    /// linearisation seeded in other parameters combines them with its own state Jacobians
    /// ([`param_column_with`](Self::param_column_with)); nothing else may read this
    /// collocation's Jacobians. Requires the midpoint states of `y` (as
    /// [`jacobians`](Self::jacobians)).
    pub(crate) fn param_jacobians_only<P: Bvp>(
        &mut self,
        problem: &P,
        y: &[f64],
        p: &[f64],
        model: &[usize],
    ) -> Result<(), BvpError> {
        self.set_seed_lists(model, false);
        self.dual_pass_listed(problem, y, p, false)
    }

    /// [`dual_pass`](Self::dual_pass) with the seeds of the nodes and midpoints and of the
    /// boundary conditions.
    fn dual_pass_seeded<P: Bvp>(
        &mut self,
        problem: &P,
        y: &[f64],
        p: &[f64],
        (node_seeds, bc_seeds): (Seeds<'_>, Seeds<'_>),
        values: bool,
    ) -> Result<(), BvpError> {
        self.refresh_singular(problem)?;
        let colored = self.refresh_coloring(problem, node_seeds)?;
        let (n, m) = (self.n, self.m());
        // the widths of the node and the boundary Jacobians' rows: `n + seeded` and
        // `2 n + seeded` but for `param_jacobians_only`
        let w = node_seeds.len();
        let wb = bc_seeds.len();
        self.jn.resize(m * n * w, 0.0);
        self.jm.resize((m - 1) * n * w, 0.0);
        let nb = n + self.k;
        self.jbc.resize(nb * wb, 0.0);
        let mut fbuf = std::mem::take(&mut self.fbuf);
        fbuf.resize(n.max(nb), 0.0);
        self.node_jacobians(problem, y, p, node_seeds, colored, values, &mut fbuf);
        if values {
            if let Err(e) = check_finite(&self.f, n, 1, |i| self.x[i], "right-hand side") {
                self.fbuf = fbuf;
                return Err(e);
            }
            self.midpoint_states(y);
        }
        self.midpoint_jacobians(problem, p, node_seeds, colored, values, &mut fbuf);
        let passes = if colored {
            self.coloring.passes()
        } else {
            w.div_ceil(8).max(1)
        };
        self.jac_evals += (2 * m - 1) * passes;
        if values {
            if let Err(e) = check_finite(
                &self.f_mid,
                n,
                1,
                |i| self.x[i] + 0.5 * self.h[i],
                "right-hand side",
            ) {
                self.fbuf = fbuf;
                return Err(e);
            }
        }
        check_finite(&self.jn, n * w, w, |i| self.x[i], "Jacobian")?;
        check_finite(
            &self.jm,
            n * w,
            w,
            |i| self.x[i] + 0.5 * self.h[i],
            "Jacobian",
        )?;
        let boundary = self.boundary_jacobians(problem, y, p, bc_seeds, &mut fbuf);
        self.fbuf = fbuf;
        boundary
    }

    /// The right-hand side's values (into `f` if `values`, else scratch `fbuf`) and Jacobians
    /// (`jn`) at the nodes.
    #[allow(clippy::too_many_arguments)]
    fn node_jacobians<P: Bvp>(
        &mut self,
        problem: &P,
        y: &[f64],
        p: &[f64],
        node_seeds: Seeds<'_>,
        colored: bool,
        values: bool,
        fbuf: &mut [f64],
    ) {
        for i in 0..self.m() {
            let at = Point::Node(i);
            self.point_jacobian(problem, at, y, p, node_seeds, colored, values, fbuf);
        }
    }

    /// The right-hand side's values (into `f_mid` if `values`) and Jacobians (`jm`) at the
    /// midpoints (zero rows at an interface, whose rows come from `jif`).
    fn midpoint_jacobians<P: Bvp>(
        &mut self,
        problem: &P,
        p: &[f64],
        node_seeds: Seeds<'_>,
        colored: bool,
        values: bool,
        fbuf: &mut [f64],
    ) {
        let (n, w) = (self.n, node_seeds.len());
        for i in 0..self.m() - 1 {
            if self.h[i] == 0.0 {
                // an interface: its rows come from `jif`
                self.jm[i * n * w..(i + 1) * n * w].fill(0.0);
                if values {
                    self.f_mid[i * n..(i + 1) * n].fill(0.0);
                }
                continue;
            }
            let at = Point::Midpoint(i);
            self.point_jacobian(problem, at, &[], p, node_seeds, colored, values, fbuf);
        }
    }

    /// The right-hand side's value and Jacobian at one point: node `i` (state from `y`, into
    /// `f` and `jn`) or the midpoint of interval `i` (state from `y_mid`, into `f_mid` and
    /// `jm`); the value into scratch `fbuf` unless `values`.
    #[allow(clippy::too_many_arguments)]
    fn point_jacobian<P: Bvp>(
        &mut self,
        problem: &P,
        at: Point,
        y: &[f64],
        p: &[f64],
        seeds: Seeds<'_>,
        colored: bool,
        values: bool,
        fbuf: &mut [f64],
    ) {
        let (n, w) = (self.n, seeds.len());
        let (i, x, state, f, jac) = match at {
            Point::Node(i) => (
                i,
                self.x[i],
                &y[i * n..(i + 1) * n],
                &mut self.f,
                &mut self.jn,
            ),
            Point::Midpoint(i) => (
                i,
                self.x[i] + 0.5 * self.h[i],
                &self.y_mid[i * n..(i + 1) * n],
                &mut self.f_mid,
                &mut self.jm,
            ),
        };
        self.input.clear();
        self.input.extend_from_slice(state);
        self.input.extend_from_slice(p);
        let rf = RhsFn {
            problem,
            x,
            n,
            singular: self.singular.as_ref(),
            region: self.region[i],
        };
        let out = if values {
            &mut f[i * n..(i + 1) * n]
        } else {
            &mut fbuf[..n]
        };
        let jac = &mut jac[i * n * w..(i + 1) * n * w];
        let coloring = colored.then_some(&self.coloring);
        rhs_jacobian(
            &mut self.engine,
            coloring,
            &rf,
            &self.input,
            seeds,
            out,
            jac,
        );
    }

    /// The boundary conditions' Jacobian (`jbc`) and the interface conditions' (`jif`), seeded
    /// with `bc_seeds`; `fbuf` (at least `n + k` long) takes their values.
    fn boundary_jacobians<P: Bvp>(
        &mut self,
        problem: &P,
        y: &[f64],
        p: &[f64],
        bc_seeds: Seeds<'_>,
        fbuf: &mut [f64],
    ) -> Result<(), BvpError> {
        let (n, m) = (self.n, self.m());
        let nb = n + self.k;
        self.input.clear();
        self.input.extend_from_slice(&y[..n]);
        self.input.extend_from_slice(&y[(m - 1) * n..]);
        self.input.extend_from_slice(p);
        let bf = BcFn { problem, n };
        self.engine
            .jacobian_in(&bf, &self.input, bc_seeds, &mut fbuf[..nb], &mut self.jbc);
        self.interface_jacobians(problem, y, p, bc_seeds, fbuf)?;
        let wb = bc_seeds.len();
        match self.jbc.iter().position(|v| !v.is_finite()) {
            Some(c) => Err(BvpError::NonFinite {
                what: "boundary-condition Jacobian",
                component: c / wb.max(1),
                x: self.x[0],
            }),
            None => Ok(()),
        }
    }

    /// The interface conditions' Jacobians, seeded as the boundary conditions (`[left, right,
    /// p]`), into `jif`; `fbuf` (at least `n` long) takes their values.
    fn interface_jacobians<P: Bvp>(
        &mut self,
        problem: &P,
        y: &[f64],
        p: &[f64],
        bc_seeds: Seeds<'_>,
        fbuf: &mut [f64],
    ) -> Result<(), BvpError> {
        let (n, m) = (self.n, self.m());
        let wb = bc_seeds.len();
        let interfaces = self.region.last().copied().unwrap_or(0);
        self.jif.resize(interfaces * n * wb, 0.0);
        for i in 0..m - 1 {
            if self.h[i] != 0.0 {
                continue;
            }
            let j = self.region[i];
            self.input.clear();
            self.input.extend_from_slice(&y[i * n..(i + 2) * n]);
            self.input.extend_from_slice(p);
            let hf = InterfaceFn {
                problem,
                index: j,
                n,
            };
            self.engine.jacobian_in(
                &hf,
                &self.input,
                bc_seeds,
                &mut fbuf[..n],
                &mut self.jif[j * n * wb..(j + 1) * n * wb],
            );
        }
        match self.jif.iter().position(|v| !v.is_finite()) {
            Some(c) => Err(BvpError::NonFinite {
                what: "interface-condition Jacobian",
                component: (c / wb.max(1)) % n,
                x: self.x[0],
            }),
            None => Ok(()),
        }
    }

    /// The `n × n` blocks `A_i = ∂r_i/∂y_i` and `B_i = ∂r_i/∂y_{i+1}` side by side: row `r`
    /// of `[A_i B_i]` is written to `out[r ld..r ld + 2n]` (`ld >= 2n`).
    pub(crate) fn interval_rows(&self, i: usize, out: &mut [f64], ld: usize) {
        if self.h[i] == 0.0 {
            // an interface: `[∂h_j/∂left ∂h_j/∂right]`
            let n = self.n;
            let wb = 2 * n + self.seeded_params;
            let j = self.region[i];
            for r in 0..n {
                let row = &self.jif[(j * n + r) * wb..(j * n + r) * wb + 2 * n];
                out[r * ld..r * ld + 2 * n].copy_from_slice(row);
            }
            return;
        }
        // small systems with the sizes known at compile time (the same operations in the same
        // order: bit-identical to the general loop)
        match self.n {
            1 => self.interval_rows_fixed::<1>(i, out, ld),
            2 => self.interval_rows_fixed::<2>(i, out, ld),
            3 => self.interval_rows_fixed::<3>(i, out, ld),
            4 => self.interval_rows_fixed::<4>(i, out, ld),
            5 => self.interval_rows_fixed::<5>(i, out, ld),
            6 => self.interval_rows_fixed::<6>(i, out, ld),
            _ => self.interval_rows_general(i, out, ld),
        }
    }

    /// [`interval_rows`](Self::interval_rows) for `n = N`.
    fn interval_rows_fixed<const N: usize>(&self, i: usize, out: &mut [f64], ld: usize) {
        let w = N + self.seeded_params;
        let h = self.h[i];
        let block = |j: &[f64]| -> [[f64; N]; N] {
            std::array::from_fn(|r| std::array::from_fn(|c| j[r * w + c]))
        };
        let ji = block(&self.jn[i * N * w..(i + 1) * N * w]);
        let jj = block(&self.jn[(i + 1) * N * w..(i + 2) * N * w]);
        let jm = block(&self.jm[i * N * w..(i + 1) * N * w]);
        for r in 0..N {
            let mut sa = [0.0; N];
            let mut sb = [0.0; N];
            for l in 0..N {
                let jml = jm[r][l];
                for c in 0..N {
                    sa[c] += jml * ji[l][c];
                    sb[c] += jml * jj[l][c];
                }
            }
            let (oa, ob) = out[r * ld..r * ld + 2 * N].split_at_mut(N);
            for c in 0..N {
                let d = if r == c { 1.0 } else { 0.0 };
                let m_a = 2.0 * jm[r][c] + 0.5 * h * sa[c];
                let m_b = 2.0 * jm[r][c] - 0.5 * h * sb[c];
                oa[c] = -d - h / 6.0 * (ji[r][c] + m_a);
                ob[c] = d - h / 6.0 * (jj[r][c] + m_b);
            }
        }
    }

    /// [`interval_rows`](Self::interval_rows) for any `n`.
    fn interval_rows_general(&self, i: usize, out: &mut [f64], ld: usize) {
        let n = self.n;
        let w = n + self.seeded_params;
        let h = self.h[i];
        let ji = &self.jn[i * n * w..(i + 1) * n * w];
        let jj = &self.jn[(i + 1) * n * w..(i + 2) * n * w];
        let jm = &self.jm[i * n * w..(i + 1) * n * w];
        // A = -I - h/6 (J_i + 4 Jm (I/2 + h/8 J_i)),  B = I - h/6 (J_j + 4 Jm (I/2 - h/8 J_j));
        // the products Jm J_i and Jm J_j are accumulated row by row over contiguous rows of J;
        // a zero of Jm adds nothing (exactly: the sums start at +0), so a sparse right-hand side
        // costs O(n · nonzeros) instead of O(n³)
        for r in 0..n {
            let (sa, sb) = out[r * ld..r * ld + 2 * n].split_at_mut(n);
            sa.fill(0.0);
            sb.fill(0.0);
            let jmr = &jm[r * w..r * w + n];
            for (l, &jml) in jmr.iter().enumerate() {
                if jml == 0.0 {
                    continue;
                }
                let jil = &ji[l * w..l * w + n];
                let jjl = &jj[l * w..l * w + n];
                for (((a, b), &vi), &vj) in sa.iter_mut().zip(sb.iter_mut()).zip(jil).zip(jjl) {
                    *a += jml * vi;
                    *b += jml * vj;
                }
            }
            let jir = &ji[r * w..r * w + n];
            let jjr = &jj[r * w..r * w + n];
            for c in 0..n {
                let d = if r == c { 1.0 } else { 0.0 };
                let m_a = 2.0 * jmr[c] + 0.5 * h * sa[c];
                let m_b = 2.0 * jmr[c] - 0.5 * h * sb[c];
                sa[c] = -d - h / 6.0 * (jir[c] + m_a);
                sb[c] = d - h / 6.0 * (jjr[c] + m_b);
            }
        }
    }

    /// The column of the Jacobians' parameter part holding `p_col` (`col` an index into
    /// `p = (unknowns, model parameters)`), if it was seeded: `col` itself for an unknown, `k + s`
    /// for model parameter `model_seeds[s]`.
    pub(crate) fn param_slot(&self, col: usize) -> Option<usize> {
        if col < self.k {
            return (col < self.seeded_params).then_some(col);
        }
        self.model_seeds
            .binary_search(&(col - self.k))
            .ok()
            .map(|s| self.k + s)
    }

    /// Column `col` (a column of the parameter part, `< seeded_params`: see
    /// [`param_slot`](Self::param_slot)) of `∂r/∂p`: writes the collocation part
    /// (`(m-1) n` rows) and the boundary part (`n + k` rows) into `out` (length `m n + k`).
    pub(crate) fn param_column(&self, col: usize, out: &mut [f64]) {
        let n = self.n;
        let w = n + self.seeded_params;
        let parts = ParamParts {
            jn: &self.jn,
            jm: &self.jm,
            jbc: &self.jbc,
            width: w,
            column: n + col,
            bc_width: 2 * n + self.seeded_params,
            bc_column: 2 * n + col,
            jif: &self.jif,
        };
        self.param_column_from(&parts, out);
    }

    /// [`param_column`](Self::param_column) for column `s` of `extra`, computed by
    /// [`param_jacobians_only`](Self::param_jacobians_only) on this mesh at this solution:
    /// its parameter derivatives with this linearisation's state Jacobians.
    pub(crate) fn param_column_with(&self, extra: &Collocation, s: usize, out: &mut [f64]) {
        let parts = ParamParts {
            jn: &extra.jn,
            jm: &extra.jm,
            jbc: &extra.jbc,
            width: extra.seeded_params,
            column: s,
            bc_width: extra.seeded_params,
            bc_column: s,
            jif: &extra.jif,
        };
        self.param_column_from(&parts, out);
    }

    /// `∂r/∂p` for one parameter whose derivatives of `f` and `g` are in `parts`, with the
    /// state Jacobians of this collocation.
    fn param_column_from(&self, parts: &ParamParts<'_>, out: &mut [f64]) {
        let (n, m) = (self.n, self.m());
        let w = n + self.seeded_params;
        let (pw, pc) = (parts.width, parts.column);
        let fp = |j: &[f64], i: usize, r: usize| j[(i * n + r) * pw + pc];
        for i in 0..m - 1 {
            let h = self.h[i];
            if h == 0.0 {
                let j = self.region[i];
                for r in 0..n {
                    out[i * n + r] = parts.jif[(j * n + r) * parts.bc_width + parts.bc_column];
                }
                continue;
            }
            let jm = &self.jm[i * n * w..(i + 1) * n * w];
            for r in 0..n {
                // d y_mid / dp = -h/8 (fp_j - fp_i); a zero of Jm adds nothing (the sum starts
                // at +0), so a sparse right-hand side skips it
                let mut s = 0.0;
                for (l, &jml) in jm[r * w..r * w + n].iter().enumerate() {
                    if jml != 0.0 {
                        s += jml * (-0.125 * h) * (fp(parts.jn, i + 1, l) - fp(parts.jn, i, l));
                    }
                }
                out[i * n + r] = -h / 6.0
                    * (fp(parts.jn, i, r)
                        + 4.0 * (fp(parts.jm, i, r) + s)
                        + fp(parts.jn, i + 1, r));
            }
        }
        let off = (m - 1) * n;
        for r in 0..n + self.k {
            out[off + r] = parts.jbc[r * parts.bc_width + parts.bc_column];
        }
    }

    /// Boundary Jacobian entry `∂g_r/∂ya_c` (`end = 0`) or `∂g_r/∂yb_c` (`end = 1`).
    #[inline]
    pub(crate) fn bc_state(&self, r: usize, end: usize, c: usize) -> f64 {
        let wb = 2 * self.n + self.seeded_params;
        self.jbc[r * wb + end * self.n + c]
    }
}

/// Where one parameter's derivatives of `f` (nodes `jn`, midpoints `jm`, rows of `width`, at
/// `column`) and of `g` (`jbc`, rows of `bc_width`, at `bc_column`) are stored.
struct ParamParts<'a> {
    jn: &'a [f64],
    jm: &'a [f64],
    jbc: &'a [f64],
    width: usize,
    column: usize,
    bc_width: usize,
    bc_column: usize,
    /// The interface conditions' derivatives (rows of `bc_width`, at `bc_column`).
    jif: &'a [f64],
}

/// A collocation point of a dual pass: a node or the midpoint of an interval.
#[derive(Clone, Copy)]
enum Point {
    Node(usize),
    Midpoint(usize),
}

/// The Jacobian of the right-hand side `rf` at `input` in the seeds `seeds`, compressed by
/// `coloring` where given ([`Coloring`]), else one direction per seed.
fn rhs_jacobian<P: Bvp>(
    engine: &mut DualJacobian,
    coloring: Option<&Coloring>,
    rf: &RhsFn<'_, P>,
    input: &[f64],
    seeds: Seeds<'_>,
    out: &mut [f64],
    jac: &mut [f64],
) {
    match coloring {
        Some(c) => engine.jacobian_colored(rf, input, seeds, c, out, jac),
        None => engine.jacobian_in(rf, input, seeds, out, jac),
    }
}

fn check_finite(
    v: &[f64],
    stride: usize,
    row_width: usize,
    pos: impl Fn(usize) -> f64,
    what: &'static str,
) -> Result<(), BvpError> {
    if let Some(idx) = v.iter().position(|x| !x.is_finite()) {
        return Err(BvpError::NonFinite {
            what,
            component: (idx % stride) / row_width,
            x: pos(idx / stride),
        });
    }
    Ok(())
}
