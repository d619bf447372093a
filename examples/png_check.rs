//! Checks that a PNG is not blank, for the browser check `.ci/html-check`:
//!
//! ```text
//! cargo run --release --example png_check -- SHOT.png [MIN_COLOURS] [MIN_INK_PERCENT]
//! ```
//!
//! Prints the size, the number of distinct colours and the share of pixels that differ from
//! the most common colour (the background); exits with status 1 when there are fewer than
//! `MIN_COLOURS` (default 16) distinct colours or less than `MIN_INK_PERCENT` (default 1) %
//! of the pixels differ from the background — a blank or nearly blank page — and 2 when the
//! file cannot be read as a PNG.

use std::collections::HashMap;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(path) = args.first() else {
        eprintln!("usage: png_check SHOT.png [MIN_COLOURS] [MIN_INK_PERCENT]");
        return ExitCode::from(2);
    };
    let min_colours: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(16);
    let min_ink: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1.0);
    let file = match std::fs::File::open(path) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("png_check: cannot open {path}: {e}");
            return ExitCode::from(2);
        }
    };
    let mut decoder = png::Decoder::new(file);
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = match decoder.read_info() {
        Ok(r) => r,
        Err(e) => {
            eprintln!("png_check: {path} is not a readable PNG: {e}");
            return ExitCode::from(2);
        }
    };
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = match reader.next_frame(&mut buf) {
        Ok(i) => i,
        Err(e) => {
            eprintln!("png_check: {path}: {e}");
            return ExitCode::from(2);
        }
    };
    let channels = info.color_type.samples();
    let mut counts: HashMap<u32, usize> = HashMap::new();
    for p in buf[..info.buffer_size()].chunks_exact(channels) {
        // grey or grey+alpha expands to one channel (or two), colour to three (or four)
        let rgb = match channels {
            1 | 2 => [p[0], p[0], p[0]],
            _ => [p[0], p[1], p[2]],
        };
        *counts
            .entry(u32::from_be_bytes([0, rgb[0], rgb[1], rgb[2]]))
            .or_default() += 1;
    }
    let total = (info.width as usize * info.height as usize).max(1);
    let background = counts.values().copied().max().unwrap_or(0);
    let ink = 100.0 * (total - background) as f64 / total as f64;
    println!(
        "{path}: {} × {} pixels, {} distinct colours, {ink:.1} % differ from the background",
        info.width,
        info.height,
        counts.len()
    );
    if counts.len() < min_colours || ink < min_ink {
        eprintln!(
            "png_check: {path} looks blank (fewer than {min_colours} colours or under {min_ink} % ink)"
        );
        return ExitCode::from(1);
    }
    ExitCode::SUCCESS
}
