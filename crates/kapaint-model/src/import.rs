//! Importing an image into one channel of the maps.
//!
//! PNG, JPEG, TGA and EXR are read with decoder limits (at most 16384 x 16384 pixels and
//! 2 GiB decoded, checked against the memory available before anything is allocated), so a
//! decompression bomb is a clear error rather than an out-of-memory kill. A JPEG without its
//! end-of-image marker is truncated and refused. The image is resampled to the map size by a
//! triangle filter, streamed over bands of rows: peak memory is the decoded image plus a few
//! rows, never a float copy of the whole image. 8- and 16-bit images are sRGB-encoded and
//! converted to linear for `k_d`/`k_s`; float images (EXR) are taken as linear. For `n`, a
//! gray level `v` of an integer image maps through the perceptual scale
//! (`n = (1 + N_MAX)^v - 1`, the same scale as the brush's log blending); a float image
//! holds `n` itself (never clamped to `[0, 1]` by the resampling).

use std::io::{Read as _, Seek as _};
use std::path::Path;

use glam::Vec3;
use image::DynamicImage;
use rayon::prelude::*;

use super::ModelError;
use super::maps::MaterialMaps;
use super::texel::{Channel, encode_n, encode_rgb, n_from_blend, srgb_to_linear};
use super::tile::{Plane, TILE_SIZE};

/// Largest image side accepted.
pub const MAX_IMAGE_SIDE: u32 = 16384;

/// Largest decoded size accepted, in bytes.
pub const MAX_DECODED_BYTES: u64 = 2 << 30;

/// Largest image file accepted, in bytes (an incompressible image at the decoded limit).
pub const MAX_FILE_BYTES: u64 = MAX_DECODED_BYTES + (64 << 20);

/// How far from its end a JPEG must hold its end-of-image marker (bytes): anything after it
/// is trailing data some cameras append.
const JPEG_TAIL_BYTES: u64 = 64 << 10;

/// Decodes an image file with the import limits.
pub fn read_image(path: &Path) -> Result<DynamicImage, ModelError> {
    let fail = |reason: String| ModelError::Image {
        path: path.to_path_buf(),
        reason,
    };
    kapaint_base::file_check::regular_file(path, MAX_FILE_BYTES).map_err(|e| match e {
        kapaint_base::file_check::FileCheck::Io(source) => ModelError::io(path, source),
        other => fail(format!("the file {other}")),
    })?;
    let mut file = std::fs::File::open(path).map_err(|e| ModelError::io(path, e))?;
    let (image, format) = decode(std::io::BufReader::new(&mut file), path)?;
    if format == image::ImageFormat::Jpeg
        && !jpeg_ends(&mut file).map_err(|e| ModelError::io(path, e))?
    {
        return Err(truncated_jpeg(path));
    }
    Ok(image)
}

/// Decodes an image held in memory (one embedded in a glTF binary) with the import limits;
/// `name` says where it came from in errors.
pub fn decode_bytes(bytes: &[u8], name: &Path) -> Result<DynamicImage, ModelError> {
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(ModelError::Image {
            path: name.to_path_buf(),
            reason: format!("it is {} bytes, more than an image may be", bytes.len()),
        });
    }
    let (image, format) = decode(std::io::Cursor::new(bytes), name)?;
    let tail = &bytes[bytes.len().saturating_sub(JPEG_TAIL_BYTES as usize)..];
    if format == image::ImageFormat::Jpeg && !tail.windows(2).any(|w| w == [0xFF, 0xD9]) {
        return Err(truncated_jpeg(name));
    }
    Ok(image)
}

fn truncated_jpeg(path: &Path) -> ModelError {
    ModelError::Image {
        path: path.to_path_buf(),
        reason: "the JPEG is truncated (it has no end-of-image marker)".into(),
    }
}

