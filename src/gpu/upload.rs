//! Staging a sync's dirty tiles for the map textures: the tiles grouped into rectangles (one
//! image per rectangle and mip level, so a 256 x 256 region is 7 images, not 16 x 7), each
//! level's texels written straight into the mapped staging buffer, one band of tile rows per
//! parallel job (each band its own mapped views), and the levels above one texel per tile
//! rebuilt from per-tile sums.

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
        if unorm16 && self.count.is_power_of_two() {
            // Whole blocks (away from the map's edges): an integer mean, rounded half up.
            let (shift, half) = (self.count.trailing_zeros(), self.count >> 1);
            let c = |i: usize| ((self.codes[first + i] + half) >> shift) as u16;
            return [c(0), c(1), c(2), a];
        }
        let inv = 1.0 / self.count.max(1) as f64;
        let c = |i: usize| {
            let mean = self.codes[first + i] as f64 * inv;
            if unorm16 {
                // In range by construction (a mean of codes); `as` saturates anyway.
                (mean + 0.5) as u16
            } else {
                half::f16::from_f64(mean / 65535.0).to_bits()
            }
        };
        [c(0), c(1), c(2), a]
    }

    /// The mean `n`.
    fn n(&self) -> f32 {
        (self.n / self.count.max(1) as f64) as f32
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
/// last batch, the whole levels above one texel per tile) and the staging bytes they take.
#[derive(Debug, Default)]
pub(super) struct Batch {
    pub images: Vec<StagedImage>,
    pub len: u64,
    /// Each rectangle and how many of `images` are its levels, in order.
    rects: Vec<(TileRect, usize)>,
}

impl Batch {
    /// The whole levels above one texel per tile (in the last batch only).
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
/// rectangle's levels up to one texel per tile, then the levels above, whole, in the last.
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
    // The whole levels above: every channel (the means of all the tiles, tiny).
    for level in TILE_LEVEL + 1..levels {
        let extent = ((size.0 >> level).max(1), (size.1 >> level).max(1));
        batch.push_level(level, (0, 0), extent, Channels::ALL);
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
    fn put(&mut self, (x, y): (usize, usize), row: &[u16]) {
        if let Some(view) = &mut self.view {
            let bytes: &[u8] = bytemuck::cast_slice(row);
            let at = y * self.pitch + 2 * x;
            view.slice(at..at + bytes.len()).copy_from_slice(bytes);
        }
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
/// tile staged. The levels above one texel per tile are left to [`fill_top_levels`].
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
                let (skip, rows) = (u64::from(r.1 - image.origin.1), r.3.saturating_sub(r.1));
                let rgba_skip = skip * u64::from(image.rgba_row);
                let on = image.channels;
                let staged = |on: bool| if on { rows } else { 0 };
                job.bands.push(Band {
                    level,
                    origin: (image.origin.0, r.1),
                    kd: Rows::map(buffer, image.kd + rgba_skip, staged(on.kd), image.rgba_row)?,
                    ks: Rows::map(buffer, image.ks + rgba_skip, staged(on.ks), image.rgba_row)?,
                    n: Rows::map(
                        buffer,
                        image.n + skip * u64::from(image.n_row),
                        staged(on.n),
                        image.n_row,
                    )?,
                });
            }
        }
    }
    Ok(run_jobs(jobs, |job| {
        let bands = &mut job.bands;
        job.tiles
            .iter()
            .map(|&id| (id, stage_tile(maps, id, unorm16, bands)))
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

/// Writes the whole levels above one texel per tile (`images`, in level order) into `out`,
/// the first from the per-tile sums (`tiles_x` to a row), each next from the one below.
pub(super) fn fill_top_levels(
    tile_sums: &[Sums],
    tiles_x: usize,
    unorm16: bool,
    images: &[StagedImage],
    buffer: &wgpu::Buffer,
) -> Result<(), GpuError> {
    let tiles_y = tile_sums.len() / tiles_x.max(1);
    let mut below: Option<(Vec<Sums>, usize, usize)> = None;
    for image in images {
        let (grid, gw, gh) = match &below {
            None => fold(tile_sums, tiles_x, tiles_y),
            Some((grid, gw, gh)) => fold(grid, *gw, *gh),
        };
        let rows = image.extent.1;
        let mut band = Band {
            level: image.level,
            origin: (0, 0),
            kd: Rows::map(buffer, image.kd, rows, image.rgba_row)?,
            ks: Rows::map(buffer, image.ks, rows, image.rgba_row)?,
            n: Rows::map(buffer, image.n, rows, image.n_row)?,
        };
        // The texture's levels may be smaller than the grids (sizes that are not powers of
        // two round down): their texels are the grids' top-left ones.
        let extent = (image.extent.0 as usize, image.extent.1 as usize);
        write_means(&grid, gw, unorm16, extent, &mut band, (0, 0));
        below = Some((grid, gw, gh));
    }
    Ok(())
}

/// Stages tile `id` into `bands` (levels 0, 1, ... in order): level 0 copied from its planes,
/// the levels above from box sums (each from the one below, rounded once). Returns the
/// whole tile's sums.
fn stage_tile(maps: &MaterialMaps, id: usize, unorm16: bool, bands: &mut [Band]) -> Sums {
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
            if let Plane::Data(d) = plane {
                let src = &d[y * TILE_SIZE..y * TILE_SIZE + w];
                if unorm16 {
                    rgb_to_rgba(src, row, a);
                } else {
                    for (o, v) in row.iter_mut().zip(src) {
                        *o = texel(v);
                    }
                }
            }
            out.put((x * 4, y0 + y), row.as_flattened());
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
    stage_tile_mips(tile, rect, (maps.width(), maps.height()), unorm16, mips)
}

/// Copies RGB texels into RGBA ones with alpha `a`, four at a time: three 8-byte loads and
/// four 8-byte stores (the components move as whole words, never one at a time).
fn rgb_to_rgba(src: &[[u16; 3]], out: &mut [[u16; 4]], a: u16) {
    let alpha = u64::from(a) << 48;
    let low48 = (1_u64 << 48) - 1;
    let (groups, rest) = src.as_chunks::<4>();
    let (out_groups, out_rest) = out.as_chunks_mut::<4>();
    for (o, g) in out_groups.iter_mut().zip(groups) {
        // Four texels are 24 bytes: three little-endian words, each texel 48 bits of them.
        let [w0, w1, w2] = bytemuck::cast::<[[u16; 3]; 4], [u64; 3]>(*g).map(u64::from_le);
        let texels = [
            w0 & low48,
            (w0 >> 48 | w1 << 16) & low48,
            (w1 >> 32 | w2 << 32) & low48,
            w2 >> 16,
        ];
        *o = bytemuck::cast(texels.map(|t| (t | alpha).to_le()));
    }
    for (o, v) in out_rest.iter_mut().zip(rest) {
        *o = [v[0], v[1], v[2], a];
    }
}

/// Stages the mip levels over `tile` (texels `rect` of maps of `size`) into `bands` (levels
/// 1, 2, ... in order): box sums on the tile-local grid, level 1 summed straight from the
/// tile's planes, each level above from the one below, rounded once. Returns the whole
/// tile's sums.
fn stage_tile_mips(
    tile: &Tile,
    rect: (u32, u32, u32, u32),
    size: (u32, u32),
    unorm16: bool,
    bands: &mut [Band],
) -> Sums {
    let (w, h) = ((rect.2 - rect.0) as usize, (rect.3 - rect.1) as usize);
    let (mut gw, mut gh) = (w.div_ceil(2), h.div_ceil(2));
    let mut grid = vec![Sums::default(); gw * gh];
    // Level 1 from pairs of rows: each pair added down the columns first (codes as `u32`,
    // `n` decoded), then across.
    let mut columns = [[0_u32; 3 * TILE_SIZE]; 2];
    let mut n_columns = [0.0_f32; TILE_SIZE];
    let mut n_row = [0.0_f32; TILE_SIZE];
    for gy in 0..gh {
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
        for (gx, o) in grid[gy * gw..(gy + 1) * gw].iter_mut().enumerate() {
            let x = 2 * gx;
            let pair = (w - x).min(2);
            let mut codes = [0_u32; 6];
            for (k, col) in columns.iter().enumerate() {
                for c in 0..3 {
                    let right = if pair == 2 { col[3 * x + 3 + c] } else { 0 };
                    codes[3 * k + c] = col[3 * x + c] + right;
                }
            }
            let right = if pair == 2 { n_columns[x + 1] } else { 0.0 };
            *o = Sums {
                codes: codes.map(u64::from),
                n: f64::from(n_columns[x] + right),
                count: (pair as u32 * row_count).into(),
            };
        }
    }
    for (k, band) in bands.iter_mut().enumerate() {
        if k > 0 {
            (grid, gw, gh) = fold(&grid, gw, gh);
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
            write_means(&grid, gw, unorm16, extent, band, at);
        }
    }
    let mut total = Sums::default();
    for s in grid {
        total += s;
    }
    total
}

/// The next mip level's sums: each `2 x 2` block of the `w x h` grid added up (the last row
/// or column alone when odd).
pub(super) fn fold(grid: &[Sums], w: usize, h: usize) -> (Vec<Sums>, usize, usize) {
    let (nw, nh) = (w.div_ceil(2), h.div_ceil(2));
    let mut next = vec![Sums::default(); nw * nh];
    for (y, row) in grid.chunks(w).enumerate() {
        let out = &mut next[(y / 2) * nw..(y / 2 + 1) * nw];
        for (x, s) in row.iter().enumerate() {
            out[x / 2] += *s;
        }
    }
    (next, nw, nh)
}

/// Writes the means of the top-left `w x h` sums of `grid` (rows `stride` apart) into the
/// three textures of `band`, at texel `(x, y)` of the band.
fn write_means(
    grid: &[Sums],
    stride: usize,
    unorm16: bool,
    (w, h): (usize, usize),
    band: &mut Band,
    (x, y): (usize, usize),
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
            out.put((x * 4, y + row), rgba.as_flattened());
        }
        if !band.n.staged() {
            continue;
        }
        for (o, s) in n.iter_mut().zip(sums) {
            *o = s.n();
        }
        half::slice::HalfFloatSliceExt::convert_from_f32_slice(&mut n_bits[..], &n);
        band.n.put(
            (x, y + row),
            bytemuck::cast_slice::<half::f16, u16>(&n_bits),
        );
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
            let mut out = vec![[0_u16; 4]; len];
            rgb_to_rgba(&src, &mut out, 0xabcd);
            for (o, v) in out.iter().zip(&src) {
                assert_eq!(*o, [v[0], v[1], v[2], 0xabcd], "length {len}");
            }
        }
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
