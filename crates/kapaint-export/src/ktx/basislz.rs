//! KTX2 files of ETC1S with BasisLZ (supercompression scheme 1): the image's codebooks and
//! Huffman tables in the supercompression global data (after a header of counts and lengths,
//! one image description per level: where its colour and alpha slices lie in the level's
//! data), each level's data its colour slice then its alpha slice. The data format descriptor
//! names the ETC1S colour model (163) with one sample for the colour slice (`ETC1S_RGB`) and
//! one for the alpha slice (`ETC1S_AAA`) where there is one, `bytesPlane` zero as the
//! specification asks of BasisLZ; `typeSize` 1; no level has an uncompressed length.

use ktx2::dfd;

use super::assembly::{Described, assemble};
use crate::codec::etc1s::{Etc1sImage, Level};

/// The supercompression global data's header: two counts and four lengths (20 bytes), then
/// one image description of five words per level (20 bytes).
const SGD_HEADER: usize = 20;
const IMAGE_DESC: usize = 20;

/// The data format descriptor of an ETC1S image, with an alpha sample where `alpha`.
fn descriptor(srgb: bool, alpha: bool) -> Result<Described, String> {
    let four = std::num::NonZeroU8::new(4).ok_or("a block of four")?;
    let one = std::num::NonZeroU8::MIN;
    let sample = |offset: u16, channel: u8| -> Result<dfd::SampleInformation, String> {
        Ok(dfd::SampleInformation {
            bit_offset: offset,
            bit_length: std::num::NonZeroU8::new(64).ok_or("64 bits")?,
            channel_type: channel,
            channel_type_qualifiers: dfd::ChannelTypeQualifiers::empty(),
            sample_positions: [0; 4],
            lower: 0,
            upper: u32::MAX,
        })
    };
    // KHR_DF_CHANNEL_ETC1S_RGB (0) and KHR_DF_CHANNEL_ETC1S_AAA (15).
    let mut samples = vec![sample(0, 0)?];
    if alpha {
        samples.push(sample(64, 15)?);
    }
    let basic = dfd::Basic {
        color_model: Some(ktx2::ColorModel::ETC1S),
        color_primaries: Some(ktx2::ColorPrimaries::BT709),
        transfer_function: Some(if srgb {
            ktx2::TransferFunction::SRGB
        } else {
            ktx2::TransferFunction::Linear
        }),
        flags: dfd::DataFormatFlags::STRAIGHT_ALPHA,
        texel_block_dimensions: [four, four, one, one],
        bytes_planes: [0; 8],
        sample_information: samples,
    };
    Ok(Described::new(None, &basic, 1, 1))
}

/// The KTX2 file of `image` (`srgb` colour or linear data).
///
/// # Errors
/// An image without levels, or one too large for the format's 32-bit lengths.
pub fn etc1s_file(image: &Etc1sImage, srgb: bool) -> Result<Vec<u8>, String> {
    let first = image
        .levels
        .first()
        .ok_or("the ETC1S image has no levels")?;
    let too_large = || "the ETC1S image is too large for KTX2's 32-bit lengths".to_string();
    let word = |n: usize| u32::try_from(n).map_err(|_| too_large());
    let mut sgd = Vec::new();
    sgd.extend_from_slice(&image.endpoint_count.to_le_bytes());
    sgd.extend_from_slice(&image.selector_count.to_le_bytes());
    for part in [
        &image.endpoints,
        &image.selectors,
        &image.tables,
        &image.extended,
    ] {
        sgd.extend_from_slice(&word(part.len())?.to_le_bytes());
    }
    let mut levels = Vec::with_capacity(image.levels.len());
    for level in &image.levels {
        let alpha = level.alpha.as_deref().unwrap_or_default();
        let desc = [
            0,
            0,
            word(level.rgb.len())?,
            if alpha.is_empty() {
                0
            } else {
                word(level.rgb.len())?
            },
            word(alpha.len())?,
        ];
        for w in desc {
            sgd.extend_from_slice(&w.to_le_bytes());
        }
        let mut data = level.rgb.clone();
        data.extend_from_slice(alpha);
        levels.push(data);
    }
    for part in [
        &image.endpoints,
        &image.selectors,
        &image.tables,
        &image.extended,
    ] {
        sgd.extend_from_slice(part);
    }
    let described = descriptor(srgb, image.has_alpha())?;
    let stored: Vec<(&[u8], u64)> = levels.iter().map(|l| (l.as_slice(), 0)).collect();
    Ok(assemble(
        &described,
        (first.width, first.height),
        &stored,
        Some((ktx2::SupercompressionScheme::BasisLZ, &sgd)),
    ))
}

/// The ETC1S image of a BasisLZ KTX2 file `reader` reads, and whether it is sRGB.
///
/// # Errors
/// Global data or levels that do not hold what the header says (truncated, lengths past the
/// data, a level count that is not the descriptions').
pub fn read_etc1s(reader: &ktx2::Reader<&[u8]>) -> Result<(Etc1sImage, bool), String> {
    let header = reader.header();
    let sgd = reader.supercompression_global_data();
    let bad = |what: &str| format!("the BasisLZ global data {what}");
    let word = |at: usize| -> Result<usize, String> {
        sgd.get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
            .ok_or_else(|| bad("is truncated"))
    };
    let half = |at: usize| -> Result<u16, String> {
        sgd.get(at..at + 2)
            .map(|b| u16::from_le_bytes([b[0], b[1]]))
            .ok_or_else(|| bad("is truncated"))
    };
    let count = reader.levels().len();
    if header.layer_count > 1 || header.face_count != 1 || header.pixel_depth > 1 {
        return Err("a BasisLZ file of layers, faces or depth is not one kapaint reads".into());
    }
    let lengths = [word(4)?, word(8)?, word(12)?, word(16)?];
    let mut at = SGD_HEADER + count * IMAGE_DESC;
    let mut parts = Vec::with_capacity(4);
    for len in lengths {
        let end = at.checked_add(len).ok_or_else(|| bad("is truncated"))?;
        parts.push(
            sgd.get(at..end)
                .ok_or_else(|| bad("is truncated"))?
                .to_vec(),
        );
        at = end;
    }
    let mut levels = Vec::with_capacity(count);
    for (i, level) in reader.levels().enumerate() {
        let d = SGD_HEADER + i * IMAGE_DESC;
        let slice = |offset: usize, len: usize| {
            level
                .data
                .get(offset..offset.saturating_add(len))
                .map(<[u8]>::to_vec)
                .ok_or_else(|| format!("level {i}'s slices lie outside its data"))
        };
        let rgb = slice(word(d + 4)?, word(d + 8)?)?;
        let alpha_len = word(d + 16)?;
        let alpha = if alpha_len > 0 {
            Some(slice(word(d + 12)?, alpha_len)?)
        } else {
            None
        };
        levels.push(Level {
            width: (header.pixel_width >> i).max(1),
            height: (header.pixel_height.max(1) >> i).max(1),
            rgb,
            alpha,
        });
    }
    let [endpoints, selectors, tables, extended] =
        <[Vec<u8>; 4]>::try_from(parts).map_err(|_| bad("has no codebooks"))?;
    let srgb = reader.transfer_function() == Some(ktx2::TransferFunction::SRGB);
    Ok((
        Etc1sImage {
            endpoint_count: half(0)?,
            selector_count: half(2)?,
            endpoints,
            selectors,
            tables,
            extended,
            levels,
        },
        srgb,
    ))
}
