//! The maps on the GPU: `k_d` and `k_s` as RGBA 16-bit unorm (the model's own precision; half
//! floats where the adapter lacks 16-bit norm formats) and `n` as R16 float (the model's own
//! bits), each with a full mip chain. Each sync uploads only the tiles changed since the last
//! one and rebuilds only those tiles' footprint in every mip level (box means computed on the
//! CPU from the tile, rounded once per level): all of it staged in one buffer, filled per
//! tile in parallel, and copied by one command buffer of sub-rectangle copies.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use crate::model::MaterialMaps;
use crate::model::tile::{Plane, TILE_SIZE};

use super::Gpu;

/// Which channels are one value over the whole map (the preview then skips their fetch).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct UniformChannels {
    /// `k_d` everywhere, if uniform (linear).
    pub kd: Option<[f32; 3]>,
    /// `k_s` everywhere, if uniform (linear).
    pub ks: Option<[f32; 3]>,
    /// `n` everywhere, if uniform.
    pub n: Option<f32>,
}

impl UniformChannels {
    /// Scans the tiles' planes (no texel is read unless a plane is full).
    pub fn of(maps: &MaterialMaps) -> Self {
        let (kd, ks, n) = maps.uniform_channels();
        let rgb = |v: [u16; 3]| v.map(crate::model::texel::decode_unorm);
        Self {
            kd: kd.map(rgb),
            ks: ks.map(rgb),
            n: n.map(crate::model::texel::decode_n),
        }
    }
}

/// Which map texture.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MapChannel {
    /// `k_d`.
    Kd,
    /// `k_s`.
    Ks,
    /// `n`.
    N,
}

/// The three map textures and the version of the maps they mirror.
pub struct MapTextures {
    /// `k_d`, RGBA (A unused).
    pub kd: wgpu::Texture,
    /// `k_s`, RGBA (A unused).
    pub ks: wgpu::Texture,
    /// `n`, R16 float.
    pub n: wgpu::Texture,
    /// Channels that are uniform over the map, as of the last sync.
    pub uniform: UniformChannels,
    version: u64,
    size: (u32, u32),
    unorm16: bool,
    /// Per tile, the sums of its texels (what the mip levels above one texel per tile are
    /// built from).
    tile_sums: Vec<Sums>,
    /// The staged texels of the last sync (little-endian `u16`s as the GPU reads them), kept to
    /// reuse the allocation.
    scratch: Vec<u16>,
    /// The staging buffer, mapped for writing again after each sync's copies, and whether
    /// that mapping has completed.
    staging: Option<(wgpu::Buffer, Arc<AtomicBool>)>,
}

/// Sums of a mip texel's level-0 texels: `k_d` RGB, `k_s` RGB, `n`, and how many.
type Sums = [f32; 8];