/// Decodes with the limits: the size from the header is checked before anything is
/// allocated.
fn decode(
    reader: impl std::io::BufRead + std::io::Seek,
    path: &Path,
) -> Result<(DynamicImage, image::ImageFormat), ModelError> {
    let fail = |reason: String| ModelError::Image {
        path: path.to_path_buf(),
        reason,
    };
    let reader = image::ImageReader::new(reader)
        .with_guessed_format()
        .map_err(|e| ModelError::io(path, e))?;
    let Some(format) = reader.format() else {
        return Err(fail("not a supported image (PNG, JPEG, TGA or EXR)".into()));
    };
    let too_large = |what: String| {
        fail(format!(
            "image is too large to import (limits: {MAX_IMAGE_SIDE}x{MAX_IMAGE_SIDE} pixels, 2 GiB decoded): {what}"
        ))
    };
    let mut reader = reader;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_IMAGE_SIDE);
    limits.max_image_height = Some(MAX_IMAGE_SIDE);
    limits.max_alloc = Some(MAX_DECODED_BYTES);
    reader.limits(limits);
    let decoder = reader.into_decoder().map_err(|e| match e {
        image::ImageError::Limits(l) => too_large(l.to_string()),
        other => fail(decode_error(&other)),
    })?;
    let bytes = image::ImageDecoder::total_bytes(&decoder);
    if bytes > MAX_DECODED_BYTES {
        return Err(too_large(format!("it decodes to {bytes} bytes")));
    }
    kapaint_base::memory::check_fits("decoding it", bytes).map_err(fail)?;
    let image = DynamicImage::from_decoder(decoder).map_err(|e| match e {
        image::ImageError::Limits(l) => too_large(l.to_string()),
        other => fail(decode_error(&other)),
    })?;
    Ok((image, format))
}

/// Whether a JPEG file holds its end-of-image marker (`FF D9`) near its end. Inside the
/// compressed data every `FF` is followed by `00` or a restart marker, so the marker cannot
/// appear by chance: a file cut anywhere before its end lacks it.
fn jpeg_ends(file: &mut std::fs::File) -> std::io::Result<bool> {
    let len = file.metadata()?.len();
    let start = len.saturating_sub(JPEG_TAIL_BYTES);
    file.seek(std::io::SeekFrom::Start(start))?;
    let mut tail = Vec::new();
    file.take(JPEG_TAIL_BYTES).read_to_end(&mut tail)?;
    Ok(tail.windows(2).any(|w| w == [0xFF, 0xD9]))
}

/// A decoder's error as one line, saying "truncated" where the file ends too early.
fn decode_error(e: &image::ImageError) -> String {
    let text = one_line(&e.to_string());
    let lower = text.to_lowercase();
    let early_end = matches!(e, image::ImageError::IoError(io) if io.kind() == std::io::ErrorKind::UnexpectedEof)
        || lower.contains("end of file")
        || lower.contains("eof");
    if early_end && !lower.contains("truncated") {
        format!("the image is truncated ({text})")
    } else {
        text
    }
}

/// A decoder's message as one line (some end in a blank line).
fn one_line(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Whether the decoded image holds linear floats (EXR) rather than sRGB-encoded integers.
pub fn is_float(image: &DynamicImage) -> bool {
    matches!(
        image,
        DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_)
    )
}

/// Row `y` of `image` as RGB floats: integer samples scaled to `[0, 1]`, float samples as they
/// are, gray repeated, alpha dropped.
fn source_row(image: &DynamicImage, y: u32, out: &mut [[f32; 3]]) {
    fn fill<T: Copy>(raw: &[T], stride: usize, out: &mut [[f32; 3]], f: impl Fn(T) -> f32) {
        for (px, o) in raw.chunks_exact(stride).zip(out.iter_mut()) {
            *o = if stride < 3 {
                [f(px[0]); 3]
            } else {
                [f(px[0]), f(px[1]), f(px[2])]
            };
        }
    }
    let w = image.width() as usize;
    let row = |stride: usize| (y as usize * w * stride)..((y as usize + 1) * w * stride);
    let u8f = |v: u8| f32::from(v) / 255.0;
    let u16f = |v: u16| f32::from(v) / 65535.0;
    match image {
        DynamicImage::ImageLuma8(b) => fill(&b.as_raw()[row(1)], 1, out, u8f),
        DynamicImage::ImageLumaA8(b) => fill(&b.as_raw()[row(2)], 2, out, u8f),
        DynamicImage::ImageRgb8(b) => fill(&b.as_raw()[row(3)], 3, out, u8f),
        DynamicImage::ImageRgba8(b) => fill(&b.as_raw()[row(4)], 4, out, u8f),
        DynamicImage::ImageLuma16(b) => fill(&b.as_raw()[row(1)], 1, out, u16f),
        DynamicImage::ImageLumaA16(b) => fill(&b.as_raw()[row(2)], 2, out, u16f),
        DynamicImage::ImageRgb16(b) => fill(&b.as_raw()[row(3)], 3, out, u16f),
        DynamicImage::ImageRgba16(b) => fill(&b.as_raw()[row(4)], 4, out, u16f),
        DynamicImage::ImageRgb32F(b) => fill(&b.as_raw()[row(3)], 3, out, |v| v),
        DynamicImage::ImageRgba32F(b) => fill(&b.as_raw()[row(4)], 4, out, |v| v),
        other => {
            let line = other.crop_imm(0, y, other.width(), 1).to_rgb32f();
            fill(line.as_raw(), 3, out, |v| v);
        }
    }
}

