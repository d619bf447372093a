#!/usr/bin/env python3
"""CasADi peer of `rheometer fit`: identify (n, kappa) by one simultaneous-collocation NLP.

What it does
------------
Reads an experiments file (default: the 9 shipped experiments of
`data/pmma7n_synthetic/experiments.toml` and their CSVs) and identifies the two parameters
(n, kappa = ln(K / 1 Pa)) of the Carreau-type elongational viscosity law with the same model and
the same estimator as the default of `rheometer fit` (the "principled" estimator):

    J = sum over experiments k and measurement points j of (d_k(s_j) / d_meas,kj - 1)^2

the raw relative residuals of the diameters (sigma = 1, so J is the plain sum of squares, as in
the `cost` of our JSON), with one take-up diameter per experiment fitted as a nuisance parameter.

The model is the paper's strain-rate formulation at continuation parameter c = 1, written out
here independently of the Rust code from `crates/rheometer/src/model/bvp.rs`, `material_law.rs`,
`contributions.rs`, `scaling.rs` and `../shared/docs/model-closure.md`: dimensionless states
(u, N, T, epsdot) on s in [0, L/L_o], gravity, Stokes air drag (delta = 1e-3), convective cooling
with the regularised inclined Churchill-Bernstein law, viscous heating, still air at 293.15 K,
VFT zero-rate viscosity with Trouton ratio 3, rho(T) and c_p(T) linear, paper Table 2 scaling.
Boundary conditions: u(0) = u_in = 4 Q / (pi rho(T_in) d_in^2), T(0) = T_in, the constitutive
relation at the nozzle Re/Q rho(T_in) u_in N(0) = epsdot(0) mu_e(T_in, epsdot(0)), and the take-up
diameter d(L) free (it is the fitted nuisance parameter; ours writes it as d(L) = phi d_fit(L)
with phi in [0.5, 1.5], a bound inactive on this data set).

Discretisation: for every experiment, Radau IIA collocation of degree 3 (order 5 at the mesh
points) on a fixed mesh that contains all measurement positions (default: 4 sub-intervals per
0.02 m for s < 0.06 m, 2 for s < 0.20 m, 1 beyond, plus [0.50, 0.51] m: 42 intervals);
`--refine R` multiplies the number of sub-intervals by R, to check the discretisation error.
All states of all experiments, n and kappa form one NLP with the collocation equations and
boundary conditions as equality constraints, solved by IPOPT (CasADi `nlpsol`, exact Hessian,
MUMPS). Bounds on (n, kappa) are ours: [0, 1] x [7, 20].

Start: (n, kappa) = (0.5, 15), the start our heuristic prints for this data set (`--start`
changes it). The states start from a shooting solve at that law (class `Shooting`: CVODES from
the nozzle, epsdot(0) bisected until d(L) meets the data extrapolated to L), the analogue of our
cold start; no simulation of ours is used. `--init data` starts them from the data instead
(u from the measured diameters at a guessed temperature, epsdot = du/ds, N from the
constitutive relation); IPOPT does not converge from there on the shipped data.
IPOPT options: mu_strategy adaptive (the default monotone strategy fails from the shooting
start), tol 1e-10, at most 500 iterations.

Output (units): n [-], kappa [-] (K = exp(kappa) Pa), J [-], RMS relative residual [%],
fitted take-up diameters d(L) [um], IPOPT iterations and status, wall times [s] (build, solve,
whole process). With `--ours FILE` (the JSON of `rheometer fit ... --json FILE`) it also prints
our n, kappa, J and the differences in our standard errors. `--json FILE` writes the results.

Run with the venv of `benches/peers/README.md`:
    target/peer-venv/bin/python benches/peers/casadi_identify.py --ours target/ours.json
"""

import argparse
import contextlib
import csv
import json
import math
import os
import sys
import time

T_PROCESS_START = time.perf_counter()

import numpy as np  # noqa: E402
import casadi as ca  # noqa: E402

try:
    import tomllib  # Python >= 3.11
except ImportError:  # pragma: no cover
    tomllib = None