/// Stages the mip levels `mips` (levels 1, 2, ... in order) over tile `id` into `out`, which
/// starts at staging offset `base`: box sums on the tile-local grid, level 1 summed straight
/// from the tile's planes, each level above from the one below, rounded once. Returns the
/// whole tile's sums.
fn stage_tile_mips(
    maps: &MaterialMaps,
    id: usize,
    unorm16: bool,
    mips: &[StagedImage],
    base: u64,
    out: &mut [u16],
) -> Sums {
    let rect = maps.tile_rect(id);
    let (w, h) = ((rect.2 - rect.0) as usize, (rect.3 - rect.1) as usize);
    let tile = maps.tile(id);
    let (mut gw, mut gh) = (w.div_ceil(2), h.div_ceil(2));
    let mut grid: Vec<Sums> = vec![[0.0; 8]; gw * gh];
    // Level 1 from pairs of rows: components summed as integer codes (exact), `n` decoded a
    // row at a time, then scaled once.
    let mut codes = [vec![[0_u32; 3]; gw], vec![[0_u32; 3]; gw]];
    let mut n_sum = vec![0.0_f32; gw];
    let mut count = vec![0_u32; gw];
    let mut n_row = vec![half::f16::ZERO; w];
    let mut n_f32 = vec![0.0_f32; w];
    for gy in 0..gh {
        for c in &mut codes {
            c.fill([0; 3]);
        }
        n_sum.fill(0.0);
        count.fill(0);
        for y in 2 * gy..(2 * gy + 2).min(h) {
            let base = y * TILE_SIZE;
            for (acc, plane) in codes.iter_mut().zip([&tile.kd, &tile.ks]) {
                match plane {
                    Plane::Uniform(v) => {
                        for (gx, a) in acc.iter_mut().enumerate() {
                            let pair = (w - 2 * gx).min(2) as u32;
                            *a = [
                                a[0] + u32::from(v[0]) * pair,
                                a[1] + u32::from(v[1]) * pair,
                                a[2] + u32::from(v[2]) * pair,
                            ];
                        }
                    }
                    Plane::Data(d) => sum_pairs(&d[base..base + w], acc),
                }
            }
            match &tile.n {
                Plane::Uniform(v) => n_f32.fill(crate::model::texel::decode_n(*v)),
                Plane::Data(d) => {
                    for (o, &bits) in n_row.iter_mut().zip(&d[base..base + w]) {
                        *o = half::f16::from_bits(bits);
                    }
                    half::slice::HalfFloatSliceExt::convert_to_f32_slice(&n_row[..], &mut n_f32);
                    for v in &mut n_f32 {
                        *v =
                            crate::model::texel::clamp_nan_low(*v, 0.0, crate::model::texel::N_MAX);
                    }
                }
            }
            for ((sum, n), pair) in n_sum.iter_mut().zip(&mut count).zip(n_f32.chunks(2)) {
                *sum += pair.iter().sum::<f32>();
                *n += pair.len() as u32;
            }
        }
        let scale = 1.0 / 65535.0;
        for ((((o, kd), ks), n), c) in grid[gy * gw..(gy + 1) * gw]
            .iter_mut()
            .zip(&codes[0])
            .zip(&codes[1])
            .zip(&n_sum)
            .zip(&count)
        {
            *o = [
                kd[0] as f32 * scale,
                kd[1] as f32 * scale,
                kd[2] as f32 * scale,
                ks[0] as f32 * scale,
                ks[1] as f32 * scale,
                ks[2] as f32 * scale,
                *n,
                *c as f32,
            ];
        }
    }
    for (k, image) in mips.iter().enumerate() {
        if k > 0 {
            (grid, gw, gh) = fold(&grid, gw, gh);
        }
        // The grid's origin is the tile's at this level: the image is its top-left part.
        write_means(&grid, gw, unorm16, image, base, out);
    }
    let mut total = [0.0; 8];
    for s in &grid {
        for (t, s) in total.iter_mut().zip(s) {
            *t += s;
        }
    }
    total
}

/// The next mip level's sums: each `2 x 2` block of the `w x h` grid added up (the last row
/// or column alone when odd).
fn fold(grid: &[Sums], w: usize, h: usize) -> (Vec<Sums>, usize, usize) {
    let (nw, nh) = (w.div_ceil(2), h.div_ceil(2));
    let mut next = vec![[0.0; 8]; nw * nh];
    for (i, s) in grid.iter().enumerate() {
        let o = &mut next[(i / w / 2) * nw + (i % w) / 2];
        for (o, s) in o.iter_mut().zip(s) {
            *o += s;
        }
    }
    (next, nw, nh)
}

/// Adds each pair of neighbouring texels of `row` (RGB codes) into `acc` (the last one alone
/// when the row is odd).
fn sum_pairs(row: &[[u16; 3]], acc: &mut [[u32; 3]]) {
    let (pairs, rest) = row.as_chunks::<2>();
    for (a, [p, q]) in acc.iter_mut().zip(pairs) {
        *a = [
            a[0] + u32::from(p[0]) + u32::from(q[0]),
            a[1] + u32::from(p[1]) + u32::from(q[1]),
            a[2] + u32::from(p[2]) + u32::from(q[2]),
        ];
    }
    if let ([p], Some(a)) = (rest, acc.get_mut(pairs.len())) {
        *a = [
            a[0] + u32::from(p[0]),
            a[1] + u32::from(p[1]),
            a[2] + u32::from(p[2]),
        ];
    }
}

