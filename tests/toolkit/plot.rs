//! Writes real PNG/SVG figures and checks them from the outside.

use std::fs;
use std::path::{Path, PathBuf};

use diffbvp::plot::{save_heatmap, save_panels, Heatmap, Panel, PlotError, Series, Style};

fn out_dir() -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join("test-plots")
}

/// Width and height from a PNG's IHDR chunk (big-endian at bytes 16..20 and 20..24).
fn png_size(path: &Path) -> (u32, u32) {
    let bytes = fs::read(path).expect("read png");
    assert!(bytes.len() > 24, "PNG too short");
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "not a PNG signature");
    assert_eq!(&bytes[12..16], b"IHDR");
    let be = |r: std::ops::Range<usize>| u32::from_be_bytes(bytes[r].try_into().expect("4 bytes"));
    (be(16..20), be(20..24))
}

/// Six diameter-profile panels like the paper's 2 × 3 figures, one with a gap, one log-scaled,
/// one empty and one with only NaN.
fn profile_panels() -> Vec<Panel> {
    let mut panels = Vec::new();
    for e in 1..=6 {
        let rate = 0.5 * f64::from(e);
        let z: Vec<f64> = (0..=40).map(|i| f64::from(i) * 0.025).collect();
        let model: Vec<(f64, f64)> = z.iter().map(|&z| (z, (-rate * z).exp())).collect();
        let data: Vec<(f64, f64)> = z
            .iter()
            .step_by(5)
            .map(|&z| (z, (-rate * z).exp() * (1.0 + 0.03 * (7.0 * z).sin())))
            .collect();
        let guess: Vec<(f64, f64)> = z.iter().map(|&z| (z, 1.0 - 0.5 * rate * z)).collect();
        panels.push(
            Panel::new(format!("Experiment {e}"), "z (m)", "D/D0")
                .with_series(Series::markers("measured", data).with_color(0))
                .with_series(Series::line("fitted model", model).with_color(1))
                .with_series(Series::dashed("initial guess", guess).with_color(2)),
        );
    }
    // A gap in a line, a log axis with non-positive values.
    panels[1].series[1].points[10].1 = f64::NAN;
    panels[2].log_y = true;
    panels[2].series[2].label = "guess (y ≤ 0 hidden)".into();
    // An empty series, and a panel with nothing usable at all.
    panels[4].series.push(Series::line("empty", Vec::new()));
    panels[5] = Panel::new("NaN only", "x", "y")
        .with_series(Series::new(
            "nan",
            vec![(f64::NAN, f64::NAN); 3],
            Style::Line,
        ))
        .with_series(Series::markers("", vec![(1.0, f64::INFINITY)]));
    panels
}

#[test]
fn panel_grid_png_and_svg() {
    let dir = out_dir();
    let panels = profile_panels();

    let png = dir.join("profiles.png");
    save_panels(&png, &panels, 3, (1500, 900)).expect("png written");
    assert_eq!(png_size(&png), (1500, 900));

    let svg = dir.join("nested").join("profiles.svg");
    let _ = fs::remove_dir_all(dir.join("nested"));
    save_panels(&svg, &panels, 3, (1500, 900)).expect("svg written (creating its directory)");
    let text = fs::read_to_string(&svg).expect("read svg");
    assert!(text.starts_with("<svg"));
    for label in [
        "Experiment 1",
        "Experiment 5",
        "NaN only",
        "z (m)",
        "D/D0",
        "measured",
        "fitted model",
        "initial guess",
        "guess (y ≤ 0 hidden)",
    ] {
        assert!(text.contains(label), "SVG lacks {label:?}");
    }
}

#[test]
fn degenerate_panels_do_not_panic() {
    let dir = out_dir();
    let cases = [
        Panel::new("empty panel", "x", "y"),
        Panel::new("single point", "x", "y").with_series(Series::line("p", vec![(1.0, 2.0)])),
        Panel::new("constant", "x", "y")
            .with_series(Series::dashed("c", vec![(0.0, 5.0), (1.0, 5.0)]))
            .with_log_y(true),
        Panel::new("all NaN, log", "x", "y")
            .with_series(Series::markers(
                "nan",
                vec![(f64::NAN, 1.0), (0.0, f64::NAN)],
            ))
            .with_log_y(true),
        Panel::new("huge", "x", "y").with_series(Series::line(
            "h",
            vec![(-f64::MAX, f64::MAX), (f64::MAX, -f64::MAX)],
        )),
    ];
    save_panels(&dir.join("degenerate.png"), &cases, 10, (1200, 300)).expect("degenerate png");
    save_panels(&dir.join("degenerate.svg"), &cases, 2, (600, 900)).expect("degenerate svg");
    // Tiny figures still do not panic.
    save_panels(&dir.join("tiny.png"), &cases, 3, (30, 20)).expect("tiny png");
}

