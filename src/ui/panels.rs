//! The editor's panels: tools, brush and material on the left; shading, compare, view, light
//! and presets on the right; the menu bar, the status bar, dropped files and notices. Each
//! reads the state and issues [`Command`]s.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use super::canvas::CanvasChannel;
use super::keys::{self, Action};
use super::viewport::Compare;
use super::{EditorState, notice, stamp_image, stamp_key};
use crate::model::Command;
use crate::model::paint::GradientShape;
use crate::model::texel::{Channel, MaterialValue};
use crate::reflectance::{self, AmbientApprox, ShadingModel};
use crate::render::{FrameSettings, ViewMode};
use crate::tools::{FillMode, ToolKind};

/// The key that selects a tool.
fn tool_key(kind: ToolKind) -> &'static str {
    match kind {
        ToolKind::Brush => "B",
        ToolKind::Eraser => "E",
        ToolKind::Blur => "R",
        ToolKind::Fill => "F on the UV canvas",
        ToolKind::Gradient => "G",
        ToolKind::Picker => "I",
    }
}

impl EditorState {
    /// The active tool's options: the fill's mode, the gradient's shape.
    fn tool_options_ui(&mut self, ui: &mut egui::Ui) {
        match self.tools.active() {
            ToolKind::Fill => {
                let mode = &mut self.tools.fill.mode;
                let name = match mode {
                    FillMode::Island => "UV island (or all)",
                    FillMode::Similar { .. } => "Similar texels",
                    FillMode::All => "Whole map",
                };
                egui::ComboBox::from_label("Fill")
                    .selected_text(name)
                    .show_ui(ui, |ui| {
                        ui.selectable_value(mode, FillMode::Island, "UV island (or all)");
                        if ui
                            .selectable_label(
                                matches!(mode, FillMode::Similar { .. }),
                                "Similar texels",
                            )
                            .clicked()
                        {
                            *mode = FillMode::Similar {
                                channel: Channel::Kd,
                                tolerance: 0.05,
                            };
                        }
                        ui.selectable_value(mode, FillMode::All, "Whole map");
                    });
                if let FillMode::Similar { channel, tolerance } = mode {
                    egui::ComboBox::from_label("Compared channel")
                        .selected_text(channel.name())
                        .show_ui(ui, |ui| {
                            for c in Channel::ALL {
                                ui.selectable_value(channel, c, c.name());
                            }
                        });
                    ui.add(egui::Slider::new(tolerance, 0.0..=1.0).text("Tolerance"))
                        .on_hover_text("The largest difference still filled, in blend space");
                }
            }
            ToolKind::Gradient => {
                let shape = &mut self.tools.gradient.shape;
                ui.horizontal(|ui| {
                    ui.selectable_value(shape, GradientShape::Linear, "Linear");
                    ui.selectable_value(shape, GradientShape::Radial, "Radial");
                });
            }
            ToolKind::Blur => {
                let mut brush = self.doc.settings().brush.clone();
                ui.add(egui::Slider::new(&mut brush.blur_radius_px, 1..=16).text("Blur radius"))
                    .on_hover_text("Kernel radius in texels");
                if brush != self.doc.settings().brush {
                    self.apply(Command::SetBrush(brush));
                }
            }
            ToolKind::Brush | ToolKind::Eraser | ToolKind::Picker => {}
        }
    }

