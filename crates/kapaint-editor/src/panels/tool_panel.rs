//! The left panel: tools and their options, brush settings and stamp, material, channels.

use super::presets::Presets;
use crate::desk::{Ask, Desk};
use crate::files::FilePurpose;
use egui::Color32;
use kapaint_model::SettingsCommand;
use kapaint_reflectance as reflectance;
use kapaint_tools::{OptionChange, OptionWidget, ToolOption};

/// The tool panel's own state.
#[derive(Default)]
pub(crate) struct ToolPanel {
    /// How the brush's size is given: in texels, or on screen.
    pub(crate) brush_size: crate::screen_brush::BrushSize,
    /// The hex field's text while it is typed in (`None`: it shows the primary's `k_d`).
    pub(crate) hex_text: Option<String>,
    /// Materials laid last by a stroke, fill or gradient, newest first.
    pub(crate) recent_materials: Vec<kapaint_model::texel::MaterialValue>,
    /// The other model's exponent matching the primary's `n`, for the model and `n` (its
    /// bits) it was found for.
    pub(crate) equivalent_n: Option<((kapaint_reflectance::ShadingModel, u32), f64)>,
    /// The brush stamp's preview texture, and which stamp it shows.
    pub(crate) stamp_preview: Option<(u64, egui::TextureHandle)>,
}

impl ToolPanel {
    /// The active tool's options, drawn from what the tool says they are.
    fn tool_options_ui(ui: &mut egui::Ui, desk: &mut Desk) {
        for option in desk.tools.options(desk.doc) {
            if let OptionWidget::Image { path } = &option.widget {
                image_option_ui(ui, &option, path.as_deref(), desk);
            } else if let Some(value) = option_ui(ui, &option) {
                desk.ask(Ask::ToolOption(value));
            }
        }
    }

    /// Left panel: tools, brush, material, channels.
    pub(crate) fn ui(&mut self, ui: &mut egui::Ui, desk: &mut Desk, presets: &mut Presets) {
        let doc = desk.doc;
        ui.heading("Tools");
        let mut chosen = desk.tools.active();
        ui.horizontal_wrapped(|ui| {
            for tool in desk.tools.metas() {
                ui.selectable_value(&mut chosen, tool.kind, tool.label)
                    .on_hover_text(format!("{} ({})", tool.label, tool.key_help));
            }
        });
        if chosen != desk.tools.active() {
            desk.ask(Ask::SelectTool(chosen));
        }
        Self::tool_options_ui(ui, desk);
        if crate::stencil_view::paints_through(desk.tools.active()) {
            crate::stencil_view::panel_ui(ui, desk);
        }
        // The brush's settings with the tools that paint with the brush (not a decal's
        // placement, a fill, a gradient or the picker).
        if desk.tools.active_meta().cursor == kapaint_tools::ToolCursor::BrushOutline {
            self.brush_ui(ui, desk, presets);
        }
        ui.separator();
        ui.heading("Material");
        // The primary as the frame's commands leave it (a swap makes the secondary it).
        let mut before = doc.settings().primary;
        let mut primary = before;
        if self.colour_ui(ui, &mut primary, desk) {
            before = primary;
        }
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
            egui::Slider::new(&mut primary.n, 0.0..=kapaint_model::texel::N_MAX)
                .logarithmic(true)
                .text("n"),
        );
        let model = doc.settings().model;
        let other = reflectance::equivalent::counterpart(model);
        // A root search over the lobes' integrals (about 4 ms): made again only when the
        // exponent or the model changes, not every frame.
        let key = (model, primary.n.to_bits());
        let eq = match self.equivalent_n {
            Some((k, eq)) if k == key => eq,
            _ => {
                let eq = reflectance::equivalent::equivalent_exponent(model, f64::from(primary.n));
                self.equivalent_n = Some((key, eq));
                eq
            }
        };
        ui.label(format!(
            "≈ n {eq:.1} in {}",
            super::view_panel::model_label(other)
        ))
        .on_hover_text("The exponent of the other model with the closest highlight");
        if primary != before {
            desk.command(SettingsCommand::SetPrimary(primary));
        }
        if ui
            .button("Swap primary / secondary")
            .on_hover_text("X")
            .clicked()
        {
            desk.command(SettingsCommand::SwapMaterials);
        }
        self.recent_materials_ui(ui, desk);
        ui.separator();
        channels_ui(ui, desk);
    }

    /// The brush's settings: its preset, size, hardness, opacity, flow, spacing, jitter,
    /// pressure, stamp and the stroke's options.
    fn brush_ui(&mut self, ui: &mut egui::Ui, desk: &mut Desk, presets: &mut Presets) {
        let doc = desk.doc;
        ui.separator();
        ui.heading("Brush settings");
        presets.brush_ui(ui, desk);
        let mut brush = doc.settings().brush.clone();
        self.brush_size
            .radius_ui(ui, &mut brush, desk.texels_per_point);
        ui.add(egui::Slider::new(&mut brush.hardness, 0.0..=1.0).text("Hardness"))
            .on_hover_text("Shift+[ and Shift+] change the hardness");
        ui.add(egui::Slider::new(&mut brush.opacity, 0.0..=1.0).text("Opacity"));
        ui.add(egui::Slider::new(&mut brush.flow, 0.0..=1.0).text("Flow"));
        ui.add(egui::Slider::new(&mut brush.spacing_percent, 1.0..=200.0).text("Spacing %"));
        ui.add(egui::Slider::new(&mut brush.jitter, 0.0..=1.0).text("Jitter"));
        ui.checkbox(&mut brush.pressure_size, "Pressure: size");
        ui.checkbox(&mut brush.pressure_opacity, "Pressure: opacity");
        self.stamp_ui(ui, &mut brush, desk);
        stroke_options_ui(ui, &mut brush);
        if brush != doc.settings().brush {
            desk.command(SettingsCommand::SetBrush(brush));
        }
    }

    /// The brush's stamp row: a preview of the stamp, the built-in grain, loading one from an
    /// image, and back to the round dab.
    fn stamp_ui(
        &mut self,
        ui: &mut egui::Ui,
        brush: &mut kapaint_model::brush::BrushSettings,
        desk: &mut Desk,
    ) {
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
                brush.stamp = Some(kapaint_model::brush::Stamp::grain(64));
            }
            if ui
                .button("Load…")
                .on_hover_text("A stamp from an image (luminance times alpha)")
                .clicked()
            {
                desk.ask(Ask::ChooseFile(FilePurpose::StampImage));
            }
            if brush.stamp.is_some() && ui.button("Round").clicked() {
                brush.stamp = None;
            }
        });
    }
}

