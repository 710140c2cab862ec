//! Image textures: the host's description, and the validated copy the kernel samples.
//!
//! Coordinates follow glTF: uv (0, 0) is the top-left corner of the image (the first texel
//! of the first row), u grows to the right and v downwards. Texel (i, j) covers
//! [i/w, (i+1)/w] × [j/h, (j+1)/h], so its centre is ((i + 0.5)/w, (j + 0.5)/h).

// Materials do not sample textures yet; until they do only the tests use `Texture`.
#![cfg_attr(not(test), allow(dead_code))]

use std::sync::OnceLock;

use crate::error::{Error, MLT_STATUS_OUT_OF_MEMORY, Result, check_finite};
use std::borrow::Cow;

/// Largest width or height of a texture, in texels.
pub const MLT_MAX_TEXTURE_SIDE: u32 = 1 << 15;
/// Most texels of a texture (width × height): 2^28, 16384 × 16384 — 1 GiB as 8-bit RGBA,
/// 4 GiB as float RGBA.
pub const MLT_MAX_TEXTURE_TEXELS: u64 = 1 << 28;

/// The texel values of a texture, row-major from the top row of the image to the bottom,
/// channels interleaved. Borrowed from the host, or owned (a loaded file's images).
#[derive(Clone, Debug, PartialEq)]
pub enum TexelData<'a> {
    /// 8-bit values, 255 meaning 1; decoded according to the [`TextureEncoding`].
    U8(Cow<'a, [u8]>),
    /// Linear floats, finite and >= 0 (above 1 is allowed: emission may be HDR).
    F32(Cow<'a, [f32]>),
}

/// How the colour channels of 8-bit data encode linear values. Alpha (the 4th channel, or
/// the 2nd of a grey + alpha image) is always linear.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TextureEncoding {
    /// The sRGB transfer function (IEC 61966-2-1), as glTF base colour and emissive images
    /// use. Only for [`TexelData::U8`].
    Srgb,
    /// value / 255 for 8-bit data (glTF normal, metallic-roughness and occlusion images);
    /// the value itself for float data.
    Linear,
}

/// What a coordinate outside [0, 1] reads: glTF's sampler `wrapS` / `wrapT`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum WrapMode {
    /// The image tiles the plane (glTF's default).
    #[default]
    Repeat,
    /// The edge texels extend outwards.
    ClampToEdge,
    /// The image tiles with period 2, mirrored on every odd tile.
    MirroredRepeat,
}

/// How a point between texel centres is read.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum TextureFilter {
    /// The texel containing the point.
    Nearest,
    /// The four texels around the point, weighted by distance (on linear values).
    #[default]
    Bilinear,
}

/// A texture as the host passes it.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureDesc<'a> {
    pub width: u32,
    pub height: u32,
    /// 1 (grey), 2 (grey, alpha), 3 (RGB) or 4 (RGBA).
    pub channels: u32,
    /// width × height × channels values.
    pub data: TexelData<'a>,
    pub encoding: TextureEncoding,
    /// Along u (glTF `wrapS`).
    pub wrap_u: WrapMode,
    /// Along v (glTF `wrapT`).
    pub wrap_v: WrapMode,
    pub filter: TextureFilter,
}

impl TextureDesc<'_> {
    /// Checks a texture's size (reported as `desc.textures[index]`): each side in [1,
    /// [`MLT_MAX_TEXTURE_SIDE`]], at most [`MLT_MAX_TEXTURE_TEXELS`] texels, 1 to 4 channels.
    /// Returns the number of values its data must hold (width × height × channels, at
    /// most 2^30), so a host's array can be sized before it is read.
    pub fn value_count(width: u32, height: u32, channels: u32, index: usize) -> Result<usize> {
        let name = format!("desc.textures[{index}]");
        for (field, side) in [("width", width), ("height", height)] {
            if side == 0 {
                return Err(Error::invalid(format!(
                    "{name}.{field} is 0; a texture needs at least 1 x 1 texels"
                )));
            }
            if side > MLT_MAX_TEXTURE_SIDE {
                return Err(Error::invalid(format!(
                    "{name}.{field} is {side}; each side may be at most {MLT_MAX_TEXTURE_SIDE} texels"
                )));
            }
        }
        let texel_count = width as u64 * height as u64;
        if texel_count > MLT_MAX_TEXTURE_TEXELS {
            return Err(Error::invalid(format!(
                "{name} is {width} x {height} texels; a texture may have at most {MLT_MAX_TEXTURE_TEXELS}"
            )));
        }
        if !(1..=4).contains(&channels) {
            return Err(Error::invalid(format!(
                "{name}.channels is {channels}; it must be 1 (grey), 2 (grey, alpha), 3 (RGB) or 4 (RGBA)"
            )));
        }
        // At most 2^28 texels of 4 channels: fits any usize of 32 bits or more.
        usize::try_from(texel_count * channels as u64)
            .map_err(|_| Error::invalid(format!("{name} is too large for this platform")))
    }
}

/// The texels of one level, kept at the host's precision: an 8-bit texture takes a quarter
/// of the memory floats would, at every level.
#[derive(Clone, Debug)]
enum Texels {
    U8(Box<[u8]>),
    F32(Box<[f32]>),
}

/// One level of a texture's mip pyramid: the host's image (level 0) or a reduction of it.
#[derive(Clone, Debug)]
struct Level {
    width: u32,
    height: u32,
    texels: Texels,
}

