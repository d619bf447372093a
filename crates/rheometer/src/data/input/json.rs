//! Reading a JSON report the program wrote (`fit --json`, `diagnose --json`, …) back, bounded
//! and strict: the same file checks as the TOML and CSV readers (regular files only, a size
//! cap checked while reading, the UTF-8 byte-order mark skipped, other encodings and binary
//! data named), `-` for standard input (bounded too), and a parse that names the field of
//! every error (`n.value`), refuses duplicate keys (the last value would silently win) and
//! says what a `NaN`, an `Infinity`, an out-of-range number or a truncated file is.

use super::source::special_kind;
use std::cell::RefCell;
use std::collections::HashSet;
use std::fmt::Write as _;
use std::io::Read;
use std::path::Path;

use serde::de::{self, DeserializeSeed, MapAccess, SeqAccess, Visitor};
use serde_json::{Map, Value};

use super::error::{short, InputError, Location, ShowPath};
use super::options::{show_bytes, Limit};
use super::source::{check_start, check_text};

/// Default cap on a JSON report read back \[bytes\]: 64 MiB (a fit of a thousand experiments
/// with its covariance is under 20 MB). `--allow-large-inputs` lifts it.
pub const DEFAULT_MAX_JSON_BYTES: u64 = 64 << 20;

/// How a report file is read: its cap and the command that re-creates it (for messages).
#[derive(Debug, Clone, Copy)]
pub struct JsonSource<'a> {
    /// Largest file \[bytes\] (see [`DEFAULT_MAX_JSON_BYTES`]).
    pub max_bytes: u64,
    /// What re-creates the file, for messages (`"rheometer fit --json FILE"`).
    pub remedy: &'a str,
}

/// Whether `path` is standard input by name: `-`, `/dev/stdin`, `/dev/fd/N` or
/// `/proc/…/fd/N` (other files under `/dev`, such as `/dev/zero`, are devices and refused).
fn is_stdin_path(path: &Path) -> bool {
    if path == Path::new("-") || path == Path::new("/dev/stdin") {
        return true;
    }
    let Some(parent) = path.parent().and_then(Path::to_str) else {
        return false;
    };
    parent == "/dev/fd" || (parent.starts_with("/proc/") && parent.ends_with("/fd"))
}

fn too_large(path: &Path, max: u64) -> InputError {
    InputError::Limit {
        at: Location {
            path: path.to_path_buf(),
            line: None,
        },
        limit: Limit::JsonBytes,
        message: format!(
            "the report is larger than the limit of {} ({max} bytes); a report of this program \
             is far smaller: is it the right file? If it is, raise the limit `{}`",
            show_bytes(max),
            Limit::JsonBytes.option()
        ),
    }
}

/// The first NUL byte of `bytes` as binary data, unless the bytes look UTF-16 (then the
/// encoding check names the encoding).
fn binary_data(path: &Path, bytes: &[u8], offset: u64) -> Result<(), InputError> {
    let Some(nul) = bytes.iter().position(|&b| b == 0) else {
        return Ok(());
    };
    if offset == 0 && check_text(path, bytes, 0, 1).is_err_and(|e| e.to_string().contains("UTF-16"))
    {
        return check_text(path, bytes, 0, 1);
    }
    Err(InputError::Encoding {
        at: Location {
            path: path.to_path_buf(),
            line: None,
        },
        column: None,
        offset: offset + nul as u64,
        message: format!(
            "byte {} is a NUL byte: the file contains binary data (NUL bytes), not JSON text; \
             give the report a `--json` option wrote",
            offset + nul as u64
        ),
    })
}