/// The channels tools paint.
fn channels_ui(ui: &mut egui::Ui, desk: &mut Desk) {
    ui.heading("Channels");
    let mut ch = desk.doc.settings().channels;
    ui.horizontal(|ui| {
        ui.checkbox(&mut ch.kd, "k_d");
        ui.checkbox(&mut ch.ks, "k_s");
        ui.checkbox(&mut ch.n, "n");
    });
    if ch != desk.doc.settings().channels {
        desk.command(SettingsCommand::SetChannels(ch));
    }
}

/// The stroke's options: blend mode, lazy mouse, mirrors, front faces only, energy guard.
fn stroke_options_ui(ui: &mut egui::Ui, brush: &mut kapaint_model::brush::BrushSettings) {
    use kapaint_model::brush::BlendMode;
    egui::ComboBox::from_label("Blend")
        .selected_text(blend_label(brush.blend))
        .show_ui(ui, |ui| {
            for mode in BlendMode::ALL {
                ui.selectable_value(&mut brush.blend, mode, blend_label(mode));
            }
        })
        .response
        .on_hover_text("How the material is laid over the map (n blends in log space)");
    ui.add(
        egui::Slider::new(&mut brush.smoothing_px, 0.0..=64.0)
            .text("Lazy mouse")
            .suffix(" px"),
    )
    .on_hover_text("The brush trails the pointer by this many texels: steadier lines (0: off)");
    ui.horizontal(|ui| {
        ui.label("Mirror");
        ui.checkbox(&mut brush.mirror_u, "U")
            .on_hover_text("Across the UV map's vertical centre line");
        ui.checkbox(&mut brush.mirror_v, "V")
            .on_hover_text("Across the UV map's horizontal centre line");
        ui.checkbox(&mut brush.mirror_x, "X")
            .on_hover_text("On the mesh, across its X = 0 plane");
        ui.checkbox(&mut brush.mirror_y, "Y")
            .on_hover_text("On the mesh, across its Y = 0 plane");
        ui.checkbox(&mut brush.mirror_z, "Z")
            .on_hover_text("On the mesh, across its Z = 0 plane");
    });
    ui.checkbox(&mut brush.front_faces_only, "Front faces only")
        .on_hover_text("On the mesh: paint only where the surface faces you, not through it");
    ui.checkbox(&mut brush.energy_guard, "Energy guard")
        .on_hover_text("Keep k_d + k_s at most 1 per colour channel while painting");
}

