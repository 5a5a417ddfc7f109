//! The editor's dialogs: New (resolution, base preset, mesh), the recent files, and the
//! recovery offer after a crash, Preferences and the keyboard shortcut sheet (the export
//! dialog is [`crate::export_dialog`]).

use std::path::PathBuf;

use super::files::FilePurpose;
use super::jobs::new_document_with;
use super::panels::presets::PresetEntry;
use super::project_jobs::Project;
use crate::desk::{Ask, Desk, JobStart, centred};
use crate::keys;
use crate::preferences::{self, Preferences};
use kapaint_model::document::MeshRef;
use kapaint_model::{Document, DocumentSettings};

/// The New dialog's choices.
#[derive(Clone, Debug, PartialEq)]
pub struct NewDialog {
    /// Map width, texels.
    pub width: u32,
    /// Map height, texels.
    pub height: u32,
    /// Index into the material presets: the base material.
    pub preset: usize,
    /// A built-in mesh name, or a mesh file's path.
    pub mesh: String,
}

/// Map sizes the New dialog offers.
pub const NEW_SIZES: [u32; 5] = [512, 1024, 2048, 4096, 8192];

impl NewDialog {
    /// The New dialog's first choices: the document's size, its base preset (else the
    /// default preset), the sphere.
    pub(super) fn starting(doc: &Document, materials: &[PresetEntry]) -> Self {
        let preset = materials
            .iter()
            .position(|p| Some(&p.stem) == doc.settings().preset.as_ref())
            .or_else(|| materials.iter().position(|p| p.stem == "default"))
            .unwrap_or(0);
        Self {
            width: doc.maps().width(),
            height: doc.maps().height(),
            preset,
            mesh: "sphere".into(),
        }
    }

    /// The job replacing the document with a new one as the dialog says (the old one's
    /// unsaved changes are in its recovery copy and were asked about before).
    pub(super) fn create(&self, materials: &[PresetEntry]) -> JobStart {
        let mut settings = DocumentSettings {
            mesh: MeshRef::from_spec(&self.mesh),
            ..DocumentSettings::default()
        };
        if let Some(p) = materials.get(self.preset) {
            settings.base = p.value;
            settings.secondary = p.value;
            settings.preset = Some(p.stem.clone());
        }
        let size = (self.width, self.height);
        // Loading and baking the mesh at up to 8192^2 takes seconds: a worker does it.
        JobStart::new(
            "New",
            move |progress| {
                progress.start("bake", 1);
                match new_document_with(size, settings) {
                    Ok(doc) => Ok(Box::new(doc)),
                    Err(e) => Err(format!("new project: {e}")),
                }
            },
            crate::jobs::create_done,
        )
    }
}

/// The recovery offer at start, while `offer`ed: recover the copy, or discard it. Modal: until
/// it is answered the document is a placeholder, and a stroke on it would be autosaved over
/// the untitled recovery copy.
pub(super) fn recovery_window(
    offer: &mut Option<PathBuf>,
    project: &mut Project,
    ctx: &egui::Context,
    desk: &mut Desk,
) {
    let Some(copy) = offer.clone() else {
        return;
    };
    egui::Modal::new(egui::Id::new("kapaint-recovery-offer")).show(ctx, |ui| {
        ui.heading("Recover unsaved work?");
        ui.label(format!(
            "kapaint found a recovery copy of unsaved work:\n{}",
            copy.display()
        ));
        ui.horizontal(|ui| {
            // Recover is the default: Enter takes it.
            let enter = ui.input(|i| i.key_pressed(egui::Key::Enter));
            let recover = ui.button("Recover").on_hover_text("Enter");
            if recover.clicked() || enter {
                *offer = None;
                let path = project.starting.take().or_else(|| project.path.clone());
                desk.job(crate::project_jobs::recover(copy.clone(), path));
            }
            if ui.button("Discard").clicked() {
                *offer = None;
                kapaint_model::recovery::remove(&copy);
                // The project named at start opens as saved.
                if let Some(p) = project.starting.take() {
                    desk.ask(Ask::OpenNow(p));
                }
            }
        });
    });
}

