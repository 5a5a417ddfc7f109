//! File > Export: the preset and the folder, the set measured on a worker before it is
//! written (its preview), and the export itself on a worker.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

use super::export_plan::{block_search_ui, export_plan_ui};
use super::files::FilePurpose;
use crate::desk::{Ask, Desk, JobStart, centred};
use kapaint_export::preset::ExportPreset;
use kapaint_model::Document;

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
    /// With `glb`: its textures as Basis Universal KTX2 files (`KHR_texture_basisu`).
    basisu: bool,
}

impl ExportDialog {
    /// The dialog on the `last` export's preset and folder, else the first preset and a folder
    /// named after the `project`.
    pub(super) fn new(last: Option<&(String, String)>, project: Option<&Path>) -> Self {
        let presets = kapaint_export::preset::builtin();
        let (chosen, folder) = match last {
            Some((name, folder)) => (
                presets.iter().position(|p| &p.name == name).unwrap_or(0),
                folder.clone(),
            ),
            None => (
                0,
                project.map_or_else(
                    || "export".to_string(),
                    |p| p.with_extension("").display().to_string() + "-set",
                ),
            ),
        };
        Self {
            presets,
            chosen,
            folder,
            confirm_replace: false,
            problem: None,
            plan: None,
            planning: None,
            glb: false,
            basisu: false,
        }
    }

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
    /// The export of `doc` as the dialog says, on a worker (replacing the set at the folder
    /// where `replace`), and the choice to offer next time.
    fn export(&self, doc: &Document, replace: bool) -> Option<(JobStart, (String, String))> {
        let preset = self.presets.get(self.chosen).cloned()?;
        let out = PathBuf::from(self.folder.trim());
        let choice = (preset.name.clone(), self.folder.clone());
        let pbr = preset.format.is_gltf_pbr();
        let mesh = doc.surface().filter(|_| pbr && self.glb).map(Arc::clone);
        let basisu = self.basisu;
        // A copy for the worker (the maps' tiles are shared, not copied).
        let snapshot = doc.snapshot();
        let job = JobStart::new(
            "Export",
            move |progress| {
                let glb = mesh.as_ref().map(|s| kapaint_export::gltf_pbr::Glb {
                    mesh: &s.mesh,
                    basisu,
                });
                let gpu = kapaint_gpu::blocks::for_export(&preset);
                match kapaint_export::run(&snapshot, &preset, &out, progress, replace, glb, gpu) {
                    Ok(m) => Ok((out, Box::new(m))),
                    Err(e) => Err(format!("export failed: {e}")),
                }
            },
            crate::jobs::export_done,
        );
        Some((job, choice))
    }

    /// Keeps the preview current: starts planning `doc` on a worker thread when the preset
    /// or the maps changed, and takes the result when it is done.
    fn update_plan(&mut self, doc: &Document, ctx: &egui::Context) {
        let version = doc.maps().version();
        let current = |(p, v): (usize, u64)| p == self.chosen && v == version;
        let planned = self
            .plan
            .as_ref()
            .is_some_and(|(p, v, _)| current((*p, *v)));
        // One plan at a time: a stale one finishes first, then the current one starts.
        if !planned
            && self.planning.is_none()
            && let Some(preset) = self.presets.get(self.chosen).cloned()
        {
            let doc = doc.snapshot();
            let spawned = std::thread::Builder::new()
                .name("kapaint export preview".into())
                .spawn(move || kapaint_export::set::plan(&doc, &preset));
            if let Ok(handle) = spawned {
                self.planning = Some((self.chosen, version, handle));
            }
        }
        if self
            .planning
            .as_ref()
            .is_some_and(|(_, _, h)| h.is_finished())
            && let Some((p, v, handle)) = self.planning.take()
            && let Ok(plan) = handle.join()
        {
            self.plan = Some((p, v, plan));
        }
        if self.planning.is_some() {
            ctx.request_repaint_after(Duration::from_millis(50));
        }
    }

