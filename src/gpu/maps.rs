//! The maps on the GPU: `k_d` and `k_s` as RGBA 16-bit unorm (the model's own precision; half
//! floats where the adapter lacks 16-bit norm formats) and `n` as R16 float (the model's own
//! bits). Each sync uploads only the tiles changed since the last one, one sub-rectangle write
//! per tile.

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
        fn all_same<T: Copy + PartialEq>(
            maps: &MaterialMaps,
            plane: impl Fn(&crate::model::tile::Tile) -> &Plane<T>,
        ) -> Option<T> {
            let mut value = None;
            for id in 0..maps.tile_count() {
                let v = plane(maps.tile(id)).uniform()?;
                if *value.get_or_insert(v) != v {
                    return None;
                }
            }
            value
        }
        let rgb = |v: [u16; 3]| v.map(crate::model::texel::decode_unorm);
        Self {
            kd: all_same(maps, |t| &t.kd).map(rgb),
            ks: all_same(maps, |t| &t.ks).map(rgb),
            n: all_same(maps, |t| &t.n).map(crate::model::texel::decode_n),
        }
    }
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
        let texture = |label: &str, format: wgpu::TextureFormat| {
            gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
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

    fn upload(&self, gpu: &Gpu, maps: &MaterialMaps, tiles: &[usize]) {
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