#[test]
fn heatmap_png_and_svg() {
    let dir = out_dir();
    let xs: Vec<f64> = (0..25).map(|i| 0.2 + 0.03 * f64::from(i)).collect(); // n
    let ys: Vec<f64> = (0..20)
        .map(|j| 10f64.powf(-1.0 + 0.1 * f64::from(j)))
        .collect(); // κ
    let mut values = Vec::new();
    for &y in &ys {
        for &x in &xs {
            let j = 1.0 + 40.0 * (x - 0.6).powi(2) + 5.0 * (y.log10() - 0.2).powi(2);
            values.push(j);
        }
    }
    values[3] = f64::NAN;
    values[100] = f64::NAN;
    let markers = vec![
        (0.6, 10f64.powf(0.2), "optimum".to_string()),
        (0.35, 0.2, "start".to_string()),
        (f64::NAN, 1.0, "ignored".to_string()),
        (1e12, 1.0, "far away".to_string()),
    ];
    for (name, log) in [
        ("landscape.png", true),
        ("landscape_log.svg", true),
        ("landscape_lin.png", false),
    ] {
        let map = Heatmap {
            title: "Cost landscape J(n, κ)",
            x_label: "n",
            y_label: "κ (s)",
            value_label: "J",
            markers: &markers,
            log_color: log,
            log_y: log,
            size: (800, 600),
            ..Heatmap::new(&xs, &ys, &values)
        };
        save_heatmap(&dir.join(name), &map).expect("heat map written");
    }
    assert_eq!(png_size(&dir.join("landscape.png")), (800, 600));
    let text = fs::read_to_string(dir.join("landscape_log.svg")).expect("read svg");
    for label in [
        "Cost landscape J(n, κ)",
        "κ (s)",
        "optimum",
        "start",
        "no value",
    ] {
        assert!(text.contains(label), "SVG lacks {label:?}");
    }
    assert!(!text.contains("ignored") && !text.contains("far away"));
}

#[test]
fn heatmap_degenerate_inputs() {
    let dir = out_dir();
    // One cell, constant and all-missing values.
    let one = [1.0];
    for (name, values) in [("one_cell.png", [3.0]), ("one_nan.svg", [f64::NAN])] {
        let map = Heatmap {
            log_color: true,
            ..Heatmap::new(&one, &one, &values)
        };
        save_heatmap(&dir.join(name), &map).expect("degenerate heat map");
    }
    let xs = [3.0, 2.0, 1.0]; // decreasing is fine
    let ys = [0.0, 1.0];
    let values = [0.0; 6];
    save_heatmap(&dir.join("constant.png"), &Heatmap::new(&xs, &ys, &values)).expect("constant");

    let err = save_heatmap(&dir.join("bad.png"), &Heatmap::new(&xs, &ys, &values[..5]))
        .expect_err("wrong length");
    assert!(matches!(err, PlotError::InvalidInput { .. }));
    assert!(err.to_string().contains("bad.png"), "{err}");
    let err = save_heatmap(
        &dir.join("bad.png"),
        &Heatmap {
            log_y: true,
            ..Heatmap::new(&xs, &ys, &values)
        },
    )
    .expect_err("log axis with 0");
    assert!(matches!(err, PlotError::InvalidInput { .. }));
    let unsorted = [1.0, 3.0, 2.0];
    let err = save_heatmap(&dir.join("bad.png"), &Heatmap::new(&unsorted, &ys, &values))
        .expect_err("not monotonic");
    assert!(matches!(err, PlotError::InvalidInput { .. }));
    assert!(!dir.join("bad.png").exists());
}

#[test]
fn invalid_requests_are_errors_naming_the_path() {
    let dir = out_dir();
    let panel = [Panel::new("t", "x", "y")];
    let pdf = dir.join("figure.pdf");
    let err = save_panels(&pdf, &panel, 1, (100, 100)).expect_err("pdf unsupported");
    assert!(matches!(err, PlotError::UnsupportedFormat { .. }));
    assert!(err.to_string().contains("figure.pdf"));
    assert!(!pdf.exists());

    assert!(matches!(
        save_panels(&dir.join("a.png"), &[], 1, (100, 100)),
        Err(PlotError::InvalidInput { .. })
    ));
    assert!(matches!(
        save_panels(&dir.join("a.png"), &panel, 0, (100, 100)),
        Err(PlotError::InvalidInput { .. })
    ));
    assert!(matches!(
        save_panels(&dir.join("a.png"), &panel, 1, (0, 100)),
        Err(PlotError::InvalidInput { .. })
    ));
    // An existing directory is never replaced.
    let as_dir = dir.join("is_a_dir.svg");
    fs::create_dir_all(&as_dir).expect("mkdir");
    assert!(save_panels(&as_dir, &panel, 1, (100, 100)).is_err());
    assert!(as_dir.is_dir());
    // A parent that is a file cannot be created: an I/O error, not a panic.
    let file = dir.join("plain_file");
    fs::write(&file, b"x").expect("write");
    let err = save_panels(&file.join("x.png"), &panel, 1, (100, 100)).expect_err("parent is file");
    assert!(matches!(err, PlotError::Io { .. }), "{err}");
}