/// A tile's texel rectangle at a mip level, in texels of that level.
fn level_rect(rect: (u32, u32, u32, u32), level: u32, size: (u32, u32)) -> (u32, u32, u32, u32) {
    let (lw, lh) = ((size.0 >> level).max(1), (size.1 >> level).max(1));
    let (x0, y0, x1, y1) = rect;
    (
        (x0 >> level).min(lw),
        (y0 >> level).min(lh),
        ((x1 - 1) >> level).saturating_add(1).min(lw),
        ((y1 - 1) >> level).saturating_add(1).min(lh),
    )
}

impl std::fmt::Debug for MapTextures {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MapTextures")
            .field("size", &self.size)
            .field("version", &self.version)
            .finish_non_exhaustive()
    }
}

impl MapTextures {
    /// Creates the textures for `maps` and uploads every tile.
    pub fn new(gpu: &Gpu, maps: &MaterialMaps) -> Self {
        let size = wgpu::Extent3d {
            width: maps.width(),
            height: maps.height(),
            depth_or_array_layers: 1,
        };
        let mip_level_count = size.max_mips(wgpu::TextureDimension::D2);
        let texture = |label: &str, format: wgpu::TextureFormat| {
            gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size,
                mip_level_count,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_DST
                    | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            })
        };
        let rgb_format = if gpu.unorm16 {
            wgpu::TextureFormat::Rgba16Unorm
        } else {
            wgpu::TextureFormat::Rgba16Float
        };
        let mut out = Self {
            kd: texture("k_d", rgb_format),
            ks: texture("k_s", rgb_format),
            n: texture("n", wgpu::TextureFormat::R16Float),
            uniform: UniformChannels::of(maps),
            version: 0,
            size: (maps.width(), maps.height()),
            unorm16: gpu.unorm16,
            tile_sums: vec![[0.0; 8]; maps.tile_count()],
            scratch: Vec::new(),
            staging: None,
        };
        let all: Vec<usize> = (0..maps.tile_count()).collect();
        out.upload(gpu, maps, &all);
        out.version = maps.version();
        out
    }

    /// Map size mirrored.
    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// Uploads the tiles changed since the last sync; returns how many. Maps of another size
    /// need new textures ([`MapTextures::new`]).
    pub fn sync(&mut self, gpu: &Gpu, maps: &MaterialMaps) -> usize {
        if maps.version() == self.version {
            return 0;
        }
        let dirty = maps.tiles_changed_since(self.version);
        self.upload(gpu, maps, &dirty);
        self.uniform = UniformChannels::of(maps);
        self.version = maps.version();
        dirty.len()
    }

    /// Reads mip `level` of one texture back (RGBA u16 per texel for `k_d`/`k_s`, u16 for `n`;
    /// half-float bits where the format is a float one), for tests and diagnostics.
    ///
    /// # Errors
    /// When the read-back fails.
    pub fn read_level(
        &self,
        gpu: &Gpu,
        channel: MapChannel,
        level: u32,
    ) -> Result<Vec<u16>, super::GpuError> {
        let (texture, texel) = match channel {
            MapChannel::Kd => (&self.kd, 8),
            MapChannel::Ks => (&self.ks, 8),
            MapChannel::N => (&self.n, 2),
        };
        let encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        let bytes = super::preview::read_texture(gpu, encoder, texture, texel, level)?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }

    /// Uploads `tiles` and the mip levels over them: every texel of the sync is staged in one
    /// buffer (filled per tile in parallel), then copied into the textures by one command
    /// buffer, so a sync costs one staging allocation whatever the number of tiles.
    fn upload(&mut self, gpu: &Gpu, maps: &MaterialMaps, tiles: &[usize]) {
        if tiles.is_empty() {
            return;
        }
        let levels = self.kd.mip_level_count();
        let tile_level = TILE_SIZE.trailing_zeros(); // 6: one texel per tile
        let size = self.size;
        let unorm16 = self.unorm16;
        // The layout first: per tile, its images at levels 0..=tile_level, then the levels
        // above, whole.
        let mut staging = Staging::default();
        let mut tile_spans = Vec::with_capacity(tiles.len());
        for &id in tiles {
            let start = staging.len;
            let rect = maps.tile_rect(id);
            for level in 0..levels.min(tile_level + 1) {
                let r = level_rect(rect, level, size);
                if r.2 > r.0 && r.3 > r.1 {
                    staging.push_level(level, (r.0, r.1), (r.2 - r.0, r.3 - r.1));
                }
            }
            tile_spans.push((start, staging.len, staging.images.len()));
        }
        let top_start = staging.len;
        for level in tile_level + 1..levels {
            let (lw, lh) = ((size.0 >> level).max(1), (size.1 >> level).max(1));
            staging.push_level(level, (0, 0), (lw, lh));
        }
        // Every staged value is written below (row padding may keep stale values: never read).
        self.scratch.resize((staging.len / 2) as usize, 0);
        // Each tile's texels in parallel (disjoint slices of the scratch buffer).
        let mut rest: &mut [u16] = &mut self.scratch;
        let mut jobs = Vec::with_capacity(tiles.len());
        let mut image_start = 0;
        let mut offset = 0;
        for (&id, &(start, end, image_end)) in tiles.iter().zip(&tile_spans) {
            let (chunk, tail) = rest.split_at_mut(((end - start) / 2) as usize);
            rest = tail;
            jobs.push((id, chunk, &staging.images[image_start..image_end], start));
            image_start = image_end;
            offset = end;
        }
        debug_assert_eq!(offset, top_start);
        let sums: Vec<(usize, Sums)> = jobs
            .into_par_iter()
            .map(|(id, chunk, images, base)| {
                (id, stage_tile(maps, id, unorm16, images, base, chunk))
            })
            .collect();
        for (id, total) in sums {
            self.tile_sums[id] = total;
        }
        self.stage_top_levels(maps, &staging.images[image_start..]);
        // One staging buffer (kept, and mapped again between syncs), one copy per image.
        let buffer = staging_buffer(&mut self.staging, gpu, bytemuck::cast_slice(&self.scratch));
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("map upload"),
            });
        for i in &staging.images {
            for (texture, offset, bytes_per_row) in [
                (&self.kd, i.kd, i.rgba_row),
                (&self.ks, i.ks, i.rgba_row),
                (&self.n, i.n, i.n_row),
            ] {
                encoder.copy_buffer_to_texture(
                    wgpu::TexelCopyBufferInfo {
                        buffer: &buffer,
                        layout: wgpu::TexelCopyBufferLayout {
                            offset,
                            bytes_per_row: Some(bytes_per_row),
                            rows_per_image: Some(i.extent.1),
                        },
                    },
                    wgpu::TexelCopyTextureInfo {
                        texture,
                        mip_level: i.level,
                        origin: wgpu::Origin3d {
                            x: i.origin.0,
                            y: i.origin.1,
                            z: 0,
                        },
                        aspect: wgpu::TextureAspect::All,
                    },
                    wgpu::Extent3d {
                        width: i.extent.0,
                        height: i.extent.1,
                        depth_or_array_layers: 1,
                    },
                );
            }
        }
        gpu.queue.submit([encoder.finish()]);
        // Map it again for the next sync: ready once the GPU has copied out of it.
        let mapped = Arc::new(AtomicBool::new(false));
        let done = Arc::clone(&mapped);
        buffer.map_async(wgpu::MapMode::Write, .., move |r| {
            done.store(r.is_ok(), Ordering::Release);
        });
        self.staging = Some((buffer, mapped));
    }

    /// Stages the levels above one texel per tile (`images`, in level order), whole: the first
    /// from the tile sums, each next from the one below.
    fn stage_top_levels(&mut self, maps: &MaterialMaps, images: &[StagedImage]) {
        let tiles_x = maps.tiles_x() as usize;
        let tiles_y = maps.tile_count() / tiles_x.max(1);
        let Some((first, rest)) = images.split_first() else {
            return;
        };
        // The texture's levels may be smaller than the grids (sizes that are not powers of
        // two round down): their texels are the grids' top-left ones.
        let (mut grid, mut gw, mut gh) = fold(&self.tile_sums, tiles_x, tiles_y);
        write_means(&grid, gw, self.unorm16, first, 0, &mut self.scratch);
        for image in rest {
            (grid, gw, gh) = fold(&grid, gw, gh);
            write_means(&grid, gw, self.unorm16, image, 0, &mut self.scratch);
        }
    }
}

