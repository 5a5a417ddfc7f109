//! The editor's dialogs and prompts: New (resolution, base preset, mesh), the recent files,
//! the export dialog with its preview of the set, and the prompts that keep unsaved work
//! (before opening another project, before closing, recovery after a crash).

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

use super::EditorState;
use super::export_plan::{block_search_ui, export_plan_ui};
use super::files::FilePurpose;
use super::jobs::new_document_with;
use super::layout::layout_path;
use kapaint_export::preset::ExportPreset;
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

/// How many recent files are kept.
pub const RECENT_MAX: usize = 10;

/// `list` with `path` moved to the front, without duplicates, at most [`RECENT_MAX`] long.
pub fn push_recent(list: &mut Vec<PathBuf>, path: &Path) {
    let path = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
    list.retain(|p| *p != path);
    list.insert(0, path);
    list.truncate(RECENT_MAX);
}

pub(super) fn recent_path() -> Option<PathBuf> {
    layout_path().map(|p| p.with_file_name("recent.json"))
}

pub(super) fn load_recent() -> Vec<PathBuf> {
    recent_path()
        .and_then(|p| kapaint_base::file_check::read_limited(&p, 1 << 20).ok())
        .map(|text| parse_recent(&text))
        .unwrap_or_default()
}

/// The recent-files list from its JSON: at most [`RECENT_MAX`] entries, each a path of at
/// most 4096 bytes without control characters (anything else is dropped, a list that does
/// not parse is empty).
pub fn parse_recent(json: &[u8]) -> Vec<PathBuf> {
    let Ok(list) = serde_json::from_slice::<Vec<String>>(json) else {
        return Vec::new();
    };
    list.into_iter()
        .filter(|p| {
            !p.is_empty()
                && kapaint_model::check::bounded_text(
                    "path",
                    p,
                    kapaint_model::check::MAX_PATH_BYTES,
                )
                .is_ok()
        })
        .take(RECENT_MAX)
        .map(PathBuf::from)
        .collect()
}

pub(super) fn save_recent(list: &[PathBuf]) {
    if let (Some(path), Ok(json)) = (recent_path(), serde_json::to_vec_pretty(list)) {
        if let Some(dir) = path.parent() {
            let _ = std::fs::create_dir_all(dir);
        }
        let _ = kapaint_base::atomic::write_atomic(&path, &json);
    }
}

/// The export dialog's state.
pub(super) struct ExportDialog {
    presets: Vec<ExportPreset>,
    chosen: usize,
    folder: String,
    /// The folder holds a set: asking whether to replace it.
    confirm_replace: bool,
    /// Why the folder cannot take the set, shown in the dialog.
    problem: Option<String>,
    /// The preview of the chosen preset: for which preset and maps version, and the plan.
    plan: Option<(usize, u64, kapaint_export::set::SetPlan)>,
    /// A preview being computed on a worker thread.
    planning: Option<(usize, u64, JoinHandle<kapaint_export::set::SetPlan>)>,
    /// With a glTF PBR preset: also write the mesh with the material as a `.glb`.
    glb: bool,
}

impl ExportDialog {
    /// The folder the set goes to, as typed or chosen.
    pub(super) fn folder(&self) -> &str {
        &self.folder
    }

    /// Exports into the chosen `dir` where it is empty or a set already (replaced after a
    /// prompt), else into a new `set` folder inside it.
    pub(super) fn choose_folder(&mut self, dir: &Path) {
        let kind = kapaint_export::set::SetKind::of(&self.presets[self.chosen]);
        self.folder = export_folder_in(dir, kind).display().to_string();
        (self.confirm_replace, self.problem) = (false, None);
    }
}

