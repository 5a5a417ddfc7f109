//! Encoding a set's images: PNG (8 and 16 bits), EXR and KTX2, from the map's texels.

use glam::Vec3;
use image::ExtendedColorType as C;
use rayon::prelude::*;

use super::failure::Failure;
use super::manifest::{Comp, Compression, is_colour};
use crate::encoding::NEncoding;
use crate::ktx::{Space, texel_layout};
use crate::preset::{ExportPreset, Format};
use kapaint_base::task::Progress;
use kapaint_model::MaterialMaps;
use kapaint_model::texel::{
    MaterialValue, Texel, decode_n, decode_unorm, linear_to_srgb, n_to_blend,
};

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
    /// The components are linear half floats (BC6H; `stored` holds two bytes each).
    pub half: bool,
    /// KTX2: mip levels, PSNR, compression name.
    pub ktx: Option<KtxInfo>,
}

/// What a KTX2 file reports beyond its bytes.
pub(super) struct KtxInfo {
    pub levels: u32,
    pub psnr: Option<Vec<Option<f64>>>,
    pub compression: Compression,
    /// Levels 1 and on as a consumer decodes them.
    pub mips: Vec<Vec<u8>>,
}

/// Whether an image's colour components are sRGB-encoded: in 8-bit PNGs always, in KTX2
/// where the format has an sRGB variant (three or four components).
pub(super) fn srgb_image(format: Format, comps: &[Comp]) -> bool {
    let colour = comps.iter().any(|c| is_colour(*c));
    colour && (matches!(format, Format::Png8) || (format.is_ktx2() && comps.len() >= 3))
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
fn png_bytes(data: &[u8], size: (u32, u32), color: C) -> Result<Vec<u8>, String> {
    kapaint_model::import::encode_png(data, size, color)
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
) -> Result<EncodedImage, Failure> {
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
            half: false,
            ktx: None,
        }
    };
    match format {
        Format::Png8 | Format::GltfPbr | Format::PbrTextures => {
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
        Format::Exr => Ok(plain(exr_bytes(&value, channels, (width, height))?)),
        // Its codebooks span the image: the block search encodes it whole (`super::choose`).
        Format::Ktx2Etc1s { .. } => {
            Err("ETC1S images are encoded by the block search, not one at a time".into())
        }
        Format::Ktx2
        | Format::Ktx2Bc { .. }
        | Format::Ktx2Astc { .. }
        | Format::Ktx2Uastc { .. } => {
            let source = KtxTexels::new(texels, ka, comps, srgb, false, n_enc);
            let level0 = source.level0();
            let codec = preset.format.codec(source.spaces());
            let compressed = codec.as_deref().zip(preset.format.max_effort());
            let written = crate::ktx::encode(
                &source.source((width, height), &level0),
                compressed.map(|(c, e)| (crate::blocks::Coder::best_cpu(), c, e)),
                None,
                progress,
            )?;
            Ok(ktx_image(written, srgb, false))
        }
    }
}

/// An OpenEXR file of RGB floats from `value(texel, component)`; a one-component image
/// repeats its value in all three.
fn exr_bytes(
    value: &(impl Fn(usize, usize) -> f32 + Sync),
    channels: usize,
    (width, height): (u32, u32),
) -> Result<Vec<u8>, String> {
    let count = width as usize * height as usize;
    let data: Vec<f32> = (0..count * 3)
        .into_par_iter()
        .map(|j| value(j / 3, (j % 3).min(channels - 1)))
        .collect();
    let mut out = std::io::Cursor::new(Vec::new());
    image::Rgb32FImage::from_raw(width, height, data)
        .ok_or("image size")?
        .write_to(&mut out, image::ImageFormat::OpenExr)
        .map_err(|e| e.to_string())?;
    Ok(out.into_inner())
}

/// An encoded image of a written KTX2 file.
pub(super) fn ktx_image(written: crate::ktx::Written, srgb: bool, half: bool) -> EncodedImage {
    let mut decoded = written.decoded;
    let level0 = if decoded.is_empty() {
        Vec::new()
    } else {
        decoded.remove(0)
    };
    EncodedImage {
        bytes: written.bytes,
        stored: Some(level0),
        srgb,
        half,
        ktx: Some(KtxInfo {
            levels: written.levels,
            psnr: written.psnr,
            compression: written.compression,
            mips: decoded,
        }),
    }
}

/// Where a KTX2 image's component comes from: a texel's 16-bit code through two tables (its
/// value in the averaging space, and what is stored: a byte, or a half float's two), or the
/// baked `k_a`.
enum CompSource {
    Code {
        comp: Comp,
        value: Vec<f32>,
        stored: Vec<[u8; 2]>,
    },
    Ka {
        channel: usize,
        bounds: Vec<f32>,
    },
}

/// The texels of one KTX2 image: its components' spaces, stored bytes and values.
pub(super) struct KtxTexels<'a> {
    texels: &'a [Texel],
    ka: &'a [Vec3],
    spaces: Vec<Space>,
    sources: Vec<CompSource>,
}