/// A staging buffer holding `bytes` at its start, unmapped for copying: the one `kept` since
/// the last sync when it is large enough (waiting for its mapping if the GPU is still copying
/// out of it), else a new one.
fn staging_buffer(
    kept: &mut Option<(wgpu::Buffer, Arc<AtomicBool>)>,
    gpu: &Gpu,
    bytes: &[u8],
) -> wgpu::Buffer {
    let len = bytes.len() as u64;
    if let Some((buffer, mapped)) = kept.take()
        && buffer.size() >= len
    {
        if !mapped.load(Ordering::Acquire) {
            gpu.wait();
        }
        if mapped.load(Ordering::Acquire)
            && let Ok(mut view) = buffer.get_mapped_range_mut(..len)
        {
            view.copy_from_slice(bytes);
            drop(view);
            buffer.unmap();
            return buffer;
        }
    }
    // Room to grow: a little more than asked, in whole MiB.
    let mut contents = bytes.to_vec();
    contents.resize((len + 1).next_multiple_of(1 << 20) as usize, 0);
    wgpu::util::DeviceExt::create_buffer_init(
        &gpu.device,
        &wgpu::util::BufferInitDescriptor {
            label: Some("map tiles"),
            contents: &contents,
            usage: wgpu::BufferUsages::MAP_WRITE | wgpu::BufferUsages::COPY_SRC,
        },
    )
}