/// The taps of a triangle filter from `src` samples to `dst`: per output sample, its first
/// source sample and the normalised weights from there (the filter widens by `src / dst`
/// when shrinking, as `image::imageops::resize` does).
fn triangle_taps(src: u32, dst: u32) -> Vec<(u32, Vec<f32>)> {
    let ratio = src as f32 / dst as f32;
    let scale = ratio.max(1.0);
    (0..dst)
        .map(|o| {
            let centre = (o as f32 + 0.5) * ratio;
            let left = ((centre - scale).floor().max(0.0) as u32).min(src - 1);
            let right = ((centre + scale).ceil() as u32).clamp(left + 1, src);
            let weights: Vec<f32> = (left..right)
                .map(|i| (1.0 - ((i as f32 - (centre - 0.5)) / scale).abs()).max(0.0))
                .collect();
            let sum: f32 = weights.iter().sum();
            let weights = if sum > 0.0 {
                weights.iter().map(|w| w / sum).collect()
            } else {
                vec![1.0 / weights.len() as f32; weights.len()]
            };
            (left, weights)
        })
        .collect()
}

/// One channel resampled to a map size and encoded, a plane per tile (row-major tiles):
/// the heavy part of an import, done off the UI thread, installed by
/// [`super::ImportCommand::ImportChannel`].
#[derive(Clone, Debug, PartialEq)]
pub enum ChannelPlanes {
    /// `k_d` or `k_s`.
    Rgb(Channel, Vec<Plane<[u16; 3]>>),
    /// `n`.
    N(Vec<Plane<u16>>),
}

impl ChannelPlanes {
    /// The channel the planes belong to.
    pub fn channel(&self) -> Channel {
        match self {
            Self::Rgb(c, _) => *c,
            Self::N(_) => Channel::N,
        }
    }
}

/// A triangle filter from an image's size to a map's, applied a band of tile rows at a time:
/// each band streams its source rows through the horizontal filter into the few output rows
/// they feed, so no float copy of the whole image is made.
pub struct Resampler {
    xs: Vec<(u32, Vec<f32>)>,
    ys: Vec<(u32, Vec<f32>)>,
    width: usize,
    height: usize,
}

impl Resampler {
    /// The filter from `source` (width, height) to `width x height`.
    pub fn new(source: (u32, u32), width: u32, height: u32) -> Self {
        // A decoder never hands over an empty image; if one came, it would read as black.
        let (sw, sh) = (source.0.max(1), source.1.max(1));
        Self {
            xs: triangle_taps(sw, width),
            ys: triangle_taps(sh, height),
            width: width as usize,
            height: height as usize,
        }
    }

