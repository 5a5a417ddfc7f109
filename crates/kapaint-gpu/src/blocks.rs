//! Block encoding on the GPU: `block_compression`'s compute shaders (its WGSL port of Intel's
//! ISPC kernels) for the KTX2 export, on a real GPU adapter.
//!
//! The image goes up in strips of texel rows (at most [`STRIP_BYTES`] each by default), so neither the
//! host nor the device ever holds a widened copy of the whole level. Each strip is encoded
//! into its own storage buffer and read back before the next goes up.
//!
//! The CPU encodes unless `KAPAINT_BLOCK_ENCODER=gpu` asks for this encoder (on any adapter,
//! software ones included: how the tests reach this code on a machine without a GPU).
//! Measured on an NVIDIA H100 beside 16 cores (docs/performance.md): building the pipelines
//! takes 16.6 s per process, and BC7 `UltraFast` at 4096^2 takes 0.178 s against ISPC's
//! 0.033 s on the CPU, so a `ktx2` export took 16.4 to 17.8 s on the GPU against 1.07 to
//! 1.17 s on the CPU. The GPU wins only from `Basic` up (0.49 s against 0.96 s), and never by
//! the pipelines' cost.

use std::sync::{Mutex, OnceLock};

use block_compression::{CompressionVariant, GpuBlockCompressor};

use super::{Gpu, GpuError};
use kapaint_export::blocks::BlockEncoder;
use kapaint_export::codec::{Codec, Effort};

/// The most texel bytes one strip uploads.
pub const STRIP_BYTES: usize = 32 << 20;

/// A device with the block encoder's pipelines built on it.
pub struct GpuBlockEncoder {
    gpu: Gpu,
    compressor: Mutex<GpuBlockCompressor>,
    strip_rows: u32,
    /// Why the first encode that failed did: once set, the export encodes on the CPU.
    failed: OnceLock<String>,
}

impl std::fmt::Debug for GpuBlockEncoder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GpuBlockEncoder")
            .field("gpu", &self.gpu)
            .finish_non_exhaustive()
    }
}

/// What `KAPAINT_BLOCK_ENCODER` asks for: `auto` (default: the CPU, which is faster than a
/// GPU with its pipelines to build, measured: see the module), `gpu` (any adapter, software
/// included), or `cpu` (never the GPU).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Choice {
    /// The encoder measured faster for an export: the CPU's.
    Auto,
    /// Any GPU adapter, software ones included.
    Gpu,
    /// The CPU encoders only.
    Cpu,
}

impl Choice {
    /// The choice in the environment (`auto` when unset or unknown).
    pub fn from_env() -> Self {
        match std::env::var("KAPAINT_BLOCK_ENCODER")
            .unwrap_or_default()
            .to_ascii_lowercase()
            .as_str()
        {
            "gpu" => Self::Gpu,
            "cpu" => Self::Cpu,
            _ => Self::Auto,
        }
    }

    /// Whether an export opens the GPU block encoder: only where asked to.
    pub fn opens_gpu(self) -> bool {
        self == Self::Gpu
    }
}

/// The process's GPU block encoder, once opened.
static SHARED: OnceLock<Option<GpuBlockEncoder>> = OnceLock::new();

/// The process's GPU block encoder, opened on first use where [`Choice::from_env`] asks for
/// it, or `None` (not asked for, no adapter, or an earlier failure).
///
/// Opening builds the compute pipelines: 67 s on lavapipe on 2 cores, 16.6 s on an H100,
/// once per process.
pub fn shared() -> Option<&'static GpuBlockEncoder> {
    SHARED
        .get_or_init(|| {
            if !Choice::from_env().opens_gpu() {
                return None;
            }
            let adapter = Gpu::adapter().ok()?;
            Gpu::from_adapter(&adapter).ok().map(GpuBlockEncoder::new)
        })
        .as_ref()
        .filter(|e| e.failed.get().is_none())
}

/// The encoder an export with `preset` is handed: the process's ([`shared`]) for a
/// block-compressed preset, where this machine has one; `None` for the others (nothing is
/// opened for them).
pub fn for_export(
    preset: &kapaint_export::preset::ExportPreset,
) -> Option<&'static dyn BlockEncoder> {
    // Only a format whose colour codec the shaders encode (`block_compression`'s: BC).
    let colour = [kapaint_export::ktx::Space::Srgb; 3];
    let codec = preset.format.codec(&colour)?;
    codec.portable(Effort::default())?;
    let encoder = shared()?;
    Some(encoder)
}

