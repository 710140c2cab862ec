//! Environment maps in: Radiance RGBE (`.hdr`, with the `image` crate) and OpenEXR (`.exr`,
//! with the `exr` crate) as linear RGB floats for [`crate::scene::EnvironmentDesc`].

use super::scene_data::IoError;
use std::path::Path;

/// Reads an equirectangular (latitude-longitude) environment map by its file extension
/// (case-insensitive): `.hdr` (Radiance RGBE) or `.exr` (OpenEXR; the first layer's R, G and
/// B channels at its largest resolution, alpha ignored). Returns the linear RGB texels, 3
/// floats each, rows from the top, and the width and height.
///
/// The map is used as it is stored: see [`crate::scene::EnvironmentDesc`] for how its texels
/// map to directions (+Y up, the centre looking along +Z). Every value must be finite and
/// >= 0 (radiance); a texel that is not is an error naming it.
pub fn load_environment(path: &Path) -> Result<(Vec<f32>, u32, u32), IoError> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    let (pixels, width, height) = match extension.as_deref() {
        Some("hdr") => read_hdr(path)?,
        Some("exr") => read_exr(path)?,
        _ => {
            return Err(IoError::new(format!(
                "cannot load environment {}: unsupported file extension (expected .hdr or .exr)",
                path.display()
            )));
        }
    };
    if width == 0 || height == 0 || pixels.len() != width as usize * height as usize * 3 {
        return Err(IoError::new(format!(
            "cannot load environment {}: the image is {width} x {height} texels",
            path.display()
        )));
    }
    if let Some((i, value)) = pixels
        .iter()
        .enumerate()
        .find(|(_, v)| !(**v >= 0.0 && v.is_finite()))
    {
        let texel = i / 3;
        return Err(IoError::new(format!(
            "cannot use environment {}: texel (column {}, row {}) has {} = {value}; radiance must be finite and >= 0",
            path.display(),
            texel % width as usize,
            texel / width as usize,
            ["R", "G", "B"][i % 3]
        )));
    }
    Ok((pixels, width, height))
}

fn read_error(path: &Path, e: impl std::fmt::Display) -> IoError {
    IoError::new(format!("cannot load environment {}: {e}", path.display()))
}

fn read_hdr(path: &Path) -> Result<(Vec<f32>, u32, u32), IoError> {
    let file = std::fs::File::open(path).map_err(|e| read_error(path, e))?;
    let image =
        image::ImageReader::with_format(std::io::BufReader::new(file), image::ImageFormat::Hdr)
            .decode()
            .map_err(|e| read_error(path, e))?
            .into_rgb32f();
    let (width, height) = image.dimensions();
    Ok((image.into_raw(), width, height))
}

fn read_exr(path: &Path) -> Result<(Vec<f32>, u32, u32), IoError> {
    /// The texels and the width they are stored with.
    type Texels = (usize, Vec<f32>);
    let image = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |size, _channels| -> Texels { (size.width(), vec![0.0; size.area() * 3]) },
        |(width, texels): &mut Texels, position, (r, g, b, _a): (f32, f32, f32, f32)| {
            let i = (position.y() * *width + position.x()) * 3;
            texels[i..i + 3].copy_from_slice(&[r, g, b]);
        },
    )
    .map_err(|e| read_error(path, e))?;
    let size = image.layer_data.size;
    let (_, texels) = image.layer_data.channel_data.pixels;
    let side = |n: usize| u32::try_from(n).map_err(|_| read_error(path, "the image is too large"));
    Ok((texels, side(size.width())?, side(size.height())?))
}
