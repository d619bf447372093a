//! Tick values and their labels: 1-2-5 steps on a linear axis (zero exactly zero, every label
//! with the digits its step needs), decades or 1-2-5 mantissas on a logarithmic axis (decades
//! labelled `10ⁿ`); and [`TickedAxis`], the plotters coordinate that uses them.

use std::ops::Range;

use plotters::coord::ranged1d::{KeyPointHint, NoDefaultFormatting, Ranged, ValueFormatter};

/// A linear or logarithmic axis over `[lo, hi]` whose tick marks, labels and minor grid lines
/// are those of [`AxisTicks`] (a plotters coordinate; plotters' own key-point wrapper offers
/// no label formatting for linear axes).
#[derive(Debug, Clone)]
pub(in crate::report::plot) struct TickedAxis {
    lo: f64,
    hi: f64,
    log: bool,
    ticks: AxisTicks,
}

impl TickedAxis {
    /// The axis over `[lo, hi]` (`0 < lo` if `log`) with [`AxisTicks::new`]'s ticks.
    pub(in crate::report::plot) fn new(lo: f64, hi: f64, log: bool) -> Self {
        Self {
            lo,
            hi,
            log,
            ticks: AxisTicks::new(lo, hi, log),
        }
    }

    /// The position of `v` along the axis, 0 at `lo` and 1 at `hi`.
    fn fraction(&self, v: f64) -> f64 {
        if self.log {
            if v <= 0.0 {
                return 0.0;
            }
            (v / self.lo).ln() / (self.hi / self.lo).ln()
        } else {
            (v - self.lo) / (self.hi - self.lo)
        }
    }
}

impl Ranged for TickedAxis {
    type FormatOption = NoDefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let t = self.fraction(*value);
        let t = if t.is_finite() {
            t.clamp(-4.0, 5.0)
        } else {
            0.0
        };
        limit.0 + (t * f64::from(limit.1 - limit.0)).round() as i32
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.ticks.minor.clone()
        } else {
            self.ticks.values.clone()
        }
    }

    fn range(&self) -> Range<f64> {
        self.lo..self.hi
    }
}

impl ValueFormatter<f64> for TickedAxis {
    fn format_ext(&self, value: &f64) -> String {
        self.ticks.label(*value)
    }
}

/// The ticks of one axis: where they are, what they say, and the minor grid lines between them.
#[derive(Debug, Clone, PartialEq)]
pub(in crate::report::plot) struct AxisTicks {
    /// Tick positions, increasing.
    pub(in crate::report::plot) values: Vec<f64>,
    /// One label per tick.
    pub(in crate::report::plot) labels: Vec<String>,
    /// Positions of minor grid lines (no label).
    pub(in crate::report::plot) minor: Vec<f64>,
}

impl AxisTicks {
    /// Ticks of a linear (`log == false`) or logarithmic axis over `[lo, hi]`.
    pub(in crate::report::plot) fn new(lo: f64, hi: f64, log: bool) -> Self {
        if log {
            log_axis_ticks(lo, hi)
        } else {
            linear_axis_ticks(lo, hi)
        }
    }

