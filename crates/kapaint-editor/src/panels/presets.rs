//! Presets of the artist's own: the material preset browser (thumbnails with their names,
//! the shipped presets and the user's), saving the primary material as a preset, and named
//! brush presets.

use std::path::Path;

use crate::desk::{Ask, Desk};
use crate::{Notices, notice};
use kapaint_model::SettingsCommand;
use kapaint_model::brush::preset::{self as brush_preset, BrushPreset};
use kapaint_model::texel::MaterialValue;

/// Material, brush and mask presets, shipped and the user's.
pub(crate) struct Presets {
    /// Material presets with their thumbnails (rendered a few per frame) and the mesh each
    /// thumbnail shows.
    pub(crate) materials: Vec<PresetEntry>,
    /// Brush presets.
    pub(crate) brushes: Vec<kapaint_model::brush::preset::BrushPreset>,
    /// Smart masks.
    pub(crate) masks: Vec<kapaint_model::generator::preset::MaskPreset>,
    /// The user preset folder presets are saved to.
    pub(crate) dir: Option<std::path::PathBuf>,
    /// A preset's name being typed, what it names, and whether its field opened this frame.
    pub(crate) naming: Option<(Naming, String, bool)>,
}

/// A material preset in the browser.
pub(crate) struct PresetEntry {
    /// The file stem: what a project names as its base preset.
    pub stem: String,
    /// The name shown under the thumbnail.
    pub name: String,
    /// The material.
    pub value: MaterialValue,
    /// The thumbnail, once drawn, and the mesh it shows.
    pub thumbnail: Option<super::super::Thumbnail>,
}

/// What a name is being typed for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Naming {
    /// The primary material, as a material preset.
    Material,
    /// The brush settings, as a brush preset.
    Brush,
    /// The selected layer's mask generator, as a smart mask.
    Mask,
}

/// The shipped material presets, then the user's (a malformed user file is a notice, not a
/// preset).
/// The material, brush and mask presets: shipped, then the user's in `dir`.
pub(crate) fn load_all(
    dir: Option<&Path>,
    notices: &mut crate::Notices,
) -> (
    Vec<PresetEntry>,
    Vec<BrushPreset>,
    Vec<kapaint_model::generator::preset::MaskPreset>,
) {
    (
        load_material_presets(dir, notices),
        load_brush_presets(dir, notices),
        load_mask_presets(dir, notices),
    )
}

pub(crate) fn load_material_presets(
    dir: Option<&Path>,
    notices: &mut crate::Notices,
) -> Vec<PresetEntry> {
    let entry = |stem: String, p: &kapaint_model::preset::MaterialPreset| PresetEntry {
        stem,
        name: p.name.clone(),
        value: p.value(),
        thumbnail: None,
    };
    let mut list: Vec<PresetEntry> = kapaint_model::preset::builtin()
        .iter()
        .map(|(stem, p)| entry(stem.clone(), p))
        .collect();
    if let Some(dir) = dir {
        for found in kapaint_model::preset::load_dir(dir) {
            match found {
                Ok((stem, p)) => {
                    // A user preset of a shipped preset's file name takes its place.
                    list.retain(|e| e.stem != stem);
                    list.push(entry(stem, &p));
                }
                Err(e) => notices.push(notice(format!("skipped {e}"), true)),
            }
        }
    }
    list
}

/// The shipped brush presets, then the user's.
pub(crate) fn load_brush_presets(
    dir: Option<&Path>,
    notices: &mut crate::Notices,
) -> Vec<BrushPreset> {
    let mut list = brush_preset::builtin();
    if let Some(dir) = dir {
        for found in brush_preset::load_dir(&dir.join("brushes")) {
            match found {
                Ok(p) => {
                    list.retain(|q| q.name != p.name);
                    list.push(p);
                }
                Err(e) => notices.push(notice(format!("skipped {e}"), true)),
            }
        }
    }
    list
}