impl BlockEncoder for GpuBlockEncoder {
    /// The codecs `block_compression` has shaders for (BC4, BC5, BC6H, BC7).
    fn encodes(&self, codec: &dyn Codec) -> bool {
        codec.portable(Effort::UltraFast).is_some()
    }

    fn encode(
        &self,
        codec: &dyn Codec,
        effort: Effort,
        size: (u32, u32),
        fill: &mut dyn FnMut(u32, u32, &mut [u8]),
        strip_done: &mut dyn FnMut(u32) -> bool,
        blocks: &mut [u8],
    ) -> Result<(), kapaint_export::blocks::Interrupted> {
        GpuBlockEncoder::encode(self, (codec, effort), size, fill, strip_done, blocks).map_err(
            |stopped| kapaint_export::blocks::Interrupted {
                error: stopped.error.to_string(),
                rows_done: stopped.rows_done,
            },
        )
    }

    fn failure(&self) -> Option<String> {
        self.failed.get().cloned()
    }

    /// Gives the encoder up: [`shared`] answers `None` from now on, and
    /// [`BlockEncoder::failure`] says why (the first reason given).
    fn give_up(&self, why: &str) {
        eprintln!("kapaint: GPU block encoding failed ({why}); encoding on the CPU from now on");
        let _ = self.failed.set(why.to_owned());
    }
}

/// A GPU encode stopped by a failure part-way: the error, and the texel rows from the top whose
/// blocks were encoded and read back before it (they are in place; the rest is not).
#[derive(Debug)]
pub struct Interrupted {
    /// What failed.
    pub error: GpuError,
    /// Texel rows encoded before it, a multiple of 4.
    pub rows_done: u32,
}

/// The texture format the shaders read texels of `bytes` each from (one, two or four bytes,
/// or four half floats).
fn source_format(bytes: usize) -> wgpu::TextureFormat {
    match bytes {
        1 => wgpu::TextureFormat::R8Unorm,
        2 => wgpu::TextureFormat::Rg8Unorm,
        8 => wgpu::TextureFormat::Rgba16Float,
        _ => wgpu::TextureFormat::Rgba8Unorm,
    }
}

impl GpuBlockEncoder {
    /// Builds the encoder's pipelines on `gpu`.
    pub fn new(gpu: Gpu) -> Self {
        let compressor = GpuBlockCompressor::new(gpu.device.clone(), gpu.queue.clone());
        Self {
            gpu,
            compressor: Mutex::new(compressor),
            strip_rows: u32::MAX,
            failed: OnceLock::new(),
        }
    }

    /// The same with strips of at most `rows` texel rows (a multiple of 4; else the
    /// [`STRIP_BYTES`] a strip holds at most decides alone).
    #[must_use]
    pub fn with_strip_rows(self, rows: u32) -> Self {
        Self {
            strip_rows: rows,
            ..self
        }
    }

    /// The device it encodes on.
    pub fn gpu(&self) -> &Gpu {
        &self.gpu
    }

    /// The adapter's name and backend, for reports.
    pub fn adapter(&self) -> &wgpu::AdapterInfo {
        &self.gpu.info
    }

