//! Writing a figure: the format follows the extension (PNG or SVG), the figure is rendered and
//! encoded in memory first and then written through the output layer
//! ([`output_files`](crate::output_files)).

use std::error::Error as StdError;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::error::{invalid, PlotError};
use super::fonts::ensure_font;
use crate::output_files::write_bytes;

/// Largest accepted figure side, in pixels (guards against huge allocations).
pub const MAX_SIDE: u32 = 16_384;

pub(super) type DrawResult = Result<(), Box<dyn StdError + Send + Sync>>;

/// Something that can draw itself onto any plotters backend.
pub(super) trait Figure {
    fn draw<DB>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
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

/// Validates, renders in memory (PNG encoded in memory too), and only then writes `path`
/// through the output layer ([`write_bytes`]): a regular file via a temporary renamed into
/// place (missing directories created), a character device or FIFO in place.
pub(super) fn write_figure<F: Figure>(
    path: &Path,
    size: (u32, u32),
    figure: &F,
) -> Result<(), PlotError> {
    let format = FigureFormat::of_path(path)?;
    let (w, h) = size;
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(invalid(
            path,
            format!("figure size {w} × {h} must be between 1 and {MAX_SIDE} pixels per side"),
        ));
    }
    if path.is_dir() {
        return Err(invalid(path, "the output path is an existing directory"));
    }
    if !ensure_font() {
        return Err(PlotError::Font {
            path: path.to_path_buf(),
        });
    }
    let draw_err = |source: Box<dyn StdError + Send + Sync>| PlotError::Draw {
        path: path.to_path_buf(),
        source,
    };

    // Render first so that a drawing failure leaves no file behind.
    let bytes = match format {
        FigureFormat::Png => {
            let mut rgb = vec![255u8; w as usize * h as usize * 3];
            {
                let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
                render(&root, figure).map_err(draw_err)?;
            }
            encode_png(&rgb, size).map_err(|e| draw_err(Box::new(e)))?
        }
        FigureFormat::Svg => {
            let mut svg = String::new();
            {
                let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
                render(&root, figure).map_err(draw_err)?;
            }
            svg.into_bytes()
        }
    };
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

fn render<DB, F>(root: &DrawingArea<DB, Shift>, figure: &F) -> DrawResult
where
    DB: DrawingBackend,
    DB::ErrorType: 'static,
    F: Figure,
{
    root.fill(&WHITE)?;
    figure.draw(root)?;
    root.present()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

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
