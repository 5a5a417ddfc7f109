//! Encoding a set's images: PNG (8 and 16 bits), EXR and KTX2, from the map's texels.

use glam::Vec3;
use image::ExtendedColorType as C;
use rayon::prelude::*;

use super::manifest::{Comp, Compression, is_colour};
use crate::export::encoding::NEncoding;
use crate::export::preset::{ExportPreset, Format};
use crate::model::MaterialMaps;
use crate::model::texel::{MaterialValue, Texel, decode_n, decode_unorm, linear_to_srgb};
use crate::task::Progress;

/// Texels of the map in row-major order, read in parallel by rows.
pub(super) fn rows(maps: &MaterialMaps) -> Vec<Texel> {
    let w = maps.width() as usize;
    let mut out = vec![Texel::encode(MaterialValue::default()); w * maps.height() as usize];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, t) in row.iter_mut().enumerate() {
            *t = maps.texel(x as u32, y as u32);
        }
    });
    out
}

/// One encoded image.
pub(super) struct EncodedImage {
    /// The file.
    pub bytes: Vec<u8>,
    /// For 8-bit formats: the components a consumer decodes (level 0), per texel.
    pub stored: Option<Vec<u8>>,
    /// The colour components are sRGB-encoded.
    pub srgb: bool,
    /// KTX2: mip levels, PSNR, compression name.
    pub ktx: Option<KtxInfo>,
}

/// What a KTX2 file reports beyond its bytes.
pub(super) struct KtxInfo {
    pub levels: u32,
    pub psnr: Option<Vec<Option<f64>>>,
    pub compression: Compression,
}

/// Whether an image's colour components are sRGB-encoded: in 8-bit PNGs always, in KTX2
/// where the format has an sRGB variant (three or four components).
fn srgb_image(format: Format, comps: &[Comp]) -> bool {
    let colour = comps.iter().any(|c| is_colour(*c));
    colour && (format == Format::Png8 || (format.is_ktx2() && comps.len() >= 3))
}

/// Per stored 16-bit code, what a file holds: colour components (sRGB-encoded where `srgb`),
/// and n through its encoding (as a fraction of the code range). Tables keep the per-texel
/// work to lookups.
fn file_tables(srgb: bool, n_enc: Option<NEncoding>) -> (Vec<f32>, Vec<f32>) {
    let colour = (0..=u16::MAX)
        .map(|q| {
            let v = decode_unorm(q);
            if srgb { linear_to_srgb(v) } else { v }
        })
        .collect();
    let n = (0..=u16::MAX)
        .map(|bits| {
            let n = decode_n(bits);
            match n_enc {
                Some(e) => f32::from(e.encode(n)) / ((1_u32 << e.bits) - 1) as f32,
                None => n,
            }
        })
        .collect();
    (colour, n)
}

/// A PNG of `data` (16-bit words native-endian) with `color`.
pub(crate) fn png_bytes(data: &[u8], size: (u32, u32), color: C) -> Result<Vec<u8>, String> {
    crate::model::import::encode_png(data, size, color)
}

/// Encodes one image of `comps` components from the texels.
pub(super) fn encode_image(
    texels: &[Texel],
    ka: &[Vec3],
    (width, height): (u32, u32),
    comps: &[Comp],
    preset: &ExportPreset,
    n_enc: Option<NEncoding>,
    progress: &Progress,
) -> Result<EncodedImage, String> {
    let format = preset.format;
    let channels = comps.len();
    let srgb = srgb_image(format, comps);
    let (colour_lut, n_lut) = file_tables(srgb, n_enc);
    let value = |i: usize, k: usize| -> f32 {
        let t = &texels[i];
        match comps[k] {
            Comp::Kd(c) => colour_lut[t.kd[c] as usize],
            Comp::Ks(c) => colour_lut[t.ks[c.min(2)] as usize],
            Comp::N => n_lut[t.n as usize],
            Comp::Ka(c) => {
                let v = ka.get(i).map_or(0.0, |k| k[c]);
                if srgb { linear_to_srgb(v) } else { v }
            }
        }
    };
    let count = texels.len();
    let png = |data: &[u8], colors: [C; 4]| {
        png_bytes(data, (width, height), colors[channels.clamp(1, 4) - 1])
    };
    let plain = |bytes| {
        progress.advance(u64::from(height));
        EncodedImage {
            bytes,
            stored: None,
            srgb,
            ktx: None,
        }
    };
    match format {
        Format::Png8 | Format::GltfPbr => {
            let data: Vec<u8> = (0..count * channels)
                .into_par_iter()
                .map(|j| (value(j / channels, j % channels).clamp(0.0, 1.0) * 255.0).round() as u8)
                .collect();
            let bytes = png(&data, [C::L8, C::La8, C::Rgb8, C::Rgba8])?;
            Ok(EncodedImage {
                stored: Some(data),
                ..plain(bytes)
            })
        }
        Format::Png16 => {
            // Native-endian 16-bit words, as the encoder expects.
            let data: Vec<u8> = (0..count * channels)
                .into_par_iter()
                .flat_map_iter(|j| {
                    let v = value(j / channels, j % channels);
                    ((v.clamp(0.0, 1.0) * 65535.0).round() as u16).to_ne_bytes()
                })
                .collect();
            Ok(plain(png(&data, [C::L16, C::La16, C::Rgb16, C::Rgba16])?))
        }
        Format::Exr => {
            // RGB floats; a one-component image repeats its value in all three.
            let data: Vec<f32> = (0..count * 3)
                .into_par_iter()
                .map(|j| value(j / 3, (j % 3).min(channels - 1)))
                .collect();
            let mut out = std::io::Cursor::new(Vec::new());
            image::Rgb32FImage::from_raw(width, height, data)
                .ok_or("image size")?
                .write_to(&mut out, image::ImageFormat::OpenExr)
                .map_err(|e| e.to_string())?;
            Ok(plain(out.into_inner()))
        }
        Format::Ktx2 | Format::Ktx2Bc => {
            let values: Vec<f32> = (0..count * channels)
                .into_par_iter()
                .map(|j| value(j / channels, j % channels))
                .collect();
            let source = crate::export::ktx::Source {
                width,
                height,
                channels,
                values: &values,
                srgb,
            };
            let compressed = (format == Format::Ktx2Bc).then_some(preset.bc7_quality);
            let written = crate::export::ktx::encode(&source, compressed, progress)?;
            Ok(EncodedImage {
                bytes: written.bytes,
                stored: Some(written.level0),
                srgb,
                ktx: Some(KtxInfo {
                    levels: written.levels,
                    psnr: written.psnr,
                    compression: written.compression,
                }),
            })
        }
    }
}

/// An encoded image with its file name and components.
pub(super) type Encoded = (String, Vec<Comp>, EncodedImage);

/// The bytes a consumer decodes from an 8-bit image, `comps.len()` per texel.
pub(super) struct StoredImage {
    pub comps: Vec<Comp>,
    pub data: Vec<u8>,
    pub srgb: bool,
}
