//! A KTX2 file put together: the header, the level index, the data format descriptor, the
//! writer's name, the supercompression global data where there is some, then the levels from
//! smallest to largest, each aligned as the specification asks. Built from the `ktx2` crate's
//! header, level index and descriptor types (that crate reads KTX2 but does not assemble it).

use ktx2::{Format as KtxFormat, Header, Index, LevelIndex, dfd};

use crate::codec::{self, Codec};

/// What a KTX2 file's header and data format descriptor say its texels are.
pub(crate) struct Described {
    /// The header's `vkFormat` (`None`: UNDEFINED, the descriptor says: UASTC).
    pub(super) format: Option<KtxFormat>,
    /// The data format descriptor as the file holds it (its total size first).
    pub(super) dfd: Vec<u8>,
    /// The header's `typeSize`.
    pub(super) type_size: u32,
    /// Plain level data's alignment: lcm(texel block size, 4).
    pub(super) align: usize,
}

impl Described {
    /// Texels of `format` (uncompressed, or a block format kapaint reads back).
    pub(crate) fn of_format(format: KtxFormat) -> Result<Self, String> {
        let (basic, type_size) = dfd::Basic::from_format(format)
            .map_err(|e| format!("data format descriptor: {e:?}"))?;
        let align = codec::from_vk_format(format).map_or(4, |c| c.block_bytes().max(4));
        Ok(Self::new(Some(format), &basic, type_size, align))
    }

    /// `codec`'s blocks.
    pub(crate) fn of_codec(codec: &dyn Codec) -> Result<Self, String> {
        let (basic, type_size) = codec.dfd()?;
        Ok(Self::new(
            codec.vk_format(),
            &basic,
            type_size,
            codec.block_bytes().max(4),
        ))
    }

    /// The header's format, the descriptor, `typeSize` and plain level data's alignment.
    pub(super) fn new(
        format: Option<KtxFormat>,
        basic: &dfd::Basic,
        type_size: u32,
        align: usize,
    ) -> Self {
        let block = dfd::Block::Basic(basic.clone()).to_vec();
        let mut dfd = ((block.len() + 4) as u32).to_le_bytes().to_vec();
        dfd.extend_from_slice(&block);
        Self {
            format,
            dfd,
            type_size,
            align,
        }
    }
}

/// The file of `levels` (each its stored bytes and its length uncompressed), plain or
/// supercompressed by a scheme with its global data (BasisLZ's codebooks; none for zstd,
/// aligned to 8): a supercompressed level is aligned to 1, a plain one to lcm(texel block
/// size, 4).
pub(super) fn assemble(
    described: &Described,
    (w, h): (u32, u32),
    levels: &[(&[u8], u64)],
    supercompression: Option<(ktx2::SupercompressionScheme, &[u8])>,
) -> Vec<u8> {
    let supercompressed = supercompression.is_some();
    let sgd = supercompression.map_or(&[][..], |(_, g)| g);
    let dfd_bytes = &described.dfd;
    let mut kvd = Vec::new();
    let entry = format!("KTXwriter\0kapaint {}\0", env!("CARGO_PKG_VERSION"));
    kvd.extend_from_slice(&(entry.len() as u32).to_le_bytes());
    kvd.extend_from_slice(entry.as_bytes());
    kvd.resize(kvd.len().div_ceil(4) * 4, 0);
    // Level data alignment: lcm(texel block size, 4); 1 when supercompressed.
    let block_bytes = if supercompressed { 1 } else { described.align };
    let index_at = Header::LENGTH;
    let dfd_at = index_at + levels.len() * LevelIndex::LENGTH;
    let kvd_at = dfd_at + dfd_bytes.len();
    let sgd_at = if sgd.is_empty() {
        0
    } else {
        (kvd_at + kvd.len()).div_ceil(8) * 8
    };
    let mut at = if sgd.is_empty() {
        kvd_at + kvd.len()
    } else {
        sgd_at + sgd.len()
    };
    let mut index = vec![
        LevelIndex {
            byte_offset: 0,
            byte_length: 0,
            uncompressed_byte_length: 0,
        };
        levels.len()
    ];
    let mut body = Vec::new();
    for (i, &(level, uncompressed)) in levels.iter().enumerate().rev() {
        let aligned = at.div_ceil(block_bytes) * block_bytes;
        body.resize(body.len() + (aligned - at), 0);
        index[i] = LevelIndex {
            byte_offset: aligned as u64,
            byte_length: level.len() as u64,
            uncompressed_byte_length: uncompressed,
        };
        body.extend_from_slice(level);
        at = aligned + level.len();
    }
    let header = Header {
        format: described.format,
        type_size: described.type_size,
        pixel_width: w,
        pixel_height: h,
        pixel_depth: 0,
        layer_count: 0,
        face_count: 1,
        level_count: levels.len() as u32,
        supercompression_scheme: supercompression.map(|(scheme, _)| scheme),
        index: Index {
            dfd_byte_offset: dfd_at as u32,
            dfd_byte_length: dfd_bytes.len() as u32,
            kvd_byte_offset: kvd_at as u32,
            kvd_byte_length: kvd.len() as u32,
            sgd_byte_offset: sgd_at as u64,
            sgd_byte_length: sgd.len() as u64,
        },
    };
    let mut out = Vec::with_capacity(at);
    out.extend_from_slice(&header.as_bytes());
    for entry in &index {
        out.extend_from_slice(&entry.as_bytes());
    }
    out.extend_from_slice(dfd_bytes);
    out.extend_from_slice(&kvd);
    if !sgd.is_empty() {
        out.resize(sgd_at, 0);
        out.extend_from_slice(sgd);
    }
    out.extend_from_slice(&body);
    out
}
