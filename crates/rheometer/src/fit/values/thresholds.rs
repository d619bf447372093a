//! The thresholds of the checks of a fit (see [`summary::checks`](crate::fit::summary::checks)):
//! when an estimate is at a bound, a misfit too large, a standard error huge, a covariance
//! ill-conditioned, an `n` implausible for a melt, a refit's law a jump. Values only, shared by
//! the checks and by the error budget's warnings.

/// An estimate counts as at a bound when it is within this fraction of the width of its search
/// range from the bound (e.g. `0.001` for `n ∈ [0, 1]`, `0.013` for `κ ∈ [7, 20]`).
pub const AT_BOUND_TOLERANCE: f64 = 1e-3;
/// The report warns when the RMS relative residual exceeds this multiple of the noise level.
pub const MISFIT_RATIO: f64 = 3.0;
/// Without any noise level (too few points to estimate it), the report warns when the RMS
/// relative residual exceeds this \[-\].
pub const MISFIT_WITHOUT_NOISE: f64 = 0.1;
/// Misfit over an *estimated* noise level above which the estimate itself is suspect
/// (c15b): real diameter gauges are not a thousand times more precise than a model's misfit,
/// but interpolated or synthetic (noiseless) rows dominating the estimate make it so.
pub const IMPLAUSIBLE_NOISE_RATIO: f64 = 1000.0;
/// An *estimated* relative noise level below this \[-\] says the data carry no measurement
/// noise (synthetic or smoothed): 0.001 % is 10 nm on a 1 mm fiber, a hundred times finer than
/// a laser micrometer resolves; standard errors, which scale with the noise, then measure the
/// numerics rather than the data.
pub(crate) const NOISE_FREE_LEVEL: f64 = 1e-5;
/// A standard error of `n` above this \[-\] is reported as huge.
pub const LARGE_STDERR_N: f64 = 0.2;
/// A standard error of `κ` above this \[-\] (a factor `e` in `K`) is reported as huge.
pub const LARGE_STDERR_KAPPA: f64 = 1.0;
/// A fitted strength whose standard error exceeds this fraction of its search range is
/// reported as undetermined.
pub const LARGE_STDERR_STRENGTH_FRACTION: f64 = 0.25;
/// A correlation matrix whose smallest/largest eigenvalue ratio is below this is reported as
/// ill-conditioned.
pub const ILL_CONDITIONED_RCOND: f64 = 1e-10;

/// The power index `n` \[-\] polymer melts show in elongation: below 0.2 a fitted `n` is
/// compensating a model error, not describing a melt.
pub const PLAUSIBLE_N: [f64; 2] = [0.2, 1.0];

/// A fitted law that thins by less than this fraction \[-\] at the largest strain rate the
/// data cover is Newtonian over them, whatever its `n`: about the thinning there of the laws
/// the data cannot tell from the Newtonian one (the one-sided bound `n > 0.85` for `K` at the
/// data's largest stress thins by 5 % there; `n → 0` with `K` e times beyond it by 6 %).
pub(crate) const NEWTONIAN_THINNING: f64 = 0.05;

/// A law that moved by more than this many of the plain fit's standard errors is checked
/// against the gain in fit it bought ([`law_jump`](crate::fit::summary::checks::law_jump)).
pub const JUMP_SE: f64 = 20.0;

/// A fit that ended without a convergence test being met is reported as not converged when its
/// linearisation still places the optimum at least this much lower in `χ²` (`‖J s‖²/σ̂²` of the
/// Gauss–Newton step `s`; one unit is a move of about one standard error).
pub const NOT_CONVERGED_CHI2: f64 = 1.0;