/// The spaces of an image of `comps` (colour sRGB-encoded where `srgb`, linear half floats
/// where `half`; `n` by `n_enc`).
pub(super) fn spaces_of(
    comps: &[Comp],
    srgb: bool,
    half: bool,
    n_enc: Option<NEncoding>,
) -> Vec<Space> {
    comps
        .iter()
        .map(|c| match (c, n_enc) {
            (Comp::N, Some(e)) => Space::N(e),
            (Comp::N, None) => Space::Linear,
            _ if half => Space::Half,
            _ if srgb => Space::Srgb,
            _ => Space::Linear,
        })
        .collect()
}

impl<'a> KtxTexels<'a> {
    /// The image of `comps` (colour sRGB-encoded where `srgb`, linear half floats where
    /// `half`; `n` by `n_enc`).
    pub(super) fn new(
        texels: &'a [Texel],
        ka: &'a [Vec3],
        comps: &[Comp],
        srgb: bool,
        half: bool,
        n_enc: Option<NEncoding>,
    ) -> Self {
        let spaces = spaces_of(comps, srgb, half, n_enc);
        let sources = comps
            .iter()
            .zip(&spaces)
            .map(|(comp, space)| {
                let bounds = space.boundaries();
                if let Comp::Ka(channel) = comp {
                    return CompSource::Ka {
                        channel: *channel,
                        bounds,
                    };
                }
                let value: Vec<f32> = (0..=u16::MAX)
                    .map(|code| match comp {
                        Comp::N => n_to_blend(decode_n(code)),
                        _ => decode_unorm(code),
                    })
                    .collect();
                let stored = value
                    .iter()
                    .map(|v| {
                        let mut out = [0; 2];
                        space.store(&bounds, *v, &mut out);
                        out
                    })
                    .collect();
                CompSource::Code {
                    comp: *comp,
                    value,
                    stored,
                }
            })
            .collect();
        Self {
            texels,
            ka,
            spaces,
            sources,
        }
    }

    fn code(&self, i: usize, comp: Comp) -> usize {
        let t = &self.texels[i];
        match comp {
            Comp::Kd(c) => t.kd[c] as usize,
            Comp::Ks(c) => t.ks[c.min(2)] as usize,
            Comp::N | Comp::Ka(_) => t.n as usize,
        }
    }

    fn ka_of(&self, i: usize, channel: usize) -> f32 {
        self.ka.get(i).map_or(0.0, |k| k[channel])
    }

    /// Texel `i`'s component `k` in its averaging space.
    fn value_of(&self, i: usize, k: usize) -> f32 {
        match &self.sources[k] {
            CompSource::Code { comp, value, .. } => value[self.code(i, *comp)],
            CompSource::Ka { channel, .. } => self.ka_of(i, *channel),
        }
    }

    /// Texel `i`'s component `k` as stored, into `out`.
    fn store(&self, i: usize, k: usize, out: &mut [u8]) {
        match &self.sources[k] {
            CompSource::Code { comp, stored, .. } => {
                let s = &stored[self.code(i, *comp)];
                out[..self.spaces[k].bytes()].copy_from_slice(&s[..self.spaces[k].bytes()]);
            }
            CompSource::Ka { channel, bounds } => {
                self.spaces[k].store(bounds, self.ka_of(i, *channel), out);
            }
        }
    }

    /// Level 0 as stored bytes.
    pub(super) fn level0(&self) -> Vec<u8> {
        let (per, offsets) = texel_layout(&self.spaces);
        let mut out = vec![0_u8; self.texels.len() * per];
        out.par_chunks_mut(per).enumerate().for_each(|(i, t)| {
            for (k, o) in offsets.iter().enumerate() {
                self.store(i, k, &mut t[*o..]);
            }
        });
        out
    }

    /// Each component's space.
    pub(super) fn spaces(&self) -> &[Space] {
        &self.spaces
    }

    /// The image as the KTX2 writer takes it, with its stored level 0.
    pub(super) fn source<'s>(
        &'s self,
        (width, height): (u32, u32),
        level0: &'s [u8],
    ) -> crate::ktx::Source<'s> {
        crate::ktx::Source {
            width,
            height,
            spaces: &self.spaces,
            level0,
            value: self,
        }
    }
}

impl crate::ktx::Values for KtxTexels<'_> {
    fn value(&self, i: usize, k: usize) -> f32 {
        self.value_of(i, k)
    }
}

/// An encoded image with its file name and components.
pub(super) type Encoded = (String, Vec<Comp>, EncodedImage);

/// What a consumer decodes from an 8-bit image (`comps.len()` bytes per texel) or a BC6H
/// image (`half`: little-endian half floats, two bytes per component).
pub(super) struct StoredImage<'a> {
    pub comps: Vec<Comp>,
    /// Borrowed from a trial's blocks, or owned.
    pub data: std::borrow::Cow<'a, [u8]>,
    pub srgb: bool,
    pub half: bool,
}
