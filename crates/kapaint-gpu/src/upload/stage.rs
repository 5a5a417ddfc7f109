//! Staging: each parallel job writes one row of a rectangle's tiles, level 0 straight from the
//! tiles' planes and the mips from [`kapaint_model::mips`], into its own mapped views of the
//! staging buffer.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, PoisonError};

use super::plan::{Batch, StagedImage, TileRect, rect_texels};
use crate::GpuError;
use kapaint_model::MaterialMaps;
use kapaint_model::mips::{self, MipRows, Sums, TileSums, TopSums, alpha};
use kapaint_model::texel::{Channel, decode_unorm};
use kapaint_model::tile::{Plane, TILE_SIZE};

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
pub fn fill_rects(
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
                let r = rect_texels(row, size).at_level(level, size);
                job.bands.push(Band::map(buffer, image, r.y0, r.height())?);
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
    let (w, h) = (rect.width() as usize, rect.height() as usize);
    let x = (rect.x0 - first.origin.0) as usize;
    let y0 = (rect.y0 - first.origin.1) as usize;
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
    mips::write_tile_mips(
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

/// Writes the parts of the levels above one texel per tile that `images` hold (in level
/// order, the first from grid 1 of `top`) into `buffer` (mapped).
pub fn fill_top(
    top: &TopSums,
    unorm16: bool,
    images: &[StagedImage],
    buffer: &wgpu::Buffer,
) -> Result<(), GpuError> {
    for (k, image) in images.iter().enumerate().take(top.grid_count() - 1) {
        let mut band = Band::map(buffer, image, image.origin.1, image.extent.1)?;
        let extent = (image.extent.0 as usize, image.extent.1 as usize);
        top.write_level(k + 1, unorm16, extent, &mut band);
    }
    Ok(())
}

impl MipRows for Band {
    fn level(&self) -> u32 {
        self.level
    }

    fn origin(&self) -> (u32, u32) {
        self.origin
    }

    fn staged(&self, channel: Channel) -> bool {
        self.rows(channel).staged()
    }

    fn put(&mut self, channel: Channel, at: (usize, usize), row: &[u16]) {
        match channel {
            Channel::Kd => self.kd.put(at, row),
            Channel::Ks => self.ks.put(at, row),
            Channel::N => self.n.put(at, row),
        }
    }
}

impl Band {
    /// The rows of one texture.
    fn rows(&self, channel: Channel) -> &Rows {
        match channel {
            Channel::Kd => &self.kd,
            Channel::Ks => &self.ks,
            Channel::N => &self.n,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
