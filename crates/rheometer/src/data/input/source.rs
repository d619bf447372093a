//! Opening and reading input files, bounded: only regular files are opened (a FIFO, device,
//! socket or directory is refused from its metadata, before `open` could block), every read is
//! capped, and the bytes are checked for UTF-8 as they arrive, with the byte offset, line and
//! a guess at the encoding when they are not (UTF-16, Latin-1, binary data, a spreadsheet).

use std::fs::File;
use std::io::{BufRead, BufReader, Read, Take};
use std::path::{Path, PathBuf};

use super::error::{short, InputError, Location, ShowPath};
use super::options::{show_bytes, Limit};

/// Whether `path` names the process's standard input or one of its open descriptors
/// (`/dev/stdin`, `/dev/fd/0`, `/proc/self/fd/3`): such a file has no folder of its own.
pub(super) fn is_stdin_like(path: &Path) -> bool {
    let Some(parent) = path.parent().and_then(Path::to_str) else {
        return false;
    };
    parent == "/dev"
        || parent == "/dev/fd"
        || (parent.starts_with("/proc/") && parent.ends_with("/fd"))
}

/// What kind of non-regular file `meta` describes, if it is not a regular file (the words
/// every file input's refusal uses).
pub(super) fn special_kind(meta: &std::fs::Metadata) -> Option<&'static str> {
    let t = meta.file_type();
    if t.is_file() {
        return None;
    }
    if t.is_dir() {
        return Some("a directory");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return Some("a FIFO (named pipe)");
        }
        if t.is_char_device() {
            return Some("a character device");
        }
        if t.is_block_device() {
            return Some("a block device");
        }
        if t.is_socket() {
            return Some("a socket");
        }
    }
    Some("a special file")
}

/// The error of a failed `metadata`/`open`, with a hint for a name with stray spaces.
fn io_error(path: &Path, source: std::io::Error) -> InputError {
    let mut hint = String::new();
    if source.kind() == std::io::ErrorKind::NotFound {
        if let Some(name) = path.file_name().and_then(|n| n.to_str()) {
            let trimmed = name.trim();
            if trimmed != name {
                let candidate = path.with_file_name(trimmed);
                let exists = candidate.is_file();
                hint = format!(
                    "; the file name {name:?} has leading or trailing spaces{}",
                    if exists {
                        format!(" and {trimmed:?} exists: remove the spaces")
                    } else {
                        String::new()
                    }
                );
            }
        }
    }
    InputError::Io {
        path: path.to_path_buf(),
        source,
        hint,
    }
}

/// Opens `path` for reading if it is a regular file (or, when `stdin_ok`, standard input);
/// returns the file and its size (0 for standard input).
fn open_regular(path: &Path, stdin_ok: bool, what: &str) -> Result<(File, u64), InputError> {
    let meta = std::fs::metadata(path).map_err(|e| io_error(path, e))?;
    if let Some(kind) = special_kind(&meta) {
        let piped_stdin = stdin_ok && is_stdin_like(path) && !meta.is_dir();
        if !piped_stdin {
            let hint = match kind {
                "a directory" => format!("give the {what} itself"),
                _ => format!(
                    "{what}s are read only from regular files (a pipe or device could block or \
                     never end): save the data to a file and give its path"
                ),
            };
            return Err(InputError::NotRegular {
                path: path.to_path_buf(),
                kind,
                hint,
            });
        }
    }
    let size = if meta.is_file() { meta.len() } else { 0 };
    let file = File::open(path).map_err(|e| io_error(path, e))?;
    Ok((file, size))
}

fn too_large(path: &Path, line: Option<usize>, limit: Limit, max: u64, what: &str) -> InputError {
    InputError::Limit {
        at: Location {
            path: path.to_path_buf(),
            line,
        },
        limit,
        message: format!(
            "{what} is larger than the limit of {} ({max} bytes); if it really is the input, \
             raise the limit `{}`",
            show_bytes(max),
            limit.option()
        ),
    }
}

