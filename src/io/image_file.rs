//! Image output: the renderer's linear RGB f32 buffer (rows top to bottom) as PFM, OpenEXR or
//! 8-bit sRGB PNG.

use super::scene_data::IoError;
use std::io::{BufWriter, Write};
use std::path::Path;

/// The image formats [`write_image`] chooses from by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// Portable float map: linear RGB f32, lossless.
    Pfm,
    /// OpenEXR: linear RGB f32, lossless.
    Exr,
    /// 8-bit sRGB, values clamped to [0, 1] (no exposure or tone curve beyond that).
    Png,
}

impl ImageFormat {
    /// The format `path`'s extension (case-insensitive) names, or an error naming the file.
    /// Lets a caller reject an output path before spending time on a render.
    pub fn from_path(path: &Path) -> Result<ImageFormat, IoError> {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        match extension.as_deref() {
            Some("pfm") => Ok(ImageFormat::Pfm),
            Some("exr") => Ok(ImageFormat::Exr),
            Some("png") => Ok(ImageFormat::Png),
            _ => Err(IoError::new(format!(
                "cannot write image {}: unsupported file extension (expected .pfm, .exr or .png)",
                path.display()
            ))),
        }
    }
}

/// Writes `rgb` (width × height RGB triples, rows top to bottom) in the format named by the
/// extension of `path`: `.pfm`, `.exr` or `.png`.
pub fn write_image(path: &Path, width: u32, height: u32, rgb: &[f32]) -> Result<(), IoError> {
    match ImageFormat::from_path(path)? {
        ImageFormat::Pfm => write_pfm(path, width, height, rgb),
        ImageFormat::Exr => write_exr(path, width, height, rgb),
        ImageFormat::Png => write_png(path, width, height, rgb),
    }
}

fn check_buffer(path: &Path, width: u32, height: u32, rgb: &[f32]) -> Result<usize, IoError> {
    let needed = (width as usize)
        .checked_mul(height as usize)
        .and_then(|n| n.checked_mul(3));
    match needed {
        Some(n) if width > 0 && height > 0 && rgb.len() == n => Ok(n),
        _ => Err(IoError::new(format!(
            "cannot write image {}: the buffer holds {} floats, not the {width} x {height} x 3 of a non-empty RGB image",
            path.display(),
            rgb.len()
        ))),
    }
}

fn write_error(path: &Path, e: impl std::fmt::Display) -> IoError {
    IoError::new(format!("cannot write image {}: {e}", path.display()))
}

/// Portable float map: header `PF\n<width> <height>\n-1.0\n` (negative scale: little-endian),
/// then RGB f32 triples with rows from the bottom of the image to the top.
pub fn write_pfm(path: &Path, width: u32, height: u32, rgb: &[f32]) -> Result<(), IoError> {
    check_buffer(path, width, height, rgb)?;
    let file = std::fs::File::create(path).map_err(|e| write_error(path, e))?;
    let mut out = BufWriter::new(file);
    let row = width as usize * 3;
    let result = (|| -> std::io::Result<()> {
        write!(out, "PF\n{width} {height}\n-1.0\n")?;
        for line in rgb.chunks_exact(row).rev() {
            let mut bytes = Vec::with_capacity(row * 4);
            for v in line {
                bytes.extend_from_slice(&v.to_le_bytes());
            }
            out.write_all(&bytes)?;
        }
        out.flush()
    })();
    result.map_err(|e| write_error(path, e))
}