impl EditorState {
    /// The recovery offer at start: recover the copy, or discard it. Modal: until it is
    /// answered the document is a placeholder, and a stroke on it would be autosaved over the
    /// untitled recovery copy.
    pub(super) fn recovery_window(&mut self, ctx: &egui::Context) {
        let Some(copy) = self.prompts.recovery_offer.clone() else {
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
                    self.prompts.recovery_offer = None;
                    let path = self
                        .project
                        .starting
                        .take()
                        .or_else(|| self.project.path.clone());
                    self.recover(copy.clone(), path);
                }
                if ui.button("Discard").clicked() {
                    self.prompts.recovery_offer = None;
                    kapaint_model::recovery::remove(&copy);
                    // The project named at start opens as saved.
                    if let Some(p) = self.project.starting.take() {
                        self.open_now(p);
                    }
                }
            });
        });
    }

    /// Opens the New dialog (Ctrl+N), starting from the current document's size.
    pub(super) fn new_project(&mut self) {
        let preset = self
            .presets
            .materials
            .iter()
            .position(|p| Some(&p.stem) == self.doc.settings().preset.as_ref())
            .or_else(|| {
                self.presets
                    .materials
                    .iter()
                    .position(|p| p.stem == "default")
            })
            .unwrap_or(0);
        self.dialogs.new = Some(NewDialog {
            width: self.doc.maps().width(),
            height: self.doc.maps().height(),
            preset,
            mesh: "sphere".into(),
        });
    }

    /// Replaces the document with a new one as `dialog` says (the old one's unsaved changes
    /// are in its recovery copy and were asked about before).
    pub fn create_project(&mut self, dialog: &NewDialog) {
        let mut settings = DocumentSettings {
            mesh: MeshRef::from_spec(&dialog.mesh),
            ..DocumentSettings::default()
        };
        if let Some(p) = self.presets.materials.get(dialog.preset) {
            settings.base = p.value;
            settings.secondary = p.value;
            settings.preset = Some(p.stem.clone());
        }
        let size = (dialog.width, dialog.height);
        // Loading and baking the mesh at up to 8192^2 takes seconds: a worker does it.
        self.start_job(
            "New",
            move |progress| {
                progress.start("bake", 1);
                match new_document_with(size, settings) {
                    Ok(doc) => Ok(Box::new(doc)),
                    Err(e) => Err(format!("new project: {e}")),
                }
            },
            Self::create_done,
        );
    }

    /// The New dialog: width and height, base preset, mesh; with unsaved changes, save them
    /// first or discard them.
    pub(super) fn new_window(&mut self, ctx: &egui::Context) {
        let Some(mut dialog) = self.dialogs.new.take() else {
            return;
        };
        let (mut open, mut create, mut choose, mut save_first) = (true, false, false, false);
        centred(egui::Window::new("New project"), ctx)
            .open(&mut open)
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
                    .selected_text(
                        self.presets
                            .materials
                            .get(dialog.preset)
                            .map_or("", |p| p.name.as_str()),
                    )
                    .show_ui(ui, |ui| {
                        for (i, p) in self.presets.materials.iter().enumerate() {
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
                if self.dirty() {
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
            self.create_project(&dialog);
        } else if save_first {
            // Created once the save is done (untitled work asks where first); a save that
            // fails or is cancelled creates nothing.
            self.dialogs.pending_new = Some(dialog);
            self.save();
        } else if open {
            self.dialogs.new = Some(dialog);
            if choose {
                self.choose_file(FilePurpose::NewMesh);
            }
        }
    }

    /// Remembers `path` at the top of the recent files.
    pub(super) fn remember(&mut self, path: &Path) {
        push_recent(&mut self.project.recent, path);
        save_recent(&self.project.recent);
    }

    /// Starts the export on a worker (replacing the set at the folder where `replace`); the
    /// dialog's choices are kept for the next export.
    pub(super) fn export_now(&mut self, replace: bool) {
        let Some(dialog) = &self.dialogs.export else {
            return;
        };
        let Some(preset) = dialog.presets.get(dialog.chosen).cloned() else {
            return;
        };
        let out = PathBuf::from(dialog.folder.trim());
        self.dialogs.export_choice = Some((preset.name.clone(), dialog.folder.clone()));
        let pbr = preset.format.is_gltf_pbr();
        let mesh = self
            .doc
            .surface()
            .filter(|_| pbr && dialog.glb)
            .map(Arc::clone);
        let snapshot = self.snapshot();
        self.dialogs.export = None;
        self.start_job(
            "Export",
            move |progress| {
                let glb = mesh.as_ref().map(|s| &s.mesh);
                let gpu = kapaint_gpu::blocks::for_export(&preset);
                match kapaint_export::run(&snapshot, &preset, &out, progress, replace, glb, gpu) {
                    Ok(m) => Ok((out, Box::new(m))),
                    Err(e) => Err(format!("export failed: {e}")),
                }
            },
            Self::export_done,
        );
    }

    pub(super) fn open_export(&mut self) {
        let presets = kapaint_export::preset::builtin();
        // The last export's choices, else the project's name and the first preset.
        let (chosen, folder) = match &self.dialogs.export_choice {
            Some((name, folder)) => (
                presets.iter().position(|p| &p.name == name).unwrap_or(0),
                folder.clone(),
            ),
            None => (
                0,
                self.project.path.as_ref().map_or_else(
                    || "export".to_string(),
                    |p| p.with_extension("").display().to_string() + "-set",
                ),
            ),
        };
        self.dialogs.export = Some(ExportDialog {
            presets,
            chosen,
            folder,
            confirm_replace: false,
            problem: None,
            plan: None,
            planning: None,
            glb: false,
        });
    }

    /// A copy of the document for a worker thread (the maps' tiles are shared, not copied).
    pub(super) fn snapshot(&self) -> Document {
        self.doc.snapshot()
    }

    /// Keeps the export dialog's preview current: starts planning on a worker thread when the
    /// preset or the maps changed, and takes the result when it is done.
    pub(super) fn update_export_plan(&mut self, ctx: &egui::Context) {
        let version = self.doc.maps().version();
        let snapshot = self.dialogs.export.as_ref().and_then(|d| {
            let current = |(p, v): (usize, u64)| p == d.chosen && v == version;
            let planned = d.plan.as_ref().is_some_and(|(p, v, _)| current((*p, *v)));
            // One plan at a time: a stale one finishes first, then the current one starts.
            (!planned && d.planning.is_none()).then(|| self.snapshot())
        });
        let Some(dialog) = &mut self.dialogs.export else {
            return;
        };
        if let Some(doc) = snapshot
            && let Some(preset) = dialog.presets.get(dialog.chosen).cloned()
        {
            let spawned = std::thread::Builder::new()
                .name("kapaint export preview".into())
                .spawn(move || kapaint_export::set::plan(&doc, &preset));
            if let Ok(handle) = spawned {
                dialog.planning = Some((dialog.chosen, version, handle));
            }
        }
        if dialog
            .planning
            .as_ref()
            .is_some_and(|(_, _, h)| h.is_finished())
            && let Some((p, v, handle)) = dialog.planning.take()
            && let Ok(plan) = handle.join()
        {
            dialog.plan = Some((p, v, plan));
        }
        if dialog.planning.is_some() {
            ctx.request_repaint_after(Duration::from_millis(50));
        }
    }

    pub(super) fn export_window(&mut self, ctx: &egui::Context) {
        self.update_export_plan(ctx);
        let has_mesh = self.doc.surface().is_some();
        let Some(dialog) = &mut self.dialogs.export else {
            return;
        };
        let mut open = true;
        let (mut go, mut replace, mut choose) = (false, false, false);
        centred(egui::Window::new("Export"), ctx)
            .open(&mut open)
            .collapsible(false)
            .show(ctx, |ui| {
                egui::ComboBox::from_label("Preset")
                    .selected_text(
                        dialog
                            .presets
                            .get(dialog.chosen)
                            .map_or("", |p| p.name.as_str()),
                    )
                    .show_ui(ui, |ui| {
                        for (i, p) in dialog.presets.iter().enumerate() {
                            ui.selectable_value(&mut dialog.chosen, i, &p.name)
                                .on_hover_text(&p.description);
                        }
                    });
                if let Some(p) = dialog.presets.get(dialog.chosen) {
                    ui.label(&p.description);
                }
                ui.separator();
                let pbr = dialog
                    .presets
                    .get(dialog.chosen)
                    .is_some_and(|p| p.format.is_gltf_pbr());
                ui.horizontal(|ui| {
                    ui.label("Folder");
                    // A fixed id: the measurement arriving must not take the keyboard from a
                    // folder being typed.
                    let field =
                        egui::TextEdit::singleline(&mut dialog.folder).id_salt("export folder");
                    if ui.add(field).changed() {
                        (dialog.confirm_replace, dialog.problem) = (false, None);
                    }
                    if ui.button("…").clicked() {
                        choose = true;
                    }
                });
                if pbr {
                    ui.add_enabled(
                        has_mesh,
                        egui::Checkbox::new(
                            &mut dialog.glb,
                            "Also write model.glb (the mesh with this material)",
                        ),
                    )
                    .on_disabled_hover_text("The project's mesh is not loaded.");
                }
                if let Some(problem) = &dialog.problem {
                    ui.colored_label(ui.visuals().error_fg_color, problem);
                }
                if dialog.confirm_replace {
                    ui.label(format!(
                        "{} holds an exported set already. Replace it?",
                        dialog.folder.trim()
                    ));
                    ui.horizontal(|ui| {
                        replace = ui.button("Replace").clicked();
                        if ui.button("Cancel").clicked() {
                            dialog.confirm_replace = false;
                        }
                    });
                } else {
                    go = ui.button("Export").clicked();
                }
                // The measured set below what is clicked: it arrives from a worker, and a
                // window growing above the controls would move them from under the pointer.
                ui.separator();
                match &dialog.plan {
                    Some((p, _, plan)) if *p == dialog.chosen => {
                        export_plan_ui(ui, plan, pbr);
                        if let Some(preset) = dialog.presets.get(dialog.chosen) {
                            block_search_ui(ui, preset);
                        }
                    }
                    _ => {
                        ui.horizontal(|ui| {
                            ui.spinner();
                            ui.label("Measuring the set…");
                        });
                    }
                }
            });
        if !open {
            self.dialogs.export = None;
        } else if choose {
            self.choose_file(FilePurpose::ExportFolder);
        } else if replace {
            self.export_now(true);
        } else if go {
            self.ask_or_export();
        }
    }

    /// Exports into a free folder; asks first where a set is there already; says why where
    /// something else is. The dialog and its choices stay until the export starts.
    fn ask_or_export(&mut self) {
        use kapaint_export::set::{SetKind, Target, holds, target};
        let Some(dialog) = &mut self.dialogs.export else {
            return;
        };
        let folder = Path::new(dialog.folder.trim());
        if let Some(project) = self.project.path.as_deref().filter(|p| holds(folder, p)) {
            dialog.problem = Some(format!(
                "{} holds the project {}: choose another folder",
                folder.display(),
                project.display()
            ));
            return;
        }
        match target(folder, SetKind::of(&dialog.presets[dialog.chosen])) {
            Ok(Target::Free) => self.export_now(false),
            Ok(Target::Set) => dialog.confirm_replace = true,
            Ok(Target::Taken(why)) => {
                dialog.problem = Some(format!(
                    "{}: {why}; choose another folder",
                    folder.display()
                ));
            }
            Err(e) => dialog.problem = Some(e.to_string()),
        }
    }
}

/// Where an export into the folder `dir` the user chose goes: `dir` itself when it is free (or
/// empty) or holds a set of `kind`, else a `set` folder inside it (a folder of other things is
/// never replaced).
pub fn export_folder_in(dir: &Path, kind: kapaint_export::set::SetKind) -> PathBuf {
    use kapaint_export::set::{Target, target};
    match target(dir, kind) {
        Ok(Target::Free | Target::Set) => dir.to_path_buf(),
        _ => dir.join("set"),
    }
}

/// A window that opens about the middle of the editor (not at the top left, over the tools);
/// it can still be moved. Its top left is placed once, half a typical dialog's size from the
/// centre, so it stays put when its content grows (a centred pivot would move its buttons
/// from under the pointer).
pub(super) fn centred<'a>(window: egui::Window<'a>, ctx: &egui::Context) -> egui::Window<'a> {
    window.default_pos(ctx.content_rect().center() - egui::vec2(200.0, 150.0))
}
