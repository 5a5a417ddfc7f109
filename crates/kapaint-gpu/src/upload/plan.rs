//! Planning a sync: dirty tiles grouped into rectangles, each rectangle's mip levels laid
//! out in the staging buffer, in batches of bounded size.

use super::{BATCH_BYTES, RECT_TILES, TILE_LEVEL};
use kapaint_model::Channels;
use kapaint_model::maps::TexelRect;
use kapaint_model::tile::TILE_SIZE;

/// A rectangle of tiles: columns `x0..x1`, rows `y0..y1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TileRect {
    pub x0: usize,
    pub y0: usize,
    pub x1: usize,
    pub y1: usize,
}

/// Rectangles that cover exactly `tiles` (ascending ids, `tiles_x` to a row), at most
/// [`RECT_TILES`] on a side: runs along each row, stacked where the row above has the same run.
pub fn tile_rects(tiles: &[usize], tiles_x: usize) -> Vec<TileRect> {
    let mut rects: Vec<TileRect> = Vec::new();
    // Indices of the rectangles that end at the previous row and at this one.
    let (mut above, mut this_row): (Vec<usize>, Vec<usize>) = (Vec::new(), Vec::new());
    let mut row = None;
    let mut i = 0;
    while i < tiles.len() {
        let (y, x0) = (tiles[i] / tiles_x, tiles[i] % tiles_x);
        let mut x1 = x0 + 1;
        while x1 - x0 < RECT_TILES
            && x1 < tiles_x
            && tiles.get(i + x1 - x0) == Some(&(y * tiles_x + x1))
        {
            x1 += 1;
        }
        i += x1 - x0;
        if row != Some(y) {
            if row.is_some_and(|r| r + 1 == y) {
                above = std::mem::take(&mut this_row);
            } else {
                above.clear();
                this_row.clear();
            }
            row = Some(y);
        }
        let stack = above.iter().copied().find(|&k| {
            let r = rects[k];
            r.x0 == x0 && r.x1 == x1 && r.y1 - r.y0 < RECT_TILES
        });
        if let Some(k) = stack {
            rects[k].y1 = y + 1;
            this_row.push(k);
        } else {
            this_row.push(rects.len());
            rects.push(TileRect {
                x0,
                y0: y,
                x1,
                y1: y + 1,
            });
        }
    }
    rects
}

/// One rectangle of one mip level, staged for all three textures: where each texture's rows
/// start in the staging buffer and how far apart they are (padded to wgpu's copy alignment).
#[derive(Clone, Copy, Debug)]
pub struct StagedImage {
    pub level: u32,
    pub origin: (u32, u32),
    pub extent: (u32, u32),
    /// The textures staged (the others keep what they hold: no bytes, no copy).
    pub channels: Channels,
    pub kd: u64,
    pub ks: u64,
    pub n: u64,
    pub rgba_row: u32,
    pub n_row: u32,
}

/// One batch of copies: its images in staging order (each rectangle's levels, then, in the
/// last batch, the parts of the levels above one texel per tile over them all) and the staging
/// bytes they take.
#[derive(Debug, Default)]
pub struct Batch {
    pub images: Vec<StagedImage>,
    pub len: u64,
    /// Each rectangle and how many of `images` are its levels, in order.
    pub(super) rects: Vec<(TileRect, usize)>,
}

impl Batch {
    /// The parts of the levels above one texel per tile (in the last batch only).
    pub fn top_levels(&self) -> &[StagedImage] {
        let rect_images = self.rects.iter().map(|&(_, count)| count).sum();
        &self.images[rect_images..]
    }

    /// Reserves room for one rectangle of `level` in the textures of `channels`.
    fn push_level(
        &mut self,
        level: u32,
        origin: (u32, u32),
        extent: (u32, u32),
        channels: Channels,
    ) {
        let align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let rgba_row = (extent.0 * 8).next_multiple_of(align);
        let n_row = (extent.0 * 2).next_multiple_of(align);
        let bytes = |on: bool, row: u32| {
            if on {
                u64::from(row) * u64::from(extent.1)
            } else {
                0
            }
        };
        let kd = self.len;
        let ks = kd + bytes(channels.kd, rgba_row);
        let n = ks + bytes(channels.ks, rgba_row);
        self.images.push(StagedImage {
            level,
            origin,
            extent,
            channels,
            kd,
            ks,
            n,
            rgba_row,
            n_row,
        });
        self.len = n + bytes(channels.n, n_row);
    }
}

/// The texels of a rectangle of tiles, clipped to the map.
pub(super) fn rect_texels(rect: TileRect, size: (u32, u32)) -> TexelRect {
    let t = TILE_SIZE as u32;
    let edge = |tiles: usize, side: u32| (tiles as u32).saturating_mul(t).min(side);
    TexelRect {
        x0: edge(rect.x0, size.0),
        y0: edge(rect.y0, size.1),
        x1: edge(rect.x1, size.0),
        y1: edge(rect.y1, size.1),
    }
}