/// One rectangle of one mip level, staged for all three textures: where each texture's rows
/// start in the staging buffer and how far apart they are (padded to wgpu's copy alignment).
#[derive(Clone, Copy, Debug)]
struct StagedImage {
    level: u32,
    origin: (u32, u32),
    extent: (u32, u32),
    kd: u64,
    ks: u64,
    n: u64,
    rgba_row: u32,
    n_row: u32,
}

/// The layout of one sync's staging buffer.
#[derive(Debug, Default)]
struct Staging {
    images: Vec<StagedImage>,
    len: u64,
}

impl Staging {
    /// Reserves room for one rectangle of `level` in the three textures.
    fn push_level(&mut self, level: u32, origin: (u32, u32), extent: (u32, u32)) {
        let align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let rgba_row = (extent.0 * 8).next_multiple_of(align);
        let n_row = (extent.0 * 2).next_multiple_of(align);
        let rgba_bytes = u64::from(rgba_row) * u64::from(extent.1);
        let n_bytes = u64::from(n_row) * u64::from(extent.1);
        let kd = self.len;
        self.images.push(StagedImage {
            level,
            origin,
            extent,
            kd,
            ks: kd + rgba_bytes,
            n: kd + 2 * rgba_bytes,
            rgba_row,
            n_row,
        });
        self.len = kd + 2 * rgba_bytes + n_bytes;
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
        half::f16::from_f32(crate::model::texel::decode_unorm(v)).to_bits()
    }
}

