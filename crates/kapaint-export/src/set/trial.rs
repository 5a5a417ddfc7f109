//! One image of a block-compressed set's trials ([`super::choose`]): its texels, its codec
//! (strips, or the whole image with its mips for ETC1S), level 0 as stored and as the last
//! trial compressed it, and, once chosen, its KTX2 file.

use super::encode::{KtxTexels, StoredImage};
use super::failure::Failure;
use super::manifest::Comp;
use super::role::Role;
use crate::blocks::Coder;
use crate::codec::etc1s::{Etc1sCodec, Etc1sLevels};
use crate::codec::{Codec, Effort};
use crate::ktx::{self, Compressed};
use kapaint_base::task::Progress;

/// A mip level as stored: its size and bytes.
type Mip = ((u32, u32), Vec<u8>);

/// How an image's blocks are encoded: a strip at a time (level 0 in the trials, the mips
/// once chosen), or the whole image with its mips at once (ETC1S, whose codebooks every level
/// shares: a trial encodes the file it would write).
pub(super) enum ImageCodec {
    Strips(Box<dyn Codec>),
    Whole(Etc1sCodec),
}

/// What a trial's encode left: level 0's blocks (their PSNR measured once asked), or the
/// whole image's levels with level 0's PSNR.
pub(super) enum Blocks {
    Strips(Compressed),
    Whole(Etc1sLevels, Vec<Option<f64>>),
}

/// One image of a trial: its texels and codec, level 0 as stored, and level 0 compressed.
pub(super) struct TrialImage<'a> {
    pub(super) role: Role,
    pub(super) comps: Vec<Comp>,
    pub(super) srgb: bool,
    pub(super) half: bool,
    pub(super) texels: KtxTexels<'a>,
    /// The image's codec (its contexts serve every trial and the mips).
    pub(super) codec: ImageCodec,
    pub(super) level0: Vec<u8>,
    /// Levels 1 and on as stored, for a codec that encodes them with level 0 (made once).
    pub(super) mips: Option<Vec<Mip>>,
    /// Level 0's blocks (or the whole image's), and the effort the codec ran for them.
    pub(super) compressed: Option<(Effort, Blocks)>,
}

impl TrialImage<'_> {
    /// Compresses level 0 at `effort`, unless it already is at an effort the codec does not
    /// tell apart from it.
    pub(super) fn compress(
        &mut self,
        encoder: Coder<'_>,
        effort: Effort,
        size: (u32, u32),
        p: &Progress,
    ) -> Result<(), Failure> {
        let runs = match &self.codec {
            ImageCodec::Strips(codec) => codec.effort(effort),
            ImageCodec::Whole(_) => effort,
        };
        if self.compressed.as_ref().is_some_and(|(e, _)| *e == runs) {
            p.advance(u64::from(size.1));
            return Ok(());
        }
        let blocks = match &self.codec {
            ImageCodec::Strips(codec) => {
                let per = ktx::texel_layout(self.texels.spaces()).0;
                let blocks = (&**codec, effort);
                let c = ktx::compress_level(encoder, blocks, &self.level0, size, per, Some(p))
                    .map_err(|e| e.to_string())?;
                Blocks::Strips(c)
            }
            ImageCodec::Whole(codec) => {
                let mips = self
                    .mips
                    .get_or_insert_with(|| ktx::mips(&self.texels.source(size, &self.level0)));
                let levels: Vec<((u32, u32), &[u8])> = std::iter::once((size, &self.level0[..]))
                    .chain(mips.iter().map(|(s, t)| (*s, &t[..])))
                    .collect();
                let whole = codec.encode(&levels, effort).map_err(|e| e.to_string())?;
                let spaces = self.texels.spaces();
                let psnr = whole
                    .decoded
                    .first()
                    .map_or_else(Vec::new, |d| ktx::psnr(&self.level0, d, spaces));
                p.advance(u64::from(size.1));
                Blocks::Whole(whole, psnr)
            }
        };
        self.compressed = Some((runs, blocks));
        Ok(())
    }

    /// Level 0 as a consumer decodes it, where it was compressed.
    fn decoded(&self) -> Option<&[u8]> {
        Some(match &self.compressed.as_ref()?.1 {
            Blocks::Strips(c) => &c.decoded,
            Blocks::Whole(w, _) => w.decoded.first()?,
        })
    }

    /// Level 0's PSNR per component, where it was compressed.
    pub(super) fn psnr(&mut self) -> Vec<Option<f64>> {
        let spaces = self.texels.spaces();
        match self.compressed.as_mut() {
            Some((_, Blocks::Strips(c))) => c.psnr(&self.level0, spaces).to_vec(),
            Some((_, Blocks::Whole(_, psnr))) => psnr.clone(),
            None => Vec::new(),
        }
    }

    /// Level 0 as stored before any block: what the uncompressed files would hold.
    pub(super) fn uncompressed(&self) -> StoredImage<'_> {
        StoredImage {
            comps: self.comps.clone(),
            data: self.level0[..].into(),
            srgb: self.srgb,
            half: self.half,
        }
    }

    pub(super) fn stored(&self) -> StoredImage<'_> {
        StoredImage {
            comps: self.comps.clone(),
            data: self.decoded().map_or_else(Default::default, Into::into),
            srgb: self.srgb,
            half: self.half,
        }
    }
    /// The image's KTX2 file, with its mips: level 0 as compressed where it was (the strip
    /// codecs encode the mips now), or the whole image as its trial encoded it.
    ///
    /// # Errors
    /// A failed encode, or an image encoded whole that no trial encoded.
    pub(super) fn written(
        &mut self,
        (encoder, effort): (Coder<'_>, Effort),
        size: (u32, u32),
        progress: &Progress,
    ) -> Result<ktx::Written, Failure> {
        Ok(match (&self.codec, self.compressed.take()) {
            (ImageCodec::Whole(codec), Some((_, Blocks::Whole(whole, psnr)))) => {
                progress.advance(u64::from(size.1));
                whole_written(*codec, whole, Some(psnr))?
            }
            (ImageCodec::Whole(_), _) => return Err("the ETC1S image was not encoded".into()),
            (ImageCodec::Strips(codec), compressed) => {
                let compressed = compressed.and_then(|(_, c)| match c {
                    Blocks::Strips(c) => Some(c),
                    Blocks::Whole(..) => None,
                });
                ktx::encode(
                    &self.texels.source(size, &self.level0),
                    Some((encoder, &**codec, effort)),
                    compressed,
                    progress,
                )?
            }
        })
    }
}

/// The KTX2 file of an image encoded whole (ETC1S with BasisLZ), with every level as a
/// consumer decodes it.
fn whole_written(
    codec: Etc1sCodec,
    whole: Etc1sLevels,
    psnr: Option<Vec<Option<f64>>>,
) -> Result<ktx::Written, Failure> {
    Ok(ktx::Written {
        bytes: ktx::etc1s_file(&whole.image, codec.srgb())?,
        levels: whole.decoded.len() as u32,
        decoded: whole.decoded,
        psnr,
        compression: codec.compression(),
    })
}
