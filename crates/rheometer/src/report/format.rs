//! Numbers for people: short forms for messages and reports.
//!
//! * `fmt_g`: a number alone, 6 significant digits, trailing zeros trimmed;
//! * `fmt_sig`: a number alone with a given number of significant digits;
//! * [`fmt_pm`]: a value with its uncertainty, both rounded to the digits the uncertainty
//!   supports (`0.804 ± 0.007`, `(4.9 ± 4.4)e2`);
//! * [`fmt_at`]: a value at the precision of an uncertainty (interval ends: `[0.790, 0.818]`);
//!
//! The rounding rule (the Particle Data Group's, simplified): the uncertainty keeps two
//! significant digits when its leading digits are below 355 (`0.0012`, `0.034`), one otherwise
//! (`0.007`, `0.4`); the value is rounded to the same decimal place.

/// `v` with 6 significant digits, trailing zeros trimmed (`1e5` and above or below `1e-3` in
/// exponent notation).
pub(crate) fn fmt_g(v: f64) -> String {
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

/// `v` with `digits` significant digits (at least 1), in exponent notation from `1e5` and
/// below `1e-3` (`fmt_sig(0.016234, 2) = "0.016"`, `fmt_sig(123456.0, 3) = "1.23e5"`).
pub(crate) fn fmt_sig(v: f64, digits: usize) -> String {
    let digits = digits.max(1);
    if !v.is_finite() {
        return format!("{v}");
    }
    if v == 0.0 {
        return "0".into();
    }
    let e = decade(v);
    if !(-3..5).contains(&e) {
        let m = v / 10f64.powi(e);
        // rounding may carry into the next decade (9.96 → 10.0)
        let t = format!("{:.*}", digits - 1, m);
        if t.trim_start_matches('-').starts_with("10") {
            return format!("{:.*}e{}", digits - 1, v / 10f64.powi(e + 1), e + 1);
        }
        return format!("{t}e{e}");
    }
    let decimals = digits as i32 - 1 - e;
    if decimals < 0 {
        // round away the digits left of the point that are not significant (1409 → 1400)
        let s = 10f64.powi(-decimals);
        return format!("{:.0}", (v / s).round() * s);
    }
    format!("{v:.*}", decimals as usize)
}

/// `v` in exponent notation with `digits` significant digits (`fmt_e(112345.0, 3) = "1.12e5"`):
/// for quantities spanning decades (`K`, viscosities) so that neighbours look alike.
pub(crate) fn fmt_e(v: f64, digits: usize) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    format!("{:.*e}", digits.max(1) - 1, v)
}

/// The decade of `v`: `floor(log10 |v|)` (0 for 0).
fn decade(v: f64) -> i32 {
    if v == 0.0 || !v.is_finite() {
        0
    } else {
        v.abs().log10().floor() as i32
    }
}

/// The decimal place an uncertainty `u > 0` is rounded to: `10^place` is its last digit.
fn place_of(u: f64) -> i32 {
    let e = decade(u);
    let lead = u / 10f64.powi(e - 2); // three leading digits, 100..999
    let lead = lead.round();
    if lead < 355.0 {
        e - 1
    } else {
        // 0.96 rounds to 1.0, which keeps two digits (leading 100 < 355): place e as well
        e
    }
}

/// `v` rounded to the decimal place `place` (digits after the point: `−place`).
fn at_place(v: f64, place: i32) -> String {
    let decimals = (-place).max(0) as usize;
    let r = if place > 0 {
        let s = 10f64.powi(place);
        (v / s).round() * s
    } else {
        v
    };
    let t = format!("{r:.decimals$}");
    // no "-0"
    if t.trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        t.trim_start_matches('-').to_string()
    } else {
        t
    }
}

/// `value ± uncertainty`, both rounded to the digits the uncertainty supports (see the module
/// doc): `fmt_pm(0.80412, 0.00713) = "0.804 ± 0.007"`, `fmt_pm(11.634, 0.0312) = "11.634 ±
/// 0.031"`, `fmt_pm(489.1999, 440.1617) = "500 ± 400"`; a common power of ten outside
/// `1e-3..1e5`: `fmt_pm(1.2345e6, 2.1e4) = "(1.234 ± 0.021)e6"`. An uncertainty that is not
/// positive and finite gives the value alone (`fmt_g`).
pub fn fmt_pm(value: f64, uncertainty: f64) -> String {
    if !(uncertainty.is_finite() && uncertainty > 0.0 && value.is_finite()) {
        return fmt_g(value);
    }
    let big = value.abs().max(uncertainty);
    let e = decade(big);
    if !(-3..5).contains(&e) {
        let s = 10f64.powi(e);
        return format!("({})e{e}", fmt_pm(value / s, uncertainty / s));
    }
    let place = place_of(uncertainty);
    format!(
        "{} ± {}",
        at_place(value, place),
        at_place(uncertainty, place)
    )
}