/// Reads the whole experiments file (a regular file or standard input), at most `max_bytes`,
/// as UTF-8 text without a byte-order mark.
pub(super) fn read_toml(path: &Path, max_bytes: u64) -> Result<String, InputError> {
    let (file, size) = open_regular(path, true, "experiments file")?;
    if size > max_bytes {
        return Err(too_large(
            path,
            None,
            Limit::TomlBytes,
            max_bytes,
            "the experiments file",
        ));
    }
    let mut bytes = Vec::new();
    file.take(max_bytes.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| io_error(path, e))?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_large(
            path,
            None,
            Limit::TomlBytes,
            max_bytes,
            "the experiments file",
        ));
    }
    check_start(path, &bytes)?;
    let bytes = bytes
        .strip_prefix(b"\xEF\xBB\xBF")
        .map(<[u8]>::to_vec)
        .unwrap_or(bytes);
    check_text(path, &bytes, 0, 1)?;
    String::from_utf8(bytes).map_err(|e| {
        // unreachable after `check_text`, kept as an error rather than a panic
        encoding_error(path, e.as_bytes(), 0, 1, e.utf8_error().valid_up_to())
    })
}

/// Refuses byte-order marks of UTF-16/UTF-32 and the signatures of spreadsheets.
pub(super) fn check_start(path: &Path, bytes: &[u8]) -> Result<(), InputError> {
    let encoding = if bytes.starts_with(b"\xFF\xFE\0\0") || bytes.starts_with(b"\0\0\xFE\xFF") {
        Some("UTF-32")
    } else if bytes.starts_with(b"\xFF\xFE") || bytes.starts_with(b"\xFE\xFF") {
        Some("UTF-16")
    } else {
        None
    };
    let message = if let Some(encoding) = encoding {
        format!(
            "the file is {encoding} encoded (it starts with the byte-order mark {}); re-save it \
             as UTF-8 (in Excel: Save As \u{203a} \"CSV UTF-8\"; in Notepad or another editor: \
             encoding UTF-8)",
            bytes
                .iter()
                .take(if encoding == "UTF-32" { 4 } else { 2 })
                .map(|b| format!("{b:02X}"))
                .collect::<Vec<_>>()
                .join(" ")
        )
    } else if bytes.starts_with(b"PK\x03\x04") {
        "the file is a ZIP archive (an Excel .xlsx or OpenDocument .ods workbook?), not text; \
         export the sheet as CSV UTF-8 (File \u{203a} Save As \u{203a} \"CSV UTF-8\")"
            .to_string()
    } else if bytes.starts_with(b"\xD0\xCF\x11\xE0") {
        "the file is an old Excel .xls workbook, not text; export the sheet as CSV UTF-8 \
         (File \u{203a} Save As \u{203a} \"CSV UTF-8\")"
            .to_string()
    } else if bytes.starts_with(b"%PDF") {
        "the file is a PDF document, not text".to_string()
    } else {
        return Ok(());
    };
    Err(InputError::Encoding {
        at: Location {
            path: path.to_path_buf(),
            line: Some(1),
        },
        column: None,
        offset: 0,
        message,
    })
}

/// Checks that `bytes` (starting at byte `offset` and line `line` of the file) are UTF-8 text
/// without NUL bytes.
pub(super) fn check_text(
    path: &Path,
    bytes: &[u8],
    offset: u64,
    line: usize,
) -> Result<(), InputError> {
    if let Some(nul) = bytes.iter().position(|&b| b == 0) {
        return Err(encoding_error(path, bytes, offset, line, nul));
    }
    match std::str::from_utf8(bytes) {
        Ok(_) => Ok(()),
        Err(e) => Err(encoding_error(path, bytes, offset, line, e.valid_up_to())),
    }
}

/// Whether `window` looks like binary data rather than text in another encoding: control
/// bytes other than tab, line feed and carriage return, or several NUL bytes not in the
/// alternating pattern of UTF-16.
fn looks_binary(window: &[u8]) -> bool {
    let controls = window
        .iter()
        .filter(|&&b| b < 0x20 && !matches!(b, b'\t' | b'\n' | b'\r' | 0))
        .count();
    controls >= 2
}

/// Whether `window` looks like UTF-16 without a byte-order mark: NUL bytes at every other
/// position, ASCII in between.
fn looks_utf16(window: &[u8]) -> bool {
    let n = window.len().min(64) & !1;
    if n < 8 {
        return false;
    }
    let w = &window[..n];
    let even_nul = w.iter().step_by(2).filter(|&&b| b == 0).count();
    let odd_nul = w.iter().skip(1).step_by(2).filter(|&&b| b == 0).count();
    let half = n / 2;
    (even_nul * 10 >= half * 8 && odd_nul == 0) || (odd_nul * 10 >= half * 8 && even_nul == 0)
}

