//! ETC1S with BasisLZ: Basis Universal's smaller format (about 1 to 2 bits a texel), whose
//! blocks index codebooks of endpoints and selectors shared by the whole image and every mip
//! level. A KTX2 file keeps those codebooks and the Huffman tables as its supercompression
//! global data and each level's slices (colour, then alpha where there is one) as its level
//! data; [`Etc1sImage`] is that split.
//!
//! Binomial's encoder writes `.basis` files: [`encode_etc1s`] reads one into the split (its
//! header and slice descriptions, the format's documented fixed-size records), and
//! [`transcode_etc1s`] writes the split back into a `.basis` file in memory for the
//! transcoder. The mips are the caller's ([`encode_etc1s_levels`]), or else the encoder's own
//! (`basisu -mipmap`, filtered in linear light for sRGB colour).

use basis_universal::{
    BasisTextureFormat, ColorSpace, CompressorParams, TranscodeParameters, Transcoder,
    TranscoderTextureFormat,
};

use super::{Target, whole_blocks};

/// ETC1S's quality levels (`basisu -q`).
pub const QUALITY: std::ops::RangeInclusive<u32> = 1..=255;

/// How an ETC1S image is encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Etc1s {
    /// The quality level, in [`QUALITY`]: larger codebooks, more bytes, less error.
    pub quality: u32,
    /// The texels are sRGB-encoded colour (perceptual metrics, mips in linear light).
    pub srgb: bool,
    /// With a full mip chain (down to 1x1).
    pub mips: bool,
}

/// One mip level's slices.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Level {
    /// Size in texels.
    pub width: u32,
    /// Size in texels.
    pub height: u32,
    /// The colour slice.
    pub rgb: Vec<u8>,
    /// The alpha slice, where the image has alpha.
    pub alpha: Option<Vec<u8>>,
}

/// An ETC1S image as KTX2 stores it: the global codebooks and tables, and each level's slices
/// (level 0 first).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Etc1sImage {
    /// Endpoints in the codebook.
    pub endpoint_count: u16,
    /// Selectors in the codebook.
    pub selector_count: u16,
    /// The compressed endpoint codebook.
    pub endpoints: Vec<u8>,
    /// The compressed selector codebook.
    pub selectors: Vec<u8>,
    /// The Huffman tables the slices are decoded with.
    pub tables: Vec<u8>,
    /// Extended data (none from this encoder).
    pub extended: Vec<u8>,
    /// The levels.
    pub levels: Vec<Level>,
}

impl Etc1sImage {
    /// Whether its levels carry alpha slices.
    pub fn has_alpha(&self) -> bool {
        self.levels.first().is_some_and(|l| l.alpha.is_some())
    }
}

/// Encodes `rgba` (`width x height` RGBA8 texels, sides multiples of 4) as ETC1S. An alpha
/// slice is written where some texel's alpha is below 255.
///
/// # Errors
/// A size that is not whole blocks, a quality out of range, or the encoder's failure.
pub fn encode_etc1s(
    rgba: &[u8],
    (width, height): (u32, u32),
    how: Etc1s,
) -> Result<Etc1sImage, String> {
    encode_etc1s_levels(&[(rgba, (width, height))], how)
}

