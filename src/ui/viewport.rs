//! The 3D viewport: the wgpu preview renderer drawing into a texture that egui shows, camera
//! controls, and picking for painting on the mesh. Without a GPU (tests, broken drivers) the
//! viewport still picks and paints; it only cannot draw.

use std::sync::Arc;
use std::time::Instant;

use eframe::egui_wgpu;
use egui::{Color32, Pos2, Rect, Sense, TextureId};

use crate::gpu::difference::{Difference, SIDE_FORMAT};
use crate::gpu::maps::MapTextures;
use crate::gpu::preview::Layout;
use crate::gpu::preview::{
    DEPTH_FORMAT, DrawPart, MeshBuffers, Offscreen, PipelineKey, Preview, RenderedImage,
};
use crate::gpu::{Gpu, GpuError};
use crate::mesh::Mesh;
use crate::mesh::pick::{Bvh, Hit};
use crate::model::texel::MaterialValue;
use crate::model::{Document, MaterialMaps};
use crate::reflectance::{AmbientApprox, ShadingModel};
use crate::render::{Camera, FrameSettings};

/// The viewport's accessible name.
pub const VIEWPORT_LABEL: &str = "3D viewport painting area";

pub use crate::render::Compare;

/// One side of a comparison: its shading model and approximation of `chi`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Side {
    /// Shading model.
    pub model: ShadingModel,
    /// Approximation of `chi`.
    pub approx: AmbientApprox,
}

impl Side {
    /// The label drawn over this side of the viewport.
    pub fn label(self) -> String {
        let model = match self.model {
            ShadingModel::Phong => "Phong (eq. 8)",
            ShadingModel::BlinnPhong => "Blinn-Phong (eq. 11)",
        };
        format!("{model}, {}", self.approx.name())
    }
}

/// What the viewport compares: the mode, the two sides and where the divider is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Comparison {
    /// Compare mode.
    pub mode: Compare,
    /// The left side (Phong by default).
    pub left: Side,
    /// The right side (Blinn-Phong by default).
    pub right: Side,
    /// Split position, a fraction of the width.
    pub split_at: f32,
    /// The difference shown white in the heatmap (linear radiance).
    pub diff_max: f32,
}

impl Default for Comparison {
    fn default() -> Self {
        Self {
            mode: Compare::Single,
            left: Side {
                model: ShadingModel::Phong,
                approx: AmbientApprox::Fast,
            },
            right: Side {
                model: ShadingModel::BlinnPhong,
                approx: AmbientApprox::Fast,
            },
            split_at: 0.5,
            diff_max: 0.1,
        }
    }
}

/// GPU objects of the viewport.
pub struct ViewportGpu {
    gpu: Gpu,
    renderer: egui_wgpu::RenderState,
    preview: Preview,
    mesh: Option<(u64, MeshBuffers)>,
    maps: Option<MapTextures>,
    target: Option<Target>,
    difference: Difference,
}

