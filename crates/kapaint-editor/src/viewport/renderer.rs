//! The viewport's GPU side: its mirror of the document (mesh buffers, map textures), its
//! render targets and the frames it draws. The renderers themselves (the preview's and the
//! difference's, with their pipeline caches) live in egui_wgpu's callback resources, where
//! egui keeps the GPU state of paint callbacks, not in the app state.

use std::sync::Arc;

use eframe::egui_wgpu;
use egui::TextureId;

use super::{Compare, Comparison, Side};
use kapaint_core::render::FrameSettings;
use kapaint_gpu::difference::{Difference, DifferenceBindings, SIDE_FORMAT};
use kapaint_gpu::maps::MapTextures;
use kapaint_gpu::preview::{
    COMPARED_MODELS, DEPTH_FORMAT, DrawPart, FrameBindings, Layout, MeshBuffers, Offscreen,
    PipelineKey, Preview, PreviewDrawData, RenderedImage, begin_pass,
};
use kapaint_gpu::{Gpu, GpuError};
use kapaint_mesh::Mesh;
use kapaint_model::MaterialMaps;
use kapaint_model::texel::MaterialValue;
use kapaint_reflectance::ShadingModel;

/// GPU objects of the viewport.
pub struct ViewportGpu {
    gpu: Gpu,
    renderer: egui_wgpu::RenderState,
    mesh: Option<(u64, MeshBuffers)>,
    maps: Option<MapTextures>,
    /// Which maps `maps` mirrors (the composite, or a layer view's).
    maps_source: u64,
    target: Option<Target>,
    /// The preview's uniform buffers and bind groups, reused from frame to frame.
    bindings: FrameBindings,
    /// The heatmap's.
    difference_bindings: DifferenceBindings,
    /// What the target holds now: a frame asked for again unchanged (a job's progress
    /// redrawing the window, a notice fading) is shown as it is, not drawn again.
    drawn: Option<Drawn>,
    /// How long the last frame drawn took to record and submit, in milliseconds.
    draw_ms: f32,
}

/// Everything a viewport picture is made from.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Drawn {
    mesh: u64,
    maps: (u64, u64),
    normal: Option<usize>,
    settings: FrameSettings,
    comparison: Comparison,
    size: (u32, u32),
}

/// The viewport's renderers, immutable once made: kept in egui_wgpu's callback resources.
pub struct Renderers {
    /// The preview.
    pub preview: Preview,
    /// The difference heatmap.
    pub difference: Difference,
}

struct Target {
    size: (u32, u32),
    /// The colour target's view (egui shows the texture).
    view: wgpu::TextureView,
    depth: wgpu::TextureView,
    id: TextureId,
    /// The two linear renders the difference mode compares, made when first needed.
    sides: Option<(wgpu::TextureView, wgpu::TextureView)>,
}

const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

impl ViewportGpu {
    /// The viewport's renderer on eframe's device.
    pub fn new(render_state: &egui_wgpu::RenderState) -> Self {
        let gpu = Gpu::on_device(
            render_state.device.clone(),
            render_state.queue.clone(),
            render_state.adapter.get_info(),
        );
        let mut renderer = render_state.renderer.write();
        if !renderer.callback_resources.contains::<Renderers>() {
            renderer.callback_resources.insert(Renderers {
                preview: Preview::new(&gpu),
                difference: Difference::new(&gpu),
            });
        }
        drop(renderer);
        Self {
            gpu,
            renderer: render_state.clone(),
            mesh: None,
            maps: None,
            maps_source: 0,
            target: None,
            bindings: FrameBindings::default(),
            difference_bindings: DifferenceBindings::default(),
            drawn: None,
            draw_ms: 0.0,
        }
    }

    /// How long the last picture actually drawn took (one shown again costs nothing).
    pub fn draw_ms(&self) -> f32 {
        self.draw_ms
    }

