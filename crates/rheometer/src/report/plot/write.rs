//! Writing a figure: the format follows the extension (PNG or SVG), the figure is rendered and
//! encoded in memory first and then written through the output layer
//! ([`output_files`](crate::report::output_files)).
//!
//! A PNG is rendered supersampled (at 3 or 2 times its size, see [`supersampling`]) and
//! reduced with a box filter: plotters' bitmap backend draws lines, circles and polygons
//! without anti-aliasing, and averaging the `s × s` canvas pixels of each figure pixel gives
//! edges `s² + 1` levels of coverage (and text glyphs placed to a third of a pixel).

use std::error::Error as StdError;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::error::{invalid, PlotError};
use super::style::fonts::ensure_font;
use crate::report::output_files::write_bytes;

/// Largest accepted figure side, in pixels (guards against huge allocations).
pub const MAX_SIDE: u32 = 16_384;

pub(super) type DrawResult = Result<(), Box<dyn StdError + Send + Sync>>;

/// Most canvas pixels of a supersampled PNG (48 MB of RGB): larger figures are rendered at a
/// lower factor.
const MAX_SUPERSAMPLED_PIXELS: u64 = 16_000_000;

/// Something that can draw itself onto any plotters backend, at `scale` canvas pixels per
/// figure pixel (every size in canvas pixels is multiplied by it).
pub(super) trait Figure {
    fn draw<DB>(&self, root: &DrawingArea<DB, Shift>, scale: f64) -> DrawResult
    where
        DB: DrawingBackend,
        DB::ErrorType: 'static;
}

/// Image format of a figure file; the one place that maps formats to file extensions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FigureFormat {
    /// Bitmap (PNG).
    Png,
    /// Vector graphics (SVG).
    Svg,
}

impl FigureFormat {
    /// The file extension (`"png"`, `"svg"`).
    pub fn extension(self) -> &'static str {
        match self {
            FigureFormat::Png => "png",
            FigureFormat::Svg => "svg",
        }
    }

    /// The format a figure written to `path` gets, from its extension (case-insensitive).
    pub fn of_path(path: &Path) -> Result<Self, PlotError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        [FigureFormat::Png, FigureFormat::Svg]
            .into_iter()
            .find(|f| ext.as_deref() == Some(f.extension()))
            .ok_or_else(|| PlotError::UnsupportedFormat {
                path: path.to_path_buf(),
            })
    }
}

/// The supersampling factor of a `w × h` PNG: 3, or 2 (or 1) when 3 (or 2) would exceed
/// [`MAX_SUPERSAMPLED_PIXELS`] canvas pixels.
pub(super) fn supersampling(w: u32, h: u32) -> u32 {
    let pixels = u64::from(w) * u64::from(h);
    [3u32, 2]
        .into_iter()
        .find(|s| pixels * u64::from(s * s) <= MAX_SUPERSAMPLED_PIXELS)
        .unwrap_or(1)
}

/// Box filter: the `(w·s) × (h·s)` RGB canvas reduced to `w × h` by averaging each `s × s`
/// block.
pub(super) fn downsample(canvas: &[u8], (w, h): (u32, u32), s: u32) -> Vec<u8> {
    let (w, h, s) = (w as usize, h as usize, s as usize);
    if s == 1 {
        return canvas.to_vec();
    }
    let cw = w * s;
    let n = (s * s) as u32;
    let mut out = vec![0u8; w * h * 3];
    let mut sums = vec![0u32; w * 3];
    for y in 0..h {
        sums.fill(0);
        for row in canvas[y * s * cw * 3..(y + 1) * s * cw * 3].chunks_exact(cw * 3) {
            for (x, sum) in sums.chunks_exact_mut(3).enumerate() {
                for px in row[x * s * 3..(x + 1) * s * 3].chunks_exact(3) {
                    sum[0] += u32::from(px[0]);
                    sum[1] += u32::from(px[1]);
                    sum[2] += u32::from(px[2]);
                }
            }
        }
        for (o, sum) in out[y * w * 3..(y + 1) * w * 3].iter_mut().zip(&sums) {
            *o = ((sum + n / 2) / n) as u8;
        }
    }
    out
}

/// Checks a figure size and registers the font.
fn check_request(path: &Path, (w, h): (u32, u32)) -> Result<(), PlotError> {
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(invalid(
            path,
            format!("figure size {w} × {h} must be between 1 and {MAX_SIDE} pixels per side"),
        ));
    }
    if !ensure_font() {
        return Err(PlotError::Font {
            path: path.to_path_buf(),
        });
    }
    Ok(())
}

fn draw_error(path: &Path) -> impl Fn(Box<dyn StdError + Send + Sync>) -> PlotError + '_ {
    move |source| PlotError::Draw {
        path: path.to_path_buf(),
        source,
    }
}

