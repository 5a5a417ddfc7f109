//! The editor's questions before it goes on: unsaved changes before another project opens or
//! the window closes, whether a glTF mesh's material comes in with it, and whether a mesh
//! whose UVs cannot be painted is unwrapped.

use crate::desk::{Ask, Desk, centred};

/// The questions asked before the editor goes on, while asked.
#[derive(Default)]
pub(super) struct Prompts {
    /// A project to open once the user has decided about the unsaved changes.
    pub(super) pending_open: Option<std::path::PathBuf>,
    /// An imported glTF mesh whose material has textures: asking whether to bring them in.
    pub(super) material: Option<std::path::PathBuf>,
    /// A PBR material of another size than the maps: asking whether to adopt its size.
    pub(super) size: Option<crate::results::SizePrompt>,
    /// A mesh import waiting on whether to unwrap the mesh.
    pub(super) unwrap: Option<crate::results::UnwrapPrompt>,
    /// A recovery copy found at start, newer than the project.
    pub(super) recovery_offer: Option<std::path::PathBuf>,
    /// Quitting: asked, waiting for a save, or allowed.
    pub(super) quit: super::Quit,
}

impl Prompts {
    /// After a glTF mesh import: asks whether to bring its material's textures in too.
    pub(super) fn material_window(&mut self, ctx: &egui::Context, desk: &mut Desk) {
        let Some(path) = self.material.clone() else {
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
                    desk.doc.settings().model.label()
                ));
                ui.horizontal(|ui| {
                    bring = ui.button("Bring the material in").clicked();
                    skip = ui.button("Mesh only").clicked();
                });
            });
        if bring {
            self.material = None;
            desk.job(crate::material_size::import_pbr(desk.doc, path));
        } else if skip {
            self.material = None;
        }
    }

    /// After a mesh import whose UVs cannot be painted as they are: unwrap automatically, keep
    /// its UVs (when it has some), or cancel the import.
    pub(super) fn unwrap_window(&mut self, ctx: &egui::Context, desk: &mut Desk) {
        let Some(prompt) = self.unwrap.clone() else {
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
                    desk.doc.maps().width(),
                    desk.doc.maps().height()
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
            self.unwrap = None;
        }
        if unwrap {
            desk.job(crate::mesh_jobs::unwrap_mesh(desk.doc, prompt));
        } else if keep {
            desk.job(crate::mesh_jobs::keep_mesh_uvs(desk.doc, prompt));
        }
    }

    /// Asks what to do with unsaved changes before opening another project: save them first
    /// (the project opens once saved), discard them, or cancel.
    pub(super) fn open_window(&mut self, ctx: &egui::Context, desk: &mut Desk) {
        let Some(path) = self.pending_open.clone() else {
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
            self.pending_open = None;
            desk.ask(Ask::OpenNow(path));
        } else if cancel {
            self.pending_open = None;
        } else if save {
            desk.ask(Ask::Save);
        }
    }

    /// Quitting with unsaved changes (`dirty`): asks to save them, discard them, or stay.
    pub(super) fn close_window(&mut self, ctx: &egui::Context, dirty: bool, desk: &mut Desk) {
        let close_requested = ctx.input(|i| i.viewport().close_requested()) || self.quit.asked;
        if close_requested && dirty && self.quit.allowed.is_none() {
            ctx.send_viewport_cmd(egui::ViewportCommand::CancelClose);
            self.quit.asked = true;
        } else if self.quit.asked && (self.quit.allowed.is_some() || !dirty) {
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            return;
        }
        if self.quit.asked && dirty && self.quit.allowed.is_none() {
            egui::Window::new("Unsaved changes")
                .anchor(egui::Align2::CENTER_CENTER, egui::Vec2::ZERO)
                .collapsible(false)
                .show(ctx, |ui| {
                    ui.label("The material has unsaved changes.");
                    ui.horizontal(|ui| {
                        if ui.button("Save").clicked() {
                            // Untitled work asks where first; the window closes once saved.
                            self.quit.after_save = true;
                            desk.ask(Ask::Save);
                            self.quit.asked = false;
                        }
                        if ui.button("Discard").clicked() {
                            self.quit.allowed = Some(super::QuitAllowed::Discarded);
                        }
                        if ui.button("Cancel").clicked() {
                            self.quit.asked = false;
                        }
                    });
                });
        }
    }
}