/// Reads the bytes of a report file (`-`: standard input), at most `max_bytes`, stopping at
/// the first NUL byte.
fn read_bytes(path: &Path, max_bytes: u64) -> Result<Vec<u8>, InputError> {
    let io = |source: std::io::Error| InputError::Io {
        path: path.to_path_buf(),
        source,
        hint: String::new(),
    };
    let stdin = is_stdin_path(path);
    let mut reader: Box<dyn Read> = if path == Path::new("-") {
        Box::new(std::io::stdin())
    } else {
        let meta = std::fs::metadata(path).map_err(io)?;
        if let Some(kind) = special_kind(&meta).filter(|k| !stdin || *k == "a directory") {
            let hint = if kind == "a directory" {
                "give the report file itself (e.g. fit.json in it)".to_string()
            } else {
                "reports are read only from regular files or standard input (a pipe or device \
                 could block or never end): save the report to a file and give its path, or \
                 pipe it in as `-`"
                    .to_string()
            };
            return Err(InputError::NotRegular {
                path: path.to_path_buf(),
                kind,
                hint,
            });
        }
        if meta.is_file() && meta.len() > max_bytes {
            return Err(too_large(path, max_bytes));
        }
        Box::new(std::fs::File::open(path).map_err(io)?)
    };
    let mut bytes = Vec::new();
    let mut chunk = vec![0u8; 64 << 10];
    loop {
        let n = match reader.read(&mut chunk) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(io(e)),
        };
        let offset = bytes.len() as u64;
        bytes.extend_from_slice(&chunk[..n]);
        if offset == 0 {
            check_start(path, &bytes)?;
        }
        binary_data(path, &bytes[offset as usize..], offset)?;
        if bytes.len() as u64 > max_bytes {
            return Err(too_large(path, max_bytes));
        }
    }
    Ok(bytes)
}

/// Reads a JSON report from `path` (`-`: standard input) under the caps of `source` and
/// parses it strictly ([`parse_json`]).
pub fn read_json(path: &Path, source: JsonSource<'_>) -> Result<Value, InputError> {
    let bytes = read_bytes(path, source.max_bytes)?;
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(&bytes);
    check_text(path, bytes, 0, 1)?;
    let text = std::str::from_utf8(bytes).map_err(|e| InputError::Json {
        at: Location {
            path: path.to_path_buf(),
            line: None,
        },
        column: None,
        message: format!("not UTF-8 text: {e}"),
    })?;
    parse_json(text, path, source.remedy)
}

/// One step of the path to a value: a key or an index.
#[derive(Debug, Clone)]
enum Step {
    Key(String),
    Index(usize),
}

/// The path of a value as a reader writes it: `n.value`, `effects[0].strength`, or
/// `the top level`.
fn show_path(steps: &[Step]) -> String {
    if steps.is_empty() {
        return "the top level".into();
    }
    let mut s = String::new();
    for step in steps {
        match step {
            Step::Key(k) if s.is_empty() => s.push_str(k),
            Step::Key(k) => {
                let _ = write!(s, ".{k}");
            }
            Step::Index(i) => {
                let _ = write!(s, "[{i}]");
            }
        }
    }
    s
}

/// What the parse has seen: the path to the value being read, and a duplicate key if one
/// was found.
#[derive(Default)]
struct Trail {
    steps: Vec<Step>,
    duplicate: Option<String>,
    /// The path of the last value read whole (for an error between values).
    last: Option<String>,
}

/// A [`Value`] read with its path tracked in `trail` (left at the failing value on error).
struct Seed<'t>(&'t RefCell<Trail>);

impl<'de> DeserializeSeed<'de> for Seed<'_> {
    type Value = Value;
    fn deserialize<D: de::Deserializer<'de>>(self, d: D) -> Result<Value, D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> Visitor<'de> for Seed<'_> {
    type Value = Value;

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a JSON value")
    }
    fn visit_bool<E>(self, v: bool) -> Result<Value, E> {
        Ok(Value::Bool(v))
    }
    fn visit_i64<E>(self, v: i64) -> Result<Value, E> {
        Ok(Value::from(v))
    }
    fn visit_u64<E>(self, v: u64) -> Result<Value, E> {
        Ok(Value::from(v))
    }
    fn visit_f64<E>(self, v: f64) -> Result<Value, E> {
        Ok(Value::from(v))
    }
    fn visit_str<E>(self, v: &str) -> Result<Value, E> {
        Ok(Value::String(v.to_string()))
    }
    fn visit_string<E>(self, v: String) -> Result<Value, E> {
        Ok(Value::String(v))
    }
    fn visit_unit<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }
    fn visit_none<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Value, A::Error> {
        let mut out = Vec::new();
        loop {
            self.0.borrow_mut().steps.push(Step::Index(out.len()));
            match seq.next_element_seed(Seed(self.0))? {
                Some(v) => out.push(v),
                None => {
                    self.0.borrow_mut().steps.pop();
                    break;
                }
            }
            self.0.borrow_mut().steps.pop();
        }
        Ok(Value::Array(out))
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Value, A::Error> {
        let mut out = Map::new();
        let mut seen = HashSet::new();
        while let Some(key) = map.next_key::<String>()? {
            if !seen.insert(key.clone()) {
                let mut t = self.0.borrow_mut();
                t.steps.push(Step::Key(key.clone()));
                t.duplicate = Some(key.clone());
                return Err(de::Error::custom(format!("duplicate key \"{key}\"")));
            }
            self.0.borrow_mut().steps.push(Step::Key(key.clone()));
            let v = map.next_value_seed(Seed(self.0))?;
            let mut t = self.0.borrow_mut();
            t.last = Some(show_path(&t.steps));
            t.steps.pop();
            drop(t);
            out.insert(key, v);
        }
        Ok(Value::Object(out))
    }
}

