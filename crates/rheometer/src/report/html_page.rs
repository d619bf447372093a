//! A self-contained HTML page: a title, a verdict box, sections with paragraphs, tables,
//! preformatted text, warning lists and figures embedded inline as SVG ([`HtmlPage`]).
//!
//! The page is one file that loads nothing: no external style sheet, font, script or image
//! (a `Content-Security-Policy` meta element forbids them, so a page viewed in a browser
//! cannot reach the network even through an embedded figure). It reads offline, prints
//! cleanly (a print style sheet keeps figures and tables whole and drops the contents list),
//! and every piece of text given to the builder is escaped (`&`, `<`, `>`, `"`, `'`), so a
//! name such as `<script>` shows as text. Embedded SVG is checked: scripts, event handlers,
//! links, external references and `foreignObject` are refused ([`HtmlError::UnsafeSvg`]).
//!
//! The module is generic: it knows sections, tables, paragraphs, warnings and figures, not
//! what they report.
//!
//! # Example
//!
//! ```
//! use rheometer::report::html_page::{HtmlPage, Table, Tone};
//!
//! let mut page = HtmlPage::new("Fit of <my> data & co");
//! page.verdict(Tone::Good, "The model fits", "RMS residual 0.61 %, as the noise.");
//! page.section("Parameters");
//! page.table(
//!     Table::new(&["parameter", "value", "unit"])
//!         .row(&["n", "0.804 ± 0.007", "–"])
//!         .numeric(1),
//! );
//! page.warnings(&["one thing to check"]);
//! let html = page.render();
//! assert!(html.contains("Fit of &lt;my&gt; data &amp; co"));
//! assert!(!html.contains("<my>"));
//! ```

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::report::output_files::{write_bytes, OutputError};

/// Why a page could not be built or written.
#[derive(Debug, Error)]
pub enum HtmlError {
    /// An SVG figure contains something that could run code or load a resource.
    #[error("figure {caption:?} cannot be embedded: {reason}")]
    UnsafeSvg {
        /// The figure's caption.
        caption: String,
        /// What was found.
        reason: String,
    },
    /// The output path is an existing directory.
    #[error("cannot write HTML page {path}: the path is an existing directory")]
    IsADirectory {
        /// The requested output path.
        path: PathBuf,
    },
    /// The output layer refused the path or failed to write it.
    #[error("cannot write HTML page {path}: {source}")]
    Output {
        /// The requested output path.
        path: PathBuf,
        /// What went wrong.
        #[source]
        source: Box<OutputError>,
    },
    /// Creating a parent directory or writing the file failed.
    #[error("cannot write HTML page {path}: {source}")]
    Io {
        /// The requested output path.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
}

/// The tone of the verdict box (its colour and the word before its headline).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tone {
    /// The result can be used (green).
    Good,
    /// The result holds with reservations (amber).
    Caution,
    /// The result should not be used (red).
    Bad,
    /// Neutral information (blue).
    Info,
}

impl Tone {
    fn class(self) -> &'static str {
        match self {
            Tone::Good => "good",
            Tone::Caution => "caution",
            Tone::Bad => "bad",
            Tone::Info => "info",
        }
    }
}

/// A table: a header row, body rows of text, an optional caption, and the columns to align
/// right (numbers).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Table {
    /// Caption above the table (empty: none).
    pub caption: String,
    /// Column headings.
    pub header: Vec<String>,
    /// Body rows; a short row is padded with empty cells, a long one keeps its extra cells.
    pub rows: Vec<Vec<String>>,
    /// Indices of right-aligned (numeric) columns.
    pub numeric_columns: Vec<usize>,
}

impl Table {
    /// A table with the given column headings and no rows.
    pub fn new<S: AsRef<str>>(header: &[S]) -> Self {
        Self {
            header: header.iter().map(|s| s.as_ref().to_string()).collect(),
            ..Self::default()
        }
    }

    /// Adds a body row.
    pub fn row<S: AsRef<str>>(mut self, cells: &[S]) -> Self {
        self.rows
            .push(cells.iter().map(|s| s.as_ref().to_string()).collect());
        self
    }

    /// Aligns column `index` right (for numbers).
    pub fn numeric(mut self, index: usize) -> Self {
        self.numeric_columns.push(index);
        self
    }

    /// Sets the caption.
    pub fn with_caption(mut self, caption: impl Into<String>) -> Self {
        self.caption = caption.into();
        self
    }
}