    /// Tile row `ty` of `image` (the size the filter was made for) filtered: row-major RGB
    /// samples as the image holds them (integers scaled to `[0, 1]`, floats as they are).
    pub fn band(&self, image: &DynamicImage, ty: usize) -> Vec<[f32; 3]> {
        let (w, ys, xs) = (self.width, &self.ys, &self.xs);
        let y0 = ty * TILE_SIZE;
        let y1 = (y0 + TILE_SIZE).min(self.height);
        let mut acc = vec![[0.0_f32; 3]; y1.saturating_sub(y0) * w];
        if image.width() == 0 || y1 <= y0 {
            return acc;
        }
        let mut source = vec![[0.0_f32; 3]; image.width() as usize];
        let mut filtered = vec![[0.0_f32; 3]; w];
        let first = ys[y0].0;
        let last = ys[y1 - 1].0 + ys[y1 - 1].1.len() as u32;
        for sy in first..last.min(image.height()) {
            source_row(image, sy, &mut source);
            for (x, (left, weights)) in xs.iter().enumerate() {
                let mut sum = [0.0_f32; 3];
                for (k, wgt) in weights.iter().enumerate() {
                    let p = source[*left as usize + k];
                    for c in 0..3 {
                        sum[c] += p[c] * wgt;
                    }
                }
                filtered[x] = sum;
            }
            for y in y0..y1 {
                let (top, weights) = &ys[y];
                let Some(wgt) = sy.checked_sub(*top).and_then(|k| weights.get(k as usize)) else {
                    continue;
                };
                let row = &mut acc[(y - y0) * w..(y - y0 + 1) * w];
                for (a, f) in row.iter_mut().zip(&filtered) {
                    for c in 0..3 {
                        a[c] += f[c] * wgt;
                    }
                }
            }
        }
        acc
    }
}

/// The image filtered to `width x height`, a band of tile rows at a time (in parallel).
fn filtered_bands(image: &DynamicImage, width: u32, height: u32) -> Vec<Vec<[f32; 3]>> {
    let resampler = Resampler::new((image.width(), image.height()), width, height);
    let tiles_y = (height as usize).div_ceil(TILE_SIZE);
    (0..tiles_y)
        .into_par_iter()
        .map(|ty| resampler.band(image, ty))
        .collect()
}

/// Resamples `image` to `width x height` and encodes it into `channel`'s planes, a band of
/// tile rows at a time (in parallel): each band streams its source rows through the
/// horizontal filter into the few output rows they feed.
pub fn resample(image: &DynamicImage, channel: Channel, width: u32, height: u32) -> ChannelPlanes {
    resample_as(image, channel, width, height, false)
}

/// As [`resample`]; with `n_as_blend`, a float image holds `n`'s blend value (log space)
/// rather than `n` itself (a map being resized).
pub(super) fn resample_as(
    image: &DynamicImage,
    channel: Channel,
    width: u32,
    height: u32,
    n_as_blend: bool,
) -> ChannelPlanes {
    let linear = is_float(image);
    let tiles_x = (width as usize).div_ceil(TILE_SIZE);
    let tiles_y = (height as usize).div_ceil(TILE_SIZE);
    let w = width as usize;
    let bands = filtered_bands(image, width, height);
    let convert = |c: f32| if linear { c } else { srgb_to_linear(c) };
    let tile_texels = |tx: usize, ty: usize| {
        let band = &bands[ty];
        let x0 = tx * TILE_SIZE;
        let cols = TILE_SIZE.min(w - x0);
        let rows = band.len() / w;
        (0..rows)
            .flat_map(move |r| (0..cols).map(move |c| (r * TILE_SIZE + c, band[r * w + x0 + c])))
    };
    // The texels of a tile inside the map: columns and rows.
    let extent = |tx: usize, ty: usize| {
        (
            TILE_SIZE.min(w - tx * TILE_SIZE),
            TILE_SIZE.min(height as usize - ty * TILE_SIZE),
        )
    };
    match channel {
        Channel::Kd | Channel::Ks => {
            let planes = (0..tiles_x * tiles_y)
                .into_par_iter()
                .map(|id| {
                    let mut plane = Plane::Uniform([0; 3]);
                    let data = plane.data_mut();
                    for (i, p) in tile_texels(id % tiles_x, id / tiles_x) {
                        data[i] = encode_rgb(Vec3::from(p).map(convert));
                    }
                    fill_outside(data, extent(id % tiles_x, id / tiles_x));
                    plane.compact();
                    plane
                })
                .collect();
            ChannelPlanes::Rgb(channel, planes)
        }
        Channel::N => {
            let planes = (0..tiles_x * tiles_y)
                .into_par_iter()
                .map(|id| {
                    let mut plane = Plane::Uniform(0);
                    let data = plane.data_mut();
                    for (i, p) in tile_texels(id % tiles_x, id / tiles_x) {
                        let v = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
                        data[i] = if linear && !n_as_blend {
                            encode_n(v)
                        } else {
                            encode_n(n_from_blend(v))
                        };
                    }
                    fill_outside(data, extent(id % tiles_x, id / tiles_x));
                    plane.compact();
                    plane
                })
                .collect();
            ChannelPlanes::N(planes)
        }
    }
}

