//! Staging buffers kept between syncs and mapped again as soon as the GPU has copied out.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use super::{KEPT_BUFFER_BYTES, KEPT_BUFFERS};
use crate::Gpu;

/// Staging buffers kept between syncs, each with whether its mapping for writing has
/// completed (it is mapped again as soon as it is submitted: ready once the GPU has copied
/// out of it).
#[derive(Default)]
pub struct StagingPool {
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
    /// than [`KEPT_BUFFERS`] are kept, and one larger than [`KEPT_BUFFER_BYTES`] is let go.
    pub fn keep(&mut self, buffer: wgpu::Buffer) {
        if buffer.size() > KEPT_BUFFER_BYTES {
            return;
        }
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