    /// Left panel: tools, brush, material, channels.
    pub(super) fn tools_ui(&mut self, ui: &mut egui::Ui) {
        ui.heading("Tools");
        let mut chosen = self.tools.active();
        ui.horizontal_wrapped(|ui| {
            for kind in ToolKind::ALL {
                ui.selectable_value(&mut chosen, kind, kind.label())
                    .on_hover_text(format!("{} ({})", kind.label(), tool_key(kind)));
            }
        });
        if chosen != self.tools.active() {
            self.select_tool(chosen);
        }
        self.tool_options_ui(ui);
        ui.separator();
        ui.heading("Brush settings");
        let mut brush = self.doc.settings().brush.clone();
        ui.add(
            egui::Slider::new(&mut brush.radius_px, 0.5..=512.0)
                .logarithmic(true)
                .text("Radius"),
        )
        .on_hover_text("[ and ] change the size");
        ui.add(egui::Slider::new(&mut brush.hardness, 0.0..=1.0).text("Hardness"))
            .on_hover_text("Shift+[ and Shift+] change the hardness");
        ui.add(egui::Slider::new(&mut brush.opacity, 0.0..=1.0).text("Opacity"));
        ui.add(egui::Slider::new(&mut brush.flow, 0.0..=1.0).text("Flow"));
        ui.add(egui::Slider::new(&mut brush.spacing_percent, 1.0..=200.0).text("Spacing %"));
        ui.add(egui::Slider::new(&mut brush.jitter, 0.0..=1.0).text("Jitter"));
        ui.checkbox(&mut brush.pressure_size, "Pressure: size");
        ui.checkbox(&mut brush.pressure_opacity, "Pressure: opacity");
        self.stamp_ui(ui, &mut brush);
        if brush != self.doc.settings().brush {
            self.apply(Command::SetBrush(brush));
        }
        ui.separator();
        ui.heading("Material");
        let mut primary = self.doc.settings().primary;
        ui.horizontal(|ui| {
            let mut kd = primary.kd.to_array();
            egui::color_picker::color_edit_button_rgb(ui, &mut kd)
                .on_hover_text("Diffuse colour k_d (linear)");
            ui.label("k_d");
            primary.kd = glam::Vec3::from(kd);
            let mut ks = primary.ks.to_array();
            egui::color_picker::color_edit_button_rgb(ui, &mut ks)
                .on_hover_text("Specular colour k_s (linear)");
            ui.label("k_s");
            primary.ks = glam::Vec3::from(ks);
        });
        let mut grey = primary.ks.max_element();
        if ui
            .add(egui::Slider::new(&mut grey, 0.0..=1.0).text("k_s (grey)"))
            .changed()
        {
            primary.ks = glam::Vec3::splat(grey);
        }
        ui.add(
            egui::Slider::new(&mut primary.n, 0.0..=crate::model::texel::N_MAX)
                .logarithmic(true)
                .text("n"),
        );
        let other = match self.doc.settings().model {
            ShadingModel::Phong => ShadingModel::BlinnPhong,
            ShadingModel::BlinnPhong => ShadingModel::Phong,
        };
        let eq = reflectance::equivalent::equivalent_exponent(
            self.doc.settings().model,
            f64::from(primary.n),
        );
        ui.label(format!("≈ n {eq:.1} in {}", other.name()))
            .on_hover_text("The exponent of the other model with the closest highlight");
        if primary != self.doc.settings().primary {
            self.apply(Command::SetPrimary(primary));
        }
        if ui
            .button("Swap primary / secondary")
            .on_hover_text("X")
            .clicked()
        {
            self.apply(Command::SwapMaterials);
        }
        ui.separator();
        ui.heading("Channels");
        let mut ch = self.doc.settings().channels;
        ui.horizontal(|ui| {
            ui.checkbox(&mut ch.kd, "k_d");
            ui.checkbox(&mut ch.ks, "k_s");
            ui.checkbox(&mut ch.n, "n");
        });
        if ch != self.doc.settings().channels {
            self.apply(Command::SetChannels(ch));
        }
    }

