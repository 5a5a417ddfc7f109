//! The right panel: shading, compare, view, light, material presets and history.

use std::sync::Arc;

use super::presets::Presets;
use crate::canvas::{Canvas, CanvasChannel};
use crate::desk::{Ask, Desk};
use crate::layer_view::LayerView;
use crate::viewport::{Compare, Comparison, ViewportGpu};
use crate::{Look, MeshState};
use kapaint_core::render::{FrameSettings, ViewMode};
use kapaint_model::texel::MaterialValue;
use kapaint_model::{HistoryCommand, SettingsCommand};
use kapaint_reflectance::{AmbientApprox, ShadingModel};

/// What the right panel changes of how the editor shows the document (none of it is the
/// document's: no undo step, not saved).
pub(crate) struct Shown<'a> {
    /// How the viewport shades and lights.
    pub(crate) look: &'a mut Look,
    /// What the viewport compares.
    pub(crate) comparison: &'a mut Comparison,
    /// The layer view chosen.
    pub(crate) layers: &'a mut LayerView,
    /// What the canvas shows.
    pub(crate) canvas: &'a mut Canvas,
}

impl Shown<'_> {
    /// Compare controls: the mode, then each side's model and approximation, the divider or
    /// the heatmap's scale.
    fn compare_ui(&mut self, ui: &mut egui::Ui) {
        ui.heading("Compare");
        let c = &mut *self.comparison;
        ui.horizontal_wrapped(|ui| {
            for (mode, label) in Compare::ALL {
                ui.selectable_value(&mut c.mode, mode, label);
            }
        });
        if c.mode == Compare::Single {
            return;
        }
        // One combo box a row, within the panel's width whatever the mode (the panel would
        // grow to fit a wider row, and the layout jump as the mode changes).
        egui::Grid::new("compare sides").show(ui, |ui| {
            for (name, side) in [("Left", &mut c.left), ("Right", &mut c.right)] {
                ui.label(name);
                egui::ComboBox::from_id_salt(("compare model", name))
                    .selected_text(model_label(side.model))
                    .width(COMBO_WIDTH)
                    .show_ui(ui, |ui| {
                        for m in ShadingModel::ALL {
                            ui.selectable_value(&mut side.model, m, model_label(m));
                        }
                    });
                ui.end_row();
                ui.label("");
                egui::ComboBox::from_id_salt(("compare approx", name))
                    .selected_text(side.approx.for_model(side.model).name())
                    .width(COMBO_WIDTH)
                    .show_ui(ui, |ui| {
                        for a in AmbientApprox::ALL {
                            ui.selectable_value(&mut side.approx, a, a.name());
                        }
                    });
                ui.end_row();
                ui.label("");
                egui::ComboBox::from_id_salt(("compare view", name))
                    .selected_text(side.view.map_or("viewport's view", ViewMode::label))
                    .width(COMBO_WIDTH)
                    .height(f32::INFINITY)
                    .show_ui(ui, |ui| {
                        ui.selectable_value(&mut side.view, None, "viewport's view");
                        for v in ViewMode::ALL {
                            ui.selectable_value(&mut side.view, Some(v), v.label());
                        }
                    })
                    .response
                    .on_hover_text(
                        "What this side shows: k_a on one side and k_a per view on the other, say",
                    );
                ui.end_row();
            }
        });
        match c.mode {
            Compare::Split => {
                ui.add(egui::Slider::new(&mut c.split_at, 0.0..=1.0).text("Divider"))
                    .on_hover_text("Or drag the line in the viewport");
            }
            Compare::Difference => {
                ui.add(
                    egui::Slider::new(&mut c.diff_max, 1e-4..=1.0)
                        .logarithmic(true)
                        .text("Heat scale"),
                )
                .on_hover_text("The difference |left - right| shown white");
            }
            Compare::ThreeWay => {
                ui.label("Phong, Blinn-Phong and Cook-Torrance, each with the left side's method");
            }
            Compare::Single | Compare::SideBySide => {}
        }
    }

    /// The light: yaw and pitch in degrees, following the camera, intensities.
    fn light_ui(&mut self, ui: &mut egui::Ui, desk: &mut Desk) {
        ui.heading("Light");
        // Shown and edited in degrees, as artists think of angles; kept as a direction.
        let (yaw, pitch) = self.look.lighting.angles();
        let (mut yaw, mut pitch) = (yaw.to_degrees(), pitch.to_degrees());
        let a = ui.add(degrees(&mut yaw, 180.0, "Light yaw"));
        let b = ui.add(degrees(&mut pitch, 89.0, "Light pitch"));
        if a.changed() || b.changed() {
            self.look
                .lighting
                .set_angles(yaw.to_radians(), pitch.to_radians());
        }
        let mut follow = self.look.light_follows_camera;
        if ui
            .checkbox(&mut follow, "Light follows camera")
            .on_hover_text(
                "Keep the light where it is relative to the view while orbiting \
                 (yaw and pitch are then relative to the camera); Shift + right drag turns it",
            )
            .changed()
        {
            desk.ask(Ask::LightFollowsCamera(follow));
        }
        ui.add(egui::Slider::new(&mut self.look.lighting.ia, 0.0..=2.0).text("Ambient I_a"));
        ui.add(egui::Slider::new(&mut self.look.lighting.il, 0.0..=4.0).text("Light I_l"));
    }

    /// Right panel: model, view, compare, light, canvas channel, material presets (with their
    /// thumbnails, drawn by `thumbnail` on mesh `mesh`), history.
    pub(crate) fn ui(
        &mut self,
        ui: &mut egui::Ui,
        desk: &mut Desk,
        presets: &mut Presets,
        (mesh, thumbnail): (u64, &mut dyn FnMut(MaterialValue) -> egui::ColorImage),
    ) {
        let doc = desk.doc;
        ui.heading("Shading");
        let mut model = doc.settings().model;
        // The paper's models on one row, the others below: rows of fixed content keep the
        // panel's width the same from the first frame on.
        let (paper, others): (Vec<_>, Vec<_>) = ShadingModel::ALL
            .into_iter()
            .partition(|m| m.has_paper_forms());
        for row in [paper, others] {
            ui.horizontal(|ui| {
                for m in row {
                    ui.selectable_value(&mut model, m, model_label(m));
                }
            });
        }
        if model != doc.settings().model {
            desk.command(SettingsCommand::SetModel(model));
        }
        let mut approx = doc.settings().approx;
        ui.add_enabled_ui(model.has_paper_forms(), |ui| {
            egui::ComboBox::from_label("Approximation")
                .selected_text(approx.for_model(model).name())
                .show_ui(ui, |ui| {
                    for a in AmbientApprox::ALL {
                        ui.selectable_value(&mut approx, a, a.name());
                    }
                });
        })
        .response
        .on_disabled_hover_text(
            "The paper printed no approximation for Cook-Torrance: its k_a always uses \
             kapaint's fit (within 2e-5 of the exact integral)",
        );
        if approx != doc.settings().approx {
            desk.command(SettingsCommand::SetApprox(approx));
        }
        self.compare_ui(ui);
        ui.heading("View");
        egui::ComboBox::from_label("View mode")
            .selected_text(self.look.mode.label())
            .width(COMBO_WIDTH)
            // Every view in sight at once, no scrolling to the last ones.
            .height(f32::INFINITY)
            .show_ui(ui, |ui| {
                for v in ViewMode::ALL {
                    ui.selectable_value(&mut self.look.mode, v, v.label());
                }
            });
        egui::ComboBox::from_label("Layers shown")
            .selected_text(self.layers.label())
            .width(COMBO_WIDTH)
            .show_ui(ui, |ui| {
                for v in LayerView::ALL {
                    ui.selectable_value(&mut *self.layers, v, v.label());
                }
            })
            .response
            .on_hover_text("The selected layer alone over the base, or its mask in grey");
        egui::ComboBox::from_label("Canvas shows")
            .selected_text(self.canvas.channel.label())
            .show_ui(ui, |ui| {
                for c in CanvasChannel::ALL {
                    ui.selectable_value(&mut self.canvas.channel, c, c.label());
                }
                for b in doc.bakes() {
                    let c = CanvasChannel::Bake(b.map);
                    ui.selectable_value(&mut self.canvas.channel, c, c.label());
                }
            });
        ui.checkbox(&mut self.canvas.wireframe, "UV wireframe");
        self.light_ui(ui, desk);
        egui::CollapsingHeader::new("Material presets")
            .default_open(true)
            .show(ui, |ui| presets.materials_ui(ui, desk, mesh, thumbnail));
        ui.heading("History");
        ui.label(history_summary(
            doc.history().undo_steps().count(),
            doc.history().bytes(),
        ));
        history_list_ui(ui, desk);
    }
}

