//! Messages for TOML syntax errors that the parser states too briefly: a duplicate key or
//! table (named, with the line of its first definition), and a file that is not an experiments
//! file at all (a CSV table or a JSON report given in its place).

use std::ops::Range;
use std::path::Path;

use crate::data::input::error::{short, InputError, Location};

/// The header path of a table header line (`[material]` → `material`, `[[experiment]]` →
/// `experiment`), without spaces, and whether it is an array header.
fn header(line: &str) -> Option<(String, bool)> {
    let t = line.trim();
    let t = t.split('#').next().unwrap_or(t).trim();
    if let Some(inner) = t.strip_prefix("[[").and_then(|r| r.strip_suffix("]]")) {
        return Some((inner.replace([' ', '\t', '"'], ""), true));
    }
    let inner = t.strip_prefix('[')?.strip_suffix(']')?;
    Some((inner.replace([' ', '\t', '"'], ""), false))
}

/// The key of a `key = value` line, without spaces and quotes.
fn key_of(line: &str) -> Option<String> {
    let t = line.trim();
    if t.starts_with('#') || t.starts_with('[') {
        return None;
    }
    let (key, _) = t.split_once('=')?;
    Some(key.replace([' ', '\t', '"', '\''], ""))
}

/// The message for the parser's "duplicate key" at `span`: the key or table, its table, and
/// the line where it was first defined.
pub(in crate::data::input) fn duplicate_message(text: &str, span: Range<usize>) -> Option<String> {
    let lines: Vec<&str> = text.lines().collect();
    let line_no = text.get(..span.start)?.matches('\n').count();
    let line = lines.get(line_no)?;
    if let Some((path, is_array)) = header(line) {
        let first = lines[..line_no].iter().enumerate().find_map(|(i, l)| {
            let defines = match header(l) {
                Some((p, _)) => p == path || p.starts_with(&format!("{path}.")),
                None => {
                    let top_level = lines[..i].iter().all(|l| header(l).is_none());
                    top_level
                        && key_of(l)
                            .is_some_and(|k| k == path || k.starts_with(&format!("{path}.")))
                }
            };
            defines.then(|| (i + 1, l.trim()))
        });
        let shown = if is_array {
            format!("[[{path}]]")
        } else {
            format!("[{path}]")
        };
        return Some(match first {
            Some((n, first_line)) if is_array => format!(
                "`{shown}`: `{path}` is already a single table, defined on line {n} by `{}`; \
                 `[{path}.uncertainty]`-style tables belong after the `{shown}` they refine",
                short(first_line, 60)
            ),
            Some((n, first_line)) => format!(
                "table `{shown}` is defined twice (first on line {n}: `{}`); merge the two into \
                 one `{shown}` table",
                short(first_line, 60)
            ),
            None => format!("table `{shown}` is defined twice; merge the two"),
        });
    }
    let key = text
        .get(span.clone())?
        .trim()
        .trim_matches(['"', '\''])
        .to_string();
    let section_start = lines[..line_no].iter().rposition(|l| header(l).is_some());
    let table = match section_start {
        Some(i) => match header(lines[i]) {
            Some((p, true)) => format!("[[{p}]]"),
            Some((p, false)) => format!("[{p}]"),
            None => "the top level".into(),
        },
        None => "the top level".into(),
    };
    let from = section_start.map_or(0, |i| i + 1);
    let full_key = key_of(line).unwrap_or_else(|| key.clone());
    let first = (from..line_no).find(|&i| key_of(lines[i]).is_some_and(|k| k == full_key));
    let first = first
        .map(|i| format!(" (first on line {})", i + 1))
        .unwrap_or_default();
    Some(format!(
        "duplicate key `{}` in {table}{first}; keep one",
        short(&full_key, 60)
    ))
}

/// An [`InputError::NotExperiments`] if `text` is clearly not TOML: JSON (a fit report) or a
/// CSV table (a measurement file).
pub(in crate::data::input) fn not_experiments(path: &Path, text: &str) -> Option<InputError> {
    let (line, first) = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .find(|(_, l)| !l.is_empty() && !l.starts_with('#'))?;
    // a JSON array: `[` alone (pretty-printed), or followed by a value; TOML's table headers
    // `[name]` and `[[name]]` hold neither a lone bracket nor a comma-separated list
    let after = first.get(1..).unwrap_or("").trim_start();
    let json = first.starts_with('{')
        || first == "["
        || (first.starts_with('[')
            && !first.starts_with("[[")
            && (after.starts_with(['{', '"', '[', ']'])
                || (after.contains(',') && !first.contains('='))));
    let csv = !json
        && !first.starts_with('[')
        && !first.contains('=')
        && (first.contains([',', ';', '\t']));
    let message = if json {
        "it is JSON (a report written by `rheometer fit --json`?); pass the experiments file \
         (TOML: a [material] table and [[experiment]] tables)"
            .to_string()
    } else if csv {
        format!(
            "it looks like a CSV table (line {line}: `{}`), perhaps a measurement file; pass \
             the experiments file (TOML), which names each experiment's CSV file in `data = \
             \"...\"`",
            short(first, 60)
        )
    } else {
        return None;
    };
    Some(InputError::NotExperiments {
        at: Location {
            path: path.to_path_buf(),
            line: Some(line),
        },
        message,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dup(text: &str) -> String {
        let e = toml::de::DeTable::parse(text).unwrap_err();
        duplicate_message(text, e.span().unwrap()).unwrap()
    }

    #[test]
    fn duplicates_are_named() {
        let m = dup("[material]\nvft_B_K = 1\nx = 2\nvft_B_K = 3\n");
        assert_eq!(
            m,
            "duplicate key `vft_B_K` in [material] (first on line 2); keep one"
        );
        let m = dup("material.trouton_ratio = 3\n[a]\nb = 1\n[material]\nc = 1\n");
        assert!(
            m.contains("table `[material]` is defined twice (first on line 1"),
            "{m}"
        );
        let m = dup("[material]\na = 1\n[material]\nb = 2\n");
        assert!(m.contains("first on line 1: `[material]`"), "{m}");
        let m = dup("[experiment.uncertainty]\na = 1\n[[experiment]]\nname = \"x\"\n");
        assert!(
            m.contains("`[[experiment]]`") && m.contains("line 1"),
            "{m}"
        );
    }

    #[test]
    fn other_file_kinds_are_recognised() {
        let p = Path::new("x");
        let e = not_experiments(p, "position_m,diameter_m\n0,1\n").unwrap();
        assert!(e.to_string().contains("CSV"), "{e}");
        let e = not_experiments(p, "{\n \"a\": 1}").unwrap();
        assert!(e.to_string().contains("JSON"), "{e}");
        assert!(not_experiments(p, "[material]\na = 1").is_none());
        assert!(not_experiments(p, "[[experiment]]\n").is_none());
        assert!(not_experiments(p, "a = 1, 2").is_none());
        for array in ["[\n  {\"a\": 1}\n]", "[1, 2]", "[ -1.5, 2 ]", "[]"] {
            let e = not_experiments(p, array).unwrap();
            assert!(e.to_string().contains("JSON"), "{array}: {e}");
        }
        assert!(not_experiments(p, "[1]\na = 1").is_none());
    }
}