/// Reads a PFM file (`PF` colour or `Pf` greyscale, either byte order) and returns width,
/// height and RGB floats with rows top to bottom, like the renderer's buffers.
pub fn read_pfm(path: &Path) -> Result<(u32, u32, Vec<f32>), IoError> {
    let bytes = std::fs::read(path)
        .map_err(|e| IoError::new(format!("cannot read image {}: {e}", path.display())))?;
    let bad = |what: &str| {
        IoError::new(format!(
            "{} is not a valid PFM file: {what}",
            path.display()
        ))
    };
    // Four whitespace-separated header tokens, then exactly one whitespace byte.
    let mut tokens = Vec::new();
    let mut i = 0;
    while tokens.len() < 4 {
        while i < bytes.len() && bytes[i].is_ascii_whitespace() {
            i += 1;
        }
        let start = i;
        while i < bytes.len() && !bytes[i].is_ascii_whitespace() {
            i += 1;
        }
        if start == i || i >= bytes.len() {
            return Err(bad("the header is truncated"));
        }
        tokens.push(String::from_utf8_lossy(&bytes[start..i]).into_owned());
    }
    let data = &bytes[i + 1..];
    let channels = match tokens[0].as_str() {
        "PF" => 3,
        "Pf" => 1,
        _ => return Err(bad("it does not start with PF or Pf")),
    };
    let width: u32 = tokens[1].parse().map_err(|_| bad("bad width"))?;
    let height: u32 = tokens[2].parse().map_err(|_| bad("bad height"))?;
    let scale: f32 = tokens[3].parse().map_err(|_| bad("bad scale"))?;
    if width == 0 || height == 0 || scale == 0.0 || !scale.is_finite() {
        return Err(bad("zero size or scale"));
    }
    let little_endian = scale < 0.0;
    let row = width as usize * channels;
    let expected = row
        .checked_mul(height as usize)
        .and_then(|n| n.checked_mul(4))
        .ok_or_else(|| bad("the size overflows"))?;
    if data.len() != expected {
        return Err(bad(&format!(
            "{} bytes of pixel data instead of {expected}",
            data.len()
        )));
    }
    let floats: Vec<f32> = data
        .chunks_exact(4)
        .map(|b| {
            let b = [b[0], b[1], b[2], b[3]];
            if little_endian {
                f32::from_le_bytes(b)
            } else {
                f32::from_be_bytes(b)
            }
        })
        .collect();
    let mut rgb = Vec::with_capacity(width as usize * height as usize * 3);
    for line in floats.chunks_exact(row).rev() {
        if channels == 3 {
            rgb.extend_from_slice(line);
        } else {
            rgb.extend(line.iter().flat_map(|&v| [v; 3]));
        }
    }
    Ok((width, height, rgb))
}

/// OpenEXR with linear f32 R, G, B channels.
pub fn write_exr(path: &Path, width: u32, height: u32, rgb: &[f32]) -> Result<(), IoError> {
    check_buffer(path, width, height, rgb)?;
    let w = width as usize;
    exr::prelude::write_rgb_file(path, w, height as usize, |x, y| {
        let i = (y * w + x) * 3;
        (rgb[i], rgb[i + 1], rgb[i + 2])
    })
    .map_err(|e| write_error(path, e))
}

/// 8-bit PNG: each channel clamped to [0, 1], then encoded with the sRGB transfer curve.
/// Non-finite values (NaN) become 0.
pub fn write_png(path: &Path, width: u32, height: u32, rgb: &[f32]) -> Result<(), IoError> {
    check_buffer(path, width, height, rgb)?;
    let bytes: Vec<u8> = rgb.iter().map(|&v| srgb_encode(v)).collect();
    let image = image::RgbImage::from_raw(width, height, bytes)
        .ok_or_else(|| write_error(path, "the buffer does not match the image size"))?;
    image
        .save_with_format(path, image::ImageFormat::Png)
        .map_err(|e| write_error(path, e))
}

/// Linear value → 8-bit sRGB code.
fn srgb_encode(linear: f32) -> u8 {
    let v = if linear.is_nan() {
        0.0
    } else {
        linear.clamp(0.0, 1.0)
    };
    let encoded = if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    (encoded * 255.0 + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::srgb_encode;

    #[test]
    fn srgb_curve_end_points_and_mid_grey() {
        assert_eq!(srgb_encode(0.0), 0);
        assert_eq!(srgb_encode(-1.0), 0);
        assert_eq!(srgb_encode(f32::NAN), 0);
        assert_eq!(srgb_encode(1.0), 255);
        assert_eq!(srgb_encode(7.0), 255);
        assert_eq!(srgb_encode(f32::INFINITY), 255);
        // 18% grey encodes to about 118 in sRGB.
        assert_eq!(srgb_encode(0.18), 118);
    }
}
