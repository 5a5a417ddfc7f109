//! KTX2 files of levels the caller made (a normal map's box-filtered normals made unit again,
//! which no per-component average of its bytes gives).

use super::levels::half;
use super::{Blocks, Image, KtxError, Progress, Space, Written, level_count, write_levels};

/// Writes an image whose levels the caller made (finest first, a full chain: `levels[k]` of
/// the size [`level_count`]'s level `k` has) of `channels` linear bytes per texel, as a KTX2
/// file: uncompressed, or block-compressed as [`encode`](super::encode) does. A normal map's levels are its
/// box-filtered normals made unit again, which no per-component average gives.
///
/// # Errors
/// No levels, levels that are not a full chain of `channels` bytes per texel, or a component
/// count outside 1..=4 ([`KtxError::Shape`]); the codec's failure.
pub fn encode_levels(
    levels: &[((u32, u32), Vec<u8>)],
    channels: usize,
    compressed: Option<Blocks<'_>>,
) -> Result<Written, KtxError> {
    let spaces = vec![Space::Linear; channels];
    let Some(((w, h), level0)) = levels.first() else {
        return Err(KtxError::Shape("no levels".into()));
    };
    let mut size = (*w, *h);
    let whole = levels.len() == level_count(size.0, size.1) as usize
        && levels.iter().enumerate().all(|(k, (s, bytes))| {
            if k > 0 {
                size = half(size);
            }
            *s == size && bytes.len() == s.0 as usize * s.1 as usize * channels
        });
    if !whole || !(1..=4).contains(&channels) || *w == 0 || *h == 0 {
        return Err(KtxError::Shape(format!(
            "{} levels of a {w}x{h} image of {channels} components",
            levels.len()
        )));
    }
    let image = Image {
        spaces: &spaces,
        size: (*w, *h),
        level0,
        chain: &levels[1..],
    };
    write_levels(&image, compressed, None, &Progress::default())
}