/// Encodes `levels` (level 0 first, each `(RGBA8 texels, size)`; level 0's sides multiples of
/// 4) as one ETC1S image whose codebooks every level shares: the levels after the first are
/// the caller's mips, filtered as it chose, and `how.mips` is not used (the encoder makes
/// none). One level alone is [`encode_etc1s`]'s input.
///
/// # Errors
/// No levels, a level whose bytes or size do not follow from the one before (each side
/// halved, at least 1), a quality out of range, or the encoder's failure.
pub fn encode_etc1s_levels(
    levels: &[(&[u8], (u32, u32))],
    how: Etc1s,
) -> Result<Etc1sImage, String> {
    let Some(&(rgba, (width, height))) = levels.first() else {
        return Err("no levels to encode".into());
    };
    whole_blocks(width, height)?;
    let mut expect = (width, height);
    for (i, (texels, size)) in levels.iter().enumerate() {
        if *size != expect {
            return Err(format!(
                "level {i} is {}x{}, {}x{} expected",
                size.0, size.1, expect.0, expect.1
            ));
        }
        if texels.len() != size.0 as usize * size.1 as usize * 4 {
            return Err(format!(
                "{} bytes are not {}x{} RGBA texels",
                texels.len(),
                size.0,
                size.1
            ));
        }
        expect = ((size.0 / 2).max(1), (size.1 / 2).max(1));
    }
    if !QUALITY.contains(&how.quality) {
        return Err(format!("ETC1S quality {} is outside 1..=255", how.quality));
    }
    let space = if how.srgb {
        ColorSpace::Srgb
    } else {
        ColorSpace::Linear
    };
    let mut params = CompressorParams::new();
    params.set_basis_format(BasisTextureFormat::ETC1S);
    params.set_etc1s_quality_level(how.quality);
    params.set_color_space(space);
    params.set_mip_color_space(space);
    params.set_generate_mipmaps(how.mips && levels.len() == 1);
    params.set_mipmap_smallest_dimension(1);
    params.set_print_status_to_stdout(false);
    params.source_image_mut(0).init(rgba, width, height, 4);
    for (i, (texels, (w, h))) in levels.iter().enumerate().skip(1) {
        params
            .source_mipmap_image_mut(0, i as u32 - 1)
            .init(texels, *w, *h, 4);
    }
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get() as u32);
    let file = super::compress(&params, "ETC1S", threads)?;
    let image = from_basis(&file)?;
    if image.levels.len() != levels.len() && levels.len() > 1 {
        return Err(format!(
            "the encoder wrote {} levels of the {} given",
            image.levels.len(),
            levels.len()
        ));
    }
    Ok(image)
}

/// Reads `n` little-endian bytes at `at`.
fn read(bytes: &[u8], at: usize, n: usize) -> Result<u64, String> {
    let field = bytes
        .get(at..at + n)
        .ok_or("the .basis file is truncated")?;
    Ok(field
        .iter()
        .rev()
        .fold(0_u64, |v, b| (v << 8) | u64::from(*b)))
}

/// The `.basis` header's fields: (name, bytes), in order (77 bytes in all).
const HEADER: [(&str, usize); 26] = [
    ("sig", 2),
    ("ver", 2),
    ("header_size", 2),
    ("header_crc16", 2),
    ("data_size", 4),
    ("data_crc16", 2),
    ("total_slices", 3),
    ("total_images", 3),
    ("tex_format", 1),
    ("flags", 2),
    ("tex_type", 1),
    ("us_per_frame", 3),
    ("reserved", 4),
    ("userdata0", 4),
    ("userdata1", 4),
    ("total_endpoints", 2),
    ("endpoint_cb_file_ofs", 4),
    ("endpoint_cb_file_size", 3),
    ("total_selectors", 2),
    ("selector_cb_file_ofs", 4),
    ("selector_cb_file_size", 3),
    ("tables_file_ofs", 4),
    ("tables_file_size", 4),
    ("slice_desc_file_ofs", 4),
    ("extended_file_ofs", 4),
    ("extended_file_size", 4),
];

/// A slice description's fields (23 bytes).
const SLICE: [(&str, usize); 10] = [
    ("image_index", 3),
    ("level_index", 1),
    ("flags", 1),
    ("orig_width", 2),
    ("orig_height", 2),
    ("num_blocks_x", 2),
    ("num_blocks_y", 2),
    ("file_ofs", 4),
    ("file_size", 4),
    ("slice_data_crc16", 2),
];

/// The `.basis` format's version this reads and writes.
const VERSION: u64 = 0x13;
/// `cBASISHeaderFlagETC1S`, `cBASISHeaderFlagHasAlphaSlices`, `cBASISHeaderFlagSRGB`.
const FLAG_ETC1S: u64 = 1;
const FLAG_ALPHA: u64 = 4;
const FLAG_SRGB: u64 = 16;
/// `cSliceDescFlagsHasAlpha`: the slice is an alpha slice.
const SLICE_ALPHA: u64 = 1;

fn record_len(fields: &[(&str, usize)]) -> usize {
    fields.iter().map(|(_, n)| n).sum()
}