/// Renders `figure` as an SVG document of `size` pixels (`path` only names the figure in
/// errors).
pub(super) fn render_svg<F: Figure>(
    path: &Path,
    size: (u32, u32),
    figure: &F,
) -> Result<String, PlotError> {
    check_request(path, size)?;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        render(&root, figure, 1.0).map_err(draw_error(path))?;
    }
    Ok(svg)
}

/// Renders `figure` as `size.0 × size.1` RGB pixels, supersampled and box-filtered.
pub(super) fn render_rgb<F: Figure>(
    path: &Path,
    size: (u32, u32),
    figure: &F,
) -> Result<Vec<u8>, PlotError> {
    check_request(path, size)?;
    let s = supersampling(size.0, size.1);
    let canvas_size = (size.0 * s, size.1 * s);
    let mut canvas = vec![255u8; canvas_size.0 as usize * canvas_size.1 as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut canvas, canvas_size).into_drawing_area();
        render(&root, figure, f64::from(s)).map_err(draw_error(path))?;
    }
    Ok(downsample(&canvas, size, s))
}

/// Validates and renders `figure` in memory as the file `path` names it: PNG bytes or an SVG
/// document, as its extension says (`path` is not written).
pub(super) fn render_figure<F: Figure>(
    path: &Path,
    size: (u32, u32),
    figure: &F,
) -> Result<Vec<u8>, PlotError> {
    match FigureFormat::of_path(path)? {
        FigureFormat::Png => {
            let rgb = render_rgb(path, size, figure)?;
            encode_png(&rgb, size).map_err(|e| draw_error(path)(Box::new(e)))
        }
        FigureFormat::Svg => Ok(render_svg(path, size, figure)?.into_bytes()),
    }
}

/// Renders in memory ([`render_figure`]) and only then writes `path` through the output layer
/// ([`write_bytes`]): a regular file via a temporary renamed into place (missing directories
/// created), a character device or FIFO in place; a drawing failure leaves no file behind.
pub(super) fn write_figure<F: Figure>(
    path: &Path,
    size: (u32, u32),
    figure: &F,
) -> Result<(), PlotError> {
    FigureFormat::of_path(path)?;
    if path.is_dir() {
        return Err(invalid(path, "the output path is an existing directory"));
    }
    let bytes = render_figure(path, size, figure)?;
    write_bytes(path, &[], &bytes)?;
    Ok(())
}

/// An RGB image of `size` as PNG bytes.
fn encode_png(rgb: &[u8], (w, h): (u32, u32)) -> Result<Vec<u8>, png::EncodingError> {
    let mut out = Vec::with_capacity(rgb.len() / 8);
    let mut enc = png::Encoder::new(&mut out, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_compression(png::Compression::Default);
    enc.set_adaptive_filter(png::AdaptiveFilterType::Adaptive);
    let mut writer = enc.write_header()?;
    writer.write_image_data(rgb)?;
    writer.finish()?;
    Ok(out)
}

fn render<DB, F>(root: &DrawingArea<DB, Shift>, figure: &F, scale: f64) -> DrawResult
where
    DB: DrawingBackend,
    DB::ErrorType: 'static,
    F: Figure,
{
    root.fill(&WHITE)?;
    figure.draw(root, scale)?;
    root.present()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_filter_averages_blocks() {
        // 2 × 1 figure from a 4 × 2 canvas (s = 2): left block black, right block half white
        let mut canvas = vec![0u8; 4 * 2 * 3];
        for (i, px) in canvas.chunks_exact_mut(3).enumerate() {
            let (x, y) = (i % 4, i / 4);
            if x >= 2 && (x + y) % 2 == 0 {
                px.fill(255);
            }
        }
        assert_eq!(downsample(&canvas, (2, 1), 2), vec![0, 0, 0, 128, 128, 128]);
        assert_eq!(supersampling(900, 600), 3);
        assert_eq!(supersampling(1260, 2560), 2);
        assert_eq!(supersampling(MAX_SIDE, MAX_SIDE), 1);
    }

    #[test]
    fn format_follows_extension() {
        assert_eq!(
            FigureFormat::of_path(Path::new("a/b.PNG")).ok(),
            Some(FigureFormat::Png)
        );
        assert_eq!(
            FigureFormat::of_path(Path::new("b.svg")).ok(),
            Some(FigureFormat::Svg)
        );
        assert!(matches!(
            FigureFormat::of_path(Path::new("b.pdf")),
            Err(PlotError::UnsupportedFormat { .. })
        ));
        assert!(FigureFormat::of_path(Path::new("noext")).is_err());
    }
}
