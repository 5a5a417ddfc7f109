//! Importing an image into one channel of the maps.
//!
//! PNG, JPEG, TGA and EXR are read with decoder limits (at most 16384 x 16384 pixels and
//! 2 GiB decoded), so a decompression bomb is a clear error rather than an out-of-memory
//! crash. The image is resampled to the map size. 8- and 16-bit images are sRGB-encoded and
//! converted to linear for `k_d`/`k_s`; float images (EXR) are taken as linear. For `n`, a
//! gray level `v` of an integer image maps through the perceptual scale
//! (`n = (1 + N_MAX)^v - 1`, the same scale as the brush's log blending); a float image holds
//! `n` itself.

use std::path::Path;

use glam::Vec3;
use image::{DynamicImage, imageops::FilterType};

use super::ModelError;
use super::document::Document;
use super::texel::{Channel, encode_n, encode_rgb, n_from_blend, srgb_to_linear};
use super::tile::TILE_SIZE;

/// Largest image side accepted.
pub const MAX_IMAGE_SIDE: u32 = 16384;

/// Largest decoded size accepted, in bytes.
pub const MAX_DECODED_BYTES: u64 = 2 << 30;

/// Decodes an image file with the import limits.
pub fn read_image(path: &Path) -> Result<DynamicImage, ModelError> {
    let fail = |reason: String| ModelError::Image {
        path: path.to_path_buf(),
        reason,
    };
    let mut reader = image::ImageReader::open(path)
        .map_err(|e| ModelError::io(path, e))?
        .with_guessed_format()
        .map_err(|e| ModelError::io(path, e))?;
    if reader.format().is_none() {
        return Err(fail("not a supported image (PNG, JPEG, TGA or EXR)".into()));
    }
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_IMAGE_SIDE);
    limits.max_image_height = Some(MAX_IMAGE_SIDE);
    limits.max_alloc = Some(MAX_DECODED_BYTES);
    reader.limits(limits);
    reader.decode().map_err(|e| match e {
        image::ImageError::Limits(l) => fail(format!(
            "image is too large to import (limits: {MAX_IMAGE_SIDE}x{MAX_IMAGE_SIDE} pixels, 2 GiB decoded): {l}"
        )),
        other => fail(other.to_string()),
    })
}

/// Whether the decoded image holds linear floats (EXR) rather than sRGB-encoded integers.
fn is_float(image: &DynamicImage) -> bool {
    matches!(
        image,
        DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_)
    )
}

/// Writes `image` into `channel` of the document as one undo step.
pub fn import_into(doc: &mut Document, channel: Channel, image: &DynamicImage) {
    let (w, h) = (doc.maps.width(), doc.maps.height());
    let linear = is_float(image);
    let resized = image::imageops::resize(&image.to_rgb32f(), w, h, FilterType::Triangle);
    let convert = |c: f32| if linear { c } else { srgb_to_linear(c) };
    doc.history
        .begin(format!("Import image into {}", channel.name()));
    for id in 0..doc.maps.tile_count() {
        let (x0, y0, x1, y1) = doc.maps.tile_rect(id);
        let tile = doc.history.tile_for_write(&mut doc.maps, id);
        for y in y0..y1 {
            for x in x0..x1 {
                let p = resized.get_pixel(x, y).0;
                let i = (y - y0) as usize * TILE_SIZE + (x - x0) as usize;
                match channel {
                    Channel::Kd => tile.kd.data_mut()[i] = encode_rgb(Vec3::from(p).map(convert)),
                    Channel::Ks => tile.ks.data_mut()[i] = encode_rgb(Vec3::from(p).map(convert)),
                    Channel::N => {
                        let v = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
                        tile.n.data_mut()[i] = if linear {
                            encode_n(v)
                        } else {
                            encode_n(n_from_blend(v))
                        };
                    }
                }
            }
        }
        tile.compact();
    }
    doc.history.end();
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

/// Reads `path` and imports it into `channel`.
pub fn import_file(doc: &mut Document, channel: Channel, path: &Path) -> Result<(), ModelError> {
    let image = read_image(path)?;
    import_into(doc, channel, &image);
    Ok(())
}