/// Gives the texels of a tile outside the map (past `cols` columns or `rows` rows) the value
/// of its first texel, so that a tile of one value inside the map is stored as one value.
pub fn fill_outside<T: Copy>(data: &mut [T], (cols, rows): (usize, usize)) {
    if cols == TILE_SIZE && rows == TILE_SIZE {
        return;
    }
    let first = data[0];
    for (i, v) in data.iter_mut().enumerate() {
        if i % TILE_SIZE >= cols || i / TILE_SIZE >= rows {
            *v = first;
        }
    }
}

/// Puts resampled planes into maps made for them (not undoable by itself: [`install`] saves
/// the tiles to history first).
pub(super) fn write_planes(maps: &mut MaterialMaps, planes: &ChannelPlanes) {
    match planes {
        ChannelPlanes::Rgb(channel, planes) => {
            for (id, plane) in planes.iter().enumerate() {
                let tile = maps.tile_mut(id);
                if *channel == Channel::Kd {
                    tile.kd = plane.clone();
                } else {
                    tile.ks = plane.clone();
                }
            }
        }
        ChannelPlanes::N(planes) => {
            for (id, plane) in planes.iter().enumerate() {
                maps.tile_mut(id).n = plane.clone();
            }
        }
    }
}

/// Reads a grayscale brush stamp from an image file (luminance of the decoded image; an
/// alpha channel, if present, multiplies it), at most 1024 x 1024 pixels.
pub fn read_stamp(path: &Path) -> Result<super::brush::Stamp, ModelError> {
    let image = read_image(path)?;
    if image.width() > 1024 || image.height() > 1024 {
        return Err(ModelError::Image {
            path: path.to_path_buf(),
            reason: format!(
                "a stamp is at most 1024x1024 pixels, this one is {}x{}",
                image.width(),
                image.height()
            ),
        });
    }
    let rgba = image.to_rgba32f();
    // Float images can hold values outside [0, 1] (or NaN): the stamp takes them clamped.
    let alpha = rgba
        .pixels()
        .map(|p| super::texel::unit((0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) * p[3]))
        .collect();
    super::brush::Stamp::new(image.width(), image.height(), alpha).map_err(|reason| {
        ModelError::Image {
            path: path.to_path_buf(),
            reason,
        }
    })
}

/// A PNG of `data` (samples in the encoder's order; 16-bit words native-endian) with `color`,
/// fast deflate and adaptive filtering: what sets and normal maps are written as.
///
/// # Errors
/// The encoder's (a size that does not match `data`).
pub fn encode_png(
    data: &[u8],
    (width, height): (u32, u32),
    color: image::ExtendedColorType,
) -> Result<Vec<u8>, String> {
    let mut out = std::io::Cursor::new(Vec::new());
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new_with_quality(
            &mut out,
            image::codecs::png::CompressionType::Fast,
            image::codecs::png::FilterType::Paeth,
        ),
        data,
        width,
        height,
        color,
    )
    .map_err(|e| e.to_string())?;
    Ok(out.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn taps_are_the_identity_at_the_same_size_and_average_when_shrinking() {
        for (left, weights) in triangle_taps(7, 7) {
            let at: Vec<f32> = weights.iter().copied().filter(|w| *w > 0.0).collect();
            assert_eq!(at, vec![1.0], "left {left}");
        }
        let half = triangle_taps(8, 4);
        for (o, (left, weights)) in half.iter().enumerate() {
            let sum: f32 = weights.iter().sum();
            assert!((sum - 1.0).abs() < 1e-6);
            let centre: f32 = weights
                .iter()
                .enumerate()
                .map(|(k, w)| (*left as f32 + k as f32 + 0.5) * w)
                .sum();
            // Inside, the weights centre on the output sample; at the edges the filter is
            // cut by the image's border (as `image::imageops::resize` does).
            if (1..3).contains(&o) {
                assert!(
                    (centre - (o as f32 * 2.0 + 1.0)).abs() < 1e-4,
                    "{o}: {centre}"
                );
            }
        }
    }
}