impl Presets {
    /// Reads the presets again: the shipped ones, then the user's from the preset folder (a
    /// malformed file is a notice).
    pub(crate) fn reload(&mut self, notices: &mut Notices) {
        let dir = self.dir.clone();
        self.materials = load_material_presets(dir.as_deref(), notices);
        self.brushes = load_brush_presets(dir.as_deref(), notices);
        self.masks = load_mask_presets(dir.as_deref(), notices);
    }

    /// The material presets: thumbnails with their names (a click makes one the primary),
    /// and saving the primary as a preset of the user's.
    pub(super) fn materials_ui(
        &mut self,
        ui: &mut egui::Ui,
        desk: &mut Desk,
        mesh: u64,
        thumbnail: &mut dyn FnMut(MaterialValue) -> egui::ColorImage,
    ) {
        // A few thumbnails per frame keep the first frames fast.
        // A thumbnail of another mesh (before New, Open or a mesh import) is drawn again.
        let mut budget = 3;
        for i in 0..self.materials.len() {
            let stale = self.materials[i]
                .thumbnail
                .as_ref()
                .is_none_or(|(id, _)| *id != mesh);
            if stale && budget > 0 {
                budget -= 1;
                let image = thumbnail(self.materials[i].value);
                let texture = ui.ctx().load_texture(
                    format!("preset {}", self.materials[i].stem),
                    image,
                    egui::TextureOptions::LINEAR,
                );
                self.materials[i].thumbnail = Some((mesh, texture));
            }
        }
        if budget == 0 {
            ui.ctx().request_repaint();
        }
        self.naming_ui(ui, desk, Naming::Material, "Save primary as preset…");
        let mut chosen = None;
        // A few rows high, scrolled: the history below stays in view.
        egui::ScrollArea::vertical()
            .id_salt("material presets")
            .max_height(200.0)
            .show(ui, |ui| {
                ui.horizontal_wrapped(|ui| {
                    for p in &self.materials {
                        ui.allocate_ui(egui::vec2(58.0, 62.0), |ui| {
                            ui.vertical_centered(|ui| {
                                let response = match &p.thumbnail {
                                    Some((_, t)) => ui.add(egui::Button::image(
                                        egui::Image::from_texture(
                                            egui::load::SizedTexture::from_handle(t),
                                        )
                                        .fit_to_exact_size(egui::vec2(40.0, 40.0)),
                                    )),
                                    None => ui.add_sized([48.0, 48.0], egui::Button::new("…")),
                                };
                                let v = p.value;
                                if response
                                    .on_hover_text(format!(
                                        "{}: k_d {:.2} {:.2} {:.2}, k_s {:.2}, n {:.0}",
                                        p.name, v.kd.x, v.kd.y, v.kd.z, v.ks.x, v.n
                                    ))
                                    .clicked()
                                {
                                    chosen = Some(v);
                                }
                                ui.add(
                                    egui::Label::new(egui::RichText::new(&p.name).small())
                                        .truncate(),
                                );
                            });
                        });
                    }
                });
            });
        if let Some(v) = chosen {
            desk.command(SettingsCommand::SetPrimary(v));
        }
    }

    /// The brush presets: a choice applies one; the current settings can be saved as one.
    pub(super) fn brush_ui(&mut self, ui: &mut egui::Ui, desk: &mut Desk) {
        let current = &desk.doc.settings().brush;
        let shown = self
            .brushes
            .iter()
            .find(|p| p.brush == *current)
            .map_or("(custom)", |p| p.name.as_str())
            .to_string();
        let mut chosen = None;
        egui::ComboBox::from_label("Brush preset")
            .selected_text(shown)
            .show_ui(ui, |ui| {
                for p in &self.brushes {
                    if ui.selectable_label(p.brush == *current, &p.name).clicked() {
                        chosen = Some(p.brush.clone());
                    }
                }
            });
        if let Some(b) = chosen {
            desk.command(SettingsCommand::SetBrush(b));
        }
        self.naming_ui(ui, desk, Naming::Brush, "Save brush…");
    }