/// A validated texture, sampled by the kernel: the host's image and its mip pyramid.
///
/// Level k + 1 is level k reduced to max(1, ⌊side / 2⌋) texels per side by an exact box
/// filter: each new texel averages the old texels its area covers, weighted by the covered
/// fraction (2 × 2 texels of ¼ for even sides; along an odd side, 3 texels partly), so every
/// level keeps the image's mean. The boxes
/// lie inside the image, so the reduction never reads across an edge: the wrap modes apply at
/// lookup, at every level alike. Colours are averaged as linear values (sRGB bytes decoded
/// first) and stored back in the level 0's encoding, each value the byte whose decoded value
/// is nearest; the next level is reduced from the unrounded values, so rounding does not
/// accumulate down the pyramid. A square power-of-two texture grows by a third.
#[derive(Clone, Debug)]
pub(crate) struct Texture {
    channels: u32,
    /// Level 0 first; down to 1 × 1.
    levels: Box<[Level]>,
    /// Decodes the colour channels of 8-bit levels: the sRGB table or the linear one.
    colour_table: &'static [f32; 256],
    /// √(width × height) of level 0: texels per unit of texture coordinate, on average over
    /// the two axes (what an isotropic footprint is measured in).
    texels_per_unit: f32,
    wrap_u: WrapMode,
    wrap_v: WrapMode,
    filter: TextureFilter,
}

/// 8-bit value → value / 255.
static LINEAR_U8_TO_F32: [f32; 256] = linear_u8_table();

const fn linear_u8_table() -> [f32; 256] {
    let mut table = [0.0; 256];
    let mut i = 0;
    while i < 256 {
        table[i] = i as f32 / 255.0;
        i += 1;
    }
    table
}

/// 8-bit sRGB value → linear value, by the exact IEC 61966-2-1 formula.
fn srgb_u8_table() -> &'static [f32; 256] {
    static TABLE: OnceLock<[f32; 256]> = OnceLock::new();
    TABLE.get_or_init(|| {
        std::array::from_fn(|i| {
            let encoded = i as f64 / 255.0;
            let linear = if encoded <= 0.04045 {
                encoded / 12.92
            } else {
                ((encoded + 0.055) / 1.055).powf(2.4)
            };
            linear as f32
        })
    })
}

/// The byte whose value in `table` (increasing) is nearest to `linear`.
fn nearest_byte(table: &[f32; 256], linear: f32) -> u8 {
    let above = table.partition_point(|&v| v < linear);
    if above == 0 {
        return 0;
    }
    if above == 256 {
        return 255;
    }
    if linear - table[above - 1] <= table[above] - linear {
        (above - 1) as u8
    } else {
        above as u8
    }
}

/// Allocates `len` zeros, reporting an allocation failure instead of aborting.
fn try_zeroed<T: Copy + Default>(len: usize, name: &str) -> Result<Vec<T>> {
    let mut values = Vec::new();
    values.try_reserve_exact(len).map_err(|_| {
        Error::new(
            MLT_STATUS_OUT_OF_MEMORY,
            format!("could not allocate the mip levels of {name}"),
        )
    })?;
    values.resize(len, T::default());
    Ok(values)
}

/// The weights of an exact box reduction of `from` texels to `to` (⌊from / 2⌋, or 1): for
/// each new texel, its first old texel and the weights of up to 3 old texels (summing to 1).
fn box_weights(from: u32, to: u32) -> impl Iterator<Item = (usize, [f32; 3])> {
    // New texel j covers old texels [j·from/to, (j+1)·from/to), a stretch of from/to ≥ 2
    // (below 3) old texels; in units of 1/to of an old texel, [j·from, (j+1)·from).
    let (from, to) = (from as u64, to as u64);
    (0..to).map(move |j| {
        let (start, end) = (j * from, (j + 1) * from);
        let first = start / to;
        let mut weights = [0.0f32; 3];
        for (k, weight) in weights.iter_mut().enumerate() {
            let (texel_start, texel_end) = ((first + k as u64) * to, (first + k as u64 + 1) * to);
            let overlap = end.min(texel_end).saturating_sub(start.max(texel_start));
            *weight = overlap as f32 / from as f32;
        }
        (first as usize, weights)
    })
}

/// Level `values` (`width` × `height` texels of `channels` linear values) reduced to the
/// next level's size, returned with it.
fn reduce(
    values: &[f32],
    width: u32,
    height: u32,
    channels: usize,
    name: &str,
) -> Result<(Vec<f32>, u32, u32)> {
    let (new_width, new_height) = ((width / 2).max(1), (height / 2).max(1));
    // Along rows first, then along columns.
    let mut rows = try_zeroed::<f32>(new_width as usize * height as usize * channels, name)?;
    for row in 0..height as usize {
        let source = &values[row * width as usize * channels..][..width as usize * channels];
        let target =
            &mut rows[row * new_width as usize * channels..][..new_width as usize * channels];
        for (j, (first, weights)) in box_weights(width, new_width).enumerate() {
            for (k, weight) in weights.into_iter().enumerate() {
                if weight > 0.0 {
                    for c in 0..channels {
                        target[j * channels + c] += weight * source[(first + k) * channels + c];
                    }
                }
            }
        }
    }
    let row_len = new_width as usize * channels;
    let mut reduced = try_zeroed::<f32>(row_len * new_height as usize, name)?;
    for (j, (first, weights)) in box_weights(height, new_height).enumerate() {
        let target = &mut reduced[j * row_len..][..row_len];
        for (k, weight) in weights.into_iter().enumerate() {
            if weight > 0.0 {
                let source = &rows[(first + k) * row_len..][..row_len];
                for (t, s) in target.iter_mut().zip(source) {
                    *t += weight * s;
                }
            }
        }
    }
    Ok((reduced, new_width, new_height))
}