    /// The label of the tick at `v` (plotters asks for labels by value).
    pub(in crate::report::plot) fn label(&self, v: f64) -> String {
        let nearest = self
            .values
            .iter()
            .enumerate()
            .min_by(|a, b| (a.1 - v).abs().total_cmp(&(b.1 - v).abs()));
        match nearest {
            Some((k, t)) if (t - v).abs() <= 1e-9 * t.abs().max(v.abs()).max(f64::MIN_POSITIVE) => {
                self.labels[k].clone()
            }
            _ => plain(v, 6),
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

/// A "nice" step (1, 2 or 5 × 10^e) giving about `target` intervals over `span`, as `(m, e)`.
fn nice_step(span: f64, target: f64) -> (f64, i32) {
    let raw = span / target;
    let e = raw.log10().floor() as i32;
    let m = raw / decimal(1.0, e);
    if m < 1.5 {
        (1.0, e)
    } else if m < 3.5 {
        (2.0, e)
    } else if m < 7.5 {
        (5.0, e)
    } else {
        (1.0, e + 1)
    }
}

/// Ticks of a linear axis: multiples `k · step` of a 1-2-5 step (4 to 7 of them), computed
/// from the integer `k` so that zero is exactly `0` (never `−2.776e-17`), labelled with the
/// number of decimals the step needs ("0.00", "0.25", "0.50").
fn linear_axis_ticks(lo: f64, hi: f64) -> AxisTicks {
    let span = hi - lo;
    if !(span.is_finite() && span > 0.0) {
        let v = if lo.is_finite() { lo } else { 0.0 };
        return AxisTicks {
            values: vec![v],
            labels: vec![plain(v, 6)],
            minor: Vec::new(),
        };
    }
    let (m, e) = nice_step(span, 5.0);
    let step = decimal(m, e);
    let first = (lo / step - 1e-9).ceil();
    let last = (hi / step + 1e-9).floor();
    let values: Vec<f64> = if (last - first).abs() > 1e4 || !first.is_finite() {
        vec![lo, hi]
    } else {
        let (first, last) = (first as i64, last as i64);
        (first..=last).map(|k| decimal(k as f64 * m, e)).collect()
    };
    let minor_step = step / if m == 2.0 { 4.0 } else { 5.0 };
    let minor: Vec<f64> = if span / minor_step < 200.0 {
        let k0 = (lo / minor_step).ceil() as i64;
        let k1 = (hi / minor_step).floor() as i64;
        (k0..=k1).map(|k| k as f64 * minor_step).collect()
    } else {
        Vec::new()
    };
    let labels = linear_labels(&values, m, e);
    AxisTicks {
        values,
        labels,
        minor,
    }
}

/// Labels of the ticks `k · m · 10^e`: plain decimals with `max(0, −e)` digits while the
/// magnitudes are moderate, otherwise `a.b×10ⁿ` with the mantissa digits the step needs.
fn linear_labels(values: &[f64], m: f64, e: i32) -> Vec<String> {
    let biggest = values.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let step = decimal(m, e);
    if biggest < 1e6 && step >= 1e-4 {
        let digits = (-e).max(0) as usize;
        return values.iter().map(|&v| plain(v, digits)).collect();
    }
    // common exponent: that of the largest tick
    let p = biggest.log10().floor() as i32;
    let digits = (p - e).max(0) as usize;
    values
        .iter()
        .map(|&v| {
            if v == 0.0 {
                "0".to_string()
            } else {
                let mantissa = v / decimal(1.0, p);
                format!("{}×10{}", plain(mantissa, digits), superscript(p))
            }
        })
        .collect()
}

/// `v` with `digits` decimals, a negative zero shown as `0`, and a true minus sign.
fn plain(v: f64, digits: usize) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    let s = format!("{v:.digits$}");
    let negative_zero = s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.');
    if negative_zero {
        s[1..].to_string()
    } else {
        s.replacen('-', "−", 1)
    }
}

/// `n` in superscript digits (`−3` → `⁻³`).
pub(in crate::report::plot) fn superscript(n: i32) -> String {
    const DIGITS: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let mut s = String::new();
    if n < 0 {
        s.push('⁻');
    }
    for c in n.unsigned_abs().to_string().chars() {
        s.push(c.to_digit(10).map_or(c, |d| DIGITS[d as usize]));
    }
    s
}

/// Tick values for a logarithmic axis over `[lo, hi]` (`0 < lo < hi`): decades, or 1-2-5 / 1…9
/// mantissas when the range spans only about a decade, or plain decimal steps for a narrow range.
pub(in crate::report::plot) fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
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
    let (m, e) = nice_step(hi - lo, 4.0);
    let step = decimal(m, e);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first - 1..=last + 1)
        .map(|k| decimal(k as f64 * m, e))
        .filter(in_range)
        .collect()
}

/// Whether `v` is a power of ten (to rounding).
fn is_decade(v: f64) -> bool {
    let l = v.log10();
    (l - l.round()).abs() < 1e-9
}

