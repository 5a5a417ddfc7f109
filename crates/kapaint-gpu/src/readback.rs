//! Reading textures and buffers back to the CPU: a leaf that every room which reads back
//! (maps, offscreen renders, the difference pass, checks, the block encoder) uses, and which
//! uses none of them.

use crate::{Gpu, GpuError};

/// Copies mip `level` of `texture` (`texel` bytes per texel) out after the work in
/// `encoder`, rows packed.
///
/// # Errors
/// When the read-back fails.
pub fn read_texture(
    gpu: &Gpu,
    mut encoder: wgpu::CommandEncoder,
    texture: &wgpu::Texture,
    texel: u32,
    level: u32,
) -> Result<Vec<u8>, GpuError> {
    let extent = texture
        .size()
        .mip_level_size(level, wgpu::TextureDimension::D2);
    let (width, height) = (extent.width, extent.height);
    let row = (width * texel).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let readback = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: u64::from(row) * u64::from(height),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    encoder.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: level,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &readback,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(height),
            },
        },
        extent,
    );
    gpu.queue.submit([encoder.finish()]);
    let bytes = read_buffer(gpu, &readback)?;
    let mut packed = Vec::with_capacity((width * height * texel) as usize);
    for y in 0..height as usize {
        let start = y * row as usize;
        packed.extend_from_slice(&bytes[start..start + (width * texel) as usize]);
    }
    Ok(packed)
}

/// Maps a buffer for reading, waits, and copies its bytes out.
///
/// # Errors
/// When mapping fails.
pub fn read_buffer(gpu: &Gpu, buffer: &wgpu::Buffer) -> Result<Vec<u8>, GpuError> {
    read_buffer_prefix(gpu, buffer, buffer.size())
}

/// [`read_buffer`] of the first `bytes` of `buffer`.
///
/// # Errors
/// When mapping fails.
pub fn read_buffer_prefix(
    gpu: &Gpu,
    buffer: &wgpu::Buffer,
    bytes: u64,
) -> Result<Vec<u8>, GpuError> {
    let slice = buffer.slice(..bytes);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    gpu.wait();
    rx.recv()
        .map_err(|e| GpuError(format!("read-back lost: {e}")))?
        .map_err(|e| GpuError(format!("read-back failed: {e}")))?;
    let bytes = slice
        .get_mapped_range()
        .map_err(|e| GpuError(format!("read-back failed: {e}")))?
        .to_vec();
    buffer.unmap();
    Ok(bytes)
}