# ---------------------------------------------------------------------------------------------
# Constants: paper Table 2 reference values (SI) and the derived dimensionless numbers
# ---------------------------------------------------------------------------------------------
REF = dict(
    mass_flow=3.08e-5,  # Q_o [kg/s]
    length=0.51,  # L_o [m]
    velocity=0.0283,  # u_o [m/s]
    temperature=513.15,  # T_o [K]
    density=1.077e3,  # rho_o [kg/m^3]
    heat_capacity=2.2903e3,  # c_p,o [J/(kg K)]
    viscosity=1.4865e3,  # mu_o [Pa s]
    heat_transfer=12.762,  # alpha_o [W/(m^2 K)] (drops out)
    air_density=1.0,  # [kg/m^3]
    air_heat_capacity=1000.0,  # [J/(kg K)]
    air_kinematic_viscosity=2e-5,  # [m^2/s]
    air_heat_conductivity=0.031,  # [W/(m K)]
    stress=1.0,  # K_o [Pa]
    gravity=9.81,  # g [m/s^2]
)
SLENDERNESS = 1e-3  # delta of the Stokes drag coefficient [-]
TROUTON = 3.0  # mu_e0 = 3 mu_s0 [-]
RE_REG = 1e-3  # Re regularisation of the Nusselt law [-]
INC_REG = 1e-3  # inclination regularisation of the Nusselt law [-]


def scaling(r):
    """Dimensionless numbers of the paper's non-dimensionalisation (Table 2)."""
    d_o = math.sqrt(r["mass_flow"] / (r["density"] * r["velocity"]))
    f_o = r["mass_flow"] * r["velocity"] / r["length"]
    s = dict(d_o=d_o)
    s["re"] = r["density"] * r["velocity"] * r["length"] / r["viscosity"]
    s["fr"] = r["velocity"] / math.sqrt(r["gravity"] * r["length"])
    s["ec"] = r["velocity"] ** 2 / (r["heat_capacity"] * r["temperature"])
    s["st"] = r["heat_transfer"] * d_o * r["length"] / (r["heat_capacity"] * r["mass_flow"])
    s["de"] = r["viscosity"] / r["stress"] * r["velocity"] / r["length"]
    s["a_star"] = r["air_density"] * d_o * r["velocity"] ** 2 / f_o
    s["re_star"] = d_o * r["velocity"] / r["air_kinematic_viscosity"]
    s["nu_star"] = r["heat_transfer"] * d_o / r["air_heat_conductivity"]
    s["pr_star"] = (
        r["air_heat_capacity"] * r["air_density"] * r["air_kinematic_viscosity"]
        / r["air_heat_conductivity"]
    )
    return s


def stokes_resistance(delta):
    """Regularised tangential Stokes coefficient r_tau,S^delta [-]."""
    l = math.log(4.0 / delta)
    return 2.0 * math.pi / l + 0.5 * math.pi / (l * l)


# ---------------------------------------------------------------------------------------------
# Input
# ---------------------------------------------------------------------------------------------
def load_experiments(path):
    """Material, air, defaults and the experiments (with their measurements) of a TOML file."""
    if tomllib is None:
        sys.exit("Python >= 3.11 is needed (tomllib)")
    with open(path, "rb") as f:
        cfg = tomllib.load(f)
    base = os.path.dirname(os.path.abspath(path))
    exps = []
    for e in cfg["experiment"]:
        if any(k in e for k in ("take_up_diameter_m", "take_up_velocity_m_s")):
            sys.exit(f"{e['name']}: a given take-up condition is not supported by this peer")
        pos, dia = [], []
        with open(os.path.join(base, e["data"]), newline="") as f:
            for row in csv.DictReader(f):
                pos.append(float(row["position_m"]))
                dia.append(float(row["diameter_m"]))
        d = dict(cfg.get("defaults", {}))
        d.update(e)
        d["positions"] = np.array(pos)
        d["diameters"] = np.array(dia)
        exps.append(d)
    return cfg["material"], exps