struct Target {
    size: (u32, u32),
    color: wgpu::Texture,
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
        let preview = Preview::new(&gpu);
        let difference = Difference::new(&gpu);
        Self {
            gpu,
            renderer: render_state.clone(),
            preview,
            mesh: None,
            maps: None,
            target: None,
            difference,
        }
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
        };
        match self
            .preview
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
    fn render(
        &mut self,
        doc: &Document,
        mesh: &(u64, Arc<Mesh>),
        settings: &FrameSettings,
        comparison: &Comparison,
        size: (u32, u32),
    ) -> Result<TextureId, GpuError> {
        if self.mesh.as_ref().is_none_or(|(id, _)| *id != mesh.0) {
            self.mesh = None;
            self.mesh = Some((mesh.0, MeshBuffers::new(&self.gpu, &mesh.1)?));
        }
        let maps_size = (doc.maps().width(), doc.maps().height());
        match &mut self.maps {
            Some(m) if m.size() == maps_size => {
                m.sync(&self.gpu, doc.maps())?;
            }
            _ => {
                self.maps = None;
                self.maps = Some(MapTextures::new(&self.gpu, doc.maps())?);
            }
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
        let scope = self.gpu.scope()?;
        let id = self.draw(settings, comparison, size);
        scope.finish("drawing the viewport")?;
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
        let key = PipelineKey::for_frame(settings, &maps.uniform, FORMAT);
        let side = |s: Side, format| PipelineKey {
            model: s.model,
            approx: s.approx,
            format,
            ..key
        };
        let mut encoder = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("viewport"),
            });
        let view = target
            .color
            .create_view(&wgpu::TextureViewDescriptor::default());
        let (left, right) = if comparison.mode == Compare::Single {
            (key, key)
        } else {
            (
                side(comparison.left, FORMAT),
                side(comparison.right, FORMAT),
            )
        };
        let parts = Layout::of(comparison.mode, comparison.split_at, size.0)
            .map(|layout| layout.parts(left, right, size));
        match (parts, &target.sides) {
            (Some(parts), _) => self.preview.draw(
                &self.gpu,
                &mut encoder,
                &view,
                &target.depth,
                size,
                mesh,
                maps,
                settings,
                &parts,
            ),
            (None, Some((a, b))) => {
                for (s, out) in [(comparison.left, a), (comparison.right, b)] {
                    let part = DrawPart::whole(side(s, SIDE_FORMAT), size);
                    self.preview.draw(
                        &self.gpu,
                        &mut encoder,
                        out,
                        &target.depth,
                        size,
                        mesh,
                        maps,
                        settings,
                        &[part],
                    );
                }
                self.difference.draw(
                    &self.gpu,
                    &mut encoder,
                    a,
                    b,
                    &view,
                    FORMAT,
                    comparison.diff_max,
                );
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
            color,
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

/// The viewport's state.
pub struct Viewport {
    /// Camera.
    pub camera: Camera,
    /// What is compared, and how.
    pub comparison: Comparison,
    /// The renderer, when there is a GPU.
    pub gpu: Option<ViewportGpu>,
    /// Milliseconds the last frame took to record and submit.
    pub frame_ms: f32,
    /// Why there is no GPU, for the placeholder.
    pub no_gpu: String,
    /// Why the last frame could not be drawn (a map beyond the GPU's limits, a lost device).
    pub gpu_error: Option<String>,
    frame_pending: bool,
    /// The compare mode the camera was last framed for.
    framed_for: Compare,
}

impl Viewport {
    /// A viewport; `gpu` from eframe's render state when it has one.
    pub fn new(gpu: Option<ViewportGpu>) -> Self {
        Self {
            camera: Camera::default().orbit(0.5, 0.35),
            comparison: Comparison::default(),
            gpu,
            frame_ms: 0.0,
            no_gpu: "The 3D preview needs a GPU (wgpu); painting on the mesh still works.".into(),
            gpu_error: None,
            frame_pending: true,
            framed_for: Compare::Single,
        }
    }

    /// Frames the mesh (F) at the next draw, when the viewport's aspect is known.
    pub fn frame(&mut self, _mesh: &Mesh) {
        self.frame_pending = true;
    }

    /// The picture under `pos`: the whole viewport, or the half it is in when side by side.
    pub fn picture_at(&self, rect: Rect, pos: Pos2) -> Rect {
        if self.comparison.mode != Compare::SideBySide {
            return rect;
        }
        let half = rect.width() / 2.0;
        if pos.x < rect.center().x {
            Rect::from_min_size(rect.min, egui::vec2(half, rect.height()))
        } else {
            Rect::from_min_size(
                Pos2::new(rect.max.x - half, rect.min.y),
                egui::vec2(half, rect.height()),
            )
        }
    }

    /// The surface point under a screen position, if the ray hits the mesh.
    pub fn pick(&self, rect: Rect, pos: Pos2, mesh: &Mesh, bvh: &Bvh) -> Option<Hit> {
        let rect = self.picture_at(rect, pos);
        let (w, h) = (rect.width().max(1.0), rect.height().max(1.0));
        let (origin, dir) =
            self.camera
                .ray(pos.x - rect.min.x, pos.y - rect.min.y, w as u32, h as u32);
        bvh.pick(mesh, origin, dir)
    }

    /// Draws the viewport and handles the camera (right drag or Alt + left: orbit; middle or
    /// Shift + right: pan; wheel: zoom). Returns the response for painting with the left
    /// button (not while Alt is held).
    pub fn show(
        &mut self,
        ui: &mut egui::Ui,
        doc: &Document,
        mesh: &(u64, Arc<Mesh>),
        settings: &FrameSettings,
    ) -> (egui::Response, Rect) {
        let (rect, response) = ui.allocate_exact_size(ui.available_size(), Sense::click_and_drag());
        response.widget_info(|| {
            egui::WidgetInfo::labeled(egui::WidgetType::Other, true, VIEWPORT_LABEL)
        });
        if self.comparison.mode == Compare::Split {
            self.divider_ui(ui, rect);
        }
        // Side by side halves the pictures' width: frame again when entering or leaving it.
        if (self.comparison.mode == Compare::SideBySide) != (self.framed_for == Compare::SideBySide)
        {
            self.frame_pending = true;
        }
        if self.frame_pending {
            // Fit the bounding sphere in the narrower of the two fields of view (of one half
            // when side by side).
            self.frame_pending = false;
            self.framed_for = self.comparison.mode;
            self.camera = self.camera.framing(&mesh.1.positions);
            let picture = self.picture_at(rect, rect.min);
            let aspect = picture.width() / picture.height().max(1.0);
            if aspect < 1.0 {
                self.camera.distance /= aspect.max(0.05);
            }
        }
        let (alt, shift) = ui.input(|i| (i.modifiers.alt, i.modifiers.shift));
        let delta = response.drag_delta();
        let right = response.dragged_by(egui::PointerButton::Secondary);
        let middle = response.dragged_by(egui::PointerButton::Middle);
        let left = response.dragged_by(egui::PointerButton::Primary);
        if middle || (right && shift) {
            self.camera = self
                .camera
                .pan(delta.x / rect.height(), delta.y / rect.height());
        } else if right || (left && alt) {
            self.camera = self.camera.orbit(-delta.x * 0.01, delta.y * 0.01);
        }
        if response.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                self.camera = self.camera.zoom((scroll * 0.002).exp());
            }
        }
        let painter = ui.painter_at(rect);
        painter.rect_filled(rect, 0.0, Color32::from_gray(40));
        let ppp = ui.ctx().pixels_per_point();
        let size = (
            ((rect.width() * ppp) as u32).max(1),
            ((rect.height() * ppp) as u32).max(1),
        );
        let mut frame = *settings;
        frame.camera = self.camera;
        match &mut self.gpu {
            Some(gpu) => {
                let start = Instant::now();
                match gpu.render(doc, mesh, &frame, &self.comparison, size) {
                    Ok(id) => {
                        self.frame_ms = start.elapsed().as_secs_f32() * 1000.0;
                        self.gpu_error = None;
                        painter.image(
                            id,
                            rect,
                            Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0)),
                            Color32::WHITE,
                        );
                    }
                    Err(e) => {
                        painter.text(
                            rect.center(),
                            egui::Align2::CENTER_CENTER,
                            format!(
                                "The 3D preview cannot draw: {e}\nPainting on the UV canvas and saving still work."
                            ),
                            egui::FontId::proportional(14.0),
                            Color32::from_rgb(230, 120, 110),
                        );
                        self.gpu_error = Some(e.to_string());
                    }
                }
            }
            None => {
                painter.text(
                    rect.center(),
                    egui::Align2::CENTER_CENTER,
                    &self.no_gpu,
                    egui::FontId::proportional(14.0),
                    Color32::GRAY,
                );
            }
        }
        self.labels_ui(&painter, rect);
        (response, rect)
    }

    /// The split's divider: a handle over the line that drags it (drawn on top of the
    /// viewport, so it wins over painting there).
    fn divider_ui(&mut self, ui: &mut egui::Ui, rect: Rect) {
        let x = rect.min.x + rect.width() * self.comparison.split_at;
        let handle = Rect::from_min_max(
            Pos2::new(x - 5.0, rect.min.y),
            Pos2::new(x + 5.0, rect.max.y),
        );
        let response = ui
            .interact(handle, ui.id().with("split divider"), Sense::drag())
            .on_hover_cursor(egui::CursorIcon::ResizeHorizontal);
        response.widget_info(|| {
            egui::WidgetInfo::labeled(egui::WidgetType::Other, true, DIVIDER_LABEL)
        });
        if response.dragged()
            && let Some(p) = response.interact_pointer_pos()
        {
            self.comparison.split_at = ((p.x - rect.min.x) / rect.width().max(1.0)).clamp(0.0, 1.0);
        }
    }

    /// The sides' labels, the divider and the heatmap's scale bar.
    fn labels_ui(&self, painter: &egui::Painter, rect: Rect) {
        let c = &self.comparison;
        let font = egui::FontId::proportional(13.0);
        let label = |pos: Pos2, align, text: String| {
            painter.text(pos, align, text, font.clone(), Color32::WHITE);
        };
        let top_left = rect.min + egui::vec2(8.0, 8.0);
        let top_right = Pos2::new(rect.max.x - 8.0, rect.min.y + 8.0);
        match c.mode {
            Compare::Single => {}
            Compare::Split => {
                let x = rect.min.x + rect.width() * c.split_at;
                painter.line_segment(
                    [Pos2::new(x, rect.min.y), Pos2::new(x, rect.max.y)],
                    egui::Stroke::new(1.5, Color32::WHITE),
                );
                label(top_left, egui::Align2::LEFT_TOP, c.left.label());
                label(top_right, egui::Align2::RIGHT_TOP, c.right.label());
            }
            Compare::SideBySide => {
                label(top_left, egui::Align2::LEFT_TOP, c.left.label());
                let mid = Pos2::new(rect.center().x + 8.0, rect.min.y + 8.0);
                label(mid, egui::Align2::LEFT_TOP, c.right.label());
            }
            Compare::Difference => {
                label(
                    top_left,
                    egui::Align2::LEFT_TOP,
                    format!("|{} - {}|", c.left.label(), c.right.label()),
                );
                heat_scale_ui(painter, rect, c.diff_max);
            }
        }
    }
}