/// A blend mode's name in the panel.
fn blend_label(mode: kapaint_model::brush::BlendMode) -> &'static str {
    use kapaint_model::brush::BlendMode;
    match mode {
        BlendMode::Normal => "Normal",
        BlendMode::Add => "Add",
        BlendMode::Subtract => "Subtract",
        BlendMode::Multiply => "Multiply",
    }
}

/// One tool option's control; the change it was given this frame, if any.
fn option_ui(ui: &mut egui::Ui, option: &ToolOption) -> Option<OptionChange> {
    let (value, response) = match &option.widget {
        OptionWidget::Choice {
            choices,
            chosen,
            dropdown,
        } => {
            let mut picked = *chosen;
            let response = if *dropdown {
                let name = choices.get(*chosen).map_or("", |(n, _)| *n);
                egui::ComboBox::from_label(option.label)
                    .selected_text(name)
                    .show_ui(ui, |ui| {
                        for (i, (choice, _)) in choices.iter().enumerate() {
                            ui.selectable_value(&mut picked, i, *choice);
                        }
                    })
                    .response
            } else {
                ui.horizontal(|ui| {
                    if !option.label.is_empty() {
                        ui.label(option.label);
                    }
                    for (i, (choice, _)) in choices.iter().enumerate() {
                        ui.selectable_value(&mut picked, i, *choice);
                    }
                })
                .response
            };
            (
                choices
                    .get(picked)
                    .filter(|_| picked != *chosen)
                    .map(|(_, change)| change.clone()),
                response,
            )
        }
        &OptionWidget::Slider {
            value,
            min,
            max,
            integer,
            change,
        } => {
            let mut v = value;
            let slider = egui::Slider::new(&mut v, min..=max).text(option.label);
            let response = ui.add(if integer { slider.integer() } else { slider });
            ((v != value).then(|| change(v)), response)
        }
        // Drawn by `image_option_ui`, which asks for the file itself.
        OptionWidget::Image { .. } => return None,
    };
    if !option.hover.is_empty() {
        response.on_hover_text(option.hover);
    }
    value
}

/// An image option: the file's name and a button that chooses another (loaded on a worker,
/// then handed to the tool).
fn image_option_ui(
    ui: &mut egui::Ui,
    option: &ToolOption,
    path: Option<&std::path::Path>,
    desk: &mut Desk,
) {
    ui.horizontal(|ui| {
        ui.label(option.label);
        let name = path
            .and_then(|p| p.file_name())
            .map_or("none".into(), |n| n.to_string_lossy().into_owned());
        let label = ui.label(name);
        if let Some(p) = path {
            label.on_hover_text(p.display().to_string());
        }
        let choose = ui.button("Choose…");
        let choose = if option.hover.is_empty() {
            choose
        } else {
            choose.on_hover_text(option.hover)
        };
        if choose.clicked() {
            desk.ask(Ask::ChooseFile(FilePurpose::ToolImage));
        }
    });
}

/// A cheap identity of a stamp for its preview cache: size and a few samples' bits.
fn stamp_key(stamp: &kapaint_model::brush::Stamp) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    (stamp.width(), stamp.height()).hash(&mut h);
    let step = (stamp.alpha().len() / 61).max(1);
    for v in stamp.alpha().iter().step_by(step) {
        v.to_bits().hash(&mut h);
    }
    h.finish()
}

/// A `size`^2 grey picture of a stamp (white where it paints).
fn stamp_image(stamp: &kapaint_model::brush::Stamp, size: usize) -> egui::ColorImage {
    let mut pixels = Vec::with_capacity(size * size);
    for y in 0..size {
        for x in 0..size {
            let at = |i: usize| (i as f32 + 0.5) / size as f32 * 2.0 - 1.0;
            let a = stamp.sample(at(x), at(y));
            pixels.push(Color32::from_gray((a * 255.0 + 0.5) as u8));
        }
    }
    egui::ColorImage::new([size, size], pixels)
}