impl Texture {
    /// Validates `desc` (reported as `desc.textures[index]`), copies its texels and builds
    /// the mip pyramid.
    pub(crate) fn new(desc: &TextureDesc, index: usize) -> Result<Texture> {
        let name = format!("desc.textures[{index}]");
        let (width, height, channels) = (desc.width, desc.height, desc.channels);
        let expected = TextureDesc::value_count(width, height, channels, index)? as u64;
        let (length, kind) = match &desc.data {
            TexelData::U8(values) => (values.len(), "8-bit values"),
            TexelData::F32(values) => (values.len(), "floats"),
        };
        if length as u64 != expected {
            return Err(Error::invalid(format!(
                "{name}.data has {length} {kind}, but {width} x {height} texels of {channels} channels need {expected}"
            )));
        }
        let colour_table = match desc.encoding {
            TextureEncoding::Srgb => srgb_u8_table(),
            TextureEncoding::Linear => &LINEAR_U8_TO_F32,
        };
        let texels = match &desc.data {
            TexelData::U8(values) => Texels::U8(copy_texels(values.as_ref(), &name)?),
            TexelData::F32(values) => {
                if desc.encoding == TextureEncoding::Srgb {
                    return Err(Error::invalid(format!(
                        "{name}.encoding is Srgb, but the data are floats; sRGB applies to 8-bit data only (floats are linear)"
                    )));
                }
                // Negative values have no meaning as colour, alpha or encoded normals.
                if let Some(i) = values.iter().position(|v| !(*v >= 0.0 && v.is_finite())) {
                    let channel = i % channels as usize;
                    let texel = i / channels as usize;
                    return Err(Error::invalid(format!(
                        "{name}.data[{i}] (row {}, column {}, channel {channel}) is {}; texel values must be finite and >= 0",
                        texel / width as usize,
                        texel % width as usize,
                        values[i]
                    )));
                }
                Texels::F32(copy_texels(values.as_ref(), &name)?)
            }
        };
        let mut texture = Texture {
            channels,
            levels: Box::new([Level {
                width,
                height,
                texels,
            }]),
            colour_table,
            texels_per_unit: ((width as f64 * height as f64).sqrt()) as f32,
            wrap_u: desc.wrap_u,
            wrap_v: desc.wrap_v,
            filter: desc.filter,
        };
        texture.levels = texture.pyramid(&name)?;
        Ok(texture)
    }

    /// Level 0 and its reductions down to 1 × 1 (see [`Texture`]).
    fn pyramid(&self, name: &str) -> Result<Box<[Level]>> {
        let level0 = &self.levels[0];
        let channels = self.channels as usize;
        let (mut width, mut height) = (level0.width, level0.height);
        let mut levels = vec![level0.clone()];
        if width == 1 && height == 1 {
            return Ok(levels.into_boxed_slice());
        }
        // The linear values of the level being reduced, unrounded.
        let mut linear = try_zeroed::<f32>(width as usize * height as usize * channels, name)?;
        for (i, value) in linear.iter_mut().enumerate() {
            *value = self.value(0, i);
        }
        while width > 1 || height > 1 {
            let (reduced, new_width, new_height) = reduce(&linear, width, height, channels, name)?;
            let texels = match level0.texels {
                Texels::F32(_) => Texels::F32(reduced.clone().into_boxed_slice()),
                Texels::U8(_) => {
                    let mut bytes = try_zeroed::<u8>(reduced.len(), name)?;
                    for (i, (byte, &value)) in bytes.iter_mut().zip(&reduced).enumerate() {
                        *byte = nearest_byte(self.table_of(i % channels), value);
                    }
                    Texels::U8(bytes.into_boxed_slice())
                }
            };
            levels.push(Level {
                width: new_width,
                height: new_height,
                texels,
            });
            (linear, width, height) = (reduced, new_width, new_height);
        }
        Ok(levels.into_boxed_slice())
    }

