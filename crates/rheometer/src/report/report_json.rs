//! The stamp of every JSON report the program writes: `"schema_version"` (the layout of the
//! report, `SCHEMA_VERSION`), `"report"` (which report it is: [`ReportKind`]) and
//! `"written_by"` (the program and version that wrote it), first in the file. A reader
//! (`check_report`) accepts the current schema version only, so that a report of another
//! layout is never half-read; it names the program version that wrote the file and what to
//! do, and says which report a file of the wrong kind is.

use serde::Serialize;
use serde_json::Value;

/// The layout version of the JSON reports this program writes and reads. It changes whenever
/// a field a reader needs changes meaning, type or name.
pub(crate) const SCHEMA_VERSION: u64 = 1;

/// The program and version recorded as `"written_by"`.
pub fn written_by() -> String {
    format!("rheometer {}", env!("CARGO_PKG_VERSION"))
}

/// Which report a JSON file is (its `"report"` field).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReportKind {
    /// `rheometer fit --json`.
    Fit,
    /// `rheometer diagnose --json`.
    Diagnosis,
    /// `rheometer design --json`.
    Design,
    /// `rheometer design --rivals … --json`.
    Discrimination,
    /// `rheometer compare --json` (and `compare --out`'s `comparison.json`).
    Comparison,
    /// `fit --out`'s `flow_curve.json`.
    FlowCurve,
}

impl ReportKind {
    /// The value of the `"report"` field.
    pub fn tag(self) -> &'static str {
        match self {
            ReportKind::Fit => "fit",
            ReportKind::Diagnosis => "diagnosis",
            ReportKind::Design => "design",
            ReportKind::Discrimination => "discrimination",
            ReportKind::Comparison => "comparison",
            ReportKind::FlowCurve => "flow_curve",
        }
    }

    /// The command that writes it, for messages.
    pub fn command(self) -> &'static str {
        match self {
            ReportKind::Fit => "rheometer fit --json",
            ReportKind::Diagnosis => "rheometer diagnose --json",
            ReportKind::Design => "rheometer design --json",
            ReportKind::Discrimination => "rheometer design --rivals --json",
            ReportKind::Comparison => "rheometer compare --json",
            ReportKind::FlowCurve => "rheometer fit --out (flow_curve.json)",
        }
    }

    const ALL: [ReportKind; 6] = [
        ReportKind::Fit,
        ReportKind::Diagnosis,
        ReportKind::Design,
        ReportKind::Discrimination,
        ReportKind::Comparison,
        ReportKind::FlowCurve,
    ];

    fn from_tag(tag: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.tag() == tag)
    }

    /// The kind of an unstamped object, guessed from its fields (for messages only).
    fn sniff(obj: &serde_json::Map<String, Value>) -> Option<Self> {
        let has = |k: &str| obj.contains_key(k);
        if has("verdict") && has("base_fit") {
            Some(ReportKind::Diagnosis)
        } else if has("estimator") && has("n") {
            Some(ReportKind::Fit)
        } else if has("rivals") && has("candidates") {
            Some(ReportKind::Discrimination)
        } else if has("criterion") && has("candidates") {
            Some(ReportKind::Design)
        } else if has("chi2_per_dof") && has("experiments") {
            Some(ReportKind::Comparison)
        } else {
            None
        }
    }
}

/// A report with its stamp first: serialised as `{"schema_version": 1, "report": "fit",
/// "written_by": "rheometer 0.1.0", ...the report's fields}`.
#[derive(Serialize)]
struct Stamped<'a, T: Serialize> {
    schema_version: u64,
    report: &'static str,
    written_by: String,
    #[serde(flatten)]
    body: &'a T,
}

/// The pretty JSON of `report` with the stamp of `kind` first.
pub fn to_report_json<T: Serialize>(kind: ReportKind, report: &T) -> serde_json::Result<String> {
    serde_json::to_string_pretty(&Stamped {
        schema_version: SCHEMA_VERSION,
        report: kind.tag(),
        written_by: written_by(),
        body: report,
    })
}

/// `a fit report (rheometer fit --json)` or `a diagnosis (...)`, joined with "or".
fn wanted_list(wanted: &[ReportKind]) -> String {
    wanted
        .iter()
        .map(|k| format!("a {} report (`{}`)", k.tag().replace('_', " "), k.command()))
        .collect::<Vec<_>>()
        .join(" or ")
}

