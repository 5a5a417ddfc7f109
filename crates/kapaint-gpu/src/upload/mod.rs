//! Staging a sync's dirty tiles for the map textures: the tiles grouped into rectangles (one
//! image per rectangle and mip level, so a 256 x 256 region is 7 images, not 16 x 7), each
//! level's texels written straight into the mapped staging buffer, one band of tile rows per
//! parallel job (each band its own mapped views). Inside a tile the mips come from a compact
//! pyramid of sums; above one texel per tile, from sums per tile and per block kept between
//! syncs and re-added over the dirty tiles only.

mod plan;
mod pool;
mod stage;

pub use plan::{TileRect, batches, tile_rects};
pub use pool::StagingPool;
pub use stage::{fill_rects, fill_top};

use kapaint_model::tile::TILE_SIZE;

/// Tiles along each side of the largest rectangle staged as one image.
const RECT_TILES: usize = 8;

/// The most staging bytes one batch of copies fills: a larger sync (the first upload of a
/// large map) goes in several batches, so no staging buffer outgrows the device's limits.
const BATCH_BYTES: u64 = 64 << 20;

/// Staging buffers kept between syncs: one can still be read by the GPU's copies while the
/// next sync fills another.
const KEPT_BUFFERS: usize = 2;

/// The largest staging buffer kept after its sync: a stroke's few tiles reuse it; the buffers
/// of a whole-map upload (64 MB batches) go once copied, not held while the user paints.
const KEPT_BUFFER_BYTES: u64 = 16 << 20;

/// The mip level at which a tile is one texel.
const TILE_LEVEL: u32 = TILE_SIZE.trailing_zeros();
