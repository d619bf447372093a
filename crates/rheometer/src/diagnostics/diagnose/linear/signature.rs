//! Where along the spin line a change of the residuals lies, and residual profiles by name.

use crate::diagnostics::diagnosis::ResidualProfiles;
use crate::fit::Identification;

/// Where along `s` a residual change lies: the position \[m\] of the largest pooled change and
/// the 10%–90% range \[m\] of its cumulative weight.
pub(crate) fn signature_location(positions: &[f64], change: &[f64]) -> (f64, [f64; 2]) {
    let mut pts: Vec<(f64, f64)> = positions
        .iter()
        .zip(change)
        .map(|(&s, &d)| (s, d * d))
        .collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    // pool equal positions
    let mut pooled: Vec<(f64, f64)> = Vec::new();
    for (s, w) in pts {
        match pooled.last_mut() {
            Some(l) if (l.0 - s).abs() < 1e-9 => l.1 += w,
            _ => pooled.push((s, w)),
        }
    }
    let total: f64 = pooled.iter().map(|p| p.1).sum();
    if pooled.is_empty() || total <= 0.0 {
        return (f64::NAN, [f64::NAN, f64::NAN]);
    }
    let peak = pooled
        .iter()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(f64::NAN, |p| p.0);
    let (mut acc, mut lo, mut hi) = (0.0, f64::NAN, f64::NAN);
    for &(s, w) in &pooled {
        acc += w;
        if lo.is_nan() && acc >= 0.1 * total {
            lo = s;
        }
        if hi.is_nan() && acc >= 0.9 * total {
            hi = s;
        }
    }
    (peak, [lo, hi])
}

/// The residuals of a fit on its own model (a refit's parameter vector belongs to the
/// candidate's model, not to the diagnosis' one), named by experiment.
pub(crate) fn named_residuals(id: &Identification) -> ResidualProfiles {
    id.residual_profiles
        .iter()
        .enumerate()
        .map(|(k, (s, r))| {
            (
                id.summary
                    .experiments
                    .get(k)
                    .cloned()
                    .unwrap_or_else(|| format!("#{}", k + 1)),
                s.iter().copied().zip(r.iter().copied()).collect(),
            )
        })
        .collect()
}