/// The [`InputError::Encoding`] of the offending byte at index `bad` of `bytes` (which start
/// at byte `offset` and line `line` of the file).
fn encoding_error(path: &Path, bytes: &[u8], offset: u64, line: usize, bad: usize) -> InputError {
    let before = &bytes[..bad];
    let line = line + before.iter().filter(|&&b| b == b'\n').count();
    let line_start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |p| p + 1);
    let column = String::from_utf8_lossy(&before[line_start..])
        .chars()
        .count()
        + 1;
    let byte = bytes.get(bad).copied().unwrap_or(0);
    let window = &bytes[bad.saturating_sub(128)..(bad + 128).min(bytes.len())];
    let at_byte = format!("byte {} (0x{byte:02X})", offset + bad as u64);
    let resave = "re-save it as UTF-8 (in Excel: Save As \u{203a} \"CSV UTF-8\"; in an editor: \
                  encoding UTF-8)";
    let message = if byte == 0 && looks_utf16(&bytes[bad.saturating_sub(1) & !1..]) {
        format!(
            "{at_byte} is a NUL byte: the file looks UTF-16 encoded (without a byte-order \
             mark); {resave}"
        )
    } else if byte == 0 || looks_binary(window) {
        format!(
            "{at_byte}: the file contains binary data (NUL or control bytes), not text; give \
             the text file (CSV or TOML) instead"
        )
    } else {
        let next = bytes.get(bad + 1).copied();
        let single = byte >= 0x80 && next.is_none_or(|b| !(0x80..0xC0).contains(&b));
        if single && byte >= 0xA0 {
            format!(
                "{at_byte} is not valid UTF-8; the file looks Latin-1 or Windows-1252 encoded, \
                 where 0x{byte:02X} is '{}'; {resave}",
                char::from(byte)
            )
        } else if single {
            format!(
                "{at_byte} is not valid UTF-8; the file looks Windows-1252 encoded (0x80 to \
                 0x9F are typographic characters there); {resave}"
            )
        } else {
            format!("{at_byte} is not valid UTF-8; {resave}")
        }
    };
    InputError::Encoding {
        at: Location {
            path: path.to_path_buf(),
            line: Some(line),
        },
        column: Some(column),
        offset: offset + bad as u64,
        message,
    }
}

/// The lines of a measurement file, read one at a time: a regular file only, at most
/// `max_bytes` in all and `max_line` per line, each line checked for UTF-8. Lines end at
/// `\n`, `\r\n` or a lone `\r`.
pub(super) struct Lines {
    path: PathBuf,
    reader: BufReader<Take<File>>,
    max_bytes: u64,
    max_line: usize,
    /// Bytes consumed so far.
    offset: u64,
    /// 1-based number of the next line.
    next_line: usize,
    buf: Vec<u8>,
    /// The previous line ended with `\r` (a following `\n` belongs to it).
    after_cr: bool,
}

impl Lines {
    /// Opens `path` (a regular file only).
    pub(super) fn open(path: &Path, max_bytes: u64, max_line: usize) -> Result<Self, InputError> {
        let (file, size) = open_regular(path, false, "measurement file")?;
        if size > max_bytes {
            return Err(too_large(
                path,
                None,
                Limit::CsvBytes,
                max_bytes,
                "the measurement file",
            ));
        }
        Ok(Lines {
            path: path.to_path_buf(),
            reader: BufReader::with_capacity(64 << 10, file.take(max_bytes.saturating_add(1))),
            max_bytes,
            max_line,
            offset: 0,
            next_line: 1,
            buf: Vec::new(),
            after_cr: false,
        })
    }

