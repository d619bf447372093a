//! Writes real PNG/SVG figures and checks them from the outside.

use std::fs;
use std::path::{Path, PathBuf};

use rheometer::report::plot::{
    save_heatmap, save_panels, Heatmap, Panel, PlotError, Series, Style,
};

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
    // A parent that is a file cannot be created: an error of the output layer naming it, not
    // a panic.
    let file = dir.join("plain_file");
    fs::write(&file, b"x").expect("write");
    let err = save_panels(&file.join("x.png"), &panel, 1, (100, 100)).expect_err("parent is file");
    assert!(matches!(err, PlotError::Output(_)), "{err}");
    assert!(err.to_string().contains("plain_file"), "{err}");
}

// ---- issue 31: glyphs, ticks, legends, anti-aliasing, bands, formats, the flow curve ----

/// The text of every `<text>` element of an SVG written by plotters.
fn svg_texts(svg: &str) -> Vec<String> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| {
            let body = &t[t.find('>')? + 1..t.find("</text>")?];
            Some(body.trim().to_string())
        })
        .collect()
}

/// Attribute `name` of the tag text `tag` (`name="value"`).
fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let key = format!("{name}=\"");
    let at = if tag.starts_with(&key) {
        0
    } else {
        tag.find(&format!(" {key}"))? + 1
    };
    let start = at + key.len();
    Some(&tag[start..start + tag[start..].find('"')?])
}

/// Every `<TAG .../>` of an SVG, as its attribute text.
fn svg_tags<'a>(svg: &'a str, tag: &str) -> Vec<&'a str> {
    let open = format!("<{tag} ");
    svg.split(open.as_str())
        .skip(1)
        .filter_map(|t| t.find('>').map(|e| &t[..e]))
        .collect()
}

fn num(tag: &str, name: &str) -> f64 {
    attr(tag, name)
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no numeric {name} in {tag}"))
}

/// The legend boxes of an SVG: the white, 90 %-opaque rectangles, as `(x0, y0, x1, y1)`.
fn legend_boxes(svg: &str) -> Vec<(f64, f64, f64, f64)> {
    svg_tags(svg, "rect")
        .into_iter()
        .filter(|t| attr(t, "fill") == Some("#FFFFFF") && attr(t, "opacity") == Some("0.9"))
        .map(|t| {
            let (x, y) = (num(t, "x"), num(t, "y"));
            (x, y, x + num(t, "width"), y + num(t, "height"))
        })
        .collect()
}

/// The filled data markers of colour `fill`, as `(cx, cy, r)`.
fn markers(svg: &str, fill: &str) -> Vec<(f64, f64, f64)> {
    svg_tags(svg, "circle")
        .into_iter()
        .filter(|t| attr(t, "fill") == Some(fill))
        .map(|t| (num(t, "cx"), num(t, "cy"), num(t, "r")))
        .collect()
}

/// RGB pixels of a PNG (8-bit RGB or RGBA) with its width and height.
fn png_pixels(path: &Path) -> (Vec<[u8; 3]>, u32, u32) {
    let decoder = png::Decoder::new(fs::File::open(path).expect("open png"));
    let mut reader = decoder.read_info().expect("png header");
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).expect("png frame");
    let channels = info.color_type.samples();
    assert_eq!(info.bit_depth, png::BitDepth::Eight);
    let pixels = buf[..info.buffer_size()]
        .chunks_exact(channels)
        .map(|p| [p[0], p[1], p[2]])
        .collect();
    (pixels, info.width, info.height)
}

#[test]
fn tick_labels_have_the_digits_of_their_step_and_no_float_noise() {
    let dir = out_dir();
    // residual-like data around zero whose range ends are sums with rounding noise, and a
    // legend with a decimal number
    let pts: Vec<(f64, f64)> = (0..=20)
        .map(|i| {
            let x = 0.1 * f64::from(i) + 0.2 - 0.3 + 0.1; // 0.1*i + 2.776e-17
            (x, 0.3 * (x * 7.0).sin() - 0.1 + 0.2 - 0.1)
        })
        .collect();
    let panel = Panel::new("residuals", "s / m", "r / %")
        .with_series(Series::markers("identified n = 0.804, κ = 11.63", pts));
    let path = dir.join("ticks.svg");
    save_panels(&path, &[panel], 1, (700, 450)).expect("svg");
    let texts = svg_texts(&fs::read_to_string(&path).expect("read"));
    assert!(
        texts.iter().all(|t| !t.contains("e-") && !t.contains('·')),
        "{texts:?}"
    );
    assert!(texts.iter().any(|t| t == "identified n = 0.804, κ = 11.63"));
    // the x ticks are 0.0, 0.5, …, 2.0 (one decimal, as the step 0.5 needs), zero exactly "0.0"
    for label in ["0.0", "0.5", "1.0", "1.5", "2.0"] {
        assert!(
            texts.iter().any(|t| t == label),
            "no tick {label}: {texts:?}"
        );
    }
    // the y ticks: a 0.1 step, one decimal each, a true minus sign
    assert!(texts.iter().any(|t| t == "−0.2"), "{texts:?}");
    assert!(texts.iter().any(|t| t == "0.0"), "{texts:?}");
}

