//! A projection fill's image as a project keeps it: the pixels the tools read, exactly, as two
//! 16-bit PNGs (RGBA: linear colour premultiplied and coverage; gray-alpha: the gray and
//! `n`'s blend value, premultiplied), so a project reopened lays the same texels.

use std::io::{Read, Seek};
use std::sync::Arc;

use image::{ImageBuffer, LumaA, Rgba};

use super::layers::ProjectionEntry;
use crate::paint_image::{MAX_PAINT_IMAGE_SIDE, Pixels};

/// The two PNGs of `pixels`: RGBA, then gray-alpha.
pub fn encode(pixels: &Pixels) -> Result<[Vec<u8>; 2], String> {
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    let (w, h) = (pixels.width(), pixels.height());
    let (rgba, gray) = pixels.raw();
    let mut out = [Vec::new(), Vec::new()];
    let [a, b] = &mut out;
    ImageBuffer::<Rgba<u16>, Vec<u16>>::from_raw(w, h, rgba)
        .ok_or("image size mismatch")?
        .write_with_encoder(PngEncoder::new_with_quality(
            a,
            CompressionType::Fast,
            FilterType::Up,
        ))
        .map_err(|e| e.to_string())?;
    ImageBuffer::<LumaA<u16>, Vec<u16>>::from_raw(w, h, gray)
        .ok_or("image size mismatch")?
        .write_with_encoder(PngEncoder::new_with_quality(
            b,
            CompressionType::Fast,
            FilterType::Up,
        ))
        .map_err(|e| e.to_string())?;
    Ok(out)
}

/// The image of projection fill `e` (`what` names the layer), read from the archive with the
/// limits its declared size allows.
pub fn read<R: Read + Seek>(
    zip: &mut zip::ZipArchive<R>,
    e: &ProjectionEntry,
    what: &str,
) -> Result<Arc<Pixels>, String> {
    let (w, h) = (e.width, e.height);
    if w == 0 || h == 0 || w > MAX_PAINT_IMAGE_SIDE || h > MAX_PAINT_IMAGE_SIDE {
        return Err(format!(
            "{what}: its image is {w}x{h} pixels, outside 1 to {MAX_PAINT_IMAGE_SIDE} a side"
        ));
    }
    let rgba = decode(zip, &e.rgba, (w, h), 4, what)?;
    let gray = decode(zip, &e.gray, (w, h), 2, what)?;
    Pixels::from_raw(w, h, &rgba, &gray)
        .map(Arc::new)
        .map_err(|e| format!("{what}: {e}"))
}

/// Entry `file`: a 16-bit PNG of `w x h` pixels of `components` samples, its samples.
fn decode<R: Read + Seek>(
    zip: &mut zip::ZipArchive<R>,
    file: &str,
    (w, h): (u32, u32),
    components: u64,
    what: &str,
) -> Result<Vec<u16>, String> {
    let mut entry = zip
        .by_name(file)
        .map_err(|e| format!("{what}: {file}: {e}"))?;
    // A 16-bit PNG of this size can never need more than this.
    let limit = u64::from(w) * u64::from(h) * components * 2 * 2 + (1 << 20);
    if entry.size() > limit {
        return Err(format!(
            "{what}: {file} claims {} bytes, more than a {w}x{h} image can need",
            entry.size()
        ));
    }
    let mut bytes = Vec::new();
    (&mut entry)
        .take(limit)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("{what}: {file}: {e}"))?;
    let mut reader =
        image::ImageReader::with_format(std::io::Cursor::new(bytes), image::ImageFormat::Png);
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(w);
    limits.max_image_height = Some(h);
    limits.max_alloc = Some(limit);
    reader.limits(limits);
    let image = reader
        .decode()
        .map_err(|e| format!("{what}: {file}: {e}"))?;
    if (image.width(), image.height()) != (w, h) {
        return Err(format!(
            "{what}: {file} is {}x{}, the manifest says {w}x{h}",
            image.width(),
            image.height()
        ));
    }
    match (components, image) {
        (4, image::DynamicImage::ImageRgba16(img)) => Ok(img.into_raw()),
        (2, image::DynamicImage::ImageLumaA16(img)) => Ok(img.into_raw()),
        (_, other) => Err(format!(
            "{what}: {file} has colour type {:?}, expected 16-bit {}",
            other.color(),
            if components == 4 {
                "RGBA"
            } else {
                "gray-alpha"
            }
        )),
    }
}