    /// Encodes a `(width, height)` image (sides multiples of 4) of [`Codec::texel_bytes`]
    /// bytes per texel as the codec at the effort into `blocks` ([`Codec::blocks_len`]
    /// bytes), strip by strip:
    /// `fill(row, rows, texels)` writes texel rows `row..row + rows` into `texels` (exactly
    /// `rows` rows). `strip_done(rows)` follows each strip; it answers `false` to stop (the
    /// rest is then left as it was).
    ///
    /// # Errors
    /// A side beyond the device's largest texture, or the device failed (out of memory,
    /// lost), with the texel rows from the top whose blocks are in place.
    pub fn encode(
        &self,
        (codec, effort): (&dyn Codec, Effort),
        (width, height): (u32, u32),
        fill: &mut dyn FnMut(u32, u32, &mut [u8]),
        strip_done: &mut dyn FnMut(u32) -> bool,
        blocks: &mut [u8],
    ) -> Result<(), Interrupted> {
        debug_assert!(width % 4 == 0 && height % 4 == 0);
        debug_assert_eq!(blocks.len(), codec.blocks_len((width, height)));
        let at_start = |error| Interrupted {
            error,
            rows_done: 0,
        };
        let Some(variant) = codec.portable(effort) else {
            return Err(at_start(GpuError(format!(
                "{} is not a codec the GPU encodes",
                codec.name()
            ))));
        };
        let texel_bytes = codec.texel_bytes();
        let row_bytes = width as usize * texel_bytes;
        let fit = u32::try_from(STRIP_BYTES / row_bytes.max(1)).unwrap_or(u32::MAX);
        let strip_rows = (fit.min(self.strip_rows) / 4 * 4).clamp(4, height);
        self.gpu
            .check_texture_size("a level to block-encode", (width, strip_rows))
            .map_err(at_start)?;
        let blocks_row = (width as usize / 4) * codec.block_bytes();
        let mut compressor = self
            .compressor
            .lock()
            .map_err(|_| at_start(GpuError("the GPU block encoder is poisoned".into())))?;
        let strip = self
            .gpu
            .checked("block encoding", || {
                Strip::new(
                    &self.gpu,
                    (texel_bytes, codec.block_bytes()),
                    variant,
                    (width, strip_rows),
                )
            })
            .map_err(at_start)?;
        let mut texels = vec![0_u8; row_bytes * strip_rows as usize];
        let mut row = 0;
        while row < height {
            let rows = strip_rows.min(height - row);
            let src = &mut texels[..row_bytes * rows as usize];
            fill(row, rows, src);
            let at = blocks_row * row as usize / 4;
            let dst = &mut blocks[at..at + blocks_row * rows as usize / 4];
            strip
                .encode(&self.gpu, &mut compressor, src, rows, dst)
                .map_err(|error| Interrupted {
                    error,
                    rows_done: row,
                })?;
            row += rows;
            if !strip_done(rows) {
                break;
            }
        }
        Ok(())
    }
}

/// The device side of one strip: what it encodes, its source texture, its blocks, and their
/// read-back.
struct Strip {
    /// Bytes per source texel.
    texel_bytes: usize,
    variant: CompressionVariant,
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    out: wgpu::Buffer,
    staging: wgpu::Buffer,
}

impl Strip {
    fn new(
        gpu: &Gpu,
        (texel_bytes, block_bytes): (usize, usize),
        variant: CompressionVariant,
        (width, rows): (u32, u32),
    ) -> Self {
        let texture = gpu.texture_2d(
            "blocks source strip",
            (width, rows),
            source_format(texel_bytes),
            wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        );
        let size = ((width as usize / 4) * block_bytes * rows as usize / 4) as u64;
        let buffer = |label, usage| {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        Self {
            texel_bytes,
            variant,
            view: texture.create_view(&wgpu::TextureViewDescriptor::default()),
            texture,
            out: buffer(
                "blocks strip",
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            ),
            staging: buffer(
                "blocks read-back",
                wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            ),
        }
    }

    /// Uploads `rows` rows of `texels`, encodes them and reads the blocks back into `dst`.
    fn encode(
        &self,
        gpu: &Gpu,
        compressor: &mut GpuBlockCompressor,
        texels: &[u8],
        rows: u32,
        dst: &mut [u8],
    ) -> Result<(), GpuError> {
        let width = self.texture.width();
        let scope = gpu.scope()?;
        gpu.queue.write_texture(
            self.texture.as_image_copy(),
            texels,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(width * self.texel_bytes as u32),
                rows_per_image: Some(rows),
            },
            wgpu::Extent3d {
                width,
                height: rows,
                depth_or_array_layers: 1,
            },
        );
        let mut commands = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        {
            let mut pass = commands.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("block encoding"),
                timestamp_writes: None,
            });
            compressor.add_compression_task(
                self.variant,
                &self.view,
                width,
                rows,
                &self.out,
                None,
                None,
            );
            compressor.compress(&mut pass);
        }
        let bytes = dst.len() as u64;
        commands.copy_buffer_to_buffer(&self.out, 0, &self.staging, 0, bytes);
        gpu.queue.submit([commands.finish()]);
        let blocks = super::readback::read_buffer_prefix(gpu, &self.staging, bytes);
        scope.finish("block encoding")?;
        dst.copy_from_slice(&blocks?);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::Choice;

    /// Regression: `auto` opened any hardware GPU, and on an H100 beside 16 cores the
    /// pipelines alone (16.6 s) made a 4096^2 `ktx2` export 15 times slower than the CPU's.
    #[test]
    fn only_an_explicit_choice_opens_the_gpu() {
        assert!(!Choice::Auto.opens_gpu());
        assert!(!Choice::Cpu.opens_gpu());
        assert!(Choice::Gpu.opens_gpu());
    }
}