/// `" unit"`, or nothing for a dimensionless quantity (unit `""` or `"-"`).
pub(crate) fn unit_suffix(unit: &str) -> String {
    match unit.trim() {
        "" | "-" => String::new(),
        u => format!(" {u}"),
    }
}

/// `v` at the precision an uncertainty `u` supports (the same decimal place as in
/// [`fmt_pm`]): interval ends and values beside a `±`. `u` not positive and finite: `fmt_g`.
pub fn fmt_at(v: f64, u: f64) -> String {
    if !(u.is_finite() && u > 0.0 && v.is_finite()) {
        return fmt_g(v);
    }
    let e = decade(v.abs().max(u));
    if !(-3..5).contains(&e) {
        let place = place_of(u) - decade(v);
        return fmt_sig(v, (1 - place).max(1) as usize);
    }
    at_place(v, place_of(u))
}

/// The widest line a report prints, in characters.
pub(crate) const LINE_WIDTH: usize = 100;

/// `text` wrapped at word boundaries to lines of at most `width` characters: the first line
/// starts with `first`, the following ones with `rest` (indentation). A single word longer
/// than the room is kept whole; runs of spaces are kept except at a break.
pub(crate) fn wrap(text: &str, width: usize, first: &str, rest: &str) -> String {
    let mut out = String::new();
    let mut line = first.to_string();
    let mut empty = true;
    // split at single spaces so that runs of spaces (aligned `key   = value`) survive on a line
    for word in text.split(' ') {
        let len = line.chars().count();
        if !empty && !word.is_empty() && len + 1 + word.chars().count() > width {
            out.push_str(line.trim_end());
            out.push('\n');
            line = rest.to_string();
            empty = true;
        }
        if empty && word.is_empty() {
            continue;
        }
        if !empty {
            line.push(' ');
        }
        line.push_str(word);
        empty = false;
    }
    out.push_str(line.trim_end());
    out
}

/// Every line of `text` longer than [`LINE_WIDTH`] wrapped at word boundaries, continuation
/// lines indented 4 more than the line's own indentation. Lines that fit are kept as they are
/// (tables stay aligned).
pub(crate) fn wrap_long_lines(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for line in text.split_inclusive('\n') {
        let (body, nl) = match line.strip_suffix('\n') {
            Some(b) => (b, "\n"),
            None => (line, ""),
        };
        if body.chars().count() <= LINE_WIDTH {
            out.push_str(line);
            continue;
        }
        let indent: String = body.chars().take_while(|c| *c == ' ').collect();
        let rest = format!("{indent}    ");
        out.push_str(&wrap(body.trim_start(), LINE_WIDTH, &indent, &rest));
        out.push_str(nl);
    }
    out
}

/// A number as people read it: the shortest form that reads back exactly, in exponent
/// notation below 1e-4 and from 1e6 on (`1e308`, not 309 digits).
pub fn show(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-4..1e6).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_carry_the_digits_their_uncertainty_supports() {
        assert_eq!(fmt_pm(0.80412, 0.00713), "0.804 ± 0.007");
        assert_eq!(fmt_pm(11.634, 0.0472), "11.63 ± 0.05");
        assert_eq!(fmt_pm(11.634, 0.0312), "11.634 ± 0.031");
        assert_eq!(fmt_pm(489.1999, 440.1617), "500 ± 400");
        assert_eq!(fmt_pm(16.1, 19.8), "16 ± 20");
        assert_eq!(fmt_pm(0.8, 0.96), "0.8 ± 1.0");
        assert_eq!(fmt_pm(1.2345e6, 2.1e4), "(1.234 ± 0.021)e6");
        assert_eq!(fmt_pm(-0.0004, 0.0012), "-0.0004 ± 0.0012");
        assert_eq!(fmt_pm(2.0, f64::NAN), "2");
        assert_eq!(fmt_at(0.790123, 0.00713), "0.790");
        assert_eq!(fmt_at(-0.00001, 0.007), "0.000");
        assert_eq!(fmt_sig(0.016234, 2), "0.016");
        assert_eq!(fmt_sig(123456.0, 3), "1.23e5");
        assert_eq!(fmt_sig(999600.0, 3), "1.00e6");
        assert_eq!(fmt_sig(1409.0, 2), "1400");
        assert_eq!(fmt_sig(4459.2, 3), "4460");
        assert_eq!(fmt_e(95123.0, 2), "9.5e4");
    }

    #[test]
    fn long_lines_wrap_and_short_ones_stay() {
        let long = format!("    {}\n  short   table\n", "word ".repeat(40));
        let w = wrap_long_lines(&long);
        assert!(w.lines().all(|l| l.chars().count() <= LINE_WIDTH), "{w}");
        assert!(w.lines().nth(1).unwrap().starts_with("        word"), "{w}");
        assert!(w.ends_with("  short   table\n"));
        assert_eq!(w.split_whitespace().count(), 42);
        let aligned = format!("    key    = {}", "value ".repeat(30));
        assert!(wrap_long_lines(&aligned).starts_with("    key    = value"));
    }
}
