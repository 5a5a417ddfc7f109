//! One frame's draw data: its uniforms, its bind group (uniforms, maps, sampler), its parts
//! with their pipelines, and the mesh. The uniform buffers and bind groups live in the
//! caller's [`FrameBindings`] and are reused while the maps' textures stay the same: a steady
//! frame writes its uniforms and makes no GPU object. The renderer only reads the data.

use super::{DrawPart, MeshBuffers, Preview};
use crate::Gpu;
use crate::maps::{MapTextures, UniformChannels};
use kapaint_core::render::FrameSettings;

/// The preview's per-frame uniforms, laid out as `Frame` in `shaders/preview_types.wgsl`
/// (a test checks the sizes and offsets against naga's layouter).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FrameUniforms {
    /// Object space to clip space.
    pub view_proj: [[f32; 4]; 4],
    /// The eye's position (object space).
    pub eye: [f32; 3],
    /// `I_a`, the hemispherical ambient light's intensity.
    pub ambient_intensity: f32,
    /// Unit direction towards the light.
    pub light: [f32; 3],
    /// `I_l`, the light's intensity.
    pub light_intensity: f32,
    /// `k_d` where the map is uniform.
    pub kd: [f32; 3],
    /// `n` where the map is uniform.
    pub n: f32,
    /// `k_s` where the map is uniform.
    pub ks: [f32; 3],
    /// Padding to the struct's alignment.
    pub pad: f32,
}

impl FrameUniforms {
    /// The uniforms of `settings` seen at `aspect`, on maps whose uniform channels are `u`.
    pub fn new(settings: &FrameSettings, aspect: f32, u: &UniformChannels) -> Self {
        let l = settings.lighting;
        Self {
            view_proj: settings.camera.view_proj(aspect).to_cols_array_2d(),
            eye: settings.camera.eye().to_array(),
            ambient_intensity: l.ia,
            light: l.direction().to_array(),
            light_intensity: l.il,
            kd: u.kd.unwrap_or_default(),
            n: u.n.unwrap_or(0.0),
            ks: u.ks.unwrap_or_default(),
            pad: 0.0,
        }
    }
}

/// One draw's uniform buffer and bind group, and the textures the group binds.
#[derive(Debug)]
struct Slot {
    buffer: wgpu::Buffer,
    textures: [wgpu::Texture; 4],
    bind_group: wgpu::BindGroup,
}

/// The uniform buffers and bind groups a caller's frames reuse, one slot per draw of a frame
/// (a difference compare draws two previews a frame). Each frame starts with
/// [`FrameBindings::begin_frame`]; a draw writes its uniforms into its slot's buffer, and the
/// slot's bind group is made again only when the map textures it binds changed.
#[derive(Debug, Default)]
pub struct FrameBindings {
    slots: Vec<Slot>,
    next: usize,
    made: u64,
}

impl FrameBindings {
    /// A new frame: its draws take the slots from the first.
    pub fn begin_frame(&mut self) {
        self.next = 0;
    }

    /// How many GPU objects (buffers, texture views, bind groups) the bindings have made: what
    /// a test reads to see that steady frames make none.
    pub fn made(&self) -> u64 {
        self.made
    }

    /// The next slot's bind group for `maps`, its buffer holding `uniforms`.
    fn bind(
        &mut self,
        preview: &Preview,
        gpu: &Gpu,
        maps: &MapTextures,
        uniforms: &FrameUniforms,
    ) -> wgpu::BindGroup {
        let textures = [
            maps.kd.clone(),
            maps.ks.clone(),
            maps.n.clone(),
            maps.normal.texture.clone(),
        ];
        let at = self.next;
        self.next += 1;
        if at == self.slots.len() {
            let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("frame"),
                size: std::mem::size_of::<FrameUniforms>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let bind_group = bind_group(preview, gpu, &buffer, &textures);
            self.made += 6;
            self.slots.push(Slot {
                buffer,
                textures,
                bind_group,
            });
        } else if self.slots[at].textures != textures {
            let slot = &mut self.slots[at];
            slot.bind_group = bind_group(preview, gpu, &slot.buffer, &textures);
            slot.textures = textures;
            self.made += 5;
        }
        let slot = &self.slots[at];
        gpu.queue
            .write_buffer(&slot.buffer, 0, bytemuck::bytes_of(uniforms));
        slot.bind_group.clone()
    }
}