/// Checks the stamp of the report `value` read from `source` (a file name, for messages):
/// an object of the current [`SCHEMA_VERSION`] whose `"report"` is one of `wanted`; `flag`
/// names the option that gave the file (`--from`). Returns the kind.
pub(crate) fn check_report(
    value: &Value,
    wanted: &[ReportKind],
    source: &str,
    flag: &str,
) -> Result<ReportKind, String> {
    let redo = format!(
        "re-create it with this version ({}): `{}`",
        written_by(),
        wanted.first().map_or("", |k| k.command())
    );
    let Some(obj) = value.as_object() else {
        return Err(format!(
            "{source}: the JSON is {}, not a report; {flag} wants {}",
            match value {
                Value::Array(_) => "an array",
                Value::String(_) => "a string",
                Value::Number(_) => "a number",
                Value::Bool(_) => "a boolean",
                Value::Null => "null",
                Value::Object(_) => "an object",
            },
            wanted_list(wanted)
        ));
    };
    let writer = obj
        .get("written_by")
        .and_then(Value::as_str)
        .map_or_else(|| "an unknown program".to_string(), str::to_string);
    // the kind first (stamped, or guessed from the fields of an unstamped file): a report of
    // another kind is the wrong file whatever its version
    let stamped = match obj.get("report") {
        Some(Value::String(tag)) => Some(ReportKind::from_tag(tag).ok_or_else(|| {
            format!("{source}: field `report` = \"{tag}\" is no report of this program; {redo}")
        })?),
        Some(v) => {
            return Err(format!(
                "{source}: field `report` = {v} must be a report name; {redo}"
            ))
        }
        None => None,
    };
    let kind = stamped.or_else(|| ReportKind::sniff(obj));
    if let Some(k) = kind.filter(|k| !wanted.contains(k)) {
        return Err(format!(
            "{source}: this is a `{}` report; {flag} wants {}",
            k.command().trim_start_matches("rheometer "),
            wanted_list(wanted)
        ));
    }
    let version = match obj.get("schema_version") {
        None => {
            let what = match kind {
                Some(k) => format!("a {} report", k.tag().replace('_', " ")),
                None => "a JSON file".to_string(),
            };
            return Err(format!(
                "{source}: {what} without \"schema_version\": written by a rheometer older \
                 than this one's report format (or by another program), so its fields cannot \
                 be trusted to mean what this version reads; {redo}"
            ));
        }
        Some(v) => v.as_u64().ok_or_else(|| {
            format!("{source}: field `schema_version` = {v} must be a whole number; {redo}")
        })?,
    };
    if version != SCHEMA_VERSION {
        let relation = if version > SCHEMA_VERSION {
            "newer"
        } else {
            "older"
        };
        return Err(format!(
            "{source}: schema_version {version} (written by {writer}); this program ({}) reads \
             schema_version {SCHEMA_VERSION} only, the {relation} layout may differ: {redo}, \
             or read it with {writer}",
            written_by()
        ));
    }
    let Some(kind) = stamped else {
        return Err(format!("{source}: field `report` is missing; {redo}"));
    };
    Ok(kind)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Serialize)]
    struct R {
        z: f64,
        a: &'static str,
    }

    #[test]
    fn the_stamp_comes_first_and_reads_back() {
        let js = to_report_json(ReportKind::Fit, &R { z: 1.0, a: "x" }).unwrap();
        let first: Vec<&str> = js.lines().take(6).map(str::trim).collect();
        assert_eq!(first[1], "\"schema_version\": 1,");
        assert_eq!(first[2], "\"report\": \"fit\",");
        assert!(first[3].starts_with("\"written_by\": \"rheometer "), "{js}");
        assert_eq!(first[4], "\"z\": 1.0,", "the report's own order is kept");
        let v: Value = serde_json::from_str(&js).unwrap();
        let both = [ReportKind::Fit, ReportKind::Diagnosis];
        assert_eq!(
            check_report(&v, &both, "f.json", "--from").unwrap(),
            ReportKind::Fit
        );
        let e = check_report(&v, &[ReportKind::Design], "f.json", "--x").unwrap_err();
        assert!(e.contains("this is a `fit --json` report"), "{e}");
    }

    #[test]
    fn other_versions_and_unstamped_files_are_refused_with_the_writer() {
        let mut v: Value =
            serde_json::from_str(&to_report_json(ReportKind::Fit, &R { z: 1.0, a: "x" }).unwrap())
                .unwrap();
        v["schema_version"] = 2.into();
        v["written_by"] = "rheometer 9.9.9".into();
        let e = check_report(&v, &[ReportKind::Fit], "f.json", "--from").unwrap_err();
        assert!(
            e.contains("schema_version 2 (written by rheometer 9.9.9)")
                && e.contains("newer")
                && e.contains("re-create it"),
            "{e}"
        );
        let legacy = serde_json::json!({"estimator": "principled", "n": 0.8});
        let e = check_report(&legacy, &[ReportKind::Fit], "f.json", "--from").unwrap_err();
        assert!(e.contains("a fit report without \"schema_version\""), "{e}");
        let e = check_report(
            &Value::Array(vec![]),
            &[ReportKind::Fit],
            "f.json",
            "--from",
        )
        .unwrap_err();
        assert!(e.contains("an array"), "{e}");
    }
}