    /// The table decoding 8-bit channel `channel` (of the texture's own channels): alpha
    /// (the last of 2 or 4) is always linear.
    #[inline]
    fn table_of(&self, channel: usize) -> &'static [f32; 256] {
        let channels = self.channels as usize;
        if channels.is_multiple_of(2) && channel == channels - 1 {
            &LINEAR_U8_TO_F32
        } else {
            self.colour_table
        }
    }

    /// The linear value of the `i`-th stored value (texel i / channels, channel i % channels)
    /// of level `level`.
    #[inline]
    fn value(&self, level: usize, i: usize) -> f32 {
        match &self.levels[level].texels {
            Texels::U8(bytes) => self.table_of(i % self.channels as usize)[bytes[i] as usize],
            Texels::F32(floats) => floats[i],
        }
    }

    /// Levels in the pyramid (1 for a 1 × 1 texture).
    pub(crate) fn level_count(&self) -> usize {
        self.levels.len()
    }

    /// √(width × height) of the image: texels per unit of texture coordinate.
    #[inline]
    pub(crate) fn texels_per_unit(&self) -> f32 {
        self.texels_per_unit
    }

    /// The linear RGBA value at `uv` of the image itself (level 0): grey g reads (g, g, g,
    /// 1), grey + alpha (g, g, g, a), RGB (r, g, b, 1). A non-finite coordinate reads as 0
    /// (so NaN from a degenerate hit gives a texel of the image, never a panic); one beyond
    /// ±1e30 as ±1e30.
    #[inline]
    pub(crate) fn sample(&self, uv: [f32; 2]) -> [f32; 4] {
        self.sample_level(0, uv)
    }

    /// The value at `uv` for a footprint `level_of_detail` = log2(the footprint's width in
    /// level-0 texels): level 0 at or below 0 (and for NaN), else the two levels around it
    /// blended linearly (trilinear filtering), the coarsest beyond the pyramid.
    #[inline]
    pub(crate) fn sample_filtered(&self, uv: [f32; 2], level_of_detail: f32) -> [f32; 4] {
        // NaN is not above 0: level 0.
        if level_of_detail.is_nan() || level_of_detail <= 0.0 {
            return self.sample(uv);
        }
        let last = self.levels.len() - 1;
        let level_of_detail = level_of_detail.min(last as f32);
        let finer = level_of_detail.floor();
        let blend = level_of_detail - finer;
        let finer = finer as usize;
        let fine = self.sample_level(finer, uv);
        if blend == 0.0 || finer == last {
            return fine;
        }
        lerp4(fine, self.sample_level(finer + 1, uv), blend)
    }

    /// The linear RGBA value at `uv` of level `level`.
    fn sample_level(&self, level: usize, uv: [f32; 2]) -> [f32; 4] {
        let [u, v] = uv.map(sanitize_coordinate);
        let Level {
            width: level_width,
            height: level_height,
            ..
        } = self.levels[level];
        let (width, height) = (level_width as f32, level_height as f32);
        match self.filter {
            TextureFilter::Nearest => {
                let column = wrap(self.wrap_u, (u * width).floor() as i64, level_width);
                let row = wrap(self.wrap_v, (v * height).floor() as i64, level_height);
                self.texel(level, column, row)
            }
            TextureFilter::Bilinear => {
                // Texel centres sit at half-integers: shift them onto the integers.
                let x = u * width - 0.5;
                let y = v * height - 0.5;
                let (x0, y0) = (x.floor(), y.floor());
                let (fx, fy) = (x - x0, y - y0);
                // `as` saturates; the +1 must too, for coordinates near the i64 limits.
                let (x0, y0) = (x0 as i64, y0 as i64);
                let columns = [
                    wrap(self.wrap_u, x0, level_width),
                    wrap(self.wrap_u, x0.saturating_add(1), level_width),
                ];
                let rows = [
                    wrap(self.wrap_v, y0, level_height),
                    wrap(self.wrap_v, y0.saturating_add(1), level_height),
                ];
                let top = lerp4(
                    self.texel(level, columns[0], rows[0]),
                    self.texel(level, columns[1], rows[0]),
                    fx,
                );
                let bottom = lerp4(
                    self.texel(level, columns[0], rows[1]),
                    self.texel(level, columns[1], rows[1]),
                    fx,
                );
                lerp4(top, bottom, fy)
            }
        }
    }

    /// The linear RGBA value of the texel in `column`, `row` (both in range) of `level`.
    #[inline]
    fn texel(&self, level: usize, column: u32, row: u32) -> [f32; 4] {
        let channels = self.channels as usize;
        let Level { width, texels, .. } = &self.levels[level];
        let start = (row as usize * *width as usize + column as usize) * channels;
        let mut values = [0.0; 4];
        match texels {
            Texels::U8(bytes) => {
                let bytes = &bytes[start..start + channels];
                // Grey + alpha and RGBA end with alpha, which is always linear.
                let colour_channels = if channels.is_multiple_of(2) {
                    channels - 1
                } else {
                    channels
                };
                for (c, &byte) in bytes.iter().enumerate() {
                    values[c] = if c < colour_channels {
                        self.colour_table[byte as usize]
                    } else {
                        LINEAR_U8_TO_F32[byte as usize]
                    };
                }
            }
            Texels::F32(floats) => {
                values[..channels].copy_from_slice(&floats[start..start + channels]);
            }
        }
        match channels {
            1 => [values[0], values[0], values[0], 1.0],
            2 => [values[0], values[0], values[0], values[1]],
            3 => [values[0], values[1], values[2], 1.0],
            _ => values,
        }
    }
}

/// Keeps `coordinate` × texture side finite: at 1e30 an f32 step spans far more than a tile,
/// so which texel such a coordinate reads is arbitrary anyway.
#[inline]
fn sanitize_coordinate(coordinate: f32) -> f32 {
    const LIMIT: f32 = 1e30;
    if coordinate.is_finite() {
        coordinate.clamp(-LIMIT, LIMIT)
    } else {
        0.0
    }
}

/// Copies the host's texels, reporting an allocation failure instead of aborting.
fn copy_texels<T: Copy>(values: &[T], name: &str) -> Result<Box<[T]>> {
    let mut copy = Vec::new();
    copy.try_reserve_exact(values.len()).map_err(|_| {
        Error::new(
            MLT_STATUS_OUT_OF_MEMORY,
            format!("could not allocate the {} values of {name}", values.len()),
        )
    })?;
    copy.extend_from_slice(values);
    Ok(copy.into_boxed_slice())
}

/// Maps a texel index, which may lie outside the image, to one inside it (`size` ≥ 1).
#[inline]
fn wrap(mode: WrapMode, index: i64, size: u32) -> u32 {
    let size = size as i64;
    let wrapped = match mode {
        WrapMode::Repeat => index.rem_euclid(size),
        WrapMode::ClampToEdge => index.clamp(0, size - 1),
        WrapMode::MirroredRepeat => {
            let period = index.rem_euclid(2 * size);
            if period < size {
                period
            } else {
                2 * size - 1 - period
            }
        }
    };
    wrapped as u32
}

#[inline]
fn lerp4(a: [f32; 4], b: [f32; 4], t: f32) -> [f32; 4] {
    std::array::from_fn(|c| a[c] + (b[c] - a[c]) * t)
}