#[test]
fn png_lines_are_anti_aliased() {
    let dir = out_dir();
    // one diagonal line and nothing else on the axes
    let panel = Panel::new("", "", "").with_series(Series::line("", vec![(0.0, 0.0), (1.0, 1.0)]));
    let path = dir.join("diagonal.png");
    save_panels(&path, &[panel], 1, (400, 400)).expect("png");
    let (pixels, w, h) = png_pixels(&path);
    assert_eq!((w, h), (400, 400));
    // Along rows through the middle of the plot, the pixels between the line colour
    // (31, 119, 180) and white: a line drawn without anti-aliasing has none, an
    // anti-aliased one several coverage levels.
    let mut levels = std::collections::BTreeSet::new();
    for y in 150..250u32 {
        for x in 0..w {
            let [r, g, b] = pixels[(y * w + x) as usize];
            // blends of the line colour with white keep b > g > r; grid greys have r = g = b
            if r > 40 && r < 225 && b > g && g > r {
                levels.insert(r);
            }
        }
    }
    assert!(
        levels.len() >= 6,
        "only {} intermediate levels: {levels:?}",
        levels.len()
    );
}

#[test]
fn legends_cover_no_data() {
    let dir = out_dir();
    let fill = "#1F77B4"; // PALETTE[0]
    let cases = [
        // a falling curve: the upper-right corner is free
        (
            "falling",
            (0..40)
                .map(|i| {
                    let x = f64::from(i) / 39.0;
                    (x, (-4.0 * x).exp())
                })
                .collect::<Vec<_>>(),
        ),
        // data in the upper right corner (and upper left): the legend goes elsewhere
        (
            "rising",
            (0..40)
                .map(|i| {
                    let x = f64::from(i) / 39.0;
                    (x, 1.0 - (-4.0 * x).exp())
                })
                .chain([(0.0, 1.0), (0.05, 0.98)])
                .collect(),
        ),
        // data everywhere: no free corner, the legend goes outside the plot
        (
            "everywhere",
            (0..400)
                .map(|i| (f64::from(i % 20) / 19.0, f64::from(i / 20) / 19.0))
                .collect(),
        ),
    ];
    for (name, pts) in cases {
        let panel = Panel::new(name, "x", "y")
            .with_series(Series::markers("a rather long legend label for data", pts).with_color(0))
            .with_series(Series::line("second entry", vec![]).with_color(1));
        let path = dir.join(format!("legend_{name}.svg"));
        save_panels(&path, &[panel], 1, (600, 420)).expect("svg");
        let svg = fs::read_to_string(&path).expect("read");
        let boxes = legend_boxes(&svg);
        assert_eq!(boxes.len(), 1, "{name}: one legend box");
        let (x0, y0, x1, y1) = boxes[0];
        let data = markers(&svg, fill);
        // the legend's own swatch is a marker of the same colour: it lies inside the box
        let inside: Vec<_> = data
            .iter()
            .filter(|(cx, cy, r)| *cx + r > x0 && *cx - r < x1 && *cy + r > y0 && *cy - r < y1)
            .collect();
        assert!(
            inside.len() <= 1,
            "{name}: legend box {:?} covers data markers {:?}",
            boxes[0],
            inside
        );
        assert_eq!(inside.len(), 1, "{name}: the swatch is in the box");
    }
}

