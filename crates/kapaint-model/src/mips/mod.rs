//! Mip levels of the maps from exact box sums, without a device: the renderer's uploads
//! write them into its staging buffers through [`MipRows`].
//!
//! Inside a tile the levels come from a compact pyramid of sums ([`TileSums`]); above one
//! texel per tile, from sums per tile and per block of tiles ([`TopSums`]) kept between
//! uploads and re-added over the changed tiles only. Every level is rounded once, from sums
//! of level-0 codes, so a partial update gives the same texels as a whole build.

use super::maps::TexelRect;
use super::texel::{Channel, N_MAX, clamp_nan_low, decode_n};
use super::tile::{Plane, TILE_SIZE, Tile};

/// Where the means of a mip level go: rows of one level of the three textures, from an
/// origin, `k_d` and `k_s` as four 16-bit words a texel (`r, g, b, a`) and `n` as one (half
/// float bits); a texture that is not staged keeps what it holds.
pub trait MipRows {
    /// The mip level these rows belong to.
    fn level(&self) -> u32;
    /// The first texel, in texels of the level.
    fn origin(&self) -> (u32, u32);
    /// Whether `channel`'s texture takes these rows.
    fn staged(&self, channel: Channel) -> bool;
    /// Writes `row` into `channel`'s rows at word `x` of row `y` (relative to the origin).
    fn put(&mut self, channel: Channel, at: (usize, usize), row: &[u16]);
}

/// The alpha written beside `k_d` and `k_s` (1 in either format: unorm16 or half float).
pub fn alpha(unorm16: bool) -> u16 {
    if unorm16 { u16::MAX } else { 0x3c00 }
}

/// Sums of the level-0 texels under one texel of a mip level, what its mean is rounded from:
/// `k_d` and `k_s` as sums of unorm16 codes (exact), `n`, and how many texels. Wide enough
/// for a whole 8192^2 map.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sums {
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
pub fn mean_code(sum: u64, count: u64, unorm16: bool) -> u16 {
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

/// Sums over every tile and over each block of tiles under a texel of the levels above one
/// texel per tile: grid 0 has one cell per tile, each next grid one per `2 x 2` block of the
/// one below (the last row or column alone when odd), down to one cell. Kept between syncs:
/// a sync re-adds only the blocks over the tiles it staged.
#[derive(Debug)]
pub struct TopSums {
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

    /// Writes the means of grid `k` (grid `k` is the `k`-th level above one texel per tile)
    /// over `extent` texels from `rows`' origin into `rows`. The grid's cells are the
    /// level's texels (where sizes that are not powers of two round down, the level has
    /// fewer: the grid's top-left ones).
    pub fn write_level<R: MipRows>(
        &self,
        k: usize,
        unorm16: bool,
        extent: (usize, usize),
        rows: &mut R,
    ) {
        let Some((grid, gw, _)) = self.grids.get(k) else {
            return;
        };
        let (x, y) = (rows.origin().0 as usize, rows.origin().1 as usize);
        write_means(&grid[y * gw + x..], *gw, unorm16, extent, rows);
    }

    /// How many grids there are (the levels above one texel per tile, plus grid 0).
    pub fn grid_count(&self) -> usize {
        self.grids.len()
    }
}

/// Cells on a side of a tile's level 1, the largest grid of in-tile sums.
const HALF_TILE: usize = TILE_SIZE / 2;

/// Box sums over one tile's texels at one mip level (1 and up), on the tile-local grid, kept
/// compact and folded in place: `k_d` and `k_s` as sums of unorm16 codes in `u32` (a whole
/// tile's fit), `n` in `f32`. A cell's texel count follows from its place (cells at the map's
/// right and bottom edges may be partial).
pub struct TileSums {
    codes: Vec<[u32; 6]>,
    n: Vec<f32>,
    /// Cells across and down (rows `w` apart).
    w: usize,
    h: usize,
    level: u32,
    /// The tile's texels across and down.
    texels: (usize, usize),
}

impl Default for TileSums {
    fn default() -> Self {
        Self::new()
    }
}

impl TileSums {
    /// Room for a whole tile's level 1 (28 KiB).
    pub fn new() -> Self {
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
    fn write<R: MipRows>(
        &self,
        unorm16: bool,
        (ew, eh): (usize, usize),
        band: &mut R,
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
            for (first, channel) in [(0, Channel::Kd), (3, Channel::Ks)] {
                if !band.staged(channel) {
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
                band.put(channel, (x * 4, y + gy), rgba.as_flattened());
            }
            if band.staged(Channel::N) {
                let sums = &self.n[cells];
                for (o, s) in n[..whole].iter_mut().zip(sums) {
                    *o = *s * inv_count;
                }
                for (gx, (o, s)) in n.iter_mut().zip(sums).enumerate().skip(whole) {
                    *o = *s / count(gx) as f32;
                }
                half::slice::HalfFloatSliceExt::convert_from_f32_slice(&mut *n_bits, n);
                band.put(
                    Channel::N,
                    (x, y + gy),
                    bytemuck::cast_slice::<half::f16, u16>(n_bits),
                );
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

/// Writes the mip levels over `tile` (texels `rect` of maps of `size`) into `bands` (levels
/// 1, 2, ... in order), each level folded from the one below, rounded once, with `sums` as
/// scratch. Returns the whole tile's sums.
pub fn write_tile_mips<R: MipRows>(
    tile: &Tile,
    rect: TexelRect,
    size: (u32, u32),
    unorm16: bool,
    bands: &mut [R],
    sums: &mut TileSums,
) -> Sums {
    sums.level_one(tile, (rect.width() as usize, rect.height() as usize));
    for (k, band) in bands.iter_mut().enumerate() {
        if k > 0 {
            sums.fold();
        }
        // The grid's origin is the tile's at this level; the texture's part of it is its
        // top-left (the level may round down at the map's edges).
        let r = rect.at_level(band.level(), size);
        if !r.is_empty() {
            let origin = band.origin();
            let at = ((r.x0 - origin.0) as usize, (r.y0 - origin.1) as usize);
            sums.write(unorm16, (r.width() as usize, r.height() as usize), band, at);
        }
    }
    sums.total()
}

/// Writes the means of the top-left `w x h` sums of `grid` (rows `stride` apart) into the
/// textures of `band`, from its first texel.
fn write_means<R: MipRows>(
    grid: &[Sums],
    stride: usize,
    unorm16: bool,
    (w, h): (usize, usize),
    band: &mut R,
) {
    let a = alpha(unorm16);
    let mut rgba = vec![[0_u16; 4]; w];
    let mut n = vec![0.0_f32; w];
    let mut n_bits = vec![half::f16::ZERO; w];
    for row in 0..h {
        let sums = &grid[row * stride..row * stride + w];
        for (first, channel) in [(0, Channel::Kd), (3, Channel::Ks)] {
            if !band.staged(channel) {
                continue;
            }
            for (o, s) in rgba.iter_mut().zip(sums) {
                *o = s.rgba(first, unorm16, a);
            }
            band.put(channel, (0, row), rgba.as_flattened());
        }
        if !band.staged(Channel::N) {
            continue;
        }
        for (o, s) in n.iter_mut().zip(sums) {
            *o = s.n();
        }
        half::slice::HalfFloatSliceExt::convert_from_f32_slice(&mut n_bits[..], &n);
        band.put(
            Channel::N,
            (0, row),
            bytemuck::cast_slice::<half::f16, u16>(&n_bits),
        );
    }
}

#[cfg(test)]
mod tests;