    /// A `size`-pixel picture of `value` on the mesh, for the preset browser.
    pub fn thumbnail(
        &mut self,
        mesh: &(u64, Arc<Mesh>),
        value: MaterialValue,
        settings: &FrameSettings,
        size: u32,
    ) -> Option<egui::ColorImage> {
        if self.mesh.as_ref().is_none_or(|(id, _)| *id != mesh.0) {
            self.mesh = Some((mesh.0, MeshBuffers::new(&self.gpu, &mesh.1).ok()?));
        }
        let maps = MaterialMaps::new(1, 1, value).ok()?;
        let textures = MapTextures::new(&self.gpu, &maps).ok()?;
        let (_, buffers) = self.mesh.as_ref()?;
        let offscreen = Offscreen {
            size: (size, size),
            linear: false,
            layout: Layout::Single,
            models: COMPARED_MODELS,
        };
        let renderer = self.renderer.renderer.read();
        let preview = &renderer.callback_resources.get::<Renderers>()?.preview;
        match preview
            .render_offscreen(&self.gpu, buffers, &textures, settings, offscreen)
            .ok()?
        {
            RenderedImage::Srgb8 {
                width,
                height,
                pixels,
            } => Some(egui::ColorImage::from_rgba_unmultiplied(
                [width as usize, height as usize],
                &pixels,
            )),
            RenderedImage::Linear { .. } => None,
        }
    }

    /// Adapter name for the status bar.
    pub fn adapter(&self) -> &str {
        &self.gpu.info.name
    }

    /// Renders a frame of `size` pixels; returns the texture egui shows.
    ///
    /// # Errors
    /// A mesh, maps or picture beyond the device's limits, or a device out of memory or
    /// lost: the viewport says so, and painting goes on.
    pub(super) fn render(
        &mut self,
        (maps, source, normal): super::MapsIn<'_>,
        mesh: &(u64, Arc<Mesh>),
        settings: &FrameSettings,
        comparison: &Comparison,
        size: (u32, u32),
    ) -> Result<TextureId, GpuError> {
        // Tangents (for a normal map) only when there is one to read.
        let tangents = normal.is_some();
        if self
            .mesh
            .as_ref()
            .is_none_or(|(id, b)| *id != mesh.0 || (tangents && !b.tangents))
        {
            self.mesh = None;
            self.mesh = Some((
                mesh.0,
                if tangents {
                    MeshBuffers::with_tangents(&self.gpu, &mesh.1)?
                } else {
                    MeshBuffers::new(&self.gpu, &mesh.1)?
                },
            ));
        }
        let maps_size = (maps.width(), maps.height());
        match &mut self.maps {
            Some(m) if m.size() == maps_size && self.maps_source == source => {
                m.sync(&self.gpu, maps)?;
            }
            _ => {
                self.maps = None;
                self.maps = Some(MapTextures::new(&self.gpu, maps)?);
                self.maps_source = source;
            }
        }
        if let Some(m) = &mut self.maps {
            m.set_normal(&self.gpu, normal)?;
        }
        if self.target.as_ref().is_none_or(|t| t.size != size) {
            self.gpu.check_texture_size("the viewport", size)?;
            let scope = self.gpu.scope()?;
            let target = self.make_target(size);
            scope.finish("making the viewport")?;
            self.target = Some(target);
        }
        if comparison.mode == Compare::Difference
            && let Some(target) = &mut self.target
            && target.sides.is_none()
        {
            let gpu = &self.gpu;
            target.sides = Some(gpu.checked("making the difference view", || {
                (side_texture(gpu, size), side_texture(gpu, size))
            })?);
        }
        let drawn = Drawn {
            mesh: mesh.0,
            maps: (source, maps.version()),
            normal: normal.map(|n| Arc::as_ptr(n) as usize),
            settings: *settings,
            comparison: *comparison,
            size,
        };
        if let Some(target) = &self.target
            && self.drawn == Some(drawn)
        {
            return Ok(target.id);
        }
        self.drawn = None;
        let start = std::time::Instant::now();
        let scope = self.gpu.scope()?;
        let id = self.draw(settings, comparison, size);
        scope.finish("drawing the viewport")?;
        self.draw_ms = start.elapsed().as_secs_f32() * 1000.0;
        self.drawn = Some(drawn);
        Ok(id)
    }