/// The token at 1-based `line` and `column` of `text` (up to a delimiter), for messages.
fn token_at(text: &str, line: usize, column: usize) -> String {
    let Some(l) = text.lines().nth(line.saturating_sub(1)) else {
        return String::new();
    };
    let start = l
        .char_indices()
        .nth(column.saturating_sub(1))
        .map_or(l.len(), |(i, _)| i);
    // serde_json's column may point at the token's last character: back up to its start
    let head = &l[..start];
    let begin = head
        .rfind([',', ':', '[', '{', ' ', '\t'])
        .map_or(0, |i| i + 1);
    let rest = &l[begin..];
    let end = rest
        .find([',', ']', '}', ' ', '\t', '\r'])
        .unwrap_or(rest.len());
    short(&rest[..end], 40)
}

/// Parses `text` (the report `path`) strictly: duplicate keys, `NaN`/`Infinity`, numbers
/// beyond the range of a 64-bit float, truncation and syntax errors are refused with the
/// line, column and path of the field (`n.value`); `remedy` says what re-creates the file.
pub fn parse_json(text: &str, path: &Path, remedy: &str) -> Result<Value, InputError> {
    let at = |line: Option<usize>| Location {
        path: path.to_path_buf(),
        line,
    };
    if text.trim().is_empty() {
        return Err(InputError::Json {
            at: at(None),
            column: None,
            message: format!(
                "the file is empty{}: re-create it with `{remedy}`",
                if text.is_empty() {
                    ""
                } else {
                    " (whitespace only)"
                }
            ),
        });
    }
    let trail = RefCell::new(Trail::default());
    let mut de = serde_json::Deserializer::from_str(text);
    let result = Seed(&trail)
        .deserialize(&mut de)
        .and_then(|v| de.end().map(|()| v));
    let e = match result {
        Ok(v) => return Ok(v),
        Err(e) => e,
    };
    let trail = trail.into_inner();
    let field = show_path(&trail.steps);
    let (line, column) = (e.line(), e.column());
    let token = token_at(text, line, column);
    let message = failure_message(text, &e, &trail, &field, &token, remedy);
    Err(InputError::Json {
        at: at(Some(line)),
        column: Some(column),
        message,
    })
}