/// The preview's bind group of `buffer` and the `k_d`, `k_s`, `n` and normal textures.
fn bind_group(
    preview: &Preview,
    gpu: &Gpu,
    buffer: &wgpu::Buffer,
    [kd, ks, n, normal]: &[wgpu::Texture; 4],
) -> wgpu::BindGroup {
    let view = |t: &wgpu::Texture| t.create_view(&wgpu::TextureViewDescriptor::default());
    let (kd, ks, n, normal) = (view(kd), view(ks), view(n), view(normal));
    // In the order of `bindings::PREVIEW`.
    let entries = super::bindings::entries([
        buffer.as_entire_binding(),
        wgpu::BindingResource::TextureView(&kd),
        wgpu::BindingResource::TextureView(&ks),
        wgpu::BindingResource::TextureView(&n),
        wgpu::BindingResource::Sampler(&preview.sampler),
        wgpu::BindingResource::TextureView(&normal),
        wgpu::BindingResource::TextureView(&preview.view_table),
    ]);
    gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("preview"),
        layout: &preview.bind_layout,
        entries: &entries,
    })
}

/// One frame of the preview, ready to record (see [`Preview::draw`]).
#[derive(Debug)]
pub struct PreviewDrawData {
    bind_group: wgpu::BindGroup,
    parts: Vec<(DrawPart, wgpu::RenderPipeline)>,
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
}

impl PreviewDrawData {
    /// The draw data of `parts` of a frame of `settings`, `mesh` and `maps`: the uniforms
    /// (the projection's aspect is the first part's viewport's) written into the next slot of
    /// `bindings`, its bind group, and each part's pipeline, compiled now if it is new.
    pub fn new(
        preview: &Preview,
        gpu: &Gpu,
        (mesh, maps): (&MeshBuffers, &MapTextures),
        settings: &FrameSettings,
        parts: &[DrawPart],
        bindings: &mut FrameBindings,
    ) -> Self {
        let (_, _, vw, vh) = parts.first().map_or((0, 0, 1, 1), |p| p.viewport);
        let uniforms = FrameUniforms::new(settings, vw as f32 / vh.max(1) as f32, &maps.uniform);
        let bind_group = bindings.bind(preview, gpu, maps, &uniforms);
        Self {
            bind_group,
            parts: parts
                .iter()
                .map(|p| (*p, preview.pipeline(gpu, p.key)))
                .collect(),
            vertices: mesh.vertices.clone(),
            indices: mesh.indices.clone(),
            index_count: mesh.index_count,
        }
    }

    /// Records the frame into `pass`.
    pub(super) fn record(&self, pass: &mut wgpu::RenderPass<'_>) {
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
        for (part, pipeline) in &self.parts {
            let (x, y, w, h) = part.scissor;
            let (vx, vy, vw, vh) = part.viewport;
            if w == 0 || h == 0 || vw == 0 || vh == 0 {
                continue;
            }
            pass.set_viewport(vx as f32, vy as f32, vw as f32, vh as f32, 0.0, 1.0);
            pass.set_scissor_rect(x, y, w, h);
            pass.set_pipeline(pipeline);
            pass.draw_indexed(0..self.index_count, 0, 0..1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_uniforms_match_the_shader_struct() {
        let (size, members) = crate::shader::struct_layout("preview.wgsl", "Frame");
        assert_eq!(size as usize, std::mem::size_of::<FrameUniforms>());
        let rust = [
            ("view_proj", std::mem::offset_of!(FrameUniforms, view_proj)),
            ("eye", std::mem::offset_of!(FrameUniforms, eye)),
            (
                "ambient_intensity",
                std::mem::offset_of!(FrameUniforms, ambient_intensity),
            ),
            ("light", std::mem::offset_of!(FrameUniforms, light)),
            (
                "light_intensity",
                std::mem::offset_of!(FrameUniforms, light_intensity),
            ),
            ("kd", std::mem::offset_of!(FrameUniforms, kd)),
            ("n", std::mem::offset_of!(FrameUniforms, n)),
            ("ks", std::mem::offset_of!(FrameUniforms, ks)),
            ("pad", std::mem::offset_of!(FrameUniforms, pad)),
        ];
        let rust: Vec<(String, u32)> = rust
            .iter()
            .map(|(n, o)| ((*n).to_string(), *o as u32))
            .collect();
        assert_eq!(members, rust);
    }
}