# ---------------------------------------------------------------------------------------------
# The model (dimensionless), symbolic in CasADi
# ---------------------------------------------------------------------------------------------
class Model:
    """Constants shared by all experiments and the right-hand side as a CasADi Function."""

    def __init__(self, mat, t_air_si):
        r, s = REF, scaling(REF)
        self.s = s
        self.rho_a = mat["density_slope_kg_m3_K"] * r["temperature"] / r["density"]
        self.rho_b = mat["density_intercept_kg_m3"] / r["density"]
        self.cp_a = mat["heat_capacity_slope_J_kg_K2"] * r["temperature"] / r["heat_capacity"]
        self.cp_b = mat["heat_capacity_intercept_J_kg_K"] / r["heat_capacity"]
        self.vft_a = TROUTON * mat["vft_mu_c_Pa_s"] / r["viscosity"]
        self.vft_b = mat["vft_B_K"] / r["temperature"]
        self.vft_tvf = mat["vft_T_VF_K"] / r["temperature"]
        rho_air = mat["air_density_kg_m3"] / r["air_density"]
        nu_air = mat["air_kinematic_viscosity_m2_s"] / r["air_kinematic_viscosity"]
        lam_air = mat["air_heat_conductivity_W_m_K"] / r["air_heat_conductivity"]
        cp_air = mat["air_heat_capacity_J_kg_K"] / r["air_heat_capacity"]
        self.inv_fr2 = 1.0 / s["fr"] ** 2
        self.drag = s["a_star"] / s["re_star"] * stokes_resistance(SLENDERNESS) * rho_air * nu_air
        self.convection = math.pi * (s["st"] / s["nu_star"]) * lam_air
        self.re_air = s["re_star"] / nu_air
        pr = s["pr_star"] * cp_air * rho_air * nu_air / lam_air
        self.pr_arg = 0.62 * pr ** (1.0 / 3.0) * (1.0 + (0.4 / pr) ** (2.0 / 3.0)) ** (-0.25)
        self.t_air = t_air_si / r["temperature"]
        self.rhs = self._rhs_function()
        self.mu = self._mu_function()

    def rho(self, t):
        return self.rho_a * t + self.rho_b

    def cp(self, t):
        return self.cp_a * t + self.cp_b

    def diameter(self, u, t, q):
        """Dimensionless fiber diameter 2 sqrt(Q / (pi rho u))."""
        return ca.sqrt(4.0 * q / (math.pi * self.rho(t) * u))

    def mu_e(self, t, rate, n, kappa):
        """Carreau-type mu_e(T, epsdot) / mu_o [-]."""
        mu0 = self.vft_a * ca.exp(self.vft_b / (t - self.vft_tvf))
        w = mu0 * rate * ca.exp(-kappa) * (self.s["de"] * REF["stress"])
        return mu0 * ca.exp((n - 1.0) * 0.5 * ca.log1p(w * w))

    def nusselt(self, re_tau):
        """Regularised inclined Churchill-Bernstein law (default of model-closure.md)."""
        re_sq = re_tau * re_tau
        re_eps2 = re_sq + RE_REG**2
        inclination = 1.0 - 0.5 * re_sq / (re_sq + INC_REG**2)
        sqrt_re = re_eps2**0.25
        re_58 = sqrt_re * sqrt_re**0.25 * 282000.0 ** (-0.625)
        return inclination * (sqrt_re * self.pr_arg * ca.exp(0.8 * ca.log1p(re_58)) + 0.3)

    def _mu_function(self):
        t, rate, n, kappa = (ca.SX.sym(v) for v in ("t", "rate", "n", "kappa"))
        return ca.Function("mu_e", [t, rate, n, kappa], [self.mu_e(t, rate, n, kappa)])

    def _rhs_function(self):
        y = ca.SX.sym("y", 4)
        th = ca.SX.sym("theta", 2)  # (n, kappa)
        q = ca.SX.sym("q")  # dimensionless mass flow Q / Q_o
        u, nn, t, rate = y[0], y[1], y[2], y[3]
        rho, cp = self.rho(t), self.cp(t)
        d = self.diameter(u, t, q)
        force = q * self.inv_fr2 / u + (0.0 - u) * self.drag  # gravity + air drag
        re_tau = d * (0.0 - u) * self.re_air
        heat = -self.nusselt(re_tau) * (t - self.t_air) * self.convection + nn * rate * self.s["ec"]
        f_n = rate * q - force
        f_t = heat / (cp * q)
        mu = self.mu_e(t, rate, th[0], th[1])
        mu_t = ca.jacobian(mu, t)
        mu_r = ca.jacobian(mu, rate)
        re_over_q = self.s["re"] / q
        num = re_over_q * (rho * nn * rate + rho * u * f_n + u * nn * f_t * self.rho_a) - rate * mu_t * f_t
        f = ca.vertcat(rate, f_n, f_t, num / (mu + rate * mu_r))
        return ca.Function("rhs", [y, th, q], [f])


