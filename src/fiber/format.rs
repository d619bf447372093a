//! Numbers for people: short forms for messages and reports.

/// `v` with 6 significant digits, trailing zeros trimmed (`1e5` and above or below `1e-3` in
/// exponent notation).
pub fn fmt_g(v: f64) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    if v != 0.0 && (v.abs() >= 1e5 || v.abs() < 1e-3) {
        return format!("{v:.4e}");
    }
    let digits = if v == 0.0 {
        0
    } else {
        (5 - v.abs().log10().floor() as i64).clamp(0, 8) as usize
    };
    let t = format!("{v:.digits$}");
    if t.contains('.') {
        t.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        t
    }
}
