//! The 3D viewport: the wgpu preview renderer drawing into a texture that egui shows, camera
//! controls, and picking for painting on the mesh. Without a GPU (tests, broken drivers) the
//! viewport still picks and paints; it only cannot draw.

pub(crate) mod overlay;
mod renderer;
pub(crate) mod traced;

pub use overlay::{DIVIDER_LABEL, N_LEGEND_LABEL};
pub use renderer::ViewportGpu;

use std::sync::Arc;

use egui::{Color32, Pos2, Rect, Sense};

use kapaint_core::render::{Camera, FrameSettings, ViewMode};
use kapaint_mesh::Mesh;
use kapaint_mesh::pick::{Bvh, Hit};
use kapaint_model::MaterialMaps;
use kapaint_reflectance::{AmbientApprox, ShadingModel};

/// The viewport's accessible name.
pub const VIEWPORT_LABEL: &str = "3D viewport painting area";

pub use kapaint_core::render::Compare;

/// What the viewport shows: the maps with their source id (a new id means new textures), and
/// the material's normal map.
pub type MapsIn<'a> = (
    &'a MaterialMaps,
    u64,
    Option<&'a Arc<kapaint_model::normal::NormalMap>>,
);

/// One side of a comparison: its shading model and approximation of `chi`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Side {
    /// Shading model.
    pub model: ShadingModel,
    /// Approximation of `chi`.
    pub approx: AmbientApprox,
    /// The side's own view (`k_a` on one side, `k_a` per view on the other, say); `None`
    /// shows the viewport's.
    pub view: Option<ViewMode>,
}

impl Side {
    /// The label drawn over this side of the viewport.
    pub fn label(self) -> String {
        // The paper printed no form for Cook-Torrance: there the method is always kapaint's fit.
        let approx = self.approx.for_model(self.model);
        let label = match self.model.paper_equation() {
            Some(eq) => format!("{} (eq. {eq}), {}", self.model.label(), approx.name()),
            None => format!("{}, {}", self.model.full_label(), approx.name()),
        };
        self.with_view(label)
    }

    /// `label` followed by the side's own view, if it has one.
    fn with_view(self, label: String) -> String {
        match self.view {
            Some(view) => format!("{label} · {}", view.label()),
            None => label,
        }
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

impl Comparison {
    /// The views the frame shows when the viewport's is `view` (each side may have its own).
    pub fn views(&self, view: ViewMode) -> Vec<ViewMode> {
        match self.mode {
            Compare::Single => vec![view],
            // The three models, each with the left side's method and view.
            Compare::ThreeWay => vec![self.left.view.unwrap_or(view)],
            Compare::Split | Compare::SideBySide | Compare::Difference => vec![
                self.left.view.unwrap_or(view),
                self.right.view.unwrap_or(view),
            ],
        }
    }
}

impl Default for Comparison {
    fn default() -> Self {
        Self {
            mode: Compare::Single,
            left: Side {
                model: ShadingModel::Phong,
                approx: AmbientApprox::Fast,
                view: None,
            },
            right: Side {
                model: ShadingModel::BlinnPhong,
                approx: AmbientApprox::Fast,
                view: None,
            },
            split_at: 0.5,
            diff_max: 0.1,
        }
    }
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
    /// How many pictures side by side the camera was last framed for.
    framed_columns: usize,
    /// The traced views' worker and picture.
    pub traced: traced::TracedView,
    /// The project's AO bake, for the AO stand-in's view (the editor sets it each frame).
    pub ao_bake: Option<Arc<kapaint_mesh::bakes::Baked>>,
    /// Set when the user asked for the untraced view instead of a trace that does not fit;
    /// the editor switches the view and clears it.
    pub untraced_requested: bool,
    /// A stencil on the screen the right button can take hold of (the editor sets it each
    /// frame): a right-drag that starts on it moves it instead of the camera.
    pub stencil: Option<Arc<kapaint_model::paint::Stencil>>,
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
            framed_columns: 1,
            traced: traced::TracedView::default(),
            ao_bake: None,
            untraced_requested: false,
            stencil: None,
        }
    }

    /// Whether the right button went down on the stencil (then its drag is the stencil's).
    pub fn stencil_held(&self, ctx: &egui::Context, rect: Rect) -> bool {
        let Some(stencil) = &self.stencil else {
            return false;
        };
        let origin = ctx.input(|i| {
            i.pointer
                .button_down(egui::PointerButton::Secondary)
                .then(|| i.pointer.press_origin())
                .flatten()
        });
        origin.is_some_and(|o| {
            let picture = self.picture_at(rect, o);
            let at = o - picture.min;
            crate::stencil_view::holds(stencil, glam::Vec2::new(at.x, at.y))
        })
    }