# ---------------------------------------------------------------------------------------------
# Collocation
# ---------------------------------------------------------------------------------------------
def radau3():
    """Radau IIA degree 3: collocation points tau (with 0), derivative matrix C, end weights D."""
    tau = [0.0] + list(ca.collocation_points(3, "radau"))
    deg = 3
    C = np.zeros((deg + 1, deg + 1))
    D = np.zeros(deg + 1)
    for j in range(deg + 1):
        p = np.poly1d([1.0])
        for r in range(deg + 1):
            if r != j:
                p *= np.poly1d([1.0, -tau[r]]) / (tau[j] - tau[r])
        D[j] = p(1.0)
        dp = np.polyder(p)
        for r in range(deg + 1):
            C[j, r] = dp(tau[r])
    return np.array(tau), C, D


def make_mesh(positions_m, length_m, refine):
    """Mesh [m] through every measurement position and L, finer near the nozzle."""
    nodes = sorted(set(np.round(positions_m, 12)) | {0.0, length_m})
    mesh = [nodes[0]]
    for a, b in zip(nodes[:-1], nodes[1:]):
        m = 4 if a < 0.06 - 1e-12 else 2 if a < 0.20 - 1e-12 else 1
        m *= refine
        mesh.extend(a + (b - a) * (i + 1) / m for i in range(m))
    return np.array(mesh)


def initial_states(model, e, q, u_in, t_in, pts, n0, kappa0):
    """Data-based start of the states (u, N, T, epsdot) at dimensionless positions `pts`."""
    r = REF
    pos = e["positions"]
    ln_d = np.log(e["diameters"] / D_O)
    s_m = pts * r["length"]
    # log-linear interpolation, the last segment extrapolated to L
    ln_d_i = np.interp(s_m, pos, ln_d)
    beyond = s_m > pos[-1]
    slope = (ln_d[-1] - ln_d[-2]) / (pos[-1] - pos[-2])
    ln_d_i[beyond] = ln_d[-1] + slope * (s_m[beyond] - pos[-1])
    length = e["spinline_length_m"] / r["length"]
    t = model.t_air + (t_in - model.t_air) * np.exp(-pts / length)
    rho = model.rho_a * t + model.rho_b
    u = 4.0 * q / (math.pi * rho * np.exp(2.0 * ln_d_i))
    u = u * (u_in / u[0])  # u(0) = u_in exactly
    uniq, inv = np.unique(pts, return_inverse=True)
    u_u = np.interp(uniq, pts, u)
    rate = np.maximum(np.gradient(u_u, uniq), 0.0)[inv]
    mu0 = model.vft_a * np.exp(model.vft_b / (t - model.vft_tvf))
    wv = mu0 * rate * math.exp(-kappa0) * model.s["de"] * REF["stress"]
    mu = mu0 * np.exp((n0 - 1.0) * 0.5 * np.log1p(wv * wv))
    nn = q * mu * rate / (model.s["re"] * rho * u)
    return np.vstack([u, nn, t, rate])


@contextlib.contextmanager
def quiet_stderr():
    """Silences file descriptor 2 (C libraries' messages) for the duration."""
    sys.stderr.flush()
    saved = os.dup(2)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 2)
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(devnull)


class Shooting:
    """Consistent start states at the start (n, kappa): the IVP from the nozzle (CVODES),
    epsdot(0) found by bisection on its logarithm so that d(L) meets the data extrapolated to L
    (N(0) from the nozzle's constitutive relation). The analogue of our cold start."""

    def __init__(self, model, grid):
        y = ca.SX.sym("y", 4)
        p = ca.SX.sym("p", 3)  # n, kappa, q
        dae = {"x": y, "p": p, "ode": model.rhs(y, p[:2], p[2])}
        opts = {"abstol": 1e-8, "reltol": 1e-6, "max_num_steps": 3000, "show_eval_warnings": False}
        self.end = ca.integrator("shoot_end", "cvodes", dae, 0.0, [grid[-1]], opts)
        self.full = ca.integrator("shoot_full", "cvodes", dae, 0.0, list(grid[1:]), opts)
        self.grid = grid
        self.model = model

    def y0(self, rate0, q, u_in, t_in, theta):
        m = self.model
        mu = float(m.mu(t_in, rate0, theta[0], theta[1]))
        n0 = rate0 * mu * q / (m.s["re"] * m.rho(t_in) * u_in)
        return [u_in, n0, t_in, rate0]

    def d_end(self, rate0, q, u_in, t_in, theta):
        """d(L) [-], or 0 where the fiber breaks (the IVP fails: too much draw)."""
        try:
            yl = np.array(self.end(x0=self.y0(rate0, q, u_in, t_in, theta), p=[*theta, q])["xf"]).ravel()
        except RuntimeError:
            return 0.0
        if not np.all(np.isfinite(yl)) or yl[0] <= 0:
            return 0.0
        return float(self.model.diameter(yl[0], yl[2], q))

    def states(self, d_target, q, u_in, t_in, theta):
        with quiet_stderr():  # CVODES reports its failed trial integrations on fd 2
            return self._states(d_target, q, u_in, t_in, theta)

    def _states(self, d_target, q, u_in, t_in, theta):
        lo, hi = math.log(1e-4), math.log(1e3)  # ln epsdot(0)
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            d = self.d_end(math.exp(mid), q, u_in, t_in, theta)
            if d > d_target:
                lo = mid  # too little draw
            else:
                hi = mid
            if abs(d / d_target - 1.0) < 1e-3:  # a start, not a solution: 0.1 % is plenty
                lo = mid
                break
        y0 = self.y0(math.exp(lo), q, u_in, t_in, theta)
        ys = np.array(self.full(x0=y0, p=[*theta, q])["xf"])
        return np.hstack([np.array(y0)[:, None], ys])