/// Ticks of a logarithmic axis: [`log_ticks`]; when they are all decades, labelled `10ⁿ`
/// with the minor grid at 2…9 × 10ⁿ, otherwise plain numbers with the decimals they need
/// (`a×10ⁿ` for very small or large values).
fn log_axis_ticks(lo: f64, hi: f64) -> AxisTicks {
    let values = log_ticks(lo, hi);
    let decades = values.len() >= 2 && values.iter().all(|&v| is_decade(v));
    if decades {
        let labels = values
            .iter()
            .map(|&v| format!("10{}", superscript(v.log10().round() as i32)))
            .collect();
        let e0 = lo.log10().floor() as i32;
        let e1 = hi.log10().ceil() as i32;
        let minor = if e1 - e0 <= 12 {
            (e0..=e1)
                .flat_map(|e| (2..=9).map(move |m| decimal(f64::from(m), e)))
                .filter(|v| *v > lo && *v < hi)
                .collect()
        } else {
            Vec::new()
        };
        return AxisTicks {
            values,
            labels,
            minor,
        };
    }
    let labels = values.iter().map(|&v| log_mantissa_label(v)).collect();
    AxisTicks {
        values,
        labels,
        minor: Vec::new(),
    }
}

/// A label for a tick on a logarithmic axis that is not a decade: the shortest exact decimal
/// (`0.2`, `5`, `0.96`), or `a×10ⁿ` outside `[10⁻³, 10⁵)`.
fn log_mantissa_label(v: f64) -> String {
    let a = v.abs();
    if (1e-3..1e5).contains(&a) {
        let digits = (0..=9)
            .find(|&d| {
                let x = v * 10f64.powi(d);
                (x - x.round()).abs() < 1e-6 * x.abs().max(1.0)
            })
            .unwrap_or(6) as usize;
        return plain(v, digits);
    }
    let p = a.log10().floor() as i32;
    let mantissa = v / decimal(1.0, p);
    let m = plain(mantissa, 1);
    let m = m.trim_end_matches('0').trim_end_matches('.');
    if m == "1" {
        format!("10{}", superscript(p))
    } else {
        format!("{m}×10{}", superscript(p))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
    fn log_labels_are_powers_of_ten_or_short_decimals() {
        let t = AxisTicks::new(5e-3, 2e3, true);
        assert_eq!(t.labels, ["10⁻²", "10⁻¹", "10⁰", "10¹", "10²", "10³"]);
        assert!(t.minor.contains(&0.02) && t.minor.contains(&500.0));
        let t = AxisTicks::new(0.15, 1.2, true);
        assert_eq!(t.labels, ["0.2", "0.5", "1"]);
        let t = AxisTicks::new(0.955, 1.045, true);
        assert_eq!(t.labels, ["0.96", "0.98", "1", "1.02", "1.04"]);
        assert_eq!(log_mantissa_label(2e-5), "2×10⁻⁵");
    }

    #[test]
    fn linear_zero_is_snapped_and_digits_follow_the_step() {
        // a range whose ticks, summed in floating point, would give 0.1 + 0.2 - 0.3 style noise
        let t = AxisTicks::new(-0.3 + 0.1 + 0.2 - 0.05, 0.35, false);
        assert!(t.values.contains(&0.0));
        assert!(t.labels.iter().all(|l| !l.contains('e')), "{:?}", t.labels);
        assert_eq!(t.labels, ["0.0", "0.1", "0.2", "0.3"]);
        let t = AxisTicks::new(-5.1, 9.3, false);
        assert_eq!(t.labels, ["−4", "−2", "0", "2", "4", "6", "8"]);
        let t = AxisTicks::new(0.79, 0.83, false);
        assert_eq!(t.labels, ["0.79", "0.80", "0.81", "0.82", "0.83"]);
        let t = AxisTicks::new(-2.776e-17, 1.0, false);
        assert_eq!(t.labels[0], "0.0");
        let t = AxisTicks::new(1.1e-5, 1.9e-5, false);
        assert!(t.labels.iter().any(|l| l == "1.2×10⁻⁵"), "{:?}", t.labels);
        let t = AxisTicks::new(0.0, 3e6, false);
        assert_eq!(t.labels[1], "0.5×10⁶");
        assert_eq!(t.label(0.0), "0");
        assert!((4..=8).contains(&t.values.len()));
    }

    #[test]
    fn degenerate_linear_ranges_do_not_panic() {
        assert_eq!(AxisTicks::new(1.0, 1.0, false).values, vec![1.0]);
        assert_eq!(AxisTicks::new(f64::NAN, 1.0, false).values.len(), 1);
        let t = AxisTicks::new(-f64::MAX, f64::MAX, false);
        assert!(!t.values.is_empty());
    }

    #[test]
    fn superscripts() {
        assert_eq!(superscript(-17), "⁻¹⁷");
        assert_eq!(superscript(0), "⁰");
        assert_eq!(superscript(305), "³⁰⁵");
    }
}