#[test]
fn written_files_are_in_the_requested_format() {
    let dir = out_dir().join("formats");
    let panel =
        [Panel::new("t", "x", "y").with_series(Series::line("l", vec![(0.0, 1.0), (1.0, 2.0)]))];
    for name in ["a.png", "b.PNG", "c.svg", "d.SVG", "e.with.dots.svg"] {
        let path = dir.join(name);
        save_panels(&path, &panel, 1, (300, 200)).expect("written");
        let bytes = fs::read(&path).expect("read");
        if name.to_lowercase().ends_with(".png") {
            assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{name}");
        } else {
            assert!(bytes.starts_with(b"<svg"), "{name}");
        }
    }
    let xs = [1.0, 2.0];
    let values = [1.0, 2.0, 3.0, 4.0];
    for name in ["h.svg", "h.png"] {
        let path = dir.join(name);
        save_heatmap(&path, &Heatmap::new(&xs, &xs, &values)).expect("heat map");
        let bytes = fs::read(&path).expect("read");
        assert_eq!(bytes.starts_with(b"<svg"), name.ends_with("svg"), "{name}");
        assert_eq!(
            bytes.starts_with(b"\x89PNG"),
            name.ends_with("png"),
            "{name}"
        );
    }
    // no temporary left beside the outputs
    let leftovers: Vec<_> = fs::read_dir(&dir)
        .expect("dir")
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp-"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn noise_band_is_shaded_behind_residuals() {
    let dir = out_dir();
    let pts: Vec<(f64, f64)> = (0..30)
        .map(|i| (f64::from(i), 0.4 * (f64::from(i) * 1.3).sin()))
        .collect();
    let panel = Panel::new("residual", "s / m", "r / %")
        .with_noise_band("noise ±2σ", 1.5)
        .with_series(Series::markers("residual", pts));
    let path = dir.join("noise_band.svg");
    save_panels(&path, &[panel], 1, (600, 400)).expect("svg");
    let svg = fs::read_to_string(&path).expect("read");
    // the band is a translucent rectangle as wide as the plot, its height ±1.5 around zero:
    // the axis reaches beyond ±1.5 although the data stay within ±0.4
    let bands: Vec<_> = svg_tags(&svg, "rect")
        .into_iter()
        .filter(|t| attr(t, "opacity").is_some_and(|o| o.starts_with("0.1")))
        .collect();
    assert_eq!(bands.len(), 1, "{bands:?}");
    assert!(svg_texts(&svg)
        .iter()
        .any(|t| t == "1.5" || t == "2" || t == "2.0"));
    assert!(svg.contains("noise ±2σ"));
}

#[test]
fn flow_curve_figure() {
    use rheometer::report::plot::{
        flow_curve_svg, save_flow_curve, FlowCurvePlot, ReferencePoints,
    };
    let dir = out_dir();
    // a Carreau-type law η = 3η₀ (1 + (λ ε̇)²)^((n−1)/2) sampled over 6 decades
    let (eta0, lambda, n) = (2.0e3, 0.4, 0.55);
    let rates: Vec<f64> = (0..=60)
        .map(|i| 10f64.powf(-2.0 + 0.1 * f64::from(i)))
        .collect();
    let law = |r: f64| 3.0 * eta0 * (1.0 + (lambda * r).powi(2)).powf(0.5 * (n - 1.0));
    let eta: Vec<f64> = rates.iter().map(|&r| law(r)).collect();
    let widen = |f: f64| -> (Vec<f64>, Vec<f64>) {
        let w: Vec<f64> = rates
            .iter()
            .map(|r| f * (1.0 + 0.3 * (r.log10() - 1.0).powi(2)))
            .collect();
        (
            eta.iter().zip(&w).map(|(e, w)| e / (1.0 + w)).collect(),
            eta.iter().zip(&w).map(|(e, w)| e * (1.0 + w)).collect(),
        )
    };
    let (s_lo, s_hi) = widen(0.03);
    let (y_lo, y_hi) = widen(0.08);
    let shear_rates = [0.01, 0.03, 0.1, 0.3, 1.0];
    let shear: Vec<f64> = shear_rates.iter().map(|&r| 1.02 * law(r)).collect();
    let points = [ReferencePoints {
        label: "3 × shear viscosity",
        rates: &shear_rates,
        viscosity: &shear,
    }];
    let plateau = format!("3η₀ = {:.0} Pa s", 3.0 * eta0);
    let plot = FlowCurvePlot {
        temperature_k: Some(503.15),
        statistical: Some((&s_lo, &s_hi)),
        systematic: Some((&y_lo, &y_hi)),
        plateau: Some((3.0 * eta0, &plateau)),
        data_range: Some((0.5, 60.0)),
        points: &points,
        ..FlowCurvePlot::new(&rates, &eta)
    };
    save_flow_curve(&dir.join("flow_curve.png"), &plot).expect("png");
    let svg = flow_curve_svg(&plot).expect("svg");
    let texts = svg_texts(&svg);
    for needed in [
        "Flow curve, T = 230.0 °C",
        "strain rate / s⁻¹",
        "identified law",
        "extrapolated",
        "3η₀ = 6000 Pa s",
        "3 × shear viscosity",
        "95 % confidence band",
        "systematic uncertainty",
        "strain rates of the data",
        "10⁻²",
        "10⁰",
        "10⁴",
    ] {
        assert!(
            texts.iter().any(|t| t == needed),
            "no {needed:?} in {texts:?}"
        );
    }
    assert!(texts.iter().all(|t| !t.contains("e-") && !t.contains("e+")));
    // the extrapolated parts are dashed: plotters writes a dashed line as many short paths
    assert!(svg.matches("<polyline").count() > 20);
    // bad input is an error naming the problem
    let bad = [1.0, -2.0];
    let err = save_flow_curve(&dir.join("bad.svg"), &FlowCurvePlot::new(&bad, &bad))
        .expect_err("negative rate");
    assert!(err.to_string().contains("rates[1]"), "{err}");
    assert!(!dir.join("bad.svg").exists());
}
