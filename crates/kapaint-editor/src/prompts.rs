//! The editor's questions before it goes on: unsaved changes before another project opens or
//! the window closes, whether a glTF mesh's material comes in with it, and whether a mesh
//! whose UVs cannot be painted is unwrapped.

use super::EditorState;
use super::dialogs::centred;

/// The questions asked before the editor goes on, while asked.
#[derive(Default)]
pub(super) struct Prompts {
    /// A project to open once the user has decided about the unsaved changes.
    pub(super) pending_open: Option<std::path::PathBuf>,
    /// An imported glTF mesh whose material has textures: asking whether to bring them in.
    pub(super) material: Option<std::path::PathBuf>,
    /// A PBR material of another size than the maps: asking whether to adopt its size.
    pub(super) size: Option<super::jobs::SizePrompt>,
    /// A mesh import waiting on whether to unwrap the mesh.
    pub(super) unwrap: Option<super::jobs::UnwrapPrompt>,
    /// A recovery copy found at start, newer than the project.
    pub(super) recovery_offer: Option<std::path::PathBuf>,
    /// Quitting: asked, waiting for a save, or allowed.
    pub(super) quit: super::Quit,
}

impl EditorState {
    /// After a glTF mesh import: asks whether to bring its material's textures in too.
    pub(super) fn material_prompt_window(&mut self, ctx: &egui::Context) {
        let Some(path) = self.prompts.material.clone() else {
            return;
        };
        let (mut bring, mut skip) = (false, false);
        centred(egui::Window::new("Import the material too?"), ctx)
            .collapsible(false)
            .resizable(false)
            .show(ctx, |ui| {
                ui.label(format!(
                    "{} has a material with textures. Bring it in too? Its base colour, \
                     metallic and roughness are converted for {} into the selected layer's \
                     k_d, k_s and n (one undo step), and its normal map is kept.",
                    path.display(),
                    self.doc.settings().model.label()
                ));
                ui.horizontal(|ui| {
                    bring = ui.button("Bring the material in").clicked();
                    skip = ui.button("Mesh only").clicked();
                });
            });
        if bring {
            self.prompts.material = None;
            self.import_pbr(path);
        } else if skip {
            self.prompts.material = None;
        }
    }

    /// After a mesh import whose UVs cannot be painted as they are: unwrap automatically, keep
    /// its UVs (when it has some), or cancel the import.
    pub(super) fn unwrap_prompt_window(&mut self, ctx: &egui::Context) {
        let Some(prompt) = self.prompts.unwrap.clone() else {
            return;
        };
        let (mut unwrap, mut keep, mut cancel) = (false, false, false);
        centred(egui::Window::new("Unwrap the mesh?"), ctx)
            .collapsible(false)
            .resizable(false)
            .show(ctx, |ui| {
                ui.label(format!(
                    "{} {}. kapaint can give it a new UV atlas: charts packed for this map \
                     ({}x{}), padded, none overlapping. The project keeps the unwrapped mesh.",
                    prompt.path.display(),
                    prompt.why,
                    self.doc.maps().width(),
                    self.doc.maps().height()
                ));
                ui.horizontal(|ui| {
                    unwrap = ui.button("Unwrap automatically").clicked();
                    if prompt.has_uvs {
                        keep = ui.button("Keep its UVs").clicked();
                    }
                    cancel = ui.button("Cancel").clicked();
                });
            });
        if unwrap || keep || cancel {
            self.prompts.unwrap = None;
        }
        if unwrap {
            self.unwrap_mesh(prompt);
        } else if keep {
            self.keep_mesh_uvs(prompt);
        }
    }

    /// Asks what to do with unsaved changes before opening another project: save them first
    /// (the project opens once saved), discard them, or cancel.
    pub(super) fn open_prompt(&mut self, ctx: &egui::Context) {
        let Some(path) = self.prompts.pending_open.clone() else {
            return;
        };
        let (mut save, mut discard, mut cancel) = (false, false, false);
        egui::Window::new("Open: unsaved changes")
            .anchor(egui::Align2::CENTER_CENTER, egui::Vec2::ZERO)
            .collapsible(false)
            .resizable(false)
            .show(ctx, |ui| {
                ui.label(format!(
                    "The material has unsaved changes. Save them before opening {}?",
                    path.display()
                ));
                ui.horizontal(|ui| {
                    save = ui.button("Save, then open").clicked();
                    discard = ui.button("Discard and open").clicked();
                    cancel = ui.button("Cancel").clicked();
                });
            });
        if discard {
            self.prompts.pending_open = None;
            self.open_now(path);
        } else if cancel {
            self.prompts.pending_open = None;
        } else if save {
            self.save();
        }
    }

    pub(super) fn close_prompt(&mut self, ctx: &egui::Context) {
        let close_requested =
            ctx.input(|i| i.viewport().close_requested()) || self.prompts.quit.asked;
        if close_requested && self.dirty() && self.prompts.quit.allowed.is_none() {
            ctx.send_viewport_cmd(egui::ViewportCommand::CancelClose);
            self.prompts.quit.asked = true;
        } else if self.prompts.quit.asked && (self.prompts.quit.allowed.is_some() || !self.dirty())
        {
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            return;
        }
        if self.prompts.quit.asked && self.dirty() && self.prompts.quit.allowed.is_none() {
            egui::Window::new("Unsaved changes")
                .anchor(egui::Align2::CENTER_CENTER, egui::Vec2::ZERO)
                .collapsible(false)
                .show(ctx, |ui| {
                    ui.label("The material has unsaved changes.");
                    ui.horizontal(|ui| {
                        if ui.button("Save").clicked() {
                            // Untitled work asks where first; the window closes once saved.
                            self.prompts.quit.after_save = true;
                            self.save();
                            self.prompts.quit.asked = false;
                        }
                        if ui.button("Discard").clicked() {
                            self.prompts.quit.allowed = Some(super::QuitAllowed::Discarded);
                        }
                        if ui.button("Cancel").clicked() {
                            self.prompts.quit.asked = false;
                        }
                    });
                });
        }
    }
}