    /// The preset chooser and the chosen preset's description.
    fn preset_ui(&mut self, ui: &mut egui::Ui) {
        // Tall enough for every built-in preset without scrolling.
        egui::ComboBox::from_label("Preset")
            .height(420.0)
            .selected_text(
                self.presets
                    .get(self.chosen)
                    .map_or("", |p| p.name.as_str()),
            )
            .show_ui(ui, |ui| {
                for (i, p) in self.presets.iter().enumerate() {
                    ui.selectable_value(&mut self.chosen, i, &p.name)
                        .on_hover_text(&p.description);
                }
            });
        if let Some(p) = self.presets.get(self.chosen) {
            ui.label(&p.description);
        }
    }

    /// Whether the folder may take the set now: asks first where a set is there already
    /// (`false`, the question shown); says why where something else is, or where it holds
    /// the `project`.
    fn folder_free(&mut self, project: Option<&Path>) -> bool {
        use kapaint_export::set::{SetKind, Target, holds, target};
        let folder = Path::new(self.folder.trim());
        if let Some(project) = project.filter(|p| holds(folder, p)) {
            self.problem = Some(format!(
                "{} holds the project {}: choose another folder",
                folder.display(),
                project.display()
            ));
            return false;
        }
        match target(folder, SetKind::of(&self.presets[self.chosen])) {
            Ok(Target::Free) => return true,
            Ok(Target::Set) => self.confirm_replace = true,
            Ok(Target::Taken(why)) => {
                self.problem = Some(format!(
                    "{}: {why}; choose another folder",
                    folder.display()
                ));
            }
            Err(e) => self.problem = Some(e.to_string()),
        }
        false
    }
}

/// The export dialog, while `open`: preset, folder, the measured set below them; Export
/// starts the export (the choice is kept in `last` for the next) and closes it. The dialog
/// and its choices stay until the export starts.
pub(super) fn export_window(
    (open, last): (&mut Option<ExportDialog>, &mut Option<(String, String)>),
    project: Option<&Path>,
    ctx: &egui::Context,
    desk: &mut Desk,
) {
    let Some(dialog) = open else {
        return;
    };
    let doc = desk.doc;
    dialog.update_plan(doc, ctx);
    let has_mesh = doc.surface().is_some();
    let mut shown = true;
    let (mut go, mut replace, mut choose) = (false, false, false);
    centred(egui::Window::new("Export"), ctx)
        .open(&mut shown)
        .collapsible(false)
        .show(ctx, |ui| {
            dialog.preset_ui(ui);
            ui.separator();
            let pbr = dialog
                .presets
                .get(dialog.chosen)
                .is_some_and(|p| p.format.is_gltf_pbr());
            ui.horizontal(|ui| {
                ui.label("Folder");
                // A fixed id: the measurement arriving must not take the keyboard from a
                // folder being typed.
                let field = egui::TextEdit::singleline(&mut dialog.folder).id_salt("export folder");
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
                ui.add_enabled(
                    has_mesh && dialog.glb,
                    egui::Checkbox::new(
                        &mut dialog.basisu,
                        "with Basis Universal textures (KHR_texture_basisu: ETC1S or UASTC)",
                    ),
                )
                .on_hover_text(
                    "KTX2 textures a runtime transcodes to BC7 or ASTC: smaller on the GPU; \
                     the settings are the cheapest within the preset's k_a budget.",
                );
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
                    if let Some(preset) = dialog.presets.get(dialog.chosen) {
                        export_plan_ui(ui, plan, preset);
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
    let start = if !shown {
        *open = None;
        None
    } else if choose {
        desk.ask(Ask::ChooseFile(FilePurpose::ExportFolder));
        None
    } else if replace || (go && dialog.folder_free(project)) {
        dialog.export(doc, replace)
    } else {
        None
    };
    if let Some((job, choice)) = start {
        *last = Some(choice);
        *open = None;
        desk.job(job);
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