/// A material's use of a texture: which one, and the affine map applied to the surface's
/// texture coordinates before the lookup (glTF `KHR_texture_transform`: scale, then
/// rotate, then offset).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureRef {
    /// Index into `SceneDesc::textures`.
    pub texture: u32,
    /// The texture coordinate set it is looked up at: 0 (`SceneDesc::texcoords`) or 1
    /// (`SceneDesc::texcoords1`), glTF's `texCoord`.
    pub texcoord: u32,
    pub offset: [f32; 2],
    /// Radians, counter-clockwise in uv space as `KHR_texture_transform` defines it.
    pub rotation: f32,
    pub scale: [f32; 2],
}

impl TextureRef {
    /// Texture `texture` at the surface's own coordinates.
    pub const fn new(texture: u32) -> Self {
        TextureRef {
            texture,
            texcoord: 0,
            offset: [0.0; 2],
            rotation: 0.0,
            scale: [1.0; 2],
        }
    }

    /// The transform as the rows of a 2×3 matrix applied to (u, v, 1).
    #[allow(dead_code)] // Until textures are looked up.
    pub(crate) fn matrix(&self) -> [[f32; 3]; 2] {
        let (sin, cos) = self.rotation.sin_cos();
        let [sx, sy] = self.scale;
        [
            [cos * sx, sin * sy, self.offset[0]],
            [-sin * sx, cos * sy, self.offset[1]],
        ]
    }