/// The batches that stage `rects` of maps of `size` with `levels` mip levels: each
/// rectangle's levels up to one texel per tile, then, in the last, the texels of the levels
/// above over all the rectangles.
pub fn batches(rects: &[(TileRect, Channels)], size: (u32, u32), levels: u32) -> Vec<Batch> {
    let mut out = Vec::new();
    let mut batch = Batch::default();
    for &(rect, channels) in rects {
        if batch.len >= BATCH_BYTES {
            out.push(std::mem::take(&mut batch));
        }
        let texels = rect_texels(rect, size);
        let before = batch.images.len();
        for level in 0..levels.min(TILE_LEVEL + 1) {
            let r = texels.at_level(level, size);
            if !r.is_empty() {
                batch.push_level(level, (r.x0, r.y0), (r.width(), r.height()), channels);
            }
        }
        batch.rects.push((rect, batch.images.len() - before));
    }
    // The levels above: the texels over all the rectangles (their bounding box), in the
    // channels any of them staged.
    let bounds = rects.iter().map(|&(r, _)| r).reduce(|a, b| TileRect {
        x0: a.x0.min(b.x0),
        y0: a.y0.min(b.y0),
        x1: a.x1.max(b.x1),
        y1: a.y1.max(b.y1),
    });
    let channels = rects.iter().fold(Channels::NONE, |c, &(_, r)| c.union(r));
    if let Some(bounds) = bounds {
        let texels = rect_texels(bounds, size);
        for level in TILE_LEVEL + 1..levels {
            let r = texels.at_level(level, size);
            batch.push_level(level, (r.x0, r.y0), (r.width(), r.height()), channels);
        }
    }
    out.push(batch);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tiles a list of rectangles covers, ascending.
    fn covered(rects: &[TileRect], tiles_x: usize) -> Vec<usize> {
        let mut out: Vec<usize> = rects
            .iter()
            .flat_map(|r| {
                (r.y0..r.y1).flat_map(move |y| (r.x0..r.x1).map(move |x| y * tiles_x + x))
            })
            .collect();
        out.sort_unstable();
        out
    }

    #[test]
    fn a_square_of_tiles_is_one_rectangle() {
        let tiles: Vec<usize> = (2..6)
            .flat_map(|y| (3..7).map(move |x| y * 64 + x))
            .collect();
        let rects = tile_rects(&tiles, 64);
        assert_eq!(
            rects,
            [TileRect {
                x0: 3,
                y0: 2,
                x1: 7,
                y1: 6
            }]
        );
    }

    #[test]
    fn rectangles_cover_exactly_the_tiles_and_stay_small() {
        // A diagonal stroke, a full map, scattered tiles and a row that wraps to the next.
        let diagonal: Vec<usize> = (0..20).flat_map(|k| [k * 21, k * 21 + 1]).collect();
        let full: Vec<usize> = (0..20 * 20).collect();
        let scattered = vec![0, 5, 19, 20, 39, 40, 41, 399];
        for tiles in [diagonal, full, scattered] {
            let rects = tile_rects(&tiles, 20);
            assert_eq!(covered(&rects, 20), tiles);
            for r in &rects {
                assert!(r.x1 > r.x0 && r.y1 > r.y0);
                assert!(r.x1 - r.x0 <= RECT_TILES && r.y1 - r.y0 <= RECT_TILES);
                assert!(r.x1 <= 20, "{r:?} wraps to the next row");
            }
        }
        // The full 20 x 20 map: 3 x 3 rectangles of at most 8 x 8.
        assert_eq!(tile_rects(&(0..400).collect::<Vec<_>>(), 20).len(), 9);
    }

    #[test]
    fn large_syncs_are_split_into_batches_of_bounded_size() {
        let rects = tile_rects(&(0..128 * 128).collect::<Vec<_>>(), 128);
        let rects: Vec<_> = rects.into_iter().map(|r| (r, Channels::ALL)).collect();
        let batches = batches(&rects, (8192, 8192), 14);
        assert!(batches.len() > 1);
        // One rectangle past the limit at most: 512^2 texels of 18 bytes with mips.
        for b in &batches {
            assert!(b.len < BATCH_BYTES + (8 << 20), "{}", b.len);
        }
        // Every level above one texel per tile, once, in the last batch.
        let top: Vec<u32> = batches
            .last()
            .map(|b| {
                b.images
                    .iter()
                    .map(|i| i.level)
                    .filter(|&l| l > TILE_LEVEL)
                    .collect()
            })
            .unwrap_or_default();
        assert_eq!(top, (7..14).collect::<Vec<_>>());
    }
}