/// The divider's accessible name.
pub const DIVIDER_LABEL: &str = "Split divider";

/// The heatmap's scale bar along the bottom of `rect`: the ramp from 0 to `max`.
fn heat_scale_ui(painter: &egui::Painter, rect: Rect, max: f32) {
    let bar = Rect::from_min_size(
        Pos2::new(rect.min.x + 16.0, rect.max.y - 34.0),
        egui::vec2((rect.width() - 32.0).clamp(40.0, 320.0), 12.0),
    );
    let steps = 64;
    for i in 0..steps {
        let t0 = i as f32 / steps as f32;
        let c = crate::render::heat_ramp(t0 + 0.5 / steps as f32);
        let srgb = crate::model::texel::linear_to_srgb8;
        let x0 = bar.min.x + bar.width() * t0;
        painter.rect_filled(
            Rect::from_min_max(
                Pos2::new(x0, bar.min.y),
                Pos2::new(x0 + bar.width() / steps as f32 + 0.5, bar.max.y),
            ),
            0.0,
            Color32::from_rgb(srgb(c.x), srgb(c.y), srgb(c.z)),
        );
    }
    let font = egui::FontId::proportional(12.0);
    painter.text(
        Pos2::new(bar.min.x, bar.max.y + 2.0),
        egui::Align2::LEFT_TOP,
        "0",
        font.clone(),
        Color32::WHITE,
    );
    painter.text(
        Pos2::new(bar.max.x, bar.max.y + 2.0),
        egui::Align2::RIGHT_TOP,
        format!("{max:.3}"),
        font,
        Color32::WHITE,
    );
}