/// One piece of page content.
#[derive(Debug, Clone, PartialEq)]
enum Block {
    Section { id: usize, heading: String },
    Subsection(String),
    Paragraph(String),
    Preformatted(String),
    Table(Table),
    Warnings { heading: String, items: Vec<String> },
    Figure { caption: String, svg: String },
}

/// A self-contained HTML page, built in order: [`verdict`](Self::verdict) (at most one,
/// shown under the title), then [`section`](Self::section)s and their content. Render with
/// [`render`](Self::render) or write with [`write`](Self::write).
#[derive(Debug, Clone, PartialEq)]
pub struct HtmlPage {
    title: String,
    subtitle: String,
    verdict: Option<(Tone, String, String)>,
    blocks: Vec<Block>,
    sections: usize,
}

impl HtmlPage {
    /// An empty page with a title (also the document's `<title>`).
    pub fn new(title: impl Into<String>) -> Self {
        Self {
            title: title.into(),
            subtitle: String::new(),
            verdict: None,
            blocks: Vec::new(),
            sections: 0,
        }
    }

    /// A line under the title (e.g. what produced the page, from which inputs).
    pub fn subtitle(&mut self, text: impl Into<String>) -> &mut Self {
        self.subtitle = text.into();
        self
    }

    /// The verdict box under the title: a headline and details (replaces an earlier one).
    pub fn verdict(
        &mut self,
        tone: Tone,
        headline: impl Into<String>,
        details: impl Into<String>,
    ) -> &mut Self {
        self.verdict = Some((tone, headline.into(), details.into()));
        self
    }

    /// Starts a section (listed in the contents at the top).
    pub fn section(&mut self, heading: impl Into<String>) -> &mut Self {
        self.sections += 1;
        self.blocks.push(Block::Section {
            id: self.sections,
            heading: heading.into(),
        });
        self
    }

    /// A heading inside the current section.
    pub fn subsection(&mut self, heading: impl Into<String>) -> &mut Self {
        self.blocks.push(Block::Subsection(heading.into()));
        self
    }

    /// A paragraph of text (line breaks in `text` are kept).
    pub fn paragraph(&mut self, text: impl Into<String>) -> &mut Self {
        self.blocks.push(Block::Paragraph(text.into()));
        self
    }

    /// Preformatted text in a monospace font (a text report, a command line).
    pub fn preformatted(&mut self, text: impl Into<String>) -> &mut Self {
        self.blocks.push(Block::Preformatted(text.into()));
        self
    }

    /// A table.
    pub fn table(&mut self, table: Table) -> &mut Self {
        self.blocks.push(Block::Table(table));
        self
    }

    /// A list of warnings headed "Warnings (N)"; nothing if `items` is empty.
    pub fn warnings<S: AsRef<str>>(&mut self, items: &[S]) -> &mut Self {
        if !items.is_empty() {
            let items: Vec<String> = items.iter().map(|s| s.as_ref().to_string()).collect();
            self.blocks.push(Block::Warnings {
                heading: format!("Warnings ({})", items.len()),
                items,
            });
        }
        self
    }

    /// A figure given as an SVG document (e.g. from [`crate::report::plot::panels_svg`]), embedded
    /// inline and scaled to the page width, with a caption.
    ///
    /// Refused ([`HtmlError::UnsafeSvg`]) if it is not an `<svg>` element or contains a
    /// script, an event handler, a link or external reference (`href`, `url(`, `@import`),
    /// or a `foreignObject`.
    pub fn figure_svg(
        &mut self,
        caption: impl Into<String>,
        svg: &str,
    ) -> Result<&mut Self, HtmlError> {
        let caption = caption.into();
        let svg = checked_svg(&caption, svg)?;
        self.blocks.push(Block::Figure { caption, svg });
        Ok(self)
    }