    /// The next line (its 1-based number and text without the terminator), or `None` at the
    /// end of the file.
    pub(super) fn next_line(&mut self) -> Result<Option<(usize, &str)>, InputError> {
        self.buf.clear();
        let start = self.offset;
        let mut ended = false;
        loop {
            let chunk = self
                .reader
                .fill_buf()
                .map_err(|e| io_error(&self.path, e))?;
            if chunk.is_empty() {
                break;
            }
            let mut skip = 0;
            if self.after_cr && self.buf.is_empty() && chunk[0] == b'\n' {
                skip = 1;
            }
            self.after_cr = false;
            let rest = &chunk[skip..];
            let end = rest.iter().position(|&b| b == b'\n' || b == b'\r');
            let take = end.unwrap_or(rest.len());
            let room = self.max_line.saturating_sub(self.buf.len());
            if take > room {
                let mut head = self.buf[..self.buf.len().min(200)].to_vec();
                head.extend_from_slice(&rest[..take.min(200)]);
                let head = String::from_utf8_lossy(&head).to_string();
                return Err(InputError::Limit {
                    at: Location {
                        path: self.path.clone(),
                        line: Some(self.next_line),
                    },
                    limit: Limit::LineBytes,
                    message: format!(
                        "line {} is longer than {} (it starts `{}`): not a measurement row; \
                         if such lines are intended, raise the limit `{}`",
                        self.next_line,
                        show_bytes(self.max_line as u64),
                        short(&head, 60),
                        Limit::LineBytes.option()
                    ),
                });
            }
            self.buf.extend_from_slice(&rest[..take]);
            let consumed = skip + take + usize::from(end.is_some());
            if let Some(e) = end {
                self.after_cr = rest[e] == b'\r';
                ended = true;
            }
            self.reader.consume(consumed);
            self.offset += consumed as u64;
            if self.offset > self.max_bytes {
                return Err(too_large(
                    &self.path,
                    Some(self.next_line),
                    Limit::CsvBytes,
                    self.max_bytes,
                    "the measurement file",
                ));
            }
            if ended {
                break;
            }
        }
        if !ended && self.buf.is_empty() {
            return Ok(None);
        }
        let line = self.next_line;
        self.next_line += 1;
        if line == 1 {
            check_start(&self.path, &self.buf)?;
            if self.buf.starts_with(b"\xEF\xBB\xBF") {
                self.buf.drain(..3);
            }
        }
        check_text(&self.path, &self.buf, start, line)?;
        match std::str::from_utf8(&self.buf) {
            Ok(text) => Ok(Some((line, text))),
            Err(e) => Err(encoding_error(
                &self.path,
                &self.buf,
                start,
                line,
                e.valid_up_to(),
            )),
        }
    }
}

/// The lines of a text, split as [`Lines`] splits a file (`\n`, `\r\n`, lone `\r`), numbered
/// from 1.
pub(super) fn text_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut rest = text;
    let mut line = 0;
    std::iter::from_fn(move || {
        if rest.is_empty() {
            return None;
        }
        line += 1;
        match rest.find(['\n', '\r']) {
            Some(i) => {
                let out = &rest[..i];
                let skip = if rest[i..].starts_with("\r\n") { 2 } else { 1 };
                rest = &rest[i + skip..];
                Some((line, out))
            }
            None => {
                let out = rest;
                rest = "";
                Some((line, out))
            }
        }
    })
}

/// Shows `path` for messages (quoted when it has stray spaces).
pub(super) fn show(path: &Path) -> String {
    ShowPath(path).to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_lines_split_every_terminator() {
        let v: Vec<_> = text_lines("a\r\nb\rc\nd").collect();
        assert_eq!(v, vec![(1, "a"), (2, "b"), (3, "c"), (4, "d")]);
        let v: Vec<_> = text_lines("a\n\nb\n").collect();
        assert_eq!(v, vec![(1, "a"), (2, ""), (3, "b")]);
    }

    #[test]
    fn stdin_like_paths() {
        assert!(is_stdin_like(Path::new("/dev/stdin")));
        assert!(is_stdin_like(Path::new("/dev/fd/0")));
        assert!(is_stdin_like(Path::new("/proc/self/fd/3")));
        assert!(!is_stdin_like(Path::new("/home/x/experiments.toml")));
        assert!(!is_stdin_like(Path::new("experiments.toml")));
    }

    #[test]
    fn encodings_are_named() {
        let p = Path::new("x.csv");
        let latin1 = b"position_m,diameter_m\n# temp\xe9rature\n";
        let e = check_text(p, latin1, 0, 1).unwrap_err().to_string();
        assert!(
            e.starts_with("x.csv:2:7: byte 28 (0xE9)") && e.contains("'\u{e9}'"),
            "{e}"
        );
        assert!(e.contains("UTF-8"), "{e}");
        let utf16: Vec<u8> = "position_m,diameter_m\n"
            .encode_utf16()
            .flat_map(u16::to_le_bytes)
            .collect();
        let e = check_text(p, &utf16, 0, 1).unwrap_err().to_string();
        assert!(e.contains("UTF-16"), "{e}");
        let random = [0x41, 0x9F, 0x02, 0x03, 0xF0, 0x05, 0x41, 0x06];
        let e = check_text(p, &random, 0, 1).unwrap_err().to_string();
        assert!(e.contains("binary"), "{e}");
        let e = check_start(p, b"\xFF\xFEp\0").unwrap_err().to_string();
        assert!(e.contains("UTF-16") && e.contains("FF FE"), "{e}");
        let e = check_start(p, b"PK\x03\x04rest").unwrap_err().to_string();
        assert!(e.contains("xlsx"), "{e}");
    }
}