    /// Records and submits the frame into the current target.
    fn draw(
        &mut self,
        settings: &FrameSettings,
        comparison: &Comparison,
        size: (u32, u32),
    ) -> TextureId {
        let (Some((_, mesh)), Some(maps), Some(target)) = (&self.mesh, &self.maps, &self.target)
        else {
            return TextureId::default();
        };
        let (bindings, difference_bindings) = (&mut self.bindings, &mut self.difference_bindings);
        bindings.begin_frame();
        let renderer = self.renderer.renderer.read();
        let Some(Renderers {
            preview,
            difference,
        }) = renderer.callback_resources.get::<Renderers>()
        else {
            return TextureId::default();
        };
        let key = PipelineKey::for_frame(settings, &maps.uniform, FORMAT);
        let side = |s: Side, format| {
            let settings = FrameSettings {
                model: s.model,
                approx: s.approx,
                view: s.view.unwrap_or(settings.view),
                ..*settings
            };
            PipelineKey::for_frame(&settings, &maps.uniform, format)
        };
        let mut encoder = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("viewport"),
            });
        let view = &target.view;
        let keys = match comparison.mode {
            Compare::Single => [key; 3],
            // The three models, each with the left side's approximation.
            Compare::ThreeWay => ShadingModel::ALL.map(|model| {
                side(
                    Side {
                        model,
                        ..comparison.left
                    },
                    FORMAT,
                )
            }),
            _ => [
                side(comparison.left, FORMAT),
                side(comparison.right, FORMAT),
                key,
            ],
        };
        let parts = Layout::of(comparison.mode, comparison.split_at, size.0)
            .map(|layout| layout.parts(keys, size));
        let mut frame = |parts: &[DrawPart]| {
            PreviewDrawData::new(preview, &self.gpu, (mesh, maps), settings, parts, bindings)
        };
        match (parts, &target.sides) {
            (Some(parts), _) => {
                let data = frame(&parts);
                let mut pass = begin_pass(&mut encoder, view, &target.depth);
                preview.draw(&mut pass, &data);
            }
            (None, Some((a, b))) => {
                for (s, out) in [(comparison.left, a), (comparison.right, b)] {
                    let data = frame(&[DrawPart::whole(side(s, SIDE_FORMAT), size)]);
                    let mut pass = begin_pass(&mut encoder, out, &target.depth);
                    preview.draw(&mut pass, &data);
                }
                let data = difference.draw_data(
                    &self.gpu,
                    [a, b],
                    FORMAT,
                    comparison.diff_max,
                    difference_bindings,
                );
                let mut pass = Difference::begin_pass(&mut encoder, view);
                difference.draw(&mut pass, &data);
            }
            (None, None) => {}
        }
        self.gpu.queue.submit([encoder.finish()]);
        target.id
    }

    fn make_target(&mut self, size: (u32, u32)) -> Target {
        let texture = |format, usage| self.gpu.texture_2d("viewport", size, format, usage);
        let color = texture(
            FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let depth = texture(DEPTH_FORMAT, wgpu::TextureUsages::RENDER_ATTACHMENT)
            .create_view(&wgpu::TextureViewDescriptor::default());
        let view = color.create_view(&wgpu::TextureViewDescriptor::default());
        let mut renderer = self.renderer.renderer.write();
        let id = match self.target.take() {
            Some(old) => {
                renderer.update_egui_texture_from_wgpu_texture(
                    &self.gpu.device,
                    &view,
                    wgpu::FilterMode::Linear,
                    old.id,
                );
                old.id
            }
            None => {
                renderer.register_native_texture(&self.gpu.device, &view, wgpu::FilterMode::Linear)
            }
        };
        Target {
            size,
            view,
            depth,
            id,
            sides: None,
        }
    }
}

/// A linear float render target for one side of the difference compare.
fn side_texture(gpu: &Gpu, size: (u32, u32)) -> wgpu::TextureView {
    gpu.texture_2d(
        "difference side",
        size,
        SIDE_FORMAT,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
    )
    .create_view(&wgpu::TextureViewDescriptor::default())
}