/// The fields of a record at `at`, by name.
fn fields(
    bytes: &[u8],
    at: usize,
    layout: &[(&'static str, usize)],
) -> Result<std::collections::HashMap<&'static str, u64>, String> {
    let mut out = std::collections::HashMap::new();
    let mut o = at;
    for (name, n) in layout {
        out.insert(*name, read(bytes, o, *n)?);
        o += n;
    }
    Ok(out)
}

/// The part of `file` at `(offset, length)`.
fn part(file: &[u8], at: u64, len: u64) -> Result<Vec<u8>, String> {
    let (at, len) = (at as usize, len as usize);
    file.get(at..at.saturating_add(len))
        .map(<[u8]>::to_vec)
        .ok_or_else(|| "a part of the .basis file lies outside it".to_string())
}

/// Splits an ETC1S `.basis` file of one image into its codebooks, tables and slices.
fn from_basis(file: &[u8]) -> Result<Etc1sImage, String> {
    let h = fields(file, 0, &HEADER)?;
    if h["sig"] != u64::from(u16::from_le_bytes(*b"sB")) || h["ver"] != VERSION {
        return Err("the encoder's output is not a .basis file this reads".into());
    }
    if h["tex_format"] != 0 || h["flags"] & FLAG_ETC1S == 0 || h["total_images"] != 1 {
        return Err("the encoder's output is not one ETC1S image".into());
    }
    let mut levels: Vec<Level> = Vec::new();
    for i in 0..h["total_slices"] as usize {
        let s = fields(
            file,
            h["slice_desc_file_ofs"] as usize + i * record_len(&SLICE),
            &SLICE,
        )?;
        let data = part(file, s["file_ofs"], s["file_size"])?;
        let level = s["level_index"] as usize;
        if s["flags"] & SLICE_ALPHA != 0 {
            let l = levels
                .get_mut(level)
                .ok_or("an alpha slice comes before its colour slice")?;
            l.alpha = Some(data);
        } else if level == levels.len() {
            levels.push(Level {
                width: s["orig_width"] as u32,
                height: s["orig_height"] as u32,
                rgb: data,
                alpha: None,
            });
        } else {
            return Err("the slices are not in level order".into());
        }
    }
    Ok(Etc1sImage {
        endpoint_count: h["total_endpoints"] as u16,
        selector_count: h["total_selectors"] as u16,
        endpoints: part(file, h["endpoint_cb_file_ofs"], h["endpoint_cb_file_size"])?,
        selectors: part(file, h["selector_cb_file_ofs"], h["selector_cb_file_size"])?,
        tables: part(file, h["tables_file_ofs"], h["tables_file_size"])?,
        extended: part(file, h["extended_file_ofs"], h["extended_file_size"])?,
        levels,
    })
}

/// Appends `value` as `n` little-endian bytes.
fn put(out: &mut Vec<u8>, value: u64, n: usize) {
    out.extend_from_slice(&value.to_le_bytes()[..n]);
}

/// Writes `fields` (by name) in `layout`'s order.
fn put_record(out: &mut Vec<u8>, layout: &[(&str, usize)], value: impl Fn(&str) -> u64) {
    for (name, n) in layout {
        put(out, value(name), *n);
    }
}

/// The `.basis` file of `image` (one image, its levels), for the transcoder: checksums are
/// left zero (the transcoder checks them only when asked to).
fn to_basis(image: &Etc1sImage, srgb: bool) -> Result<Vec<u8>, String> {
    let slices: Vec<(usize, bool, &Level, &[u8])> = image
        .levels
        .iter()
        .enumerate()
        .flat_map(|(i, l)| {
            std::iter::once((i, false, l, l.rgb.as_slice()))
                .chain(l.alpha.as_deref().map(|a| (i, true, l, a)))
        })
        .collect();
    let header_len = record_len(&HEADER);
    let descs_at = header_len;
    let mut at = descs_at + slices.len() * record_len(&SLICE);
    let mut place = |len: usize| {
        let here = at;
        at += len;
        here as u64
    };
    let endpoints_at = place(image.endpoints.len());
    let selectors_at = place(image.selectors.len());
    let tables_at = place(image.tables.len());
    let extended_at = place(image.extended.len());
    let slice_at: Vec<u64> = slices.iter().map(|s| place(s.3.len())).collect();
    let total = at;
    let flags = FLAG_ETC1S
        | if image.has_alpha() { FLAG_ALPHA } else { 0 }
        | if srgb { FLAG_SRGB } else { 0 };
    let mut out = Vec::with_capacity(total);
    put_record(&mut out, &HEADER, |name| match name {
        "sig" => u64::from(u16::from_le_bytes(*b"sB")),
        "ver" => VERSION,
        "header_size" => header_len as u64,
        "data_size" => (total - header_len) as u64,
        "total_slices" => slices.len() as u64,
        "total_images" => 1,
        "flags" => flags,
        "total_endpoints" => u64::from(image.endpoint_count),
        "endpoint_cb_file_ofs" => endpoints_at,
        "endpoint_cb_file_size" => image.endpoints.len() as u64,
        "total_selectors" => u64::from(image.selector_count),
        "selector_cb_file_ofs" => selectors_at,
        "selector_cb_file_size" => image.selectors.len() as u64,
        "tables_file_ofs" => tables_at,
        "tables_file_size" => image.tables.len() as u64,
        "slice_desc_file_ofs" => descs_at as u64,
        "extended_file_ofs" => extended_at,
        "extended_file_size" => image.extended.len() as u64,
        _ => 0,
    });
    for ((level, alpha, l, data), offset) in slices.iter().zip(&slice_at) {
        whole_blocks(l.width.div_ceil(4) * 4, l.height.div_ceil(4) * 4)?;
        put_record(&mut out, &SLICE, |name| match name {
            "level_index" => *level as u64,
            "flags" if *alpha => SLICE_ALPHA,
            "orig_width" => u64::from(l.width),
            "orig_height" => u64::from(l.height),
            "num_blocks_x" => u64::from(l.width.div_ceil(4)),
            "num_blocks_y" => u64::from(l.height.div_ceil(4)),
            "file_ofs" => *offset,
            "file_size" => data.len() as u64,
            _ => 0,
        });
    }
    for part in [
        &image.endpoints,
        &image.selectors,
        &image.tables,
        &image.extended,
    ] {
        out.extend_from_slice(part);
    }
    for s in &slices {
        out.extend_from_slice(s.3);
    }
    Ok(out)
}

/// Every level of `image` transcoded to `target` (level 0 first), as a runtime transcodes it;
/// `srgb` as the file says.
///
/// # Errors
/// An image whose codebooks or slices the transcoder cannot read.
pub fn transcode_etc1s(
    image: &Etc1sImage,
    srgb: bool,
    target: Target,
) -> Result<Vec<Vec<u8>>, String> {
    if image.levels.is_empty() {
        return Err("the ETC1S image has no levels".into());
    }
    basis_universal::transcoder_init();
    let file = to_basis(image, srgb)?;
    let mut transcoder = Transcoder::new();
    transcoder
        .prepare_transcoding(&file)
        .map_err(|()| "the ETC1S codebooks do not decode".to_string())?;
    let format = match target {
        Target::Bc7 => TranscoderTextureFormat::BC7_RGBA,
        Target::Astc4x4 => TranscoderTextureFormat::ASTC_4x4_RGBA,
    };
    (0..image.levels.len() as u32)
        .map(|level_index| {
            transcoder
                .transcode_image_level(
                    &file,
                    format,
                    TranscodeParameters {
                        image_index: 0,
                        level_index,
                        decode_flags: None,
                        output_row_pitch_in_blocks_or_pixels: None,
                        output_rows_in_pixels: None,
                    },
                )
                .map_err(|e| format!("ETC1S level {level_index} does not transcode: {e:?}"))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn picture(w: u32, h: u32, alpha: bool) -> Vec<u8> {
        (0..w * h)
            .flat_map(|i| {
                let (x, y) = (i % w, i / w);
                [
                    (x * 255 / w) as u8,
                    (y * 255 / h) as u8,
                    if (x / 8 + y / 8) % 2 == 0 { 60 } else { 190 },
                    if alpha { (x * 4) as u8 } else { 255 },
                ]
            })
            .collect()
    }

    /// The blocks of level 0 as bcdec reads BC7, RGBA8.
    fn bc7_texels(blocks: &[u8], (w, h): (u32, u32)) -> Vec<u8> {
        let mut out = vec![0_u8; (w * h * 4) as usize];
        for (i, block) in blocks.chunks_exact(16).enumerate() {
            let (bx, by) = (i as u32 % (w / 4), i as u32 / (w / 4));
            let at = ((by * 4 * w + bx * 4) * 4) as usize;
            bcdec_rs::bc7(block, &mut out[at..], (w * 4) as usize);
        }
        out
    }

    #[test]
    fn etc1s_splits_into_codebooks_and_slices_and_transcodes_back() {
        let (w, h) = (64, 32);
        for alpha in [false, true] {
            let rgba = picture(w, h, alpha);
            let how = Etc1s {
                quality: 200,
                srgb: !alpha,
                mips: true,
            };
            let image = encode_etc1s(&rgba, (w, h), how).expect("encode");
            assert_eq!(image.levels.len(), 7, "64x32 down to 1x1");
            assert_eq!(image.has_alpha(), alpha);
            assert!(image.endpoint_count > 0 && image.selector_count > 0);
            assert_eq!((image.levels[1].width, image.levels[1].height), (32, 16));
            let bc7 = transcode_etc1s(&image, how.srgb, Target::Bc7).expect("BC7");
            assert_eq!(bc7.len(), 7);
            assert_eq!(bc7[0].len(), (w / 4 * h / 4) as usize * 16);
            let texels = bc7_texels(&bc7[0], (w, h));
            let channels = if alpha { 4 } else { 3 };
            let mean = rgba
                .chunks_exact(4)
                .zip(texels.chunks_exact(4))
                .flat_map(|(a, b)| (0..channels).map(move |c| f64::from(a[c].abs_diff(b[c]))))
                .sum::<f64>()
                / f64::from(w * h * channels as u32);
            assert!(mean < 6.0, "alpha {alpha}: mean error {mean}");
            let astc = transcode_etc1s(&image, how.srgb, Target::Astc4x4).expect("ASTC");
            assert_eq!(astc[0].len(), bc7[0].len());
        }
    }

    #[test]
    fn given_mips_are_encoded_as_given_with_shared_codebooks() {
        let how = Etc1s {
            quality: 128,
            srgb: false,
            mips: false,
        };
        // Level 0 a gradient, level 1 (16x8) flat red: the encoder's own mip would be a
        // gradient, so a flat level back shows the given one was used.
        let level0 = picture(32, 16, false);
        let level1: Vec<u8> = [200, 20, 20, 255].repeat(16 * 8);
        let level2: Vec<u8> = [20, 200, 20, 255].repeat(8 * 4);
        let levels = [
            (&level0[..], (32, 16)),
            (&level1[..], (16, 8)),
            (&level2[..], (8, 4)),
        ];
        let image = encode_etc1s_levels(&levels, how).expect("encode");
        assert_eq!(image.levels.len(), 3);
        let bc7 = transcode_etc1s(&image, false, Target::Bc7).expect("BC7");
        let red = bc7_texels(&bc7[1], (16, 8));
        let green = bc7_texels(&bc7[2], (8, 4));
        for (texels, want) in [(red, [200, 20, 20]), (green, [20, 200, 20])] {
            for px in texels.chunks_exact(4) {
                for c in 0..3 {
                    assert!(px[c].abs_diff(want[c]) <= 8, "{px:?} vs {want:?}");
                }
            }
        }
        // Sizes that do not halve are refused before the encoder runs.
        let bad = [(&level0[..], (32, 16)), (&level2[..], (8, 4))];
        assert!(encode_etc1s_levels(&bad, how).is_err());
        assert!(encode_etc1s_levels(&[], how).is_err());
    }

    #[test]
    fn a_damaged_image_and_bad_settings_are_refused() {
        let rgba = picture(16, 16, false);
        let ok = Etc1s {
            quality: 128,
            srgb: true,
            mips: false,
        };
        assert!(encode_etc1s(&rgba, (16, 12), ok).is_err());
        assert!(encode_etc1s(&rgba, (16, 16), Etc1s { quality: 0, ..ok }).is_err());
        let mut image = encode_etc1s(&rgba, (16, 16), ok).expect("encode");
        assert_eq!(image.levels.len(), 1);
        image.endpoints.truncate(1);
        assert!(transcode_etc1s(&image, true, Target::Bc7).is_err());
        image.levels.clear();
        assert!(transcode_etc1s(&image, true, Target::Bc7).is_err());
    }
}
