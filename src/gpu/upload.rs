//! Staging a sync's dirty tiles for the map textures: the tiles grouped into rectangles (one
//! image per rectangle and mip level, so a 256 x 256 region is 7 images, not 16 x 7), each
//! level's texels written straight into the mapped staging buffer, one band of tile rows per
//! parallel job (each band its own mapped views). Inside a tile the mips come from a compact
//! pyramid of sums; above one texel per tile, from sums per tile and per block kept between
//! syncs and re-added over the dirty tiles only.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

use crate::model::texel::{N_MAX, clamp_nan_low, decode_n, decode_unorm};
use crate::model::tile::{Plane, TILE_SIZE, Tile};
use crate::model::{Channels, MaterialMaps};

use super::{Gpu, GpuError};

/// Sums of the level-0 texels under one texel of a mip level, what its mean is rounded from:
/// `k_d` and `k_s` as sums of unorm16 codes (exact), `n`, and how many texels. Wide enough
/// for a whole 8192^2 map.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Sums {
    codes: [u64; 6],
    n: f64,
    count: u64,
}

impl std::ops::AddAssign for Sums {
    fn add_assign(&mut self, o: Self) {
        for (c, o) in self.codes.iter_mut().zip(o.codes) {
            *c += o;
        }
        self.n += o.n;
        self.count += o.count;
    }
}

impl Sums {
    /// The mean `k_d` (`first == 0`) or `k_s` (`first == 3`) as the texture stores it, with
    /// alpha `a`.
    fn rgba(&self, first: usize, unorm16: bool, a: u16) -> [u16; 4] {
        let c = |i: usize| mean_code(self.codes[first + i], self.count.max(1), unorm16);
        [c(0), c(1), c(2), a]
    }

    /// The mean `n`.
    fn n(&self) -> f32 {
        (self.n / self.count.max(1) as f64) as f32
    }
}

/// The mean of `count` unorm16 codes summing to `sum`, as a texture of `k_d` or `k_s` stores
/// it: rounded half up as unorm16, or as half float.
fn mean_code(sum: u64, count: u64, unorm16: bool) -> u16 {
    if unorm16 && count.is_power_of_two() {
        // Whole blocks (away from the map's edges): an integer mean.
        return ((sum + (count >> 1)) >> count.trailing_zeros()) as u16;
    }
    let mean = sum as f64 / count as f64;
    if unorm16 {
        // In range by construction (a mean of codes); `as` saturates anyway.
        (mean + 0.5) as u16
    } else {
        half::f16::from_f64(mean / 65535.0).to_bits()
    }
}

/// Tiles along each side of the largest rectangle staged as one image.
const RECT_TILES: usize = 8;

/// The most staging bytes one batch of copies fills: a larger sync (the first upload of a
/// large map) goes in several batches, so no staging buffer outgrows the device's limits.
const BATCH_BYTES: u64 = 64 << 20;

/// Staging buffers kept between syncs: one can still be read by the GPU's copies while the
/// next sync fills another.
const KEPT_BUFFERS: usize = 2;

/// The mip level at which a tile is one texel.
const TILE_LEVEL: u32 = TILE_SIZE.trailing_zeros();

/// A rectangle of tiles: columns `x0..x1`, rows `y0..y1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct TileRect {
    pub x0: usize,
    pub y0: usize,
    pub x1: usize,
    pub y1: usize,
}

