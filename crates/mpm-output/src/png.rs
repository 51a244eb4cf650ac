//! A PNG picture of a 2D state: every material point drawn as a square of
//! its sub-cell's size at its current position, coloured by a scalar (e.g.
//! the displacement magnitude or the plastic strain) on a blue–red scale.
//! No text, so no font is needed; the scale's range goes into the file
//! name's companion, the summary.

use std::io;
use std::path::Path;

use crate::OutputError;
use crate::atomic_write_with;

/// Largest side of the picture in pixels.
const SIZE: u32 = 800;

/// Writes `path` atomically: points at `position` (x, y) with half-sizes
/// `half` coloured by `value` between its minimum and maximum. Returns
/// that range.
///
/// # Errors
/// [`OutputError::Io`] when the file cannot be written,
/// [`OutputError::LengthMismatch`] for arrays of different lengths.
pub fn write_points_png(
    path: &Path,
    position: &[[f64; 3]],
    half: &[f64],
    value: &[f64],
) -> Result<(f64, f64), OutputError> {
    for (array, len) in [("half sizes", half.len()), ("values", value.len())] {
        if len != position.len() {
            return Err(OutputError::LengthMismatch {
                array: array.into(),
                expected: position.len(),
                found: len,
            });
        }
    }
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for (x, h) in position.iter().zip(half) {
        for i in 0..2 {
            lo[i] = lo[i].min(x[i] - h);
            hi[i] = hi[i].max(x[i] + h);
        }
    }
    let (vmin, vmax) = value
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(*v), b.max(*v))
        });
    let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    if position.is_empty() || !(extent.is_finite() && extent > 0.0) {
        return Err(OutputError::LengthMismatch {
            array: "positions (a picture needs points with a non-zero extent)".into(),
            expected: 1,
            found: 0,
        });
    }
    let margin = 0.05 * extent;
    let scale = f64::from(SIZE) / (extent + 2.0 * margin);
    let width = (((hi[0] - lo[0]) + 2.0 * margin) * scale).ceil().max(1.0) as u32;
    let height = (((hi[1] - lo[1]) + 2.0 * margin) * scale).ceil().max(1.0) as u32;
    let mut rgb = vec![255u8; (width * height * 3) as usize];
    let range = vmax - vmin;
    for ((x, h), v) in position.iter().zip(half).zip(value) {
        let t = if range > 0.0 { (v - vmin) / range } else { 0.5 };
        let colour = [
            (255.0 * t) as u8,
            (80.0 * (1.0 - (2.0 * t - 1.0).abs())) as u8,
            (255.0 * (1.0 - t)) as u8,
        ];
        let px = |c: f64, axis: usize| (c - lo[axis] + margin) * scale;
        let (x0, x1) = (
            px(x[0] - h, 0).floor() as i64,
            px(x[0] + h, 0).ceil() as i64,
        );
        let (y0, y1) = (
            px(x[1] - h, 1).floor() as i64,
            px(x[1] + h, 1).ceil() as i64,
        );
        for j in y0.max(0)..y1.min(i64::from(height)) {
            // Image rows run downwards.
            let row = i64::from(height) - 1 - j;
            for i in x0.max(0)..x1.min(i64::from(width)) {
                let k = ((row * i64::from(width) + i) * 3) as usize;
                rgb[k..k + 3].copy_from_slice(&colour);
            }
        }
    }
    atomic_write_with(path, |w| {
        let mut encoder = png::Encoder::new(w, width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(io::Error::other)?;
        writer.write_image_data(&rgb).map_err(io::Error::other)?;
        writer.finish().map_err(io::Error::other)
    })?;
    Ok((vmin, vmax))
}