    /// Compare controls: the mode, then each side's model and approximation, the divider or
    /// the heatmap's scale.
    fn compare_ui(&mut self, ui: &mut egui::Ui) {
        ui.heading("Compare");
        let c = &mut self.viewport.comparison;
        ui.horizontal_wrapped(|ui| {
            for (mode, label) in Compare::ALL {
                ui.selectable_value(&mut c.mode, mode, label);
            }
        });
        if c.mode == Compare::Single {
            return;
        }
        for (name, side) in [("Left", &mut c.left), ("Right", &mut c.right)] {
            ui.horizontal(|ui| {
                egui::ComboBox::from_id_salt(("compare model", name))
                    .selected_text(side.model.name())
                    .show_ui(ui, |ui| {
                        for m in ShadingModel::ALL {
                            ui.selectable_value(&mut side.model, m, m.name());
                        }
                    });
                egui::ComboBox::from_id_salt(("compare approx", name))
                    .selected_text(side.approx.name())
                    .show_ui(ui, |ui| {
                        for a in AmbientApprox::ALL {
                            ui.selectable_value(&mut side.approx, a, a.name());
                        }
                    });
                ui.label(name);
            });
        }
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
            Compare::Single | Compare::SideBySide => {}
        }
    }

    /// Right panel: model, view, compare, light, canvas channel, history.
    pub(super) fn view_ui(&mut self, ui: &mut egui::Ui) {
        ui.heading("Shading");
        let mut model = self.doc.settings().model;
        ui.horizontal(|ui| {
            ui.selectable_value(&mut model, ShadingModel::Phong, "Phong (8)");
            ui.selectable_value(&mut model, ShadingModel::BlinnPhong, "Blinn-Phong (11)");
        });
        if model != self.doc.settings().model {
            self.apply(Command::SetModel(model));
        }
        let mut approx = self.doc.settings().approx;
        egui::ComboBox::from_label("Approximation")
            .selected_text(approx.name())
            .show_ui(ui, |ui| {
                for a in AmbientApprox::ALL {
                    ui.selectable_value(&mut approx, a, a.name());
                }
            });
        if approx != self.doc.settings().approx {
            self.apply(Command::SetApprox(approx));
        }
        self.compare_ui(ui);
        ui.heading("View");
        egui::ComboBox::from_label("View mode")
            .selected_text(self.view.name())
            .show_ui(ui, |ui| {
                for v in ViewMode::ALL {
                    ui.selectable_value(&mut self.view, v, v.name());
                }
            });
        egui::ComboBox::from_label("Canvas shows")
            .selected_text(self.canvas.channel.label())
            .show_ui(ui, |ui| {
                for c in CanvasChannel::ALL {
                    ui.selectable_value(&mut self.canvas.channel, c, c.label());
                }
            });
        ui.checkbox(&mut self.canvas.wireframe, "UV wireframe");
        ui.heading("Light");
        let l = self.lighting.light.normalize_or(glam::Vec3::Z);
        let (mut yaw, mut pitch) = (l.x.atan2(l.z), l.y.clamp(-1.0, 1.0).asin());
        let a = ui.add(
            egui::Slider::new(&mut yaw, -std::f32::consts::PI..=std::f32::consts::PI)
                .text("Light yaw"),
        );
        let b = ui.add(egui::Slider::new(&mut pitch, -1.55..=1.55).text("Light pitch"));
        if a.changed() || b.changed() {
            self.lighting.light = glam::Vec3::new(
                pitch.cos() * yaw.sin(),
                pitch.sin(),
                pitch.cos() * yaw.cos(),
            );
        }
        ui.add(egui::Slider::new(&mut self.lighting.ia, 0.0..=2.0).text("Ambient I_a"));
        ui.add(egui::Slider::new(&mut self.lighting.il, 0.0..=4.0).text("Light I_l"));
        egui::CollapsingHeader::new("Material presets")
            .default_open(true)
            .show(ui, |ui| self.presets_ui(ui));
        ui.heading("History");
        ui.label(format!(
            "{} steps, {:.1} MB",
            self.doc.history().undo_steps().count(),
            self.doc.history().bytes() as f64 / 1e6
        ));
        egui::ScrollArea::vertical()
            .max_height(160.0)
            .show(ui, |ui| {
                for step in self
                    .doc
                    .history()
                    .undo_steps()
                    .collect::<Vec<_>>()
                    .iter()
                    .rev()
                {
                    ui.label(format!("{} ({} KB)", step.label, step.bytes() / 1024));
                }
            });
    }

    /// Renders a thumbnail: on the GPU with the preview renderer, else with the CPU reference
    /// renderer (the same shading, ray traced).
    fn thumbnail(&mut self, value: MaterialValue) -> egui::ColorImage {
        const SIZE: u32 = 56;
        let camera = crate::render::Camera::default()
            .orbit(0.5, 0.35)
            .framing(&self.mesh.mesh.positions);
        let settings = FrameSettings {
            camera,
            view: ViewMode::Shaded,
            ..self.frame_settings()
        };
        let mesh = (self.mesh.id, Arc::clone(&self.mesh.mesh));
        if let Some(image) = self
            .viewport
            .gpu
            .as_mut()
            .and_then(|g| g.thumbnail(&mesh, value, &settings, SIZE))
        {
            return image;
        }
        let material = crate::render::reference::Material::Uniform(crate::render::Sample {
            kd: value.kd,
            ks: value.ks,
            n: value.n,
        });
        let pixels = crate::render::reference::render(
            &self.mesh.mesh,
            &self.mesh.bvh,
            &material,
            &settings,
            SIZE,
            SIZE,
        );
        let c = |x: f32| (crate::model::texel::linear_to_srgb(x.clamp(0.0, 1.0)) * 255.0) as u8;
        let rgba: Vec<u8> = pixels
            .iter()
            .flat_map(|p| [c(p.x), c(p.y), c(p.z), (p.w.clamp(0.0, 1.0) * 255.0) as u8])
            .collect();
        egui::ColorImage::from_rgba_unmultiplied([SIZE as usize; 2], &rgba)
    }

    /// The preset browser: thumbnails, a click makes the preset the primary material.
    fn presets_ui(&mut self, ui: &mut egui::Ui) {
        // A few thumbnails per frame keep the first frames fast.
        let mut budget = 3;
        for i in 0..self.presets.len() {
            if self.presets[i].2.is_none() && budget > 0 {
                budget -= 1;
                let image = self.thumbnail(self.presets[i].1);
                let name = self.presets[i].0.clone();
                self.presets[i].2 = Some(ui.ctx().load_texture(
                    name,
                    image,
                    egui::TextureOptions::LINEAR,
                ));
            }
        }
        if budget == 0 {
            ui.ctx().request_repaint();
        }
        let mut chosen = None;
        ui.horizontal_wrapped(|ui| {
            for (name, value, texture) in &self.presets {
                let response = match texture {
                    Some(t) => ui.add(egui::Button::image(
                        egui::Image::from_texture(egui::load::SizedTexture::from_handle(t))
                            .fit_to_exact_size(egui::vec2(40.0, 40.0)),
                    )),
                    None => ui.add_sized([48.0, 48.0], egui::Button::new("…")),
                };
                if response
                    .on_hover_text(format!(
                        "{name}: k_d {:.2} {:.2} {:.2}, k_s {:.2}, n {:.0}",
                        value.kd.x, value.kd.y, value.kd.z, value.ks.x, value.n
                    ))
                    .clicked()
                {
                    chosen = Some(*value);
                }
            }
        });
        if let Some(v) = chosen {
            self.apply(Command::SetPrimary(v));
        }
    }

    pub(super) fn status_bar_ui(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            let maps = self.doc.maps();
            ui.label(format!("{}x{}", maps.width(), maps.height()));
            ui.separator();
            ui.label(format!(
                "maps {:.0} MB, history {:.0} MB",
                maps.heap_bytes() as f64 / 1e6,
                self.doc.history().bytes() as f64 / 1e6
            ));
            ui.separator();
            match &self.viewport.gpu {
                Some(g) => ui.label(format!(
                    "frame {:.1} ms, viewport {:.1} ms ({})",
                    ui.input(|i| i.stable_dt) * 1000.0,
                    self.viewport.frame_ms,
                    g.adapter()
                )),
                None => ui.label("no GPU"),
            };
            if let Some((x, y)) = self.shown_hover {
                let v = maps.value(x, y);
                let ka = |m, a| reflectance::ka(m, a, v.kd, v.ks, v.n);
                let approx = self.doc.settings().approx;
                let phong = ka(ShadingModel::Phong, approx);
                let blinn = ka(ShadingModel::BlinnPhong, approx);
                let exact = |m| {
                    v.kd * reflectance::diffuse_factor(AmbientApprox::Fast) as f32
                        + v.ks
                            * reflectance::exact::chi_exact(m, f64::from(v.n)) as f32
                };
                let model = self.doc.settings().model;
                ui.separator();
                ui.label(format!(
                    "({x}, {y}) k_d {:.3} {:.3} {:.3}  k_s {:.3}  n {:.1}  k_a eq.8 {:.4}  eq.11 {:.4}  exact {:.4}",
                    v.kd.x, v.kd.y, v.kd.z, v.ks.x, v.n, phong.x, blinn.x, exact(model).x
                ))
                .on_hover_text("k_a of the red channel: Phong by eq. (8), Blinn-Phong by eq. (11), and the exact integral for the current model");
            }
            if let Some(job) = &self.job {
                ui.separator();
                ui.add(
                    egui::ProgressBar::new(job.progress.fraction())
                        .desired_width(160.0)
                        .text(format!("{} {}", job.label, job.progress.stage())),
                );
                if ui.button("Cancel").clicked() {
                    job.progress.cancel();
                }
            }
        });
    }

    pub(super) fn menu_ui(&mut self, ui: &mut egui::Ui) {
        // A menu entry showing its shortcut; whether it was clicked.
        let item = |ui: &mut egui::Ui, label: &str, action: Action| {
            let text =
                keys::shortcut(action).map_or_else(String::new, |k| ui.ctx().format_shortcut(&k));
            ui.add(egui::Button::new(label).shortcut_text(text))
                .clicked()
        };
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                if item(ui, "New", Action::New) {
                    self.new_project();
                }
                if item(ui, "Open…", Action::Open) {
                    self.open_dialog();
                }
                ui.menu_button("Open Recent", |ui| {
                    if self.recent.is_empty() {
                        ui.label("No recent files");
                    }
                    let mut chosen = None;
                    for p in &self.recent {
                        let name = p.file_name().map_or_else(
                            || p.display().to_string(),
                            |n| n.to_string_lossy().into_owned(),
                        );
                        if ui
                            .button(name)
                            .on_hover_text(p.display().to_string())
                            .clicked()
                        {
                            chosen = Some(p.clone());
                        }
                    }
                    if let Some(p) = chosen {
                        self.open(p);
                    }
                });
                if item(ui, "Save", Action::Save) {
                    self.save();
                }
                if item(ui, "Save As…", Action::SaveAs) {
                    self.save_as();
                }
                if item(ui, "Export…", Action::Export) {
                    self.open_export();
                }
                ui.separator();
                if ui.button("Import mesh…").clicked()
                    && let Some(p) = rfd::FileDialog::new()
                        .add_filter("mesh", &["obj", "gltf", "glb"])
                        .pick_file()
                {
                    self.import_mesh(p);
                }
                for channel in [Channel::Kd, Channel::Ks, Channel::N] {
                    if ui
                        .button(format!("Import image into {}…", channel.name()))
                        .clicked()
                        && let Some(p) = rfd::FileDialog::new()
                            .add_filter("image", &["png", "jpg", "jpeg", "tga", "exr"])
                            .pick_file()
                    {
                        self.import_image(p, channel);
                    }
                }
                ui.separator();
                if item(ui, "Quit", Action::Quit) {
                    self.quit_asked = true;
                }
            });
            ui.menu_button("Edit", |ui| {
                if item(ui, "Undo", Action::Undo) {
                    self.apply(Command::Undo);
                }
                if item(ui, "Redo", Action::Redo) {
                    self.apply(Command::Redo);
                }
            });
            ui.menu_button("Help", |ui| {
                if ui.button("Keyboard shortcuts").clicked() {
                    self.shortcuts_open = true;
                }
            });
        });
    }

    pub(super) fn dropped_files(&mut self, ctx: &egui::Context) {
        let files: Vec<PathBuf> = ctx.input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_path_buf())
                .collect()
        });
        for path in files {
            let ext = path
                .extension()
                .map(|e| e.to_string_lossy().to_lowercase())
                .unwrap_or_default();
            match ext.as_str() {
                "kapaint" => self.open(path),
                "obj" | "gltf" | "glb" => self.import_mesh(path),
                "png" | "jpg" | "jpeg" | "tga" | "exr" => {
                    let channel = self.canvas_target();
                    self.import_image(path, channel);
                }
                _ => self.notices.push(notice(
                    format!(
                        "{}: drop a project (.kapaint), a mesh (.obj, .gltf, .glb) or an image",
                        path.display()
                    ),
                    true,
                )),
            }
        }
    }

    pub(super) fn notices_ui(&mut self, ctx: &egui::Context) {
        self.notices
            .retain(|n| n.at.elapsed() < Duration::from_secs(if n.error { 12 } else { 5 }));
        if self.notices.is_empty() {
            return;
        }
        egui::Area::new(egui::Id::new("notices"))
            .anchor(egui::Align2::RIGHT_BOTTOM, egui::vec2(-12.0, -36.0))
            .show(ctx, |ui| {
                for n in &self.notices {
                    let colour = if n.error {
                        egui::Color32::from_rgb(220, 80, 80)
                    } else {
                        egui::Color32::from_rgb(120, 200, 120)
                    };
                    egui::Frame::popup(ui.style()).show(ui, |ui| {
                        ui.colored_label(colour, &n.text);
                    });
                }
            });
        ctx.request_repaint_after(Duration::from_millis(500));
    }

    /// The brush's stamp row: a preview of the stamp, the built-in grain, loading one from an
    /// image, and back to the round dab.
    fn stamp_ui(&mut self, ui: &mut egui::Ui, brush: &mut crate::model::brush::BrushSettings) {
        ui.horizontal(|ui| {
            ui.label("Stamp");
            match &brush.stamp {
                None => {
                    ui.label("round");
                }
                Some(stamp) => {
                    let key = stamp_key(stamp);
                    if self.stamp_preview.as_ref().is_none_or(|(k, _)| *k != key) {
                        let image = stamp_image(stamp, 32);
                        let texture = ui.ctx().load_texture(
                            "brush stamp",
                            image,
                            egui::TextureOptions::LINEAR,
                        );
                        self.stamp_preview = Some((key, texture));
                    }
                    if let Some((_, texture)) = &self.stamp_preview {
                        ui.image((texture.id(), egui::vec2(32.0, 32.0)))
                            .on_hover_text(format!("{}x{} stamp", stamp.width(), stamp.height()));
                    }
                }
            }
            if ui
                .button("Grain")
                .on_hover_text("A built-in grainy stamp")
                .clicked()
            {
                brush.stamp = Some(crate::model::brush::Stamp::grain(64));
            }
            if ui
                .button("Load…")
                .on_hover_text("A stamp from an image (luminance times alpha)")
                .clicked()
                && let Some(p) = rfd::FileDialog::new()
                    .add_filter("image", &["png", "jpg", "jpeg", "tga", "exr"])
                    .pick_file()
            {
                self.load_stamp(p);
            }
            if brush.stamp.is_some() && ui.button("Round").clicked() {
                brush.stamp = None;
            }
        });
    }
}