/// Rectangles that cover exactly `tiles` (ascending ids, `tiles_x` to a row), at most
/// [`RECT_TILES`] on a side: runs along each row, stacked where the row above has the same run.
pub(super) fn tile_rects(tiles: &[usize], tiles_x: usize) -> Vec<TileRect> {
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

/// A texel rectangle `(x0, y0, x1, y1)` of level 0 at mip `level`, in texels of that level,
/// clipped to the level's size (sizes that are not powers of two round down).
pub(super) fn level_rect(
    rect: (u32, u32, u32, u32),
    level: u32,
    size: (u32, u32),
) -> (u32, u32, u32, u32) {
    let (lw, lh) = ((size.0 >> level).max(1), (size.1 >> level).max(1));
    let (x0, y0, x1, y1) = rect;
    (
        (x0 >> level).min(lw),
        (y0 >> level).min(lh),
        ((x1 - 1) >> level).saturating_add(1).min(lw),
        ((y1 - 1) >> level).saturating_add(1).min(lh),
    )
}

/// One rectangle of one mip level, staged for all three textures: where each texture's rows
/// start in the staging buffer and how far apart they are (padded to wgpu's copy alignment).
#[derive(Clone, Copy, Debug)]
pub(super) struct StagedImage {
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
pub(super) struct Batch {
    pub images: Vec<StagedImage>,
    pub len: u64,
    /// Each rectangle and how many of `images` are its levels, in order.
    rects: Vec<(TileRect, usize)>,
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

/// The texels of a rectangle of tiles, `(x0, y0, x1, y1)` clipped to the map.
fn rect_texels(rect: TileRect, size: (u32, u32)) -> (u32, u32, u32, u32) {
    let t = TILE_SIZE as u32;
    let edge = |tiles: usize, side: u32| (tiles as u32).saturating_mul(t).min(side);
    (
        edge(rect.x0, size.0),
        edge(rect.y0, size.1),
        edge(rect.x1, size.0),
        edge(rect.y1, size.1),
    )
}

/// The batches that stage `rects` of maps of `size` with `levels` mip levels: each
/// rectangle's levels up to one texel per tile, then, in the last, the texels of the levels
/// above over all the rectangles.
pub(super) fn batches(rects: &[(TileRect, Channels)], size: (u32, u32), levels: u32) -> Vec<Batch> {
    let mut out = Vec::new();
    let mut batch = Batch::default();
    for &(rect, channels) in rects {
        if batch.len >= BATCH_BYTES {
            out.push(std::mem::take(&mut batch));
        }
        let texels = rect_texels(rect, size);
        let before = batch.images.len();
        for level in 0..levels.min(TILE_LEVEL + 1) {
            let r = level_rect(texels, level, size);
            if r.2 > r.0 && r.3 > r.1 {
                batch.push_level(level, (r.0, r.1), (r.2 - r.0, r.3 - r.1), channels);
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
            let r = level_rect(texels, level, size);
            batch.push_level(level, (r.0, r.1), (r.2 - r.0, r.3 - r.1), channels);
        }
    }
    out.push(batch);
    out
}

/// A run of rows of one staged image (all three textures), each mapped for writing.
struct Band {
    level: u32,
    /// The band's first texel, in texels of its level.
    origin: (u32, u32),
    kd: Rows,
    ks: Rows,
    n: Rows,
}

impl Band {
    /// Maps `rows` rows of `image` from its row `first_row` (in texels of its level), in the
    /// textures it stages.
    fn map(
        buffer: &wgpu::Buffer,
        image: &StagedImage,
        first_row: u32,
        rows: u32,
    ) -> Result<Self, GpuError> {
        let skip = u64::from(first_row - image.origin.1);
        let on = image.channels;
        let staged = |on: bool| if on { rows } else { 0 };
        let rgba = |offset: u64, on: bool| {
            let at = offset + skip * u64::from(image.rgba_row);
            Rows::map(buffer, at, staged(on), image.rgba_row)
        };
        Ok(Self {
            level: image.level,
            origin: (image.origin.0, first_row),
            kd: rgba(image.kd, on.kd)?,
            ks: rgba(image.ks, on.ks)?,
            n: Rows::map(
                buffer,
                image.n + skip * u64::from(image.n_row),
                staged(on.n),
                image.n_row,
            )?,
        })
    }
}

/// Rows of one texture in the mapped staging buffer, `pitch` bytes apart (no view when there
/// are no rows).
struct Rows {
    view: Option<wgpu::BufferViewMut>,
    pitch: usize,
}

impl Rows {
    /// Maps `rows` rows of `pitch` bytes at `offset` of `buffer`.
    fn map(buffer: &wgpu::Buffer, offset: u64, rows: u32, pitch: u32) -> Result<Self, GpuError> {
        let len = u64::from(rows) * u64::from(pitch);
        let view = if len == 0 {
            None
        } else {
            Some(
                buffer
                    .get_mapped_range_mut(offset..offset + len)
                    .map_err(|e| GpuError(format!("cannot write the staging buffer: {e}")))?,
            )
        };
        Ok(Self {
            view,
            pitch: pitch as usize,
        })
    }

    /// Whether these rows are staged (else the texture keeps what it holds).
    fn staged(&self) -> bool {
        self.view.is_some()
    }

    /// Writes `row` (`u16` words, little-endian as the GPU reads them) at row `y`, word `x`.
    fn put(&mut self, at: (usize, usize), row: &[u16]) {
        let bytes: &[u8] = bytemuck::cast_slice(row);
        if let Some(mut out) = self.bytes(at, bytes.len()) {
            out.copy_from_slice(bytes);
        }
    }

    /// The `len` bytes from row `y`, word `x`, to write (none where not staged).
    fn bytes(&mut self, (x, y): (usize, usize), len: usize) -> Option<wgpu::WriteOnly<'_, [u8]>> {
        let at = y * self.pitch + 2 * x;
        self.view.as_mut().map(|view| view.slice(at..at + len))
    }
}

/// The alpha written beside `k_d` and `k_s` (1 in either format).
fn alpha(unorm16: bool) -> u16 {
    if unorm16 { u16::MAX } else { 0x3c00 }
}

/// A unorm16 component as the texture stores it.
fn rgb_component(unorm16: bool, v: u16) -> u16 {
    if unorm16 {
        v
    } else {
        half::f16::from_f32(decode_unorm(v)).to_bits()
    }
}

/// One parallel job: one row of a rectangle's tiles and, per level, its band of rows.
struct Job {
    tiles: Vec<usize>,
    bands: Vec<Band>,
}

/// Stages the rectangles of `batch` into `buffer` (mapped) and returns the sums of every
/// tile staged. The levels above one texel per tile are left to [`TopSums::fill`].
pub(super) fn fill_rects(
    maps: &MaterialMaps,
    unorm16: bool,
    batch: &Batch,
    buffer: &wgpu::Buffer,
) -> Result<Vec<(usize, Sums)>, GpuError> {
    let size = (maps.width(), maps.height());
    let tiles_x = maps.tiles_x() as usize;
    let mut jobs: Vec<Job> = Vec::new();
    let mut images = batch.images.iter();
    for &(rect, count) in &batch.rects {
        let first_job = jobs.len();
        for ty in rect.y0..rect.y1 {
            jobs.push(Job {
                tiles: (rect.x0..rect.x1).map(|tx| ty * tiles_x + tx).collect(),
                bands: Vec::with_capacity(count),
            });
        }
        for image in images.by_ref().take(count) {
            let level = image.level;
            for (job, ty) in jobs[first_job..].iter_mut().zip(rect.y0..rect.y1) {
                // This tile row's rows at this level (none where the level rounds down).
                let row = TileRect {
                    y0: ty,
                    y1: ty + 1,
                    ..rect
                };
                let r = level_rect(rect_texels(row, size), level, size);
                job.bands
                    .push(Band::map(buffer, image, r.1, r.3.saturating_sub(r.1))?);
            }
        }
    }
    Ok(run_jobs(jobs, |job| {
        let bands = &mut job.bands;
        // One scratch pyramid per job, reused for each of its tiles.
        let mut sums = TileSums::new();
        job.tiles
            .iter()
            .map(|&id| (id, stage_tile(maps, id, unorm16, bands, &mut sums)))
            .collect()
    }))
}

/// Runs `work` on every job and gathers what it returns. The calling thread works too, taking
/// jobs in turn with the pool's threads: no job waits for a sleeping thread to wake, and a
/// single job never leaves the calling thread.
fn run_jobs<J: Send, R: Send>(jobs: Vec<J>, work: impl Fn(&mut J) -> Vec<R> + Sync) -> Vec<R> {
    let helpers = rayon::current_num_threads().min(jobs.len().saturating_sub(1));
    let jobs: Vec<Mutex<J>> = jobs.into_iter().map(Mutex::new).collect();
    let next = AtomicUsize::new(0);
    let results = Mutex::new(Vec::new());
    let take_turns = || {
        let mut done = Vec::new();
        while let Some(job) = jobs.get(next.fetch_add(1, Ordering::Relaxed)) {
            let mut job = job.lock().unwrap_or_else(PoisonError::into_inner);
            done.extend(work(&mut job));
        }
        results
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .append(&mut done);
    };
    rayon::in_place_scope(|scope| {
        for _ in 0..helpers {
            scope.spawn(|_| take_turns());
        }
        take_turns();
    });
    results.into_inner().unwrap_or_else(PoisonError::into_inner)
}

/// Sums over every tile and over each block of tiles under a texel of the levels above one
/// texel per tile: grid 0 has one cell per tile, each next grid one per `2 x 2` block of the
/// one below (the last row or column alone when odd), down to one cell. Kept between syncs:
/// a sync re-adds only the blocks over the tiles it staged.
#[derive(Debug)]
pub(super) struct TopSums {
    /// Each grid's cells (rows `w` apart), `w` and `h`.
    grids: Vec<(Vec<Sums>, usize, usize)>,
}

impl TopSums {
    /// Empty sums for `tiles_x x tiles_y` tiles.
    pub fn new(tiles_x: usize, tiles_y: usize) -> Self {
        let (mut w, mut h) = (tiles_x.max(1), tiles_y.max(1));
        let mut grids = vec![(vec![Sums::default(); w * h], w, h)];
        while w > 1 || h > 1 {
            (w, h) = (w.div_ceil(2), h.div_ceil(2));
            grids.push((vec![Sums::default(); w * h], w, h));
        }
        Self { grids }
    }

    /// Sets the sums of some tiles and re-adds the blocks over them, level by level.
    pub fn set(&mut self, tiles: &[(usize, Sums)]) {
        let Some((first, _, _)) = self.grids.first_mut() else {
            return;
        };
        let mut changed: Vec<usize> = Vec::with_capacity(tiles.len());
        for &(id, sums) in tiles {
            if let Some(cell) = first.get_mut(id) {
                *cell = sums;
                changed.push(id);
            }
        }
        for k in 1..self.grids.len() {
            let (below, above) = self.grids.split_at_mut(k);
            let ((cells, w, h), (next, nw, _)) = (&below[k - 1], &mut above[0]);
            let mut parents: Vec<usize> = changed
                .iter()
                .map(|&i| (i / w / 2) * *nw + (i % w) / 2)
                .collect();
            parents.sort_unstable();
            parents.dedup();
            for &p in &parents {
                let (x, y) = (2 * (p % *nw), 2 * (p / *nw));
                // Added in row order, as a whole fold of the grid would.
                let mut sum = Sums::default();
                for (cx, cy) in [(x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1)] {
                    if cx < *w && cy < *h {
                        sum += cells[cy * w + cx];
                    }
                }
                next[p] = sum;
            }
            changed = parents;
        }
    }

    /// Writes the parts of the levels above one texel per tile that `images` hold (in level
    /// order, the first from grid 1) into `buffer` (mapped).
    pub fn fill(
        &self,
        unorm16: bool,
        images: &[StagedImage],
        buffer: &wgpu::Buffer,
    ) -> Result<(), GpuError> {
        for (image, (grid, gw, _)) in images.iter().zip(self.grids.iter().skip(1)) {
            let mut band = Band::map(buffer, image, image.origin.1, image.extent.1)?;
            // The grid's cells are the level's texels (where sizes that are not powers of two
            // round down, the level has fewer: the grid's top-left ones).
            let (x, y) = (image.origin.0 as usize, image.origin.1 as usize);
            let extent = (image.extent.0 as usize, image.extent.1 as usize);
            write_means(&grid[y * gw + x..], *gw, unorm16, extent, &mut band);
        }
        Ok(())
    }
}

/// Stages tile `id` into `bands` (levels 0, 1, ... in order): level 0 copied from its planes,
/// the levels above from box sums (each from the one below, rounded once). Returns the
/// whole tile's sums.
fn stage_tile(
    maps: &MaterialMaps,
    id: usize,
    unorm16: bool,
    bands: &mut [Band],
    sums: &mut TileSums,
) -> Sums {
    let tile = maps.tile(id);
    let rect = maps.tile_rect(id);
    let Some((first, mips)) = bands.split_first_mut() else {
        return Sums::default();
    };
    let (w, h) = ((rect.2 - rect.0) as usize, (rect.3 - rect.1) as usize);
    let x = (rect.0 - first.origin.0) as usize;
    let y0 = (rect.1 - first.origin.1) as usize;
    let a = alpha(unorm16);
    let texel = |v: &[u16; 3]| {
        [
            rgb_component(unorm16, v[0]),
            rgb_component(unorm16, v[1]),
            rgb_component(unorm16, v[2]),
            a,
        ]
    };
    let mut row = [[0_u16; 4]; TILE_SIZE];
    let row = &mut row[..w];
    for (plane, out) in [(&tile.kd, &mut first.kd), (&tile.ks, &mut first.ks)] {
        if !out.staged() {
            continue;
        }
        if let Plane::Uniform(v) = plane {
            row.fill(texel(v));
        }
        for y in 0..h {
            let at = (x * 4, y0 + y);
            if let Plane::Data(d) = plane {
                let src = &d[y * TILE_SIZE..y * TILE_SIZE + w];
                if unorm16 {
                    // Straight into the staging buffer.
                    if let Some(bytes) = out.bytes(at, 8 * w) {
                        rgb_to_rgba(src, bytes, a);
                    }
                    continue;
                }
                for (o, v) in row.iter_mut().zip(src) {
                    *o = texel(v);
                }
            }
            out.put(at, row.as_flattened());
        }
    }
    let uniform_n = [tile.n.uniform().unwrap_or(0); TILE_SIZE];
    let n_rows = if first.n.staged() { h } else { 0 };
    for y in 0..n_rows {
        let row = match &tile.n {
            Plane::Uniform(_) => &uniform_n[..w],
            Plane::Data(d) => &d[y * TILE_SIZE..y * TILE_SIZE + w],
        };
        first.n.put((x, y0 + y), row);
    }
    stage_tile_mips(
        tile,
        rect,
        (maps.width(), maps.height()),
        unorm16,
        mips,
        sums,
    )
}

/// Writes RGB texels as RGBA ones with alpha `a` into `out` (8 bytes a texel, little-endian),
/// four at a time: three 8-byte loads and four 8-byte stores (the components move as whole
/// words, never one at a time).
fn rgb_to_rgba(src: &[[u16; 3]], out: wgpu::WriteOnly<'_, [u8]>, a: u16) {
    let alpha = u64::from(a) << 48;
    let low48 = (1_u64 << 48) - 1;
    let (groups, rest) = src.as_chunks::<4>();
    let (out_groups, out_rest) = out.into_chunks::<32>();
    out_groups.write_iter(groups.iter().map(|g| {
        // Four texels are 24 bytes: three little-endian words, each texel 48 bits of them.
        let [w0, w1, w2] = bytemuck::cast::<[[u16; 3]; 4], [u64; 3]>(*g).map(u64::from_le);
        let texels = [
            w0 & low48,
            (w0 >> 48 | w1 << 16) & low48,
            (w1 >> 32 | w2 << 32) & low48,
            w2 >> 16,
        ];
        bytemuck::cast::<[u64; 4], [u8; 32]>(texels.map(|t| (t | alpha).to_le()))
    }));
    let (out_rest, _) = out_rest.into_chunks::<8>();
    out_rest.write_iter(
        rest.iter()
            .map(|v| bytemuck::cast::<[u16; 4], [u8; 8]>([v[0], v[1], v[2], a].map(u16::to_le))),
    );
}

/// Cells on a side of a tile's level 1, the largest grid of in-tile sums.
const HALF_TILE: usize = TILE_SIZE / 2;

/// Box sums over one tile's texels at one mip level (1 and up), on the tile-local grid, kept
/// compact and folded in place: `k_d` and `k_s` as sums of unorm16 codes in `u32` (a whole
/// tile's fit), `n` in `f32`. A cell's texel count follows from its place (cells at the map's
/// right and bottom edges may be partial).
struct TileSums {
    codes: Vec<[u32; 6]>,
    n: Vec<f32>,
    /// Cells across and down (rows `w` apart).
    w: usize,
    h: usize,
    level: u32,
    /// The tile's texels across and down.
    texels: (usize, usize),
}

impl TileSums {
    /// Room for a whole tile's level 1 (28 KiB).
    fn new() -> Self {
        Self {
            codes: vec![[0; 6]; HALF_TILE * HALF_TILE],
            n: vec![0.0; HALF_TILE * HALF_TILE],
            w: 0,
            h: 0,
            level: 1,
            texels: (0, 0),
        }
    }

    /// Level 1 of `tile` (`w x h` texels): pairs of rows added down the columns first (codes
    /// as `u32`, `n` decoded and clamped), then pairs of columns.
    fn level_one(&mut self, tile: &Tile, (w, h): (usize, usize)) {
        (self.w, self.h, self.level, self.texels) = (w.div_ceil(2), h.div_ceil(2), 1, (w, h));
        let mut columns = [[0_u32; 3 * TILE_SIZE]; 2];
        let mut n_columns = [0.0_f32; TILE_SIZE];
        let mut n_row = [0.0_f32; TILE_SIZE];
        for gy in 0..self.h {
            let rows = 2 * gy..(2 * gy + 2).min(h);
            let row_count = rows.len() as u32;
            for (col, plane) in columns.iter_mut().zip([&tile.kd, &tile.ks]) {
                let col = &mut col[..3 * w];
                match plane {
                    Plane::Uniform(v) => {
                        for (c, k) in col.iter_mut().zip(v.iter().cycle()) {
                            *c = u32::from(*k) * row_count;
                        }
                    }
                    Plane::Data(d) => {
                        let row = |y: usize| d[y * TILE_SIZE..y * TILE_SIZE + w].as_flattened();
                        if row_count == 2 {
                            for ((c, a), b) in
                                col.iter_mut().zip(row(rows.start)).zip(row(rows.start + 1))
                            {
                                *c = u32::from(*a) + u32::from(*b);
                            }
                        } else {
                            for (c, a) in col.iter_mut().zip(row(rows.start)) {
                                *c = u32::from(*a);
                            }
                        }
                    }
                }
            }
            let n_columns = &mut n_columns[..w];
            match &tile.n {
                Plane::Uniform(v) => n_columns.fill(decode_n(*v) * row_count as f32),
                Plane::Data(d) => {
                    n_columns.fill(0.0);
                    for y in rows {
                        let bits: &[half::f16] = half::slice::HalfBitsSliceExt::reinterpret_cast(
                            &d[y * TILE_SIZE..y * TILE_SIZE + w],
                        );
                        half::slice::HalfFloatSliceExt::convert_to_f32_slice(bits, &mut n_row[..w]);
                        for (c, v) in n_columns.iter_mut().zip(&n_row[..w]) {
                            *c += clamp_nan_low(*v, 0.0, N_MAX);
                        }
                    }
                }
            }
            let cells = gy * self.w..(gy + 1) * self.w;
            let (kd, ks) = (&columns[0], &columns[1]);
            for (gx, (codes, n)) in self.codes[cells.clone()]
                .iter_mut()
                .zip(&mut self.n[cells])
                .enumerate()
            {
                let x = 2 * gx;
                let pair = x + 1 < w;
                let sum = |col: &[u32; 3 * TILE_SIZE], c: usize| {
                    col[3 * x + c] + if pair { col[3 * x + 3 + c] } else { 0 }
                };
                *codes = [
                    sum(kd, 0),
                    sum(kd, 1),
                    sum(kd, 2),
                    sum(ks, 0),
                    sum(ks, 1),
                    sum(ks, 2),
                ];
                *n = n_columns[x] + if pair { n_columns[x + 1] } else { 0.0 };
            }
        }
    }

    /// Texels under cell `g` along an axis with `texels` texels.
    fn cell_texels(&self, g: usize, texels: usize) -> u32 {
        let side = 1_usize << self.level;
        side.min(texels - g * side) as u32
    }

    /// The next level: each `2 x 2` block of cells added up (the last row or column alone
    /// when odd), written over the cells it came from.
    fn fold(&mut self) {
        let (w, h) = (self.w, self.h);
        let (nw, nh) = (w.div_ceil(2), h.div_ceil(2));
        // Cell `ny * nw + nx` reads cells at `2 ny * w + 2 nx` and after, which no earlier
        // cell of the next level has overwritten.
        for ny in 0..nh {
            for nx in 0..nw {
                let (x, y) = (2 * nx, 2 * ny);
                let block = [(x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1)];
                let mut codes = [0_u32; 6];
                let mut n = [0.0_f32; 4];
                for (k, (cx, cy)) in block.into_iter().enumerate() {
                    // Cells past the grid's edge add nothing.
                    if cx < w && cy < h {
                        let c = cy * w + cx;
                        for (o, v) in codes.iter_mut().zip(self.codes[c]) {
                            *o += v;
                        }
                        n[k] = self.n[c];
                    }
                }
                self.codes[ny * nw + nx] = codes;
                self.n[ny * nw + nx] = (n[0] + n[1]) + (n[2] + n[3]);
            }
        }
        (self.w, self.h, self.level) = (nw, nh, self.level + 1);
    }

    /// Writes the means of the top-left `ew x eh` cells into the textures of `band`, at
    /// texel `(x, y)` of the band.
    fn write(
        &self,
        unorm16: bool,
        (ew, eh): (usize, usize),
        band: &mut Band,
        (x, y): (usize, usize),
    ) {
        let a = alpha(unorm16);
        let mut rgba = [[0_u16; 4]; HALF_TILE];
        let mut n = [0.0_f32; HALF_TILE];
        let mut n_bits = [half::f16::ZERO; HALF_TILE];
        let (rgba, n, n_bits) = (&mut rgba[..ew], &mut n[..ew], &mut n_bits[..ew]);
        // Whole cells (`4^level` texels, all but those at a partial tile's edges) take the
        // fast path: an integer mean by shifting (unorm16), `n` scaled by an exact power of
        // two.
        let shift = 2 * self.level;
        let (half_count, inv_count) = (1_u32 << (shift - 1), 1.0 / (1_u32 << shift) as f32);
        let whole_columns = (self.texels.0 >> self.level).min(ew);
        for gy in 0..eh {
            let rows = self.cell_texels(gy, self.texels.1);
            let whole = if rows == 1 << self.level && unorm16 {
                whole_columns
            } else {
                0
            };
            let cells = gy * self.w..gy * self.w + ew;
            let count = |gx: usize| u64::from(self.cell_texels(gx, self.texels.0) * rows);
            for (first, out) in [(0, &mut band.kd), (3, &mut band.ks)] {
                if !out.staged() {
                    continue;
                }
                let codes = &self.codes[cells.clone()];
                for (o, c) in rgba[..whole].iter_mut().zip(codes) {
                    let mean = |i: usize| ((c[first + i] + half_count) >> shift) as u16;
                    *o = [mean(0), mean(1), mean(2), a];
                }
                for (gx, (o, c)) in rgba.iter_mut().zip(codes).enumerate().skip(whole) {
                    let mean = |i: usize| mean_code(u64::from(c[first + i]), count(gx), unorm16);
                    *o = [mean(0), mean(1), mean(2), a];
                }
                out.put((x * 4, y + gy), rgba.as_flattened());
            }
            if band.n.staged() {
                let sums = &self.n[cells];
                for (o, s) in n[..whole].iter_mut().zip(sums) {
                    *o = *s * inv_count;
                }
                for (gx, (o, s)) in n.iter_mut().zip(sums).enumerate().skip(whole) {
                    *o = *s / count(gx) as f32;
                }
                half::slice::HalfFloatSliceExt::convert_from_f32_slice(&mut *n_bits, n);
                band.n
                    .put((x, y + gy), bytemuck::cast_slice::<half::f16, u16>(n_bits));
            }
        }
    }

    /// The whole tile's sums (folding what is left to one cell).
    fn total(&mut self) -> Sums {
        while self.w > 1 || self.h > 1 {
            self.fold();
        }
        Sums {
            codes: self.codes[0].map(u64::from),
            n: f64::from(self.n[0]),
            count: (self.texels.0 * self.texels.1) as u64,
        }
    }
}

/// Stages the mip levels over `tile` (texels `rect` of maps of `size`) into `bands` (levels
/// 1, 2, ... in order), each level folded from the one below, rounded once. Returns the
/// whole tile's sums.
fn stage_tile_mips(
    tile: &Tile,
    rect: (u32, u32, u32, u32),
    size: (u32, u32),
    unorm16: bool,
    bands: &mut [Band],
    sums: &mut TileSums,
) -> Sums {
    let texels = ((rect.2 - rect.0) as usize, (rect.3 - rect.1) as usize);
    sums.level_one(tile, texels);
    for (k, band) in bands.iter_mut().enumerate() {
        if k > 0 {
            sums.fold();
        }
        // The grid's origin is the tile's at this level; the texture's part of it is its
        // top-left (the level may round down at the map's edges).
        let r = level_rect(rect, band.level, size);
        if r.2 > r.0 && r.3 > r.1 {
            let at = (
                (r.0 - band.origin.0) as usize,
                (r.1 - band.origin.1) as usize,
            );
            let extent = ((r.2 - r.0) as usize, (r.3 - r.1) as usize);
            sums.write(unorm16, extent, band, at);
        }
    }
    sums.total()
}

/// Writes the means of the top-left `w x h` sums of `grid` (rows `stride` apart) into the
/// textures of `band`, from its first texel.
fn write_means(
    grid: &[Sums],
    stride: usize,
    unorm16: bool,
    (w, h): (usize, usize),
    band: &mut Band,
) {
    let a = alpha(unorm16);
    let mut rgba = vec![[0_u16; 4]; w];
    let mut n = vec![0.0_f32; w];
    let mut n_bits = vec![half::f16::ZERO; w];
    for row in 0..h {
        let sums = &grid[row * stride..row * stride + w];
        for (first, out) in [(0, &mut band.kd), (3, &mut band.ks)] {
            if !out.staged() {
                continue;
            }
            for (o, s) in rgba.iter_mut().zip(sums) {
                *o = s.rgba(first, unorm16, a);
            }
            out.put((0, row), rgba.as_flattened());
        }
        if !band.n.staged() {
            continue;
        }
        for (o, s) in n.iter_mut().zip(sums) {
            *o = s.n();
        }
        half::slice::HalfFloatSliceExt::convert_from_f32_slice(&mut n_bits[..], &n);
        band.n
            .put((0, row), bytemuck::cast_slice::<half::f16, u16>(&n_bits));
    }
}

/// Staging buffers kept between syncs, each with whether its mapping for writing has
/// completed (it is mapped again as soon as it is submitted: ready once the GPU has copied
/// out of it).
#[derive(Default)]
pub(super) struct StagingPool {
    kept: Vec<(wgpu::Buffer, Arc<AtomicBool>)>,
}

impl StagingPool {
    /// A buffer of at least `len` bytes, mapped for writing: a kept one that is ready, else a
    /// new one while fewer than [`KEPT_BUFFERS`] are in flight, else a kept one once the GPU
    /// is done with it.
    pub fn take(&mut self, gpu: &Gpu, len: u64) -> wgpu::Buffer {
        let ready =
            |(b, m): &(wgpu::Buffer, Arc<AtomicBool>)| b.size() >= len && m.load(Ordering::Acquire);
        if !self.kept.iter().any(ready) && self.kept.len() >= KEPT_BUFFERS {
            // Every kept buffer is still being copied from: wait for the GPU. One still
            // unmapped after that failed to map, and goes.
            gpu.wait();
            self.kept.retain(|(_, m)| m.load(Ordering::Acquire));
        }
        if let Some(i) = self.kept.iter().position(ready) {
            return self.kept.swap_remove(i).0;
        }
        // Room to grow: a little more than asked, in whole MiB.
        gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("map tiles"),
            size: (len + 1).next_multiple_of(1 << 20),
            usage: wgpu::BufferUsages::MAP_WRITE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: true,
        })
    }

    /// Keeps `buffer` (submitted for copying) and maps it again; the smallest goes when more
    /// than [`KEPT_BUFFERS`] are kept.
    pub fn keep(&mut self, buffer: wgpu::Buffer) {
        let mapped = Arc::new(AtomicBool::new(false));
        let done = Arc::clone(&mapped);
        buffer.map_async(wgpu::MapMode::Write, .., move |r| {
            done.store(r.is_ok(), Ordering::Release);
        });
        self.kept.push((buffer, mapped));
        if self.kept.len() > KEPT_BUFFERS
            && let Some(i) = (0..self.kept.len()).min_by_key(|&i| self.kept[i].0.size())
        {
            self.kept.swap_remove(i);
        }
    }
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
    fn rgb_texels_become_rgba_with_alpha_at_any_length() {
        for len in [0_usize, 1, 3, 4, 5, 8, 63, 64] {
            let src: Vec<[u16; 3]> = (0..len as u16)
                .map(|i| [i * 3, i * 3 + 1, 0xfff0 - i].map(|c| c ^ 0x5a5a))
                .collect();
            let mut bytes = vec![0_u8; 8 * len];
            rgb_to_rgba(&src, wgpu::WriteOnly::from_mut(&mut bytes[..]), 0xabcd);
            let out: Vec<[u16; 4]> = bytes
                .as_chunks::<8>()
                .0
                .iter()
                .map(|b| bytemuck::cast::<[u8; 8], [u16; 4]>(*b).map(u16::from_le))
                .collect();
            for (o, v) in out.iter().zip(&src) {
                assert_eq!(*o, [v[0], v[1], v[2], 0xabcd], "length {len}");
            }
        }
    }

    #[test]
    fn top_sums_re_added_over_a_few_tiles_equal_sums_built_whole() {
        // 13 x 9 tiles: odd sides, so blocks at the right and bottom edges are partial.
        let (tx, ty) = (13, 9);
        let sums = |id: usize, k: u64| Sums {
            codes: [1, 2, 3, 4, 5, 6].map(|c| c * 1000 + (id as u64 * 7 + k) % 997),
            n: (id as f64 * 0.37 + k as f64).sin().abs() * 4096.0,
            count: 4096,
        };
        let all = |k: u64| (0..tx * ty).map(|id| (id, sums(id, k))).collect::<Vec<_>>();
        let mut kept = TopSums::new(tx, ty);
        kept.set(&all(0));
        // Some tiles change: the corner, an edge and a scattered few.
        let changed = [0, 12, 50, 51, 64, 116];
        let mut now = all(0);
        for &id in &changed {
            now[id] = (id, sums(id, 5));
        }
        kept.set(&changed.map(|id| now[id]));
        let mut whole = TopSums::new(tx, ty);
        whole.set(&now);
        assert_eq!(kept.grids.len(), 5, "13 x 9, 7 x 5, 4 x 3, 2 x 2, 1 x 1");
        for (k, (a, b)) in kept.grids.iter().zip(&whole.grids).enumerate() {
            assert_eq!(a, b, "grid {k}");
        }
        // The last cell is the sum of every tile.
        let mut total = Sums::default();
        for (_, s) in &now {
            total += *s;
        }
        assert_eq!(kept.grids[4].0[0].codes, total.codes);
        assert_eq!(kept.grids[4].0[0].count, total.count);
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