/// The steps, oldest first: a click jumps to the state after a step (undone steps stay
/// listed, greyed, until a new edit drops them); "Original" is the state before them.
fn history_list_ui(ui: &mut egui::Ui, desk: &mut Desk) {
    let history = desk.doc.history();
    let applied = history.undo_steps().count();
    let mut jump = None;
    egui::ScrollArea::vertical()
        .id_salt("history")
        .max_height(160.0)
        .stick_to_bottom(true)
        .show(ui, |ui| {
            if ui
                .selectable_label(applied == 0, "Original")
                .on_hover_text("Before the oldest step kept")
                .clicked()
            {
                jump = Some(0);
            }
            for (i, step) in history.undo_steps().chain(history.redo_steps()).enumerate() {
                let text = format!("{}. {} · {} KB", i + 1, step.label, step.bytes() / 1024);
                let text = if i < applied {
                    egui::RichText::new(text)
                } else {
                    egui::RichText::new(text).weak().italics()
                };
                let response = ui.selectable_label(i + 1 == applied, text);
                let response = if i < applied {
                    response
                } else {
                    response.on_hover_text("Undone: a click redoes up to here")
                };
                if response.clicked() {
                    jump = Some(i + 1);
                }
            }
        });
    if let Some(n) = jump {
        desk.command(HistoryCommand::HistoryJump(n));
    }
}

