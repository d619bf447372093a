//! Line, dashed-line, marker and shaded-band panels: [`Series`], [`Band`], [`RefLine`],
//! [`Panel`], and a grid of panels ([`save_panels`], [`panels_svg`]).

/// How a [`Series`] is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Style {
    /// A solid line through the points (broken at non-finite points).
    #[default]
    Line,
    /// Filled circles at the points.
    Markers,
    /// A dashed line through the points (broken at non-finite points).
    Dashed,
    /// Open circles, twice the marker size, around the points (to flag points drawn by
    /// another series, e.g. outliers).
    Rings,
}

/// One labelled set of points in a [`Panel`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Series {
    /// Legend text; an empty label leaves the series out of the legend.
    pub label: String,
    /// The `(x, y)` points, drawn in the given order. Non-finite points are skipped.
    pub points: Vec<(f64, f64)>,
    /// Line, dashed line or markers.
    pub style: Style,
    /// Index into [`PALETTE`](super::PALETTE) (taken modulo its length); `None` uses the
    /// series' position.
    pub color: Option<usize>,
}

impl Series {
    /// A series with the given style and automatic colour.
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>, style: Style) -> Self {
        Self {
            label: label.into(),
            points,
            style,
            color: None,
        }
    }

    /// A solid line.
    pub fn line(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self::new(label, points, Style::Line)
    }

    /// A dashed line.
    pub fn dashed(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self::new(label, points, Style::Dashed)
    }

    /// Markers only.
    pub fn markers(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self::new(label, points, Style::Markers)
    }

    /// Open rings around the points (see [`Style::Rings`]).
    pub fn rings(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self::new(label, points, Style::Rings)
    }

    /// Sets the palette index (so that, e.g., data and model of one experiment share a colour).
    pub fn with_color(mut self, palette_index: usize) -> Self {
        self.color = Some(palette_index);
        self
    }
}

/// The region a [`Band`] shades.
#[derive(Debug, Clone, PartialEq)]
pub enum BandShape {
    /// Between two curves: `lower[i]` and `upper[i]` are `(x, y)` points (the two lists may
    /// have different abscissae); the polygon runs along `lower` and back along `upper`.
    /// Non-finite points are skipped.
    Between {
        /// The lower boundary, `(x, y)` with increasing `x`.
        lower: Vec<(f64, f64)>,
        /// The upper boundary, `(x, y)` with increasing `x`.
        upper: Vec<(f64, f64)>,
    },
    /// `lo ≤ y ≤ hi` across the whole horizontal axis (e.g. a constant noise band).
    Horizontal {
        /// Lower edge (vertical-axis units).
        lo: f64,
        /// Upper edge (vertical-axis units).
        hi: f64,
    },
    /// `lo ≤ x ≤ hi` across the whole vertical axis (e.g. the range covered by data).
    Vertical {
        /// Left edge (horizontal-axis units).
        lo: f64,
        /// Right edge (horizontal-axis units).
        hi: f64,
    },
}

/// A shaded region behind the series of a [`Panel`]: an uncertainty band, a noise band around
/// zero, or a range of the horizontal axis.
///
/// Bands widen the axis ranges so that they are seen whole (a [`BandShape::Vertical`] band
/// only the horizontal one, a [`BandShape::Horizontal`] band only the vertical one).
#[derive(Debug, Clone, PartialEq)]
pub struct Band {
    /// Legend text (a filled swatch); empty leaves the band out of the legend.
    pub label: String,
    /// The shaded region.
    pub shape: BandShape,
    /// Index into [`PALETTE`](super::PALETTE); `None` is a neutral grey.
    pub color: Option<usize>,
    /// Opacity of the shading in `(0, 1]`.
    pub opacity: f64,
}

impl Band {
    /// The region between two curves (see [`BandShape::Between`]).
    pub fn between(
        label: impl Into<String>,
        lower: Vec<(f64, f64)>,
        upper: Vec<(f64, f64)>,
    ) -> Self {
        Self::new(label, BandShape::Between { lower, upper })
    }

    /// A noise band `±sigma` around zero across the panel, for residual panels (`sigma` in the
    /// units of the vertical axis, e.g. % for residuals in %; its absolute value is used).
    pub fn noise(label: impl Into<String>, sigma: f64) -> Self {
        let s = sigma.abs();
        Self::new(label, BandShape::Horizontal { lo: -s, hi: s })
    }

    /// A noise band `±sigma(x)` around zero that varies along the horizontal axis, from
    /// `(x, sigma)` pairs (absolute values used).
    pub fn noise_profile(label: impl Into<String>, sigma: &[(f64, f64)]) -> Self {
        let upper: Vec<(f64, f64)> = sigma.iter().map(|&(x, s)| (x, s.abs())).collect();
        let lower = upper.iter().map(|&(x, s)| (x, -s)).collect();
        Self::between(label, lower, upper)
    }