/// The New dialog, while `open`: width and height, base preset, mesh; with unsaved changes
/// (`dirty`), save them first (the dialog waits in `pending` for the save) or discard them.
pub(super) fn new_window(
    (open, pending): (&mut Option<NewDialog>, &mut Option<NewDialog>),
    materials: &[PresetEntry],
    dirty: bool,
    ctx: &egui::Context,
    desk: &mut Desk,
) {
    let Some(mut dialog) = open.take() else {
        return;
    };
    let (mut shown, mut create, mut choose, mut save_first) = (true, false, false, false);
    centred(egui::Window::new("New project"), ctx)
        .open(&mut shown)
        .collapsible(false)
        .show(ctx, |ui| {
            ui.horizontal(|ui| {
                for (side, label) in [
                    (&mut dialog.width, "Width"),
                    (&mut dialog.height, "× Height"),
                ] {
                    egui::ComboBox::from_label(label)
                        .selected_text(side.to_string())
                        .show_ui(ui, |ui| {
                            for size in NEW_SIZES {
                                ui.selectable_value(side, size, size.to_string());
                            }
                        });
                }
            });
            egui::ComboBox::from_label("Base preset")
                .selected_text(materials.get(dialog.preset).map_or("", |p| p.name.as_str()))
                .show_ui(ui, |ui| {
                    for (i, p) in materials.iter().enumerate() {
                        ui.selectable_value(&mut dialog.preset, i, &p.name);
                    }
                });
            ui.horizontal(|ui| {
                egui::ComboBox::from_label("Mesh")
                    .selected_text(&dialog.mesh)
                    .show_ui(ui, |ui| {
                        for m in kapaint_mesh::BUILTIN_NAMES {
                            ui.selectable_value(&mut dialog.mesh, m.to_string(), m);
                        }
                    });
                if ui.button("File…").clicked() {
                    choose = true;
                }
            });
            let bytes = u64::from(dialog.width) * u64::from(dialog.height) * 14;
            ui.label(format!("Maps: {:.0} MB", bytes as f64 / 1e6));
            if dirty {
                ui.colored_label(
                    ui.visuals().warn_fg_color,
                    "The current project has unsaved changes.",
                );
                ui.horizontal(|ui| {
                    save_first = ui.button("Save, then create").clicked();
                    create = ui.button("Discard changes and create").clicked();
                });
            } else {
                create = ui.button("Create").clicked();
            }
        });
    if create {
        desk.job(dialog.create(materials));
    } else if save_first {
        // Created once the save is done (untitled work asks where first); a save that
        // fails or is cancelled creates nothing.
        *pending = Some(dialog);
        desk.ask(Ask::Save);
    } else if shown {
        *open = Some(dialog);
        if choose {
            desk.ask(Ask::ChooseFile(FilePurpose::NewMesh));
        }
    }
}

/// The Preferences window, while `open`: a change is asked for at once.
pub(super) fn preferences_window(
    open: &mut bool,
    now: Preferences,
    ctx: &egui::Context,
    desk: &mut Desk,
) {
    if !*open {
        return;
    }
    let mut p = now;
    centred(egui::Window::new("Preferences"), ctx)
        .open(open)
        .collapsible(false)
        .resizable(false)
        .show(ctx, |ui| {
            ui.add(
                egui::DragValue::new(&mut p.autosave_seconds)
                    .range(preferences::AUTOSAVE_MIN_SECONDS..=preferences::AUTOSAVE_MAX_SECONDS)
                    .suffix(" s")
                    .prefix("Autosave every "),
            )
            .on_hover_text(
                "How often a changed project's recovery copy is written: a crash loses at \
                 most this much work",
            );
        });
    if p != now {
        desk.ask(Ask::Preferences(p));
    }
}

/// Help > Keyboard shortcuts, while `open`: the keymap, as the input code reads it, and the
/// mouse.
pub(super) fn shortcuts_window(open: &mut bool, ctx: &egui::Context) {
    centred(egui::Window::new("Keyboard shortcuts"), ctx)
        .open(open)
        .collapsible(false)
        .show(ctx, |ui| {
            egui::Grid::new("keymap").striped(true).show(ui, |ui| {
                for b in keys::keymap() {
                    ui.label(keys::printed(ctx, &b.shortcut));
                    ui.label(b.description);
                    ui.end_row();
                }
                for (keys, what) in keys::MOUSE {
                    ui.label(*keys);
                    ui.label(*what);
                    ui.end_row();
                }
            });
        });
}