/// The words of a failed parse `e` of `text`: a duplicate key, a truncated file, NaN or
/// Infinity, a number out of range, text that is no JSON, a second report, or malformed JSON
/// in `field` (the path `trail` reached; `token` the text at the error).
fn failure_message(
    text: &str,
    e: &serde_json::Error,
    trail: &Trail,
    field: &str,
    token: &str,
    remedy: &str,
) -> String {
    if let Some(key) = &trail.duplicate {
        format!(
            "`{field}`: the key \"{key}\" appears twice in its object; JSON readers differ on \
             which value counts, so neither is used: keep one"
        )
    } else if e.is_eof() {
        format!("the file ends early (truncated?) inside `{field}`: re-create it with `{remedy}`")
    } else if ["NaN", "-NaN", "Infinity", "-Infinity", "nan", "inf", "-inf"]
        .iter()
        .any(|t| token.starts_with(t))
    {
        format!(
            "`{field}` = {token}: JSON has no NaN or Infinity (this program writes a value it \
             could not compute as null); re-create the file with `{remedy}`"
        )
    } else if e.to_string().starts_with("number out of range") {
        format!(
            "`{field}` = {token}: the number is out of the range of a 64-bit float (about \
             ±1.8e308)"
        )
    } else if trail.steps.is_empty() && {
        let t = text.trim_start();
        !(t.starts_with(['{', '[', '"', '-'])
            || t.starts_with(|c: char| c.is_ascii_digit())
            || ["true", "false", "null"].iter().any(|w| t.starts_with(w)))
    } {
        format!(
            "not valid JSON, so no report of this program (it starts `{}`); give the file \
             `{remedy}` wrote",
            short(text.trim_start().lines().next().unwrap_or(""), 40)
        )
    } else if e.is_syntax() && trail.steps.is_empty() && de_trailing(text) {
        format!(
            "there is text after the report's closing brace (two reports in one file?): keep \
             one; {e}"
        )
    } else {
        let msg = e.to_string();
        let msg = msg
            .rsplit_once(" at line ")
            .map_or(msg.as_str(), |(head, _)| head);
        match &trail.last {
            Some(last) => format!("malformed JSON in `{field}` after `{last}`: {msg}"),
            None => format!("malformed JSON in `{field}`: {msg}"),
        }
    }
}

/// Whether `text` holds a complete JSON value followed by more text.
fn de_trailing(text: &str) -> bool {
    let mut it = serde_json::Deserializer::from_str(text).into_iter::<de::IgnoredAny>();
    matches!(it.next(), Some(Ok(_))) && it.next().is_some()
}

/// Shows `path` for messages (`-` as standard input).
pub fn show_json_path(path: &Path) -> String {
    if path == Path::new("-") {
        "- (standard input)".into()
    } else {
        ShowPath(path).to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        parse_json(text, Path::new("f.json"), "rheometer fit --json f.json")
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn errors_name_the_field() {
        let e = err(r#"{"n": {"value": NaN}}"#);
        assert!(e.contains("`n.value` = NaN") && e.contains("no NaN"), "{e}");
        let e = err(r#"{"a": [1, 2, {"b": -Infinity}]}"#);
        assert!(e.contains("`a[2].b` = -Infinity"), "{e}");
        let e = err(r#"{"n": {"value": 1e400}}"#);
        assert!(
            e.contains("`n.value` = 1e400") && e.contains("range"),
            "{e}"
        );
        let e = err(r#"{"n": 1, "n": 2}"#);
        assert!(e.contains("\"n\" appears twice"), "{e}");
        let e = err(r#"{"x": {"n": 1, "k": [1, {"n": 2, "n": 3}]}}"#);
        assert!(e.contains("`x.k[1].n`") && e.contains("twice"), "{e}");
        let e = err(r#"{"n": {"value": 0.8"#);
        assert!(e.contains("truncated") && e.contains("`n"), "{e}");
        let e = err("  \n");
        assert!(e.contains("empty (whitespace only)"), "{e}");
        let e = err(r#"{"a": 1, "n": 1e300{"value": 1}}"#);
        assert!(e.contains("in `the top level` after `n`"), "{e}");
        let e = err("this is the report text\n");
        assert!(
            e.contains("not valid JSON") && e.contains("`this is the report text`"),
            "{e}"
        );
        let e = err(r#"{"a": 1}{"a": 1}"#);
        assert!(e.contains("after the report"), "{e}");
        // the same keys in different objects are fine
        let v = parse_json(r#"{"a": {"n": 1}, "b": {"n": 2}}"#, Path::new("f.json"), "").unwrap();
        assert_eq!(v["b"]["n"], 2);
    }

    #[test]
    fn stdin_names() {
        assert!(is_stdin_path(Path::new("-")));
        assert!(is_stdin_path(Path::new("/dev/stdin")));
        assert!(is_stdin_path(Path::new("/dev/fd/0")));
        assert!(!is_stdin_path(Path::new("/dev/zero")));
        assert!(!is_stdin_path(Path::new("fit.json")));
    }
}