    /// The page as one HTML document.
    pub fn render(&self) -> String {
        let mut h = String::with_capacity(16_384);
        h.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
        h.push_str(
            "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; \
             style-src 'unsafe-inline'; img-src data:\">\n",
        );
        h.push_str("<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n");
        let _ = writeln!(h, "<title>{}</title>", escape(&self.title));
        let _ = writeln!(h, "<style>\n{STYLE}</style>\n</head>\n<body>\n<main>");
        let _ = writeln!(h, "<h1>{}</h1>", escape(&self.title));
        if !self.subtitle.is_empty() {
            let _ = writeln!(h, "<p class=\"subtitle\">{}</p>", escape(&self.subtitle));
        }
        if let Some((tone, headline, details)) = &self.verdict {
            let _ = writeln!(
                h,
                "<div class=\"verdict {}\" role=\"status\"><p class=\"headline\">{}</p>",
                tone.class(),
                escape(headline)
            );
            if !details.is_empty() {
                let _ = writeln!(h, "<p>{}</p>", escape_lines(details));
            }
            h.push_str("</div>\n");
        }
        self.render_contents(&mut h);
        self.render_blocks(&mut h);
        h.push_str("</main>\n</body>\n</html>\n");
        h
    }

    /// The list of sections (with two or more sections).
    fn render_contents(&self, h: &mut String) {
        if self.sections < 2 {
            return;
        }
        h.push_str("<nav class=\"contents\"><p>Contents</p><ol>\n");
        for b in &self.blocks {
            if let Block::Section { id, heading } = b {
                let _ = writeln!(h, "<li><a href=\"#s{id}\">{}</a></li>", escape(heading));
            }
        }
        h.push_str("</ol></nav>\n");
    }

    fn render_blocks(&self, h: &mut String) {
        let mut open = false;
        let mut figures = 0;
        for b in &self.blocks {
            match b {
                Block::Section { id, heading } => {
                    if open {
                        h.push_str("</section>\n");
                    }
                    open = true;
                    let _ = writeln!(h, "<section id=\"s{id}\">\n<h2>{}</h2>", escape(heading));
                }
                Block::Subsection(t) => {
                    let _ = writeln!(h, "<h3>{}</h3>", escape(t));
                }
                Block::Paragraph(t) => {
                    let _ = writeln!(h, "<p>{}</p>", escape_lines(t));
                }
                Block::Preformatted(t) => {
                    let _ = writeln!(h, "<pre>{}</pre>", escape(t));
                }
                Block::Table(t) => render_table(h, t),
                Block::Warnings { heading, items } => {
                    let _ = writeln!(
                        h,
                        "<div class=\"warnings\" role=\"note\"><p class=\"headline\">{}</p><ul>",
                        escape(heading)
                    );
                    for w in items {
                        let _ = writeln!(h, "<li>{}</li>", escape_lines(w));
                    }
                    h.push_str("</ul></div>\n");
                }
                Block::Figure { caption, svg } => {
                    figures += 1;
                    let _ = writeln!(
                        h,
                        "<figure>\n{svg}\n<figcaption>Figure {figures}. {}</figcaption>\n</figure>",
                        escape(caption)
                    );
                }
            }
        }
        if open {
            h.push_str("</section>\n");
        }
    }

    /// Writes the page to `path` atomically (a temporary sibling renamed into place, so a
    /// failed write leaves no half-written page and an existing file is replaced whole),
    /// creating missing parent directories.
    pub fn write(&self, path: &Path) -> Result<(), HtmlError> {
        if path.is_dir() {
            return Err(HtmlError::IsADirectory {
                path: path.to_path_buf(),
            });
        }
        // through the output layer: a temporary renamed into place (missing directories
        // created), a special file written in place
        let html = self.render();
        write_bytes(path, &[], html.as_bytes()).map_err(|source| HtmlError::Output {
            path: path.to_path_buf(),
            source: Box::new(source),
        })
    }
}

