//! The maps on the GPU: `k_d` and `k_s` as RGBA 16-bit unorm (the model's own precision; half
//! floats where the adapter lacks 16-bit norm formats) and `n` as R16 float (the model's own
//! bits), each with a full mip chain. Each sync uploads only the tiles changed since the last
//! one, one sub-rectangle write per tile, then rebuilds only those tiles' footprint in every
//! mip level (box means computed on the CPU from the tile, rounded once per level).

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
}

/// Sums of a mip texel's level-0 texels: `k_d` RGB, `k_s` RGB, `n`, and how many.
type Sums = [f32; 8];

/// One mip level's texels over one tile: level, origin, size, sums.
type MipPatch = (u32, (u32, u32), (u32, u32), Vec<Sums>);

/// The mip levels `1..levels` over tile `id` (box sums on the tile-local grid, each level from
/// the one below), and the whole tile's sums.
fn tile_mips(
    maps: &MaterialMaps,
    id: usize,
    levels: u32,
    size: (u32, u32),
) -> (Sums, Vec<MipPatch>) {
    let rect = maps.tile_rect(id);
    let (w, h) = ((rect.2 - rect.0) as usize, (rect.3 - rect.1) as usize);
    let tile = maps.tile(id);
    let mut grid: Vec<Sums> = (0..w * h)
        .map(|i| {
            let t = tile.texel((i / w) * TILE_SIZE + i % w);
            let kd = t.kd.map(crate::model::texel::decode_unorm);
            let ks = t.ks.map(crate::model::texel::decode_unorm);
            let n = crate::model::texel::decode_n(t.n);
            [kd[0], kd[1], kd[2], ks[0], ks[1], ks[2], n, 1.0]
        })
        .collect();
    let (mut gw, mut gh) = (w, h);
    let mut patches = Vec::new();
    for level in 1..levels {
        let (nw, nh) = (gw.div_ceil(2), gh.div_ceil(2));
        let mut next = vec![[0.0; 8]; nw * nh];
        for (i, s) in grid.iter().enumerate() {
            let o = &mut next[(i / gw / 2) * nw + (i % gw) / 2];
            for (o, s) in o.iter_mut().zip(s) {
                *o += s;
            }
        }
        grid = next;
        (gw, gh) = (nw, nh);
        let r = level_rect(rect, level, size);
        let (lw, lh) = ((r.2 - r.0) as usize, (r.3 - r.1) as usize);
        if lw == 0 || lh == 0 {
            break;
        }
        let texels: Vec<Sums> = (0..lw * lh).map(|i| grid[(i / lw) * gw + i % lw]).collect();
        patches.push((level, (r.0, r.1), (lw as u32, lh as u32), texels));
    }
    let mut total = [0.0; 8];
    for s in &grid {
        for (t, s) in total.iter_mut().zip(s) {
            *t += s;
        }
    }
    (total, patches)
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

    fn upload(&mut self, gpu: &Gpu, maps: &MaterialMaps, tiles: &[usize]) {
        self.upload_level0(gpu, maps, tiles);
        self.upload_mips(gpu, maps, tiles);
    }

    /// Writes `texels` (`w x h` sums) into `level` at `origin` of all three textures.
    fn write_level(
        &self,
        gpu: &Gpu,
        level: u32,
        origin: (u32, u32),
        (w, h): (u32, u32),
        texels: &[Sums],
    ) {
        let rgba = |offset: usize| -> Vec<u16> {
            texels
                .iter()
                .flat_map(|t| {
                    let count = t[7].max(1.0);
                    let c = |k: usize| {
                        let v = t[offset + k] / count;
                        if self.unorm16 {
                            crate::model::texel::encode_unorm(v)
                        } else {
                            half::f16::from_f32(v).to_bits()
                        }
                    };
                    [
                        c(0),
                        c(1),
                        c(2),
                        if self.unorm16 { u16::MAX } else { 0x3c00 },
                    ]
                })
                .collect()
        };
        let (kd, ks) = (rgba(0), rgba(3));
        let n: Vec<u16> = texels
            .iter()
            .map(|t| half::f16::from_f32(t[6] / t[7].max(1.0)).to_bits())
            .collect();
        for (texture, data, texel_bytes) in
            [(&self.kd, &kd, 8), (&self.ks, &ks, 8), (&self.n, &n, 2)]
        {
            gpu.queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture,
                    mip_level: level,
                    origin: wgpu::Origin3d {
                        x: origin.0,
                        y: origin.1,
                        z: 0,
                    },
                    aspect: wgpu::TextureAspect::All,
                },
                bytemuck::cast_slice(data),
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(w * texel_bytes),
                    rows_per_image: Some(h),
                },
                wgpu::Extent3d {
                    width: w,
                    height: h,
                    depth_or_array_layers: 1,
                },
            );
        }
    }

    /// Rebuilds the mip levels over the dirty tiles: box means of the level-0 texels, each
    /// level from the sums of the one below (exact, rounded once). Levels up to one texel per
    /// tile are written per dirty tile; the levels above (at most 64 x 64 texels for 8192^2
    /// maps) are rebuilt whole from the per-tile sums.
    fn upload_mips(&mut self, gpu: &Gpu, maps: &MaterialMaps, tiles: &[usize]) {
        let levels = self.kd.mip_level_count();
        let size = self.size;
        let tile_level = TILE_SIZE.trailing_zeros(); // 6: one texel per tile
        // Each dirty tile's levels, computed in parallel, then written in order.
        let per_tile: Vec<(usize, Sums, Vec<MipPatch>)> = tiles
            .par_iter()
            .map(|&id| {
                let (total, patches) = tile_mips(maps, id, levels.min(tile_level + 1), size);
                (id, total, patches)
            })
            .collect();
        for (id, total, patches) in per_tile {
            for (level, origin, extent, texels) in patches {
                self.write_level(gpu, level, origin, extent, &texels);
            }
            self.tile_sums[id] = total;
        }
        // Levels above one texel per tile, whole, from the tile sums.
        let tiles_x = maps.tiles_x() as usize;
        for level in tile_level + 1..levels {
            let (lw, lh) = ((size.0 >> level).max(1), (size.1 >> level).max(1));
            let span = 1_usize << (level - tile_level);
            let mut texels = vec![[0.0; 8]; (lw * lh) as usize];
            for (id, s) in self.tile_sums.iter().enumerate() {
                let (tx, ty) = (id % tiles_x / span, id / tiles_x / span);
                if tx < lw as usize && ty < lh as usize {
                    let o = &mut texels[ty * lw as usize + tx];
                    for k in 0..8 {
                        o[k] += s[k];
                    }
                }
            }
            self.write_level(gpu, level, (0, 0), (lw, lh), &texels);
        }
    }

    fn upload_level0(&self, gpu: &Gpu, maps: &MaterialMaps, tiles: &[usize]) {
        let mut rgba = vec![0_u16; TILE_SIZE * TILE_SIZE * 4];
        let mut n_bits = vec![0_u16; TILE_SIZE * TILE_SIZE];
        for &id in tiles {
            let (x0, y0, x1, y1) = maps.tile_rect(id);
            let (w, h) = ((x1 - x0) as usize, (y1 - y0) as usize);
            let tile = maps.tile(id);
            let write = |texture: &wgpu::Texture, data: &[u16], texel_bytes: usize| {
                gpu.queue.write_texture(
                    wgpu::TexelCopyTextureInfo {
                        texture,
                        mip_level: 0,
                        origin: wgpu::Origin3d { x: x0, y: y0, z: 0 },
                        aspect: wgpu::TextureAspect::All,
                    },
                    bytemuck::cast_slice(&data[..w * h * texel_bytes / 2]),
                    wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some((w * texel_bytes) as u32),
                        rows_per_image: Some(h as u32),
                    },
                    wgpu::Extent3d {
                        width: w as u32,
                        height: h as u32,
                        depth_or_array_layers: 1,
                    },
                );
            };
            for (plane, texture) in [(&tile.kd, &self.kd), (&tile.ks, &self.ks)] {
                let alpha = if self.unorm16 { u16::MAX } else { 0x3c00 };
                let convert = |v: [u16; 3]| -> [u16; 4] {
                    if self.unorm16 {
                        [v[0], v[1], v[2], alpha]
                    } else {
                        let h = |c: u16| {
                            half::f16::from_f32(crate::model::texel::decode_unorm(c)).to_bits()
                        };
                        [h(v[0]), h(v[1]), h(v[2]), alpha]
                    }
                };
                let out: &mut [[u16; 4]] = bytemuck::cast_slice_mut(&mut rgba[..w * h * 4]);
                match plane {
                    Plane::Uniform(v) => out.fill(convert(*v)),
                    Plane::Data(d) => {
                        for (row_out, row_in) in
                            out.chunks_exact_mut(w).zip(d.chunks_exact(TILE_SIZE))
                        {
                            for (o, &v) in row_out.iter_mut().zip(&row_in[..w]) {
                                *o = convert(v);
                            }
                        }
                    }
                }
                write(texture, &rgba, 8);
            }
            match &tile.n {
                Plane::Uniform(v) => n_bits[..w * h].fill(*v),
                Plane::Data(d) => {
                    for (row_out, row_in) in n_bits[..w * h]
                        .chunks_exact_mut(w)
                        .zip(d.chunks_exact(TILE_SIZE))
                    {
                        row_out.copy_from_slice(&row_in[..w]);
                    }
                }
            }
            write(&self.n, &n_bits, 2);
        }
    }
}