MAP_MODE = ("serial",)  # how the intervals are evaluated (set by --threads)

D_O = math.sqrt(REF["mass_flow"] / (REF["density"] * REF["velocity"]))  # d_o [m]


def interval_function(model):
    """Collocation defects of one interval (scaled): 3 x 4 collocation equations, 4 continuity."""
    tau, C, D = radau3()
    x0, x1, sc = ca.SX.sym("x0", 4), ca.SX.sym("x1", 4), ca.SX.sym("scale", 4)
    xc = ca.SX.sym("xc", 4, 3)
    h, q, th = ca.SX.sym("h"), ca.SX.sym("q"), ca.SX.sym("theta", 2)
    allx = [x0 * sc] + [xc[:, k] * sc for k in range(3)]
    out = []
    for k in range(1, 4):
        xp = sum(C[j, k] * allx[j] for j in range(4))
        out.append((h * model.rhs(allx[k], th, q) - xp) / sc)
    out.append((sum(D[j] * allx[j] for j in range(4)) - x1 * sc) / sc)
    return ca.Function("interval", [x0, xc, x1, h, th, q, sc], [ca.vertcat(*out)])


def build_nlp(model, mat, exps, start, refine, init="shooting"):
    """The NLP over all experiments: variables, constraints, objective, start and bounds."""
    r = REF
    tau, _, _ = radau3()
    theta = ca.MX.sym("theta", 2)
    w, w0, lbw, ubw = [theta], [np.array(start, float)], [[0.0, 7.0]], [[1.0, 20.0]]
    g = []
    J = 0
    per_exp = []
    cols = dict(x0=[], xc=[], x1=[], h=[], q=[], sc=[])
    inf = np.inf
    lb_u = 1e-3  # u > 0 keeps the diameter defined
    shooter = None
    for e in exps:
        q = e["mass_flow_kg_s"] / r["mass_flow"]
        t_in_si = e["inlet_temperature_K"]
        rho_in_si = mat["density_slope_kg_m3_K"] * t_in_si + mat["density_intercept_kg_m3"]
        u_in = 4.0 * e["mass_flow_kg_s"] / (math.pi * rho_in_si * e["inlet_diameter_m"] ** 2)
        u_in /= r["velocity"]
        t_in = t_in_si / r["temperature"]
        mesh_m = make_mesh(e["positions"], e["spinline_length_m"], refine)
        mesh = mesh_m / r["length"]
        ni = len(mesh) - 1
        h = np.diff(mesh)
        pc = (mesh[:-1, None] + tau[None, 1:] * h[:, None]).ravel()  # collocation points
        if init == "shooting":
            grid = np.unique(np.concatenate([mesh, pc]))
            if shooter is None or len(shooter.grid) != len(grid) or not np.allclose(shooter.grid, grid):
                shooter = Shooting(model, grid)
            pos, ln_d = e["positions"], np.log(e["diameters"] / D_O)
            slope = (ln_d[-1] - ln_d[-2]) / (pos[-1] - pos[-2])
            d_target = math.exp(ln_d[-1] + slope * (e["spinline_length_m"] - pos[-1]))
            ys = shooter.states(d_target, q, u_in, t_in, start)
            gm = ys[:, np.searchsorted(grid, mesh)]
            gc = ys[:, np.searchsorted(grid, pc)]
        else:
            gm = initial_states(model, e, q, u_in, t_in, mesh, start[0], start[1])
            gc = initial_states(model, e, q, u_in, t_in, pc, start[0], start[1])
        sc = np.maximum(np.abs(gm).max(axis=1), 1e-3)  # nominal value of each state
        xm = ca.MX.sym("xm_" + e["name"], 4, ni + 1)  # scaled states at the mesh points
        xc = ca.MX.sym("xc_" + e["name"], 4, 3 * ni)  # scaled states at the collocation points
        w += [ca.vec(xm), ca.vec(xc)]
        w0 += [(gm / sc[:, None]).ravel(order="F"), (gc / sc[:, None]).ravel(order="F")]
        lb = np.array([lb_u, -inf, -inf, -inf])
        for npts in (ni + 1, 3 * ni):
            lbw.append(np.tile(lb, npts))
            ubw.append(np.full(4 * npts, inf))
        cols["x0"].append(xm[:, :-1])
        cols["x1"].append(xm[:, 1:])
        cols["xc"].append(xc)
        cols["h"].append(h)
        cols["q"].append(np.full(ni, q))
        cols["sc"].append(np.tile(sc[:, None], (1, ni)))
        # boundary conditions at the nozzle
        X = xm[:, 0] * sc
        rho_in = model.rho(t_in)
        g += [
            X[0] - u_in,
            X[2] - t_in,
            model.s["re"] / q * (X[1] * (u_in * rho_in))
            - X[3] * model.mu_e(t_in, X[3], theta[0], theta[1]),
        ]
        # residuals at the measurement points (mesh points by construction)
        idx = [int(np.argmin(np.abs(mesh_m - s_j))) for s_j in e["positions"]]
        assert np.allclose(mesh_m[idx], e["positions"], atol=1e-9)
        xs = xm[:, idx]
        d = model.diameter(xs[0, :] * sc[0], xs[2, :] * sc[2], q)
        res = (d / (e["diameters"][None, :] / D_O) - 1.0).T
        J = J + ca.sumsqr(res)
        d_end = model.diameter(xm[0, -1] * sc[0], xm[2, -1] * sc[2], q)
        per_exp.append(dict(name=e["name"], res=res, d_end=d_end, intervals=ni))
    total = sum(p["intervals"] for p in per_exp)
    f_int = interval_function(model).map(total, *MAP_MODE)
    defects = f_int(
        ca.horzcat(*cols["x0"]),
        ca.horzcat(*cols["xc"]),
        ca.horzcat(*cols["x1"]),
        np.concatenate(cols["h"])[None, :],
        theta,
        np.concatenate(cols["q"])[None, :],
        np.hstack(cols["sc"]),
    )
    g = ca.vertcat(*g, ca.vec(defects))
    nlp = dict(x=ca.vertcat(*w), f=J, g=g)
    ng = g.numel()
    return (
        nlp,
        np.concatenate(w0),
        np.concatenate([np.asarray(v, float) for v in lbw]),
        np.concatenate([np.asarray(v, float) for v in ubw]),
        np.zeros(ng),
        np.zeros(ng),
        per_exp,
    )


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    root = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
    ap.add_argument("experiments", nargs="?", default=os.path.join(root, "data/pmma7n_synthetic/experiments.toml"))
    ap.add_argument("--start", default="0.5,15", help='start "N,KAPPA" (default 0.5,15, our heuristic\'s)')
    ap.add_argument("--refine", type=int, default=1, help="multiply the sub-intervals by R (default 1: 42 intervals)")
    ap.add_argument("--ours", help="JSON of `rheometer fit --json` to compare with")
    ap.add_argument("--json", help="write the results as JSON to FILE")
    ap.add_argument("--expand", action="store_true", help="expand the MX graph to SX before solving")
    ap.add_argument("--max-iter", type=int, default=500, help="IPOPT iteration limit (default 500)")
    ap.add_argument("--mu-strategy", default="adaptive", help="IPOPT mu_strategy (default adaptive)")
    ap.add_argument("--init", choices=["shooting", "data"], default="shooting", help="start of the states (default shooting)")
    ap.add_argument("--threads", type=int, default=1, help="evaluate the collocation equations on this many threads (default 1)")
    ap.add_argument("--verbose", action="store_true", help="print IPOPT's iteration log")
    a = ap.parse_args()
    start = [float(v) for v in a.start.split(",")]
    global MAP_MODE
    if a.threads > 1:
        MAP_MODE = ("thread", a.threads)

    mat, exps = load_experiments(a.experiments)
    t_air = exps[0]["air_temperature_K"]
    if any(e["air_temperature_K"] != t_air for e in exps):
        sys.exit("all experiments must share the air temperature")
    t0 = time.perf_counter()
    model = Model(mat, t_air)
    nlp, x0, lbx, ubx, lbg, ubg, per_exp = build_nlp(model, mat, exps, start, a.refine, a.init)
    opts = {"expand": a.expand, "ipopt.print_level": 5 if a.verbose else 0, "print_time": False, "ipopt.sb": "yes", "ipopt.tol": 1e-10, "ipopt.max_iter": a.max_iter, "ipopt.mu_strategy": a.mu_strategy, "ipopt.print_timing_statistics": "yes" if a.verbose else "no"}
    solver = ca.nlpsol("peer", "ipopt", nlp, opts)
    t1 = time.perf_counter()
    sol = solver(x0=x0, lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg)
    t2 = time.perf_counter()
    st = solver.stats()
    xopt = np.array(sol["x"]).ravel()
    n, kappa = xopt[0], xopt[1]
    J = float(sol["f"])
    fres = ca.Function("post", [nlp["x"]], [ca.vertcat(*[p["res"] for p in per_exp]), ca.vertcat(*[p["d_end"] for p in per_exp])])
    res, d_end = (np.array(v).ravel() for v in fres(xopt))
    out = dict(
        n=n, kappa=kappa, K_Pa=math.exp(kappa), cost=J, rms_relative_residual=math.sqrt(np.mean(res**2)),
        residuals=len(res), take_up_diameters_m=list(d_end * D_O), intervals=[p["intervals"] for p in per_exp],
        collocation="Radau IIA degree 3", variables=int(nlp["x"].numel()), constraints=int(nlp["g"].numel()),
        ipopt_status=st["return_status"], ipopt_iterations=st["iter_count"], success=bool(st["success"]),
        start=start, build_s=t1 - t0, solve_s=t2 - t1, casadi=ca.__version__,
    )
    out["process_s"] = time.perf_counter() - T_PROCESS_START
    print(f"CasADi {ca.__version__} + IPOPT, Radau IIA deg. 3, intervals per experiment {min(out['intervals'])}-{max(out['intervals'])}, "
          f"{out['variables']} variables, {out['constraints']} constraints")
    print(f"start (n, kappa) = ({start[0]}, {start[1]}); IPOPT: {st['return_status']} after {st['iter_count']} iterations")
    print(f"n     = {n:.6f}")
    print(f"kappa = {kappa:.6f}   (K = {math.exp(kappa):.4g} Pa)")
    print(f"J     = {J:.7e}   RMS relative residual {100 * out['rms_relative_residual']:.4f} % over {len(res)} residuals")
    print("take-up diameters d(L) [um]: " + ", ".join(f"{1e6 * v:.2f}" for v in out["take_up_diameters_m"]))
    print(f"wall time: build {out['build_s']:.3f} s, solve {out['solve_s']:.3f} s, process so far {out['process_s']:.3f} s")
    if a.ours:
        with open(a.ours) as f:
            o = json.load(f)
        on, ok, oj = o["n"]["value"], o["kappa"]["value"], o["cost"]
        sn, sk = o["n"]["stderr"], o["kappa"]["stderr"]
        out["ours"] = dict(n=on, kappa=ok, cost=oj, se_n=sn, se_kappa=sk)
        out["diff_se"] = dict(n=(n - on) / sn, kappa=(kappa - ok) / sk)
        print(f"ours: n = {on:.6f} ± {sn:.4f}, kappa = {ok:.6f} ± {sk:.4f}, J = {oj:.7e}")
        print(f"peer - ours: n {n - on:+.2e} ({out['diff_se']['n']:+.2e} SE), kappa {kappa - ok:+.2e} "
              f"({out['diff_se']['kappa']:+.2e} SE), J {J - oj:+.3e} ({100 * (J - oj) / oj:+.3f} %)")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(out, f, indent=1)
    return 0 if st["success"] else 1


if __name__ == "__main__":
    sys.exit(main())