    /// Frames the mesh (F) at the next draw, when the viewport's aspect is known.
    pub fn frame(&mut self, _mesh: &Mesh) {
        self.frame_pending = true;
    }

    /// The picture under `pos`: the whole viewport, or the half (third) it is in when side by
    /// side (all three), laid out as the renderer's columns are.
    pub fn picture_at(&self, rect: Rect, pos: Pos2) -> Rect {
        let count = self.comparison.mode.columns();
        if count == 1 {
            return rect;
        }
        let width = rect.width() / count as f32;
        let column =
            (((pos.x - rect.min.x) / width.max(1.0)).floor().max(0.0) as usize).min(count - 1);
        let x = rect.min.x + (rect.width() - width) * column as f32 / (count - 1) as f32;
        Rect::from_min_size(Pos2::new(x, rect.min.y), egui::vec2(width, rect.height()))
    }

    /// Every picture in `rect`: the whole of it, or each one side by side.
    pub fn pictures(&self, rect: Rect) -> Vec<Rect> {
        let count = self.comparison.mode.columns();
        (0..count)
            .map(|k| {
                let x = rect.min.x + rect.width() * (k as f32 + 0.5) / count as f32;
                self.picture_at(rect, Pos2::new(x, rect.center().y))
            })
            .collect()
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
        maps: MapsIn<'_>,
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
        // Side by side halves (thirds) the pictures' width: frame again when it changes.
        if self.comparison.mode.columns() != self.framed_columns {
            self.frame_pending = true;
        }
        if self.frame_pending {
            // Fit the bounding sphere in the narrower of the two fields of view (of one half
            // when side by side).
            self.frame_pending = false;
            self.framed_columns = self.comparison.mode.columns();
            self.camera = self.camera.framing(&mesh.1.positions);
            let picture = self.picture_at(rect, rect.min);
            let aspect = picture.width() / picture.height().max(1.0);
            if aspect < 1.0 {
                self.camera.distance /= aspect.max(0.05);
            }
        }
        let (alt, shift) = ui.input(|i| (i.modifiers.alt, i.modifiers.shift));
        let delta = response.drag_delta();
        let right = response.dragged_by(egui::PointerButton::Secondary)
            && !self.stencil_held(ui.ctx(), rect);
        let middle = response.dragged_by(egui::PointerButton::Middle);
        let left = response.dragged_by(egui::PointerButton::Primary);
        // Shift + right drag turns the light (the editor reads it from the response).
        if middle {
            self.camera = self
                .camera
                .pan(delta.x / rect.height(), delta.y / rect.height());
        } else if (right && !shift) || (left && alt) {
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
            Some(gpu) => match gpu.render(maps, mesh, &frame, &self.comparison, size) {
                Ok(id) => {
                    self.frame_ms = gpu.draw_ms();
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
            },
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
        self.traced_frame(ui, (&painter, rect), (maps.0, maps.1), mesh, (&frame, size));
        self.labels_ui(&painter, rect);
        self.legends_ui(ui, &painter, rect, settings.view);
        (response, rect)
    }

    /// A traced view's picture and status over `rect` while one is shown (in the single
    /// view), its trace kept going; else the trace stopped.
    fn traced_frame(
        &mut self,
        ui: &mut egui::Ui,
        (painter, rect): (&egui::Painter, Rect),
        maps: (&MaterialMaps, u64),
        mesh: &(u64, Arc<Mesh>),
        (frame, size): (&FrameSettings, (u32, u32)),
    ) {
        if !(frame.view.is_traced() && self.comparison.mode == Compare::Single) {
            self.traced.stop();
            return;
        }
        let ao = self.ao_bake.clone();
        self.traced
            .update(ui.ctx(), maps, (mesh, ao.as_ref()), frame, size);
        self.traced.paint(painter, rect);
        if self.traced_ui(ui, painter, rect, frame.view) {
            self.untraced_requested = true;
        }
    }

    /// The scale of a false-colour or heatmap view the frame shows (the viewport's `view`, or
    /// a side's own).
    fn legends_ui(&self, ui: &egui::Ui, painter: &egui::Painter, rect: Rect, view: ViewMode) {
        let views = self.comparison.views(view);
        if self.comparison.mode == Compare::Difference {
            return;
        }
        if views.contains(&ViewMode::NFalseColour) {
            overlay::n_legend_ui(ui, painter, rect);
        } else if views.iter().any(|v| v.is_error_heatmap()) {
            overlay::view_error_legend_ui(ui, painter, rect);
        }
    }
}