    /// `lo ≤ y ≤ hi` across the panel.
    pub fn horizontal(label: impl Into<String>, lo: f64, hi: f64) -> Self {
        Self::new(label, BandShape::Horizontal { lo, hi })
    }

    /// `lo ≤ x ≤ hi` over the full height of the panel.
    pub fn vertical(label: impl Into<String>, lo: f64, hi: f64) -> Self {
        Self::new(label, BandShape::Vertical { lo, hi })
    }

    fn new(label: impl Into<String>, shape: BandShape) -> Self {
        Self {
            label: label.into(),
            shape,
            color: None,
            opacity: 0.18,
        }
    }

    /// Sets the palette index.
    pub fn with_color(mut self, palette_index: usize) -> Self {
        self.color = Some(palette_index);
        self
    }

    /// Sets the opacity (clamped to `[0.02, 1]`).
    pub fn with_opacity(mut self, opacity: f64) -> Self {
        self.opacity = if opacity.is_finite() {
            opacity.clamp(0.02, 1.0)
        } else {
            0.18
        };
        self
    }
}

/// A labelled horizontal reference line across a [`Panel`] (e.g. a plateau, a target value).
///
/// The label is written on the line's right end, above it.
#[derive(Debug, Clone, PartialEq)]
pub struct RefLine {
    /// Text written on the line (empty: none).
    pub label: String,
    /// Height of the line (vertical-axis units).
    pub y: f64,
    /// Index into [`PALETTE`](super::PALETTE); `None` is dark grey.
    pub color: Option<usize>,
    /// Dashed (`true`) or solid.
    pub dashed: bool,
}

impl RefLine {
    /// A dashed dark-grey reference line at `y`.
    pub fn new(label: impl Into<String>, y: f64) -> Self {
        Self {
            label: label.into(),
            y,
            color: None,
            dashed: true,
        }
    }
}

/// Where a panel's legend goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LegendPlacement {
    /// In the corner of the plotting area that no data, band edge or reference line crosses
    /// (upper right, upper left, lower right, lower left, in this order of preference);
    /// outside the plotting area (to its right, or below it when that leaves the plot too
    /// narrow) when every corner is taken.
    #[default]
    Auto,
    /// Always outside the plotting area.
    Outside,
    /// No legend.
    Hidden,
}

/// One set of axes with a title, axis labels, bands, series, reference lines and a legend.
///
/// Axis ranges are automatic: the finite data (series, bands, reference lines) plus 5 %
/// padding; a single value or an empty panel still gets a non-degenerate range. Ticks are
/// 1-2-5 steps on a linear axis (labelled with the decimals the step needs, zero exactly
/// `0`) and decades labelled `10ⁿ` on a logarithmic axis that spans them.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Panel {
    /// Title above the axes.
    pub title: String,
    /// Horizontal-axis label.
    pub x_label: String,
    /// Vertical-axis label.
    pub y_label: String,
    /// The series, drawn in order (later ones on top).
    pub series: Vec<Series>,
    /// Shaded regions, drawn first (behind the series).
    pub bands: Vec<Band>,
    /// Horizontal reference lines, drawn after the bands.
    pub ref_lines: Vec<RefLine>,
    /// Logarithmic vertical axis; points with `y <= 0` are then skipped.
    pub log_y: bool,
    /// Logarithmic horizontal axis; points with `x <= 0` are then skipped.
    pub log_x: bool,
    /// Where the legend goes.
    pub legend: LegendPlacement,
}

impl Panel {
    /// An empty panel with a title and axis labels.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            ..Self::default()
        }
    }

    /// Adds a series.
    pub fn with_series(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }

    /// Adds a shaded band (drawn behind the series).
    pub fn with_band(mut self, band: Band) -> Self {
        self.bands.push(band);
        self
    }

    /// Adds a noise band `±sigma` around zero (`Band::noise`), labelled `label`.
    pub fn with_noise_band(self, label: impl Into<String>, sigma: f64) -> Self {
        self.with_band(Band::noise(label, sigma))
    }

    /// Adds a horizontal reference line.
    pub fn with_ref_line(mut self, line: RefLine) -> Self {
        self.ref_lines.push(line);
        self
    }

    /// Sets a logarithmic (`true`) or linear (`false`) vertical axis.
    pub fn with_log_y(mut self, log_y: bool) -> Self {
        self.log_y = log_y;
        self
    }

    /// Sets a logarithmic (`true`) or linear (`false`) horizontal axis.
    pub fn with_log_x(mut self, log_x: bool) -> Self {
        self.log_x = log_x;
        self
    }

    /// Sets where the legend goes.
    pub fn with_legend(mut self, placement: LegendPlacement) -> Self {
        self.legend = placement;
        self
    }
}