    pub(crate) fn validate(&self, name: &str, texture_count: usize) -> Result<()> {
        if self.texture as usize >= texture_count {
            return Err(Error::invalid(format!(
                "{name}.texture is {}, but there are only {texture_count} textures",
                self.texture
            )));
        }
        if self.texcoord > 1 {
            return Err(Error::invalid(format!(
                "{name}.texcoord is {}; the texture coordinate sets are 0 and 1",
                self.texcoord
            )));
        }
        check_finite(&format_args!("{name}.rotation"), self.rotation)?;
        for (field, value) in [("offset", self.offset), ("scale", self.scale)] {
            for (axis, v) in ["u", "v"].iter().zip(value) {
                check_finite(&format_args!("{name}.{field}.{axis}"), v)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::MLT_STATUS_INVALID_ARGUMENT;

    fn desc<'a>(width: u32, height: u32, channels: u32, data: TexelData<'a>) -> TextureDesc<'a> {
        TextureDesc {
            width,
            height,
            channels,
            data,
            encoding: TextureEncoding::Linear,
            wrap_u: WrapMode::ClampToEdge,
            wrap_v: WrapMode::ClampToEdge,
            filter: TextureFilter::Nearest,
        }
    }

    fn grey(value: f32) -> [f32; 4] {
        [value, value, value, 1.0]
    }

    fn assert_close(actual: [f32; 4], expected: [f32; 4], tolerance: f32) {
        for c in 0..4 {
            assert!(
                (actual[c] - expected[c]).abs() <= tolerance,
                "channel {c}: {actual:?} != {expected:?}"
            );
        }
    }

    #[test]
    fn first_row_is_the_top_and_u_grows_to_the_right() {
        // Row 0 holds 1, 2; row 1 holds 3, 4.
        let data = [1.0, 2.0, 3.0, 4.0];
        for filter in [TextureFilter::Nearest, TextureFilter::Bilinear] {
            let texture = Texture::new(
                &TextureDesc {
                    filter,
                    ..desc(2, 2, 1, TexelData::F32(Cow::Borrowed(&data)))
                },
                0,
            )
            .unwrap();
            assert_eq!(texture.sample([0.25, 0.25]), grey(1.0), "{filter:?}");
            assert_eq!(texture.sample([0.75, 0.25]), grey(2.0), "{filter:?}");
            assert_eq!(texture.sample([0.25, 0.75]), grey(3.0), "{filter:?}");
            assert_eq!(texture.sample([0.75, 0.75]), grey(4.0), "{filter:?}");
        }
    }

    #[test]
    fn srgb_bytes_decode_by_the_iec_formula() {
        let data = [0, 255, 128, 10];
        let texture = Texture::new(
            &TextureDesc {
                encoding: TextureEncoding::Srgb,
                ..desc(4, 1, 1, TexelData::U8(Cow::Borrowed(&data)))
            },
            0,
        )
        .unwrap();
        assert!(
            matches!(texture.levels[0].texels, Texels::U8(_)),
            "kept as bytes"
        );
        let at = |i: f32| texture.sample([(i + 0.5) / 4.0, 0.5]);
        assert_eq!(at(0.0), grey(0.0));
        assert_eq!(at(1.0), grey(1.0));
        // ((128/255 + 0.055) / 1.055)^2.4
        assert_close(at(2.0), grey(0.2158605), 1e-7);
        // 10/255 is below the 0.04045 knee: the linear segment.
        assert_close(at(3.0), grey(10.0 / 255.0 / 12.92), 1e-9);
    }

    #[test]
    fn srgb_alpha_stays_linear() {
        let rgba = [128, 128, 128, 128];
        let grey_alpha = [128, 128];
        for (channels, data) in [(4, &rgba[..]), (2, &grey_alpha[..])] {
            let texture = Texture::new(
                &TextureDesc {
                    encoding: TextureEncoding::Srgb,
                    ..desc(1, 1, channels, TexelData::U8(Cow::Borrowed(data)))
                },
                0,
            )
            .unwrap();
            let s = 0.2158605;
            assert_close(texture.sample([0.5, 0.5]), [s, s, s, 128.0 / 255.0], 1e-7);
        }
    }

    #[test]
    fn linear_bytes_divide_by_255() {
        let data = [0, 128, 255];
        let texture = Texture::new(&desc(3, 1, 1, TexelData::U8(Cow::Borrowed(&data))), 0).unwrap();
        assert_eq!(texture.sample([0.5 / 3.0, 0.5]), grey(0.0));
        assert_eq!(texture.sample([1.5 / 3.0, 0.5]), grey(128.0 / 255.0));
        assert_eq!(texture.sample([2.5 / 3.0, 0.5]), grey(1.0));
    }

    #[test]
    fn each_wrap_mode_reads_the_hand_derived_texel() {
        // Two texels, 10 and 20, along the axis under test. u = -0.25, 1.25, 2.75 are texel
        // centres (u·2 = -0.5, 2.5, 5.5):
        //   Repeat: u - floor(u) = 0.75, 0.25, 0.75 -> texels 1, 0, 1.
        //   ClampToEdge: 0, 1, 1 -> texels 0, 1, 1.
        //   MirroredRepeat: tiles [-1, 0] and [1, 2] are mirrored, [2, 3] is not:
        //   0.25, 2 - 1.25 = 0.75, 2.75 - 2 = 0.75 -> texels 0, 1, 1.
        let data = [10.0, 20.0];
        let coordinates = [-0.25, 1.25, 2.75];
        let cases = [
            (WrapMode::Repeat, [20.0, 10.0, 20.0]),
            (WrapMode::ClampToEdge, [10.0, 20.0, 20.0]),
            (WrapMode::MirroredRepeat, [10.0, 20.0, 20.0]),
        ];
        for (mode, expected) in cases {
            for filter in [TextureFilter::Nearest, TextureFilter::Bilinear] {
                let along_u = Texture::new(
                    &TextureDesc {
                        wrap_u: mode,
                        filter,
                        ..desc(2, 1, 1, TexelData::F32(Cow::Borrowed(&data)))
                    },
                    0,
                )
                .unwrap();
                let along_v = Texture::new(
                    &TextureDesc {
                        wrap_v: mode,
                        filter,
                        ..desc(1, 2, 1, TexelData::F32(Cow::Borrowed(&data)))
                    },
                    0,
                )
                .unwrap();
                for (t, value) in coordinates.into_iter().zip(expected) {
                    assert_eq!(
                        along_u.sample([t, 0.5]),
                        grey(value),
                        "{mode:?} {filter:?} u={t}"
                    );
                    assert_eq!(
                        along_v.sample([0.5, t]),
                        grey(value),
                        "{mode:?} {filter:?} v={t}"
                    );
                }
            }
        }
    }

    #[test]
    fn bilinear_at_an_edge_blends_with_the_wrapped_neighbour() {
        // u = 0 is halfway between texel 0 and the texel to its left.
        let data = [10.0, 20.0];
        let cases = [
            (WrapMode::Repeat, 15.0),
            (WrapMode::ClampToEdge, 10.0),
            (WrapMode::MirroredRepeat, 10.0),
        ];
        for (mode, expected) in cases {
            let texture = Texture::new(
                &TextureDesc {
                    wrap_u: mode,
                    filter: TextureFilter::Bilinear,
                    ..desc(2, 1, 1, TexelData::F32(Cow::Borrowed(&data)))
                },
                0,
            )
            .unwrap();
            assert_eq!(texture.sample([0.0, 0.5]), grey(expected), "{mode:?}");
        }
    }

    #[test]
    fn bilinear_between_four_texels_is_the_weighted_mix() {
        // RGB texels (v, 10 v, 0) with v = 1, 2 on the top row and 3, 4 below.
        let data = [
            1.0, 10.0, 0.0, 2.0, 20.0, 0.0, //
            3.0, 30.0, 0.0, 4.0, 40.0, 0.0,
        ];
        let texture = Texture::new(
            &TextureDesc {
                filter: TextureFilter::Bilinear,
                ..desc(2, 2, 3, TexelData::F32(Cow::Borrowed(&data)))
            },
            0,
        )
        .unwrap();
        // uv (0.375, 0.625): 0.25 of the way from the left centres to the right ones and
        // 0.75 from the top centres to the bottom ones. Weights 0.75·0.25, 0.25·0.25,
        // 0.75·0.75, 0.25·0.75 on 1, 2, 3, 4: 0.1875 + 0.125 + 1.6875 + 0.75 = 2.75.
        assert_close(texture.sample([0.375, 0.625]), [2.75, 27.5, 0.0, 1.0], 1e-6);
    }

    #[test]
    fn bilinear_at_a_texel_centre_is_that_texel() {
        let data: Vec<f32> = (0..4 * 4 * 4).map(|i| (i * 37 % 101) as f32).collect();
        let texture = Texture::new(
            &TextureDesc {
                wrap_u: WrapMode::Repeat,
                wrap_v: WrapMode::MirroredRepeat,
                filter: TextureFilter::Bilinear,
                ..desc(4, 4, 4, TexelData::F32(Cow::Borrowed(&data)))
            },
            0,
        )
        .unwrap();
        for row in 0..4 {
            for column in 0..4 {
                let uv = [(column as f32 + 0.5) / 4.0, (row as f32 + 0.5) / 4.0];
                let start = (row * 4 + column) * 4;
                let expected: [f32; 4] = data[start..start + 4].try_into().unwrap();
                assert_eq!(texture.sample(uv), expected, "row {row}, column {column}");
            }
        }
    }

    #[test]
    fn channels_expand_to_rgba() {
        let cases: [(&[f32], [f32; 4]); 4] = [
            (&[0.25], [0.25, 0.25, 0.25, 1.0]),
            (&[0.25, 0.5], [0.25, 0.25, 0.25, 0.5]),
            (&[0.1, 0.2, 0.3], [0.1, 0.2, 0.3, 1.0]),
            (&[0.1, 0.2, 0.3, 0.4], [0.1, 0.2, 0.3, 0.4]),
        ];
        for (data, expected) in cases {
            let channels = data.len() as u32;
            let texture = Texture::new(
                &desc(1, 1, channels, TexelData::F32(Cow::Borrowed(data))),
                0,
            )
            .unwrap();
            assert_eq!(texture.sample([0.5, 0.5]), expected, "{channels} channels");
        }
    }

    #[test]
    fn extreme_coordinates_read_a_texel_without_panicking() {
        let data = [10.0, 20.0, 30.0];
        for mode in [
            WrapMode::Repeat,
            WrapMode::ClampToEdge,
            WrapMode::MirroredRepeat,
        ] {
            for filter in [TextureFilter::Nearest, TextureFilter::Bilinear] {
                let texture = Texture::new(
                    &TextureDesc {
                        wrap_u: mode,
                        wrap_v: mode,
                        filter,
                        ..desc(3, 1, 1, TexelData::F32(Cow::Borrowed(&data)))
                    },
                    0,
                )
                .unwrap();
                for u in [
                    f32::NAN,
                    f32::INFINITY,
                    f32::NEG_INFINITY,
                    f32::MAX,
                    f32::MIN,
                    1e30,
                    -1e30,
                    1e10,
                ] {
                    let value = texture.sample([u, u])[0];
                    assert!(
                        (10.0..=30.0).contains(&value),
                        "{mode:?} {filter:?} {u}: {value}"
                    );
                }
                // Non-finite coordinates read as 0.
                assert_eq!(texture.sample([f32::NAN, 0.5]), texture.sample([0.0, 0.5]));
            }
        }
        // Far from the origin Repeat still tiles: 1000 + 0.5/3 is the centre of texel 0.
        let texture = Texture::new(
            &TextureDesc {
                wrap_u: WrapMode::Repeat,
                ..desc(3, 1, 1, TexelData::F32(Cow::Borrowed(&data)))
            },
            0,
        )
        .unwrap();
        assert_eq!(texture.sample([1000.0 + 0.5 / 3.0, 0.5]), grey(10.0));
    }

    /// Deterministic pseudo-random bytes.
    fn noise_bytes(count: usize, seed: u64) -> Vec<u8> {
        let mut state = seed;
        (0..count)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 56) as u8
            })
            .collect()
    }

    /// The mean linear value of each of the texture's channels at `level`.
    fn level_mean(texture: &Texture, level: usize) -> Vec<f64> {
        let channels = texture.channels as usize;
        let Level { width, height, .. } = texture.levels[level];
        let count = (width * height) as usize;
        let mut sums = vec![0.0f64; channels];
        for i in 0..count * channels {
            sums[i % channels] += texture.value(level, i) as f64;
        }
        sums.iter().map(|s| s / count as f64).collect()
    }

    /// Every level keeps level 0's mean, up to rounding each texel to the nearest byte: at
    /// most half the widest step between neighbouring decoded bytes (for sRGB, between 254
    /// and 255: 0.0045; for linear bytes 0.5/255), and float rounding for float textures.
    /// Odd sides (37 × 23) reduce to ⌊side / 2⌋ with exact box weights.
    #[test]
    fn every_level_keeps_the_mean() {
        let srgb_step = (1..256)
            .map(|i| srgb_u8_table()[i] - srgb_u8_table()[i - 1])
            .fold(0.0f32, f32::max);
        assert!((0.0085..0.0095).contains(&srgb_step), "{srgb_step}");
        let bytes = noise_bytes(37 * 23 * 4, 1);
        let floats: Vec<f32> = noise_bytes(37 * 23 * 3, 2)
            .into_iter()
            .map(|b| b as f32 * 0.37)
            .collect();
        let cases = [
            (
                TextureEncoding::Srgb,
                4,
                TexelData::U8(Cow::Borrowed(&bytes[..])),
                srgb_step as f64 / 2.0,
            ),
            (
                TextureEncoding::Linear,
                2,
                TexelData::U8(Cow::Borrowed(&bytes[..37 * 23 * 2])),
                0.5 / 255.0,
            ),
            (
                TextureEncoding::Linear,
                3,
                TexelData::F32(Cow::Borrowed(&floats[..])),
                1e-4,
            ),
        ];
        for (encoding, channels, data, bound) in cases {
            let texture = Texture::new(
                &TextureDesc {
                    encoding,
                    wrap_u: WrapMode::Repeat,
                    ..desc(37, 23, channels, data)
                },
                0,
            )
            .unwrap();
            let sizes: Vec<(u32, u32)> =
                texture.levels.iter().map(|l| (l.width, l.height)).collect();
            assert_eq!(sizes, [(37, 23), (18, 11), (9, 5), (4, 2), (2, 1), (1, 1)]);
            let mean = level_mean(&texture, 0);
            for level in 1..texture.level_count() {
                let level_mean = level_mean(&texture, level);
                for c in 0..channels as usize {
                    let error = (level_mean[c] - mean[c]).abs();
                    assert!(
                        error <= bound,
                        "{encoding:?} channel {c} level {level}: mean {} against {}",
                        level_mean[c],
                        mean[c]
                    );
                }
            }
        }
    }

    /// An odd side of 5 reduces to 2 texels covering 2.5 each: weights 0.4, 0.4, 0.2 and
    /// 0.2, 0.4, 0.4; then to their mean, the image's.
    #[test]
    fn odd_sides_reduce_by_covered_fractions() {
        let data = [1.0, 2.0, 3.0, 4.0, 5.0];
        let texture =
            Texture::new(&desc(5, 1, 1, TexelData::F32(Cow::Borrowed(&data))), 0).unwrap();
        assert_eq!(texture.level_count(), 3);
        let level = |l: usize| -> Vec<f32> {
            let n = texture.levels[l].width as usize;
            (0..n).map(|i| texture.value(l, i)).collect()
        };
        let close = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-6);
        assert!(close(&level(1), &[1.8, 4.2]), "{:?}", level(1));
        assert!(close(&level(2), &[3.0]), "{:?}", level(2));
    }

    /// sRGB texels average as light: black and white average to linear 0.5, stored as the
    /// byte nearest to it (188: 0.503), not the encoded mean 128 (0.216). Alpha averages as
    /// it is: 3 × 255 / 4 = 191.25 → 191.
    #[test]
    fn srgb_levels_average_in_linear_light() {
        let data = [0, 0, 255, 255, 255, 255, 0, 255];
        let texture = Texture::new(
            &TextureDesc {
                encoding: TextureEncoding::Srgb,
                ..desc(2, 2, 2, TexelData::U8(Cow::Borrowed(&data)))
            },
            0,
        )
        .unwrap();
        let Texels::U8(bytes) = &texture.levels[1].texels else {
            panic!("kept as bytes");
        };
        assert_eq!(bytes[..], [188, 191]);
    }

    /// Trilinear lookups: level 0 itself at a level of detail of 0 or below (and NaN), the
    /// 1 × 1 mean at the last level and beyond, a linear blend between.
    #[test]
    fn filtered_lookups_blend_the_levels_around_the_level_of_detail() {
        let data = [1.0, 2.0, 3.0, 6.0];
        for filter in [TextureFilter::Nearest, TextureFilter::Bilinear] {
            let texture = Texture::new(
                &TextureDesc {
                    filter,
                    wrap_u: WrapMode::Repeat,
                    wrap_v: WrapMode::MirroredRepeat,
                    ..desc(2, 2, 1, TexelData::F32(Cow::Borrowed(&data)))
                },
                0,
            )
            .unwrap();
            let uv = [0.3, 0.2];
            for lod in [0.0, -3.0, f32::NAN, f32::NEG_INFINITY] {
                assert_eq!(
                    texture.sample_filtered(uv, lod),
                    texture.sample(uv),
                    "{filter:?}"
                );
            }
            for lod in [1.0, 1.5, f32::INFINITY] {
                assert_eq!(texture.sample_filtered(uv, lod), grey(3.0), "{filter:?}");
            }
            let half = texture.sample_filtered(uv, 0.5);
            assert_close(half, grey((texture.sample(uv)[0] + 3.0) / 2.0), 1e-6);
        }
    }

    #[test]
    fn validation_names_the_field() {
        let bytes = [0u8; 16];
        let floats = [0.0f32; 16];
        let check = |desc: TextureDesc, needle: &str| {
            let error = Texture::new(&desc, 3).unwrap_err();
            assert_eq!(error.status, MLT_STATUS_INVALID_ARGUMENT);
            assert!(
                error.message.starts_with(needle),
                "{:?} should start with {needle:?}",
                error.message
            );
        };
        check(
            desc(0, 1, 1, TexelData::U8(Cow::Borrowed(&bytes))),
            "desc.textures[3].width is 0",
        );
        check(
            desc(1, 0, 1, TexelData::U8(Cow::Borrowed(&bytes))),
            "desc.textures[3].height is 0",
        );
        check(
            desc(
                1,
                MLT_MAX_TEXTURE_SIDE + 1,
                1,
                TexelData::U8(Cow::Borrowed(&bytes)),
            ),
            "desc.textures[3].height is 32769",
        );
        check(
            desc(
                MLT_MAX_TEXTURE_SIDE,
                MLT_MAX_TEXTURE_SIDE / 2,
                1,
                TexelData::U8(Cow::Borrowed(&bytes)),
            ),
            "desc.textures[3] is 32768 x 16384 texels",
        );
        check(
            desc(2, 2, 0, TexelData::U8(Cow::Borrowed(&bytes))),
            "desc.textures[3].channels is 0",
        );
        check(
            desc(2, 2, 5, TexelData::U8(Cow::Borrowed(&bytes))),
            "desc.textures[3].channels is 5",
        );
        check(
            desc(2, 2, 3, TexelData::U8(Cow::Borrowed(&bytes))),
            "desc.textures[3].data has 16 8-bit values, but 2 x 2 texels of 3 channels need 12",
        );
        check(
            TextureDesc {
                encoding: TextureEncoding::Srgb,
                ..desc(2, 2, 4, TexelData::F32(Cow::Borrowed(&floats)))
            },
            "desc.textures[3].encoding is Srgb",
        );
        let mut bad = floats;
        bad[7] = -0.5;
        check(
            desc(2, 2, 4, TexelData::F32(Cow::Borrowed(&bad))),
            "desc.textures[3].data[7] (row 0, column 1, channel 3) is -0.5",
        );
        bad[7] = f32::NAN;
        check(
            desc(2, 2, 4, TexelData::F32(Cow::Borrowed(&bad))),
            "desc.textures[3].data[7] (row 0, column 1, channel 3) is NaN",
        );
        bad[7] = 0.0;
        bad[13] = f32::INFINITY;
        check(
            desc(2, 2, 4, TexelData::F32(Cow::Borrowed(&bad))),
            "desc.textures[3].data[13] (row 1, column 1, channel 1) is inf",
        );
    }
}
