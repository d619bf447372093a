//! Axes: ranges of the data, tick values (including logarithmic axes), tick labels, and the
//! font and label-area sizes of a chart.

/// Magnitude beyond which data are clamped for range computation.
pub(super) const HUGE: f64 = 1e300;

/// Font sizes and label-area sizes scaled to the space available for one chart.
#[derive(Debug, Clone, Copy)]
pub(super) struct Metrics {
    pub(super) title: f64,
    pub(super) label: f64,
    pub(super) tick: f64,
    pub(super) margin: u32,
    pub(super) x_area: u32,
    pub(super) y_area: u32,
}

impl Metrics {
    pub(super) fn for_area(w: u32, h: u32) -> Self {
        let base = (f64::from(w.min(h)) / 24.0).clamp(9.0, 22.0);
        let tick = base * 0.85;
        Self {
            title: base * 1.25,
            label: base,
            tick,
            margin: (base * 0.6).round() as u32,
            x_area: (tick * 1.6 + base * 1.7).round() as u32,
            y_area: (tick * 4.2 + base * 1.7).round() as u32,
        }
    }
}

/// Range of the usable values (finite, and positive for a log axis), padded by 5 % (of the
/// decades for a log axis); degenerate and empty cases get a sensible non-empty range.
pub(super) fn axis_range(values: impl Iterator<Item = f64>, log: bool, pad: bool) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && (!log || *v > 0.0))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return if log { (1.0, 10.0) } else { (0.0, 1.0) };
    }
    // Keep the span finite (and tick generation sane) for values near the f64 limits.
    let (lo, hi) = (lo.clamp(-HUGE, HUGE), hi.clamp(-HUGE, HUGE));
    if log {
        let (llo, lhi) = (lo.log10(), hi.log10());
        let span = lhi - llo;
        if span < 1e-9 {
            return (lo / 2.0, hi * 2.0);
        }
        let p = if pad { 0.05 * span } else { 0.0 };
        (10f64.powf(llo - p), 10f64.powf(lhi + p))
    } else {
        let span = hi - lo;
        let scale = lo.abs().max(hi.abs());
        if span <= scale * 1e-12 {
            let d = if scale == 0.0 { 1.0 } else { 0.1 * scale };
            return (lo - d, hi + d);
        }
        if !pad || !span.is_finite() {
            return (lo, hi);
        }
        let (a, b) = (lo - 0.05 * span, hi + 0.05 * span);
        if a.is_finite() && b.is_finite() {
            (a, b)
        } else {
            (lo, hi)
        }
    }
}

/// `m × 10^e` computed so that the result is the correctly rounded decimal (e.g. exactly `0.3`).
fn decimal(m: f64, e: i32) -> f64 {
    if e >= 0 {
        m * 10f64.powi(e)
    } else {
        m / 10f64.powi(-e)
    }
}

/// Tick values for a logarithmic axis over `[lo, hi]` (`0 < lo < hi`): decades, or 1-2-5 / 1…9
/// mantissas when the range spans only about a decade, or plain decimal steps for a narrow range.
pub(super) fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    const MAX_TICKS: usize = 8;
    let e0 = lo.log10().floor() as i32;
    let e1 = hi.log10().floor() as i32;
    let in_range = |v: &f64| *v >= lo * (1.0 - 1e-12) && *v <= hi * (1.0 + 1e-12);
    let with = |mantissas: &[f64]| -> Vec<f64> {
        (e0..=e1)
            .flat_map(|e| mantissas.iter().map(move |&m| decimal(m, e)))
            .filter(in_range)
            .collect()
    };
    let all: Vec<f64> = (1..=9).map(f64::from).collect();
    for mantissas in [&all[..], &[1.0, 2.0, 5.0], &[1.0]] {
        let ticks = with(mantissas);
        if ticks.len() <= MAX_TICKS && ticks.len() >= 3 {
            return ticks;
        }
        if ticks.len() < 3 {
            break;
        }
    }
    let decades = with(&[1.0]);
    if decades.len() > MAX_TICKS {
        let stride = decades.len().div_ceil(MAX_TICKS);
        return decades.into_iter().step_by(stride).collect();
    }
    // Narrow range: evenly spaced decimal ticks.
    let raw = (hi - lo) / 4.0;
    let e = raw.log10().floor() as i32;
    let m = raw / decimal(1.0, e);
    let m = if m < 1.5 {
        1.0
    } else if m < 3.5 {
        2.0
    } else if m < 7.5 {
        5.0
    } else {
        10.0
    };
    let step = decimal(m, e);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first - 1..=last + 1)
        .map(|k| decimal(k as f64 * m, e))
        .filter(in_range)
        .collect()
}

/// Tick label: plain decimals for moderate magnitudes, `1.5e6` style otherwise, no float noise.
pub(super) fn format_tick(v: &f64) -> String {
    let v = *v;
    let a = v.abs();
    if a == 0.0 || !v.is_finite() {
        return if v.is_finite() {
            "0".into()
        } else {
            format!("{v}")
        };
    }
    if !(1e-3..1e5).contains(&a) {
        let s = format!("{v:.3e}");
        return match s.split_once('e') {
            Some((mantissa, exp)) if mantissa.contains('.') => {
                let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
                format!("{mantissa}e{exp}")
            }
            _ => s,
        };
    }
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_are_padded_and_never_degenerate() {
        let (a, b) = axis_range([0.0, 10.0].into_iter(), false, true);
        assert!((a + 0.5).abs() < 1e-12 && (b - 10.5).abs() < 1e-12);
        assert_eq!(axis_range(std::iter::empty(), false, true), (0.0, 1.0));
        assert_eq!(axis_range([f64::NAN].into_iter(), true, true), (1.0, 10.0));
        let (a, b) = axis_range([3.0, 3.0, f64::NAN].into_iter(), false, true);
        assert!(a < 3.0 && b > 3.0);
        let (a, b) = axis_range([0.0].into_iter(), false, true);
        assert!(a < 0.0 && b > 0.0);
        let (a, b) = axis_range([-1.0, 1e-3, 1e3].into_iter(), true, true);
        assert!(a < 1e-3 && a > 0.0 && b > 1e3);
        let (a, b) = axis_range([f64::MAX, -f64::MAX].into_iter(), false, true);
        assert!(a.is_finite() && b.is_finite() && a < b);
    }

    #[test]
    fn log_ticks_are_readable() {
        assert_eq!(log_ticks(0.2, 1.05), vec![0.2, 0.5, 1.0]);
        assert_eq!(log_ticks(0.5, 5.0), vec![0.5, 1.0, 2.0, 5.0]);
        assert_eq!(
            log_ticks(1e-3, 1e3),
            vec![1e-3, 1e-2, 0.1, 1.0, 10.0, 100.0, 1e3]
        );
        assert!((3..=8).contains(&log_ticks(1e-30, 1e30).len()));
        assert_eq!(log_ticks(0.96, 1.04), vec![0.96, 0.98, 1.0, 1.02, 1.04]);
        assert_eq!(log_ticks(2.0, 8.0), vec![2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]);
    }

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(format_tick(&0.30000000000000004), "0.3");
        assert_eq!(format_tick(&14.0), "14");
        assert_eq!(format_tick(&-2.5), "-2.5");
        assert_eq!(format_tick(&0.0), "0");
        assert_eq!(format_tick(&1e300), "1e300");
        assert_eq!(format_tick(&1.5e6), "1.5e6");
        assert_eq!(format_tick(&-2.0e-5), "-2e-5");
        assert_eq!(format_tick(&1e-3), "0.001");
    }
}
