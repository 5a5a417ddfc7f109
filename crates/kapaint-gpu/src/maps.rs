//! The maps on the GPU: `k_d` and `k_s` as RGBA 16-bit unorm (the model's own precision; half
//! floats where the adapter lacks 16-bit norm formats) and `n` as R16 float (the model's own
//! bits), each with a full mip chain. Each sync uploads only the tiles changed since the last
//! one and rebuilds only those tiles' footprint in every mip level (box means computed on the
//! CPU from the tile, rounded once per level): staged by `gpu::upload` straight into a
//! mapped buffer and copied by one command buffer of sub-rectangle copies.

use kapaint_model::{Channels, MaterialMaps};

use super::upload::{self, StagingPool};
use super::{Gpu, GpuError};
use kapaint_model::mips::TopSums;

/// Which channels are one value over the whole map (the preview then skips their fetch).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct UniformChannels {
    /// `k_d` everywhere, if uniform (linear).
    pub kd: Option<[f32; 3]>,
    /// `k_s` everywhere, if uniform (linear).
    pub ks: Option<[f32; 3]>,
    /// `n` everywhere, if uniform.
    pub n: Option<f32>,
    /// A normal map is bound (else the preview skips its fetch and tangent frame).
    pub normal_map: bool,
}

impl UniformChannels {
    /// Scans the tiles' planes (no texel is read unless a plane is full).
    pub fn of(maps: &MaterialMaps) -> Self {
        let (kd, ks, n) = maps.uniform_channels();
        let rgb = |v: [u16; 3]| v.map(kapaint_model::texel::decode_unorm);
        Self {
            kd: kd.map(rgb),
            ks: ks.map(rgb),
            n: n.map(kapaint_model::texel::decode_n),
            normal_map: false,
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

/// The three map textures and the version of the maps they mirror. A channel that is one
/// value over the whole map (the preview then reads its value from the uniforms, never the
/// texture) gets a one-texel texture until it is painted: an unpainted 8192^2 map costs no
/// texture memory (a full one is 24 bytes a texel with its mips).
pub struct MapTextures {
    /// `k_d`, RGBA (A unused).
    pub kd: wgpu::Texture,
    /// `k_s`, RGBA (A unused).
    pub ks: wgpu::Texture,
    /// `n`, R16 float.
    pub n: wgpu::Texture,
    /// Channels that are uniform over the map, as of the last sync.
    pub uniform: UniformChannels,
    /// The material's normal map (flat where it has none).
    pub normal: super::normal::NormalTexture,
    version: u64,
    size: (u32, u32),
    /// Which of `kd`, `ks`, `n` are at the map's size (the others are one texel).
    full: Channels,
    unorm16: bool,
    /// Sums per tile and per block of tiles (what the mip levels above one texel per tile
    /// are built from).
    top_sums: TopSums,
    /// Staging buffers, kept and mapped again between syncs.
    staging: StagingPool,
    /// Bytes staged by the last sync.
    staged_bytes: u64,
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
    ///
    /// # Errors
    /// Maps larger than the device's largest texture, or a device that is out of memory or
    /// lost: an error to show, never a panic.
    pub fn new(gpu: &Gpu, maps: &MaterialMaps) -> Result<Self, super::GpuError> {
        gpu.check_texture_size("a map", (maps.width(), maps.height()))?;
        let mut out = gpu.checked("making the map textures", || Self::textures(gpu, maps))?;
        let all: Vec<usize> = (0..maps.tile_count()).collect();
        // A failed upload leaves the version at 0: the next sync tries every tile again.
        if gpu
            .checked("uploading the maps", || out.upload(gpu, maps, &all, 0))?
            .is_ok()
        {
            out.version = maps.version();
        }
        Ok(out)
    }

    /// The textures for `maps`, nothing uploaded yet: full size for the channels that vary,
    /// one texel for the uniform ones.
    fn textures(gpu: &Gpu, maps: &MaterialMaps) -> Self {
        let uniform = UniformChannels::of(maps);
        let full = Channels {
            kd: uniform.kd.is_none(),
            ks: uniform.ks.is_none(),
            n: uniform.n.is_none(),
        };
        let size = (maps.width(), maps.height());
        Self {
            kd: Self::texture(gpu, MapChannel::Kd, full.kd.then_some(size)),
            ks: Self::texture(gpu, MapChannel::Ks, full.ks.then_some(size)),
            n: Self::texture(gpu, MapChannel::N, full.n.then_some(size)),
            uniform,
            normal: super::normal::NormalTexture::flat(gpu),
            version: 0,
            size,
            full,
            unorm16: gpu.unorm16,
            top_sums: TopSums::new(maps.tiles_x() as usize, maps.tiles_y() as usize),
            staging: StagingPool::default(),
            staged_bytes: 0,
        }
    }

    /// One channel's texture: at `size` with its full mip chain, or one texel (`None`).
    fn texture(gpu: &Gpu, channel: MapChannel, size: Option<(u32, u32)>) -> wgpu::Texture {
        let (width, height) = size.unwrap_or((1, 1));
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let format = match channel {
            MapChannel::N => wgpu::TextureFormat::R16Float,
            _ if gpu.unorm16 => wgpu::TextureFormat::Rgba16Unorm,
            _ => wgpu::TextureFormat::Rgba16Float,
        };
        gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(match channel {
                MapChannel::Kd => "k_d",
                MapChannel::Ks => "k_s",
                MapChannel::N => "n",
            }),
            size,
            mip_level_count: size.max_mips(wgpu::TextureDimension::D2),
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_DST
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        })
    }

    /// Gives the channels that now vary their full-size textures; returns whether any did
    /// (every tile must then be uploaded again: the new textures hold nothing yet).
    fn grow(&mut self, gpu: &Gpu, uniform: &UniformChannels) -> bool {
        let mut grew = false;
        for (channel, varies, full) in [
            (MapChannel::Kd, uniform.kd.is_none(), &mut self.full.kd),
            (MapChannel::Ks, uniform.ks.is_none(), &mut self.full.ks),
            (MapChannel::N, uniform.n.is_none(), &mut self.full.n),
        ] {
            if varies && !*full {
                let texture = Self::texture(gpu, channel, Some(self.size));
                match channel {
                    MapChannel::Kd => self.kd = texture,
                    MapChannel::Ks => self.ks = texture,
                    MapChannel::N => self.n = texture,
                }
                *full = true;
                grew = true;
            }
        }
        grew
    }

    /// Mirrors the material's normal map (uploaded when it changed; a flat texel for none).
    ///
    /// # Errors
    /// A map larger than the device's largest texture, or a device out of memory or lost.
    pub fn set_normal(
        &mut self,
        gpu: &Gpu,
        normal: Option<&std::sync::Arc<kapaint_model::normal::NormalMap>>,
    ) -> Result<(), GpuError> {
        self.normal.sync(gpu, normal)?;
        self.uniform.normal_map = self.normal.present();
        Ok(())
    }

    /// Bytes the last sync staged (and copied into the textures), for tests and diagnostics.
    pub fn staged_bytes(&self) -> u64 {
        self.staged_bytes
    }

    /// Map size mirrored.
    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// Uploads the tiles changed since the last sync; returns how many. Maps of another size
    /// need new textures ([`MapTextures::new`]). If staging fails (the device is out of
    /// memory), nothing is marked synced and the next sync tries the same tiles again.
    ///
    /// # Errors
    /// The device was lost or broke down during the upload.
    pub fn sync(&mut self, gpu: &Gpu, maps: &MaterialMaps) -> Result<usize, super::GpuError> {
        if maps.version() == self.version {
            return Ok(0);
        }
        let uniform = UniformChannels::of(maps);
        let grew = gpu.checked("making the map textures", || self.grow(gpu, &uniform))?;
        // A texture just made full holds nothing: every tile, every channel.
        let (dirty, from) = if grew {
            ((0..maps.tile_count()).collect(), 0)
        } else {
            (maps.tiles_changed_since(self.version), self.version)
        };
        if gpu
            .checked("uploading the maps", || {
                self.upload(gpu, maps, &dirty, from)
            })?
            .is_err()
        {
            if grew {
                // The new textures hold nothing yet: the next sync uploads every tile.
                self.version = 0;
            }
            return Ok(0);
        }
        self.uniform = UniformChannels {
            normal_map: self.normal.present(),
            ..uniform
        };
        self.version = maps.version();
        Ok(dirty.len())
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
        let bytes = super::readback::read_texture(gpu, encoder, texture, texel, level)?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }

    /// Uploads `tiles` and the mip levels over them: the tiles grouped into rectangles, each
    /// batch of them staged in one mapped buffer (filled in parallel) and copied by one
    /// command buffer, one copy per rectangle, level and texture.
    fn upload(
        &mut self,
        gpu: &Gpu,
        maps: &MaterialMaps,
        tiles: &[usize],
        since: u64,
    ) -> Result<(), GpuError> {
        if tiles.is_empty() {
            return Ok(());
        }
        let tiles_x = maps.tiles_x() as usize;
        // Each rectangle stages the channels any of its tiles changed since `since`.
        let rects: Vec<(upload::TileRect, Channels)> = upload::tile_rects(tiles, tiles_x)
            .into_iter()
            .map(|r| {
                let ids = (r.y0..r.y1).flat_map(|y| (r.x0..r.x1).map(move |x| y * tiles_x + x));
                let changed = ids.fold(Channels::NONE, |c, id| {
                    c.union(maps.channels_changed_since(id, since))
                });
                // One-texel textures take nothing: their channel is one value everywhere.
                let staged = Channels {
                    kd: changed.kd && self.full.kd,
                    ks: changed.ks && self.full.ks,
                    n: changed.n && self.full.n,
                };
                (r, staged)
            })
            .filter(|(_, staged)| *staged != Channels::NONE)
            .collect();
        if rects.is_empty() {
            return Ok(());
        }
        let extent = wgpu::Extent3d {
            width: self.size.0,
            height: self.size.1,
            depth_or_array_layers: 1,
        };
        let levels = extent.max_mips(wgpu::TextureDimension::D2);
        let batches = upload::batches(&rects, self.size, levels);
        self.staged_bytes = batches.iter().map(|b| b.len).sum();
        for batch in &batches {
            // Every staged byte is written (row padding may keep stale bytes: never read).
            let buffer = self.staging.take(gpu, batch.len);
            let sums = upload::fill_rects(maps, self.unorm16, batch, &buffer)?;
            self.top_sums.set(&sums);
            let top = batch.top_levels();
            if !top.is_empty() {
                upload::fill_top(&self.top_sums, self.unorm16, top, &buffer)?;
            }
            buffer.unmap();
            let mut encoder = gpu
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("map upload"),
                });
            for i in &batch.images {
                for (staged, texture, offset, bytes_per_row) in [
                    (i.channels.kd, &self.kd, i.kd, i.rgba_row),
                    (i.channels.ks, &self.ks, i.ks, i.rgba_row),
                    (i.channels.n, &self.n, i.n, i.n_row),
                ] {
                    if !staged {
                        continue;
                    }
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
            self.staging.keep(buffer);
        }
        Ok(())
    }
}