    /// A button that opens a name field, then saves what `kind` names under that name.
    pub(super) fn naming_ui(
        &mut self,
        ui: &mut egui::Ui,
        desk: &mut Desk,
        kind: Naming,
        button: &str,
    ) {
        match &mut self.naming {
            Some((k, name, just_opened)) if *k == kind => {
                let mut save = false;
                let mut cancel = false;
                ui.horizontal(|ui| {
                    let label = ui.label("Preset name");
                    let field = ui
                        .add(egui::TextEdit::singleline(name).desired_width(120.0))
                        .labelled_by(label.id);
                    if std::mem::take(just_opened) {
                        field.request_focus();
                    }
                    save = field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
                    save |= ui.button("Save").clicked();
                    cancel = ui.button("Cancel").clicked();
                });
                if save {
                    let name = name.clone();
                    self.save(desk, kind, &name);
                } else if cancel {
                    self.naming = None;
                }
            }
            _ => {
                if ui.button(button).clicked() {
                    self.naming = Some((kind, String::new(), true));
                }
            }
        }
    }

    /// Saves the primary material or the brush as the user's preset `name` (the naming row
    /// stays open on an error).
    fn save(&mut self, desk: &mut Desk, kind: Naming, name: &str) {
        let doc = desk.doc;
        let no_folder = || "there is no user preset folder (no HOME)".to_string();
        let saved = match kind {
            Naming::Material => self.dir.clone().ok_or_else(no_folder).and_then(|dir| {
                let value = doc.settings().primary;
                kapaint_model::preset::save_user(&dir, name, value)
                    .map_err(|e| e.to_string())
                    .map(|(stem, path)| {
                        self.materials.retain(|p| p.stem != stem);
                        self.materials.push(PresetEntry {
                            stem,
                            name: name.trim().to_string(),
                            value: value.sanitized(),
                            thumbnail: None,
                        });
                        path
                    })
            }),
            Naming::Brush => self
                .dir
                .as_ref()
                .map(|d| d.join("brushes"))
                .ok_or_else(no_folder)
                .and_then(|dir| {
                    let preset = BrushPreset {
                        name: name.trim().to_string(),
                        brush: doc.settings().brush.clone(),
                    };
                    let path = preset.save(&dir).map_err(|e| e.to_string())?;
                    self.brushes.retain(|p| p.name != preset.name);
                    self.brushes.push(preset);
                    Ok(path)
                }),
            Naming::Mask => self
                .dir
                .as_ref()
                .map(|d| d.join("masks"))
                .ok_or_else(no_folder)
                .and_then(|dir| {
                    let mask = doc
                        .selected_layer()
                        .and_then(|l| l.mask.as_ref())
                        .and_then(|m| m.generator())
                        .cloned()
                        .ok_or("the selected layer's mask is not made by a generator")?;
                    let preset = kapaint_model::generator::preset::MaskPreset {
                        name: name.trim().to_string(),
                        mask,
                    };
                    let path = preset.save(&dir).map_err(|e| e.to_string())?;
                    self.masks.retain(|p| p.name != preset.name);
                    self.masks.push(preset);
                    Ok(path)
                }),
        };
        match saved {
            Ok(path) => {
                self.naming = None;
                desk.ask(Ask::Notice(notice(
                    format!("Saved preset {:?} to {}", name.trim(), path.display()),
                    false,
                )));
            }
            Err(e) => desk.ask(Ask::Notice(notice(format!("preset not saved: {e}"), true))),
        }
    }
}

/// The shipped smart masks, then the user's from the `masks` folder of `dir` (a malformed file
/// is a notice).
pub(crate) fn load_mask_presets(
    dir: Option<&std::path::Path>,
    notices: &mut crate::Notices,
) -> Vec<kapaint_model::generator::preset::MaskPreset> {
    use kapaint_model::generator::preset;
    let mut list = preset::builtin();
    if let Some(dir) = dir {
        for found in preset::load_dir(&dir.join("masks")) {
            match found {
                Ok(p) => {
                    list.retain(|q| q.name != p.name);
                    list.push(p);
                }
                Err(e) => notices.push(crate::notice(format!("skipped {e}"), true)),
            }
        }
    }
    list
}
