//! The self-contained HTML page: user text escaped, nothing loaded from the network, figures
//! embedded inline, written atomically.

use std::fs;
use std::path::{Path, PathBuf};

use rheometer::report::html_page::{HtmlError, HtmlPage, Table, Tone};
use rheometer::report::plot::{panels_svg, Panel, Series};

fn out_dir() -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join("test-html")
}

const HOSTILE: &str = "<script>alert('x')</script> & \"quoted\" <img src=http://example.com/a.png>";

fn hostile_page() -> HtmlPage {
    let mut page = HtmlPage::new(format!("Experiment {HOSTILE}"));
    page.subtitle(format!("inputs: data/{HOSTILE}.toml"));
    page.verdict(
        Tone::Caution,
        HOSTILE,
        format!("details {HOSTILE}\nsecond line"),
    );
    page.section(format!("Section {HOSTILE}"));
    page.paragraph(format!("note: {HOSTILE}"));
    page.table(
        Table::new(&["name", "value"])
            .row(&[HOSTILE, "1.0"])
            .row(&["short row"])
            .numeric(1)
            .with_caption(HOSTILE),
    );
    page.preformatted(format!("pre {HOSTILE}"));
    page.warnings(&[HOSTILE, "plain warning"]);
    // a figure whose labels carry the same text (plotters escapes SVG text)
    let panel = Panel::new(format!("panel {HOSTILE}"), "x", "y")
        .with_series(Series::markers(HOSTILE, vec![(0.0, 1.0), (1.0, 2.0)]));
    let svg = panels_svg(&[panel], 1, (500, 300)).expect("svg");
    page.figure_svg(format!("caption {HOSTILE}"), &svg)
        .expect("plotters' SVG is safe");
    page.section("Second");
    page
}

#[test]
fn user_text_is_escaped_and_nothing_is_loaded() {
    let html = hostile_page().render();
    let lower = html.to_ascii_lowercase();
    assert!(!lower.contains("<script"), "a script tag in the page");
    assert!(!lower.contains("<img"), "an image tag in the page");
    assert!(
        html.contains("&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt; &amp; &quot;quoted&quot;"),
        "the name is not shown as text"
    );
    // no tag loads or links anything outside the page (user text is escaped, so every '<'
    // starts a real tag)
    let tags: Vec<&str> = lower
        .split('<')
        .skip(1)
        .map(|t| &t[..t.find('>').unwrap_or(t.len())])
        .collect();
    assert!(tags.len() > 50);
    for tag in &tags {
        assert!(!tag.contains("src="), "a src attribute: <{tag}>");
        assert!(
            !tag.contains("http://") && !tag.contains("https://"),
            "<{tag}>"
        );
        if let Some(i) = tag.find("href=") {
            assert!(
                tag[i + 5..].starts_with("\"#"),
                "a link out of the page: <{tag}>"
            );
        }
    }
    let style = &lower[lower.find("<style>").unwrap()..lower.find("</style>").unwrap()];
    assert!(!style.contains("url(") && !style.contains("@import"));
    // the browser is told to load nothing
    assert!(html.contains("Content-Security-Policy\" content=\"default-src 'none'"));
    // printable, with the figure inline
    assert!(html.contains("@media print"));
    assert_eq!(html.matches("<svg").count(), 1);
    assert!(html.contains("<figcaption>Figure 1. caption &lt;script&gt;"));
    // every table row as wide as the header
    assert!(html.contains("<tr><td>short row</td><td class=\"num\"></td></tr>"));
    assert!(html.contains("Warnings (2)"));
}

#[test]
fn unsafe_figures_are_refused() {
    let mut page = HtmlPage::new("t");
    for svg in [
        "<svg><script>alert(1)</script></svg>",
        "<svg><image href=\"https://example.com/x.png\"/></svg>",
        "<svg><rect onload=\"alert(1)\"/></svg>",
    ] {
        let err = page.figure_svg("bad <one>", svg).expect_err(svg);
        assert!(matches!(err, HtmlError::UnsafeSvg { .. }));
        assert!(err.to_string().contains("bad <one>"), "{err}");
    }
    assert!(!page.render().contains("<svg"));
}

#[test]
fn the_page_is_written_atomically() {
    let dir = out_dir();
    let _ = fs::remove_dir_all(&dir);
    let path = dir.join("nested").join("report.html");
    hostile_page()
        .write(&path)
        .expect("written, parents created");
    let first = fs::read_to_string(&path).expect("read");
    assert!(first.starts_with("<!DOCTYPE html>") && first.ends_with("</html>\n"));
    // an existing file is replaced whole, and a hard link to it keeps the old content
    let link = dir.join("link.html");
    fs::hard_link(&path, &link).expect("hard link");
    let mut other = HtmlPage::new("second version");
    other.paragraph("short");
    other.write(&path).expect("rewritten");
    assert!(fs::read_to_string(&path)
        .expect("read")
        .contains("second version"));
    assert_eq!(fs::read_to_string(&link).expect("read link"), first);
    // a directory is never replaced
    let err = other.write(&dir.join("nested")).expect_err("a directory");
    assert!(matches!(err, HtmlError::IsADirectory { .. }), "{err}");
    // no temporary left behind
    let leftovers: Vec<_> = fs::read_dir(dir.join("nested"))
        .expect("dir")
        .filter_map(|e| e.ok())
        .map(|e| e.file_name())
        .filter(|n| n.to_string_lossy() != "report.html")
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}