/// Stages tile `id`: level 0 copied from its planes, the levels above from box sums (each
/// from the one below, rounded once), into `out`, which starts at staging offset `base`.
/// Returns the whole tile's sums.
fn stage_tile(
    maps: &MaterialMaps,
    id: usize,
    unorm16: bool,
    images: &[StagedImage],
    base: u64,
    out: &mut [u16],
) -> Sums {
    let tile = maps.tile(id);
    let Some((first, mips)) = images.split_first() else {
        return [0.0; 8];
    };
    let (w, h) = (first.extent.0 as usize, first.extent.1 as usize);
    // Staged offsets and rows are in bytes, even; `out` holds u16 words.
    let word = |offset: u64| ((offset - base) / 2) as usize;
    let a = alpha(unorm16);
    for (plane, offset) in [(&tile.kd, first.kd), (&tile.ks, first.ks)] {
        let rgba = |v: &[u16; 3]| {
            [
                rgb_component(unorm16, v[0]),
                rgb_component(unorm16, v[1]),
                rgb_component(unorm16, v[2]),
                a,
            ]
        };
        for y in 0..h {
            let at = word(offset) + y * first.rgba_row as usize / 2;
            let out_row: &mut [[u16; 4]] = bytemuck::cast_slice_mut(&mut out[at..at + w * 4]);
            match plane {
                Plane::Uniform(v) => out_row.fill(rgba(v)),
                Plane::Data(d) if unorm16 => {
                    for (o, v) in out_row.iter_mut().zip(&d[y * TILE_SIZE..y * TILE_SIZE + w]) {
                        *o = [v[0], v[1], v[2], a];
                    }
                }
                Plane::Data(d) => {
                    for (o, v) in out_row.iter_mut().zip(&d[y * TILE_SIZE..y * TILE_SIZE + w]) {
                        *o = rgba(v);
                    }
                }
            }
        }
    }
    for y in 0..h {
        let at = word(first.n) + y * first.n_row as usize / 2;
        match &tile.n {
            Plane::Uniform(v) => out[at..at + w].fill(*v),
            Plane::Data(d) => {
                out[at..at + w].copy_from_slice(&d[y * TILE_SIZE..y * TILE_SIZE + w]);
            }
        }
    }
    stage_tile_mips(maps, id, unorm16, mips, base, out)
}

/// Writes the means of the sums in `grid` (rows `stride` apart; the image is its top-left
/// part) as `image`'s three textures into `out`, which starts at staging offset `base`.
fn write_means(
    grid: &[Sums],
    stride: usize,
    unorm16: bool,
    image: &StagedImage,
    base: u64,
    out: &mut [u16],
) {
    let (w, h) = (image.extent.0 as usize, image.extent.1 as usize);
    // Staged offsets and rows are in bytes, even; `out` holds u16 words.
    let word = |offset: u64| ((offset - base) / 2) as usize;
    let mut rgba = vec![0_u16; w * 4];
    let mut n = vec![0_u16; w];
    for y in 0..h {
        for (k, offset) in [(0, image.kd), (3, image.ks)] {
            for (o, t) in rgba
                .chunks_exact_mut(4)
                .zip(&grid[y * stride..y * stride + w])
            {
                let inv = 1.0 / t[7].max(1.0);
                let c = |i: usize| {
                    let v = t[k + i] * inv;
                    if unorm16 {
                        crate::model::texel::encode_unorm(v)
                    } else {
                        half::f16::from_f32(v).to_bits()
                    }
                };
                o.copy_from_slice(&[c(0), c(1), c(2), alpha(unorm16)]);
            }
            let at = word(offset) + y * image.rgba_row as usize / 2;
            out[at..at + rgba.len()].copy_from_slice(&rgba);
        }
        for (o, t) in n.iter_mut().zip(&grid[y * stride..y * stride + w]) {
            *o = half::f16::from_f32(t[6] / t[7].max(1.0)).to_bits();
        }
        let at = word(image.n) + y * image.n_row as usize / 2;
        out[at..at + n.len()].copy_from_slice(&n);
    }
}
