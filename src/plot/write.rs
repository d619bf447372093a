//! Writing a figure: the format follows the extension (PNG or SVG), the figure is rendered in
//! memory first and then written to a temporary sibling that is renamed into place.

use std::error::Error as StdError;
use std::fs;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::error::{invalid, PlotError};
use super::fonts::ensure_font;
use crate::atomic_write::PendingTemporary;

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

/// Validates, renders in memory, and only then creates directories and writes `path` (through a
/// temporary sibling renamed into place).
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
    let io_err = |source: std::io::Error| PlotError::Io {
        path: path.to_path_buf(),
        source,
    };

    // Render first so that a drawing failure leaves no file behind.
    let mut rgb = Vec::new();
    let mut svg = String::new();
    match format {
        FigureFormat::Png => {
            rgb = vec![255u8; w as usize * h as usize * 3];
            let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
            render(&root, figure).map_err(draw_err)?;
        }
        FigureFormat::Svg => {
            let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
            render(&root, figure).map_err(draw_err)?;
        }
    }

    if let Some(parent) = path.parent() {
        if !parent.as_os_str().is_empty() {
            fs::create_dir_all(parent).map_err(io_err)?;
        }
    }
    // written to a temporary sibling and renamed into place: never a half-written figure, and
    // an existing file (or hard link) at `path` is replaced, not truncated
    let pending = PendingTemporary::new(path);
    let tmp = pending.path();
    let written = match format {
        FigureFormat::Png => {
            let mut backend = BitMapBackend::new(tmp, size);
            backend
                .blit_bitmap((0, 0), size, &rgb)
                .and_then(|()| backend.present())
                .map_err(|e| draw_err(Box::new(e)))
        }
        FigureFormat::Svg => fs::write(tmp, svg).map_err(io_err),
    }
    .and_then(|()| fs::rename(tmp, path).map_err(io_err));
    if written.is_err() {
        let _ = fs::remove_file(tmp);
    }
    written
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