fn render_table(h: &mut String, t: &Table) {
    h.push_str("<div class=\"table\"><table>\n");
    if !t.caption.is_empty() {
        let _ = writeln!(h, "<caption>{}</caption>", escape(&t.caption));
    }
    let class = |k: usize| {
        if t.numeric_columns.contains(&k) {
            " class=\"num\""
        } else {
            ""
        }
    };
    if !t.header.is_empty() {
        h.push_str("<thead><tr>");
        for (k, c) in t.header.iter().enumerate() {
            let _ = write!(h, "<th scope=\"col\"{}>{}</th>", class(k), escape(c));
        }
        h.push_str("</tr></thead>\n");
    }
    h.push_str("<tbody>\n");
    for row in &t.rows {
        h.push_str("<tr>");
        let width = row.len().max(t.header.len());
        for k in 0..width {
            let cell = row.get(k).map_or("", String::as_str);
            let _ = write!(h, "<td{}>{}</td>", class(k), escape(cell));
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</tbody></table></div>\n");
}

/// `text` with `&`, `<`, `>`, `"` and `'` replaced by character references, and control
/// characters other than tab and line breaks dropped (they are not allowed in HTML).
pub(crate) fn escape(text: &str) -> String {
    let mut s = String::with_capacity(text.len() + 16);
    for c in text.chars() {
        match c {
            '&' => s.push_str("&amp;"),
            '<' => s.push_str("&lt;"),
            '>' => s.push_str("&gt;"),
            '"' => s.push_str("&quot;"),
            '\'' => s.push_str("&#39;"),
            '\t' | '\n' | '\r' => s.push(c),
            c if c.is_control() => {}
            c => s.push(c),
        }
    }
    s
}

/// [`escape`]d text with line breaks as `<br>`.
fn escape_lines(text: &str) -> String {
    escape(text.trim_end()).replace('\n', "<br>\n")
}

/// The SVG element of `svg` (an XML declaration or doctype before it dropped, the `xmlns`
/// declaration dropped as HTML does not need it), or why it cannot be embedded.
fn checked_svg(caption: &str, svg: &str) -> Result<String, HtmlError> {
    let refuse = |reason: &str| HtmlError::UnsafeSvg {
        caption: caption.to_string(),
        reason: reason.to_string(),
    };
    let start = svg.find("<svg").ok_or_else(|| refuse("no <svg> element"))?;
    let body = svg[start..].trim_end();
    if !body.ends_with("</svg>") {
        return Err(refuse("the <svg> element is not closed at the end"));
    }
    let lower = body.to_ascii_lowercase();
    for (needle, what) in [
        ("<script", "a script"),
        ("<foreignobject", "a foreignObject"),
        ("href", "a link or external reference (href)"),
        ("url(", "an external reference (url())"),
        ("@import", "a style import"),
        ("javascript:", "a javascript: URL"),
        ("<!entity", "an entity declaration"),
    ] {
        if lower.contains(needle) {
            return Err(refuse(&format!("it contains {what}")));
        }
    }
    if has_event_handler(&lower) {
        return Err(refuse("it contains an event-handler attribute (on…=)"));
    }
    Ok(body.replacen(" xmlns=\"http://www.w3.org/2000/svg\"", "", 1))
}

/// Whether a (lower-case) SVG text has an attribute `on…=` (an event handler) inside a tag.
fn has_event_handler(lower: &str) -> bool {
    let bytes = lower.as_bytes();
    let mut in_tag = false;
    let mut in_quote: Option<u8> = None;
    for (i, &b) in bytes.iter().enumerate() {
        match (in_tag, in_quote, b) {
            (_, Some(q), _) if b == q => in_quote = None,
            (_, Some(_), _) => {}
            (false, None, b'<') => in_tag = true,
            (true, None, b'>') => in_tag = false,
            (true, None, b'"' | b'\'') => in_quote = Some(b),
            (true, None, c) if c.is_ascii_whitespace() || c == b'/' => {
                let rest = &bytes[i + 1..];
                if rest.starts_with(b"on") {
                    let name_len = rest.iter().take_while(|c| c.is_ascii_alphabetic()).count();
                    let after = rest[name_len..].iter().find(|c| !c.is_ascii_whitespace());
                    if name_len > 2 && after == Some(&b'=') {
                        return true;
                    }
                }
            }
            _ => {}
        }
    }
    false
}

/// The page's style sheet: readable on screen, and on paper without the contents list, with
/// figures and tables kept whole and colours kept in the verdict and warning boxes.
const STYLE: &str = r#":root { color-scheme: light; }
body { margin: 0; background: #f4f5f7; color: #1d1f23;
  font: 15px/1.5 system-ui, -apple-system, "Segoe UI", "DejaVu Sans", Roboto, Helvetica, Arial, sans-serif; }
main { max-width: 1100px; margin: 0 auto; padding: 24px 32px 48px; background: #fff; }
h1 { font-size: 1.7em; margin: 0.2em 0 0.1em; }
h2 { font-size: 1.3em; margin: 1.6em 0 0.5em; padding-bottom: 0.2em; border-bottom: 1px solid #d8dbe0; }
h3 { font-size: 1.08em; margin: 1.2em 0 0.4em; }
.subtitle { color: #5a606b; margin-top: 0; }
.verdict, .warnings { border-left: 6px solid; border-radius: 4px; padding: 10px 16px; margin: 16px 0; }
.verdict .headline, .warnings .headline { font-weight: 600; font-size: 1.1em; margin: 0 0 4px; }
.verdict p { margin: 4px 0; }
.good { background: #e9f6ec; border-color: #2e8b47; }
.caution { background: #fff5e0; border-color: #d08b00; }
.bad { background: #fdeaea; border-color: #c62828; }
.info { background: #e8f1fb; border-color: #2f6db3; }
.warnings { background: #fff5e0; border-color: #d08b00; }
.warnings ul { margin: 4px 0; padding-left: 1.3em; }
.contents { background: #f7f8fa; border: 1px solid #e1e4e8; border-radius: 4px; padding: 6px 16px; margin: 16px 0; }
.contents p { margin: 4px 0; font-weight: 600; }
.contents ol { margin: 0 0 4px; }
a { color: #2f6db3; }
.table { overflow-x: auto; margin: 12px 0; }
table { border-collapse: collapse; font-variant-numeric: tabular-nums; }
caption { text-align: left; font-weight: 600; padding: 4px 0; }
th, td { border-bottom: 1px solid #e1e4e8; padding: 4px 12px; text-align: left; vertical-align: top; }
th { background: #f7f8fa; }
td.num, th.num { text-align: right; }
pre { background: #f7f8fa; border: 1px solid #e1e4e8; border-radius: 4px; padding: 10px 12px;
  overflow-x: auto; font: 13px/1.4 ui-monospace, "DejaVu Sans Mono", Menlo, Consolas, monospace; white-space: pre; }
figure { margin: 16px 0; }
figure svg { display: block; max-width: 100%; height: auto; border: 1px solid #e1e4e8; }
figcaption { color: #3c4048; font-size: 0.93em; margin-top: 6px; }
@media print {
  @page { margin: 15mm; }
  body { background: #fff; font-size: 10.5pt; }
  main { max-width: none; padding: 0; }
  .contents { display: none; }
  a { color: inherit; text-decoration: none; }
  figure, table, .verdict, .warnings, pre { break-inside: avoid; }
  h2, h3 { break-after: avoid; }
  pre { white-space: pre-wrap; }
  .verdict, .warnings { -webkit-print-color-adjust: exact; print-color-adjust: exact; }
  figure svg { border: none; }
}
"#;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escaping_covers_the_five_characters_and_controls() {
        assert_eq!(
            escape("<a href='x'>\"&\"</a>\u{0}\u{7}ok\n"),
            "&lt;a href=&#39;x&#39;&gt;&quot;&amp;&quot;&lt;/a&gt;ok\n"
        );
    }

    #[test]
    fn unsafe_svg_is_refused() {
        let ok = "<?xml version=\"1.0\"?>\n<svg width=\"10\" xmlns=\"http://www.w3.org/2000/svg\"><text>on = a</text></svg>\n";
        let svg = checked_svg("c", ok).unwrap();
        assert!(
            svg.starts_with("<svg width") && !svg.contains("xmlns"),
            "{svg}"
        );
        for bad in [
            "<svg><script>alert(1)</script></svg>",
            "<svg><SCRIPT>alert(1)</SCRIPT></svg>",
            "<svg><rect onload=\"x()\"/></svg>",
            "<svg><rect\nonclick = 'x()'/></svg>",
            "<svg><image href=\"http://example.com/a.png\"/></svg>",
            "<svg><use xlink:href=\"#a\"/></svg>",
            "<svg><rect style=\"fill:url(http://x)\"/></svg>",
            "<svg><foreignObject><div/></foreignObject></svg>",
            "<svg>",
            "no svg at all",
        ] {
            assert!(checked_svg("c", bad).is_err(), "{bad}");
        }
        // text that merely mentions "onload=" is fine, and so is an attribute like "opacity"
        let fine = "<svg><text opacity=\"1\">x onload=y</text></svg>";
        assert!(checked_svg("c", fine).is_ok());
    }

    #[test]
    fn sections_are_listed_and_closed() {
        let mut p = HtmlPage::new("t");
        p.section("A").paragraph("a").section("B").preformatted("b");
        let h = p.render();
        assert_eq!(h.matches("<section").count(), 2);
        assert_eq!(h.matches("</section>").count(), 2);
        assert!(h.contains("<a href=\"#s2\">B</a>"));
    }
}