/// Renders a material preset's thumbnail on `mesh`, lit as `frame`: on the GPU with the
/// preview renderer, else with the CPU reference renderer (the same shading, ray traced).
pub(crate) fn thumbnail(
    gpu: Option<&mut ViewportGpu>,
    mesh: &MeshState,
    frame: FrameSettings,
    value: MaterialValue,
) -> egui::ColorImage {
    const SIZE: u32 = 56;
    let camera = kapaint_core::render::Camera::default()
        .orbit(0.5, 0.35)
        .framing(&mesh.mesh.positions);
    let settings = FrameSettings {
        camera,
        view: ViewMode::Shaded,
        ..frame
    };
    let shown = (mesh.id, Arc::clone(&mesh.mesh));
    if let Some(image) = gpu.and_then(|g| g.thumbnail(&shown, value, &settings, SIZE)) {
        return image;
    }
    let material =
        kapaint_core::render::reference::Material::Uniform(kapaint_core::render::Sample {
            kd: value.kd,
            ks: value.ks,
            n: value.n,
        });
    let pixels = kapaint_core::render::reference::render(
        &mesh.mesh, &mesh.bvh, &material, &settings, SIZE, SIZE,
    );
    let c = |x: f32| (kapaint_model::texel::linear_to_srgb(x.clamp(0.0, 1.0)) * 255.0) as u8;
    let rgba: Vec<u8> = pixels
        .iter()
        .flat_map(|p| [c(p.x), c(p.y), c(p.z), (p.w.clamp(0.0, 1.0) * 255.0) as u8])
        .collect();
    egui::ColorImage::from_rgba_unmultiplied([SIZE as usize; 2], &rgba)
}

/// The width of the right panel's drop-down menus: wide enough for the longest entry
/// ("n false colour", "Blinn-Phong (11)").
const COMBO_WIDTH: f32 = 130.0;

/// A shading model as the editor names it: with the paper's equation of its `k_a`.
pub(crate) fn model_label(model: ShadingModel) -> String {
    match model.paper_equation() {
        Some(eq) => format!("{} ({eq})", model.label()),
        None => model.label().to_owned(),
    }
}

/// The history's size: "1 step, 0.2 MB", "3 steps, 1.5 MB" (the status bar shows the same
/// memory figure).
pub(crate) fn history_summary(steps: usize, bytes: usize) -> String {
    let noun = if steps == 1 { "step" } else { "steps" };
    format!("{steps} {noun}, {}", megabytes(bytes))
}

/// Bytes as megabytes with one decimal, as the panel and the status bar both show them.
pub(crate) fn megabytes(bytes: usize) -> String {
    format!("{:.1} MB", bytes as f64 / 1e6)
}

/// A slider of an angle in degrees within `±limit`, shown to 0.1 degree but not rounded (a
/// rounding slider would change the value every frame it is drawn).
fn degrees<'a>(value: &'a mut f32, limit: f32, text: &str) -> egui::Slider<'a> {
    egui::Slider::new(value, -limit..=limit)
        .suffix("°")
        .custom_formatter(|v, _| format!("{v:.1}"))
        .clamping(egui::SliderClamping::Never)
        .text(text)
}
