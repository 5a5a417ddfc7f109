//! The menu bar, the status bar, dropped files and notices.

use std::path::PathBuf;
use std::time::Duration;

use crate::desk::{Ask, Desk, Window};
use crate::files::FilePurpose;
use crate::jobs::Job;
use crate::keys::{self, Action};
use crate::readout::ExactChi;
use crate::viewport::Viewport;
use crate::{Notices, notice};
use kapaint_model::Document;
use kapaint_model::texel::Channel;
use kapaint_reflectance::{self as reflectance, AmbientApprox, ShadingModel};

/// What the status bar reads: the document, the job under way, the viewport, the texel under
/// the pointer and the exact `chi` values integrated on a worker.
pub(crate) struct Status<'a> {
    pub(crate) doc: &'a Document,
    pub(crate) job: Option<&'a Job>,
    pub(crate) viewport: &'a Viewport,
    pub(crate) hover: Option<(u32, u32)>,
    pub(crate) exact_chi: &'a mut ExactChi,
}

impl Status<'_> {
    /// The status bar: the job's progress and Cancel, the map size and memory, the frame
    /// times, and the texel under the pointer with its `k_a` by each model.
    pub(crate) fn ui(self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            // A job's progress and Cancel first: the readouts after them may run past the
            // window's edge, the job's controls never do.
            if let Some(job) = self.job {
                ui.add(
                    egui::ProgressBar::new(job.progress.fraction())
                        .desired_width(160.0)
                        .text(job_text(&job.label, &job.progress.stage())),
                );
                if ui.button("Cancel").clicked() {
                    job.progress.cancel();
                }
                ui.separator();
            }
            let maps = self.doc.maps();
            ui.label(format!("{}x{}", maps.width(), maps.height()));
            ui.separator();
            ui.label(format!(
                "maps {}, history {}",
                super::view_panel::megabytes(maps.heap_bytes()),
                super::view_panel::megabytes(self.doc.history().bytes())
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
            if let Some((x, y)) = self
                .hover
                .filter(|&(x, y)| x < maps.width() && y < maps.height())
            {
                let v = maps.value(x, y);
                let ka = |m, a| reflectance::ka(m, a, v.kd, v.ks, v.n);
                let approx = self.doc.settings().approx;
                let [phong, blinn, ct] = ShadingModel::ALL.map(|m| ka(m, approx));
                let model = self.doc.settings().model;
                // Integrated on a worker, shown when it arrives: never on this thread.
                let n_bits = maps.texel(x, y).n;
                let exact = self
                    .exact_chi
                    .get(ui.ctx(), model, n_bits)
                    .map_or_else(
                        || "...".to_string(),
                        |[chi1, chi0]| {
                            let diffuse = reflectance::diffuse_factor(AmbientApprox::Fast) as f32;
                            format!("{:.4}", diffuse * v.kd.x + v.ks.x * chi1 as f32 + chi0 as f32)
                        },
                    );
                ui.separator();
                ui.label(format!(
                    "({x}, {y}) k_d {:.3} {:.3} {:.3}  k_s {:.3}  n {:.1}  k_a eq.8 {:.4}  eq.11 {:.4}  CT {:.4}  exact {exact}",
                    v.kd.x, v.kd.y, v.kd.z, v.ks.x, v.n, phong.x, blinn.x, ct.x
                ))
                .on_hover_text("k_a of the red channel: Phong by eq. (8), Blinn-Phong by eq. (11), Cook-Torrance (GGX) by kapaint's fit, and the exact integral for the current model");
            }
        });
    }
}

/// The menu bar: each entry asks (a key binding's entries do what the key does).
pub(crate) fn menu_ui(ui: &mut egui::Ui, recent: &[PathBuf], desk: &mut Desk) {
    // A menu entry showing its shortcut; whether it was clicked.
    let item = |ui: &mut egui::Ui, label: &str, action: Action| {
        let text = keys::shortcut(action).map_or_else(String::new, |k| keys::printed(ui.ctx(), &k));
        ui.add(egui::Button::new(label).shortcut_text(text))
            .clicked()
    };
    egui::MenuBar::new().ui(ui, |ui| {
        ui.menu_button("File", |ui| {
            for (label, action) in [("New", Action::New), ("Open…", Action::Open)] {
                if item(ui, label, action) {
                    desk.ask(Ask::Act(action));
                }
            }
            ui.menu_button("Open Recent", |ui| {
                if recent.is_empty() {
                    ui.label("No recent files");
                }
                let mut chosen = None;
                for p in recent {
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
                    desk.ask(Ask::Open(p));
                }
            });
            for (label, action) in [
                ("Save", Action::Save),
                ("Save As…", Action::SaveAs),
                ("Export…", Action::Export),
            ] {
                if item(ui, label, action) {
                    desk.ask(Ask::Act(action));
                }
            }
            ui.separator();
            if ui.button("Import mesh…").clicked() {
                desk.ask(Ask::ChooseFile(FilePurpose::ImportMesh));
            }
            if ui
                .button("Import PBR material…")
                .on_hover_text(
                    "A glTF file's material, or a texture set (choose any one of its \
                         images: name_BaseColor, _Metallic, _Roughness or _ORM, _Normal): \
                         converted for the current model into the selected layer",
                )
                .clicked()
            {
                desk.ask(Ask::ChooseFile(FilePurpose::ImportPbr));
            }
            for channel in [Channel::Kd, Channel::Ks, Channel::N] {
                if ui
                    .button(format!("Import image into {}…", channel.label()))
                    .clicked()
                {
                    desk.ask(Ask::ChooseFile(FilePurpose::ImportImage(channel)));
                }
            }
            ui.separator();
            if item(ui, "Quit", Action::Quit) {
                desk.ask(Ask::Act(Action::Quit));
            }
        });
        ui.menu_button("Edit", |ui| {
            for (label, action) in [("Undo", Action::Undo), ("Redo", Action::Redo)] {
                if item(ui, label, action) {
                    desk.ask(Ask::Act(action));
                }
            }
            ui.separator();
            if ui.button("Preferences…").clicked() {
                desk.ask(Ask::Show(Window::Preferences));
            }
        });
        image_and_mesh_menus(ui, desk);
        ui.menu_button("Help", |ui| {
            if ui.button("Keyboard shortcuts").clicked() {
                desk.ask(Ask::Show(Window::Shortcuts));
            }
        });
    });
}

/// The Image menu (resize, project an image) and the Mesh menu (bake).
fn image_and_mesh_menus(ui: &mut egui::Ui, desk: &mut Desk) {
    ui.menu_button("Image", |ui| {
        if ui
            .button("Resize…")
            .on_hover_text("Resample the maps to another size (one undo step)")
            .clicked()
        {
            desk.ask(Ask::Show(Window::Resize));
        }
        if ui
            .button("Project image…")
            .on_hover_text(
                "Paint an image onto the mesh through a planar, cylindrical, spherical, \
                 tri-planar or UV projection (one undo step)",
            )
            .clicked()
        {
            desk.ask(Ask::Show(Window::ProjectImage));
        }
    });
    ui.menu_button("Mesh", |ui| {
        if ui
            .button("Bake…")
            .on_hover_text(
                "Bake ambient occlusion, curvature, thickness, position or normal from \
                     the mesh into the project (one undo step)",
            )
            .clicked()
        {
            desk.ask(Ask::Show(Window::Bake));
        }
        if ui
            .button("Bake from high poly…")
            .on_hover_text(
                "Bake a high-poly sculpt's normals, or its AO, thickness, curvature and \
                     position for the masks, onto the mesh (rays, with a cage if you have one; \
                     one undo step)",
            )
            .clicked()
        {
            desk.ask(Ask::Show(Window::BakeHigh));
        }
        if ui
            .button("Unwrap automatically…")
            .on_hover_text(
                "Give the mesh a new UV atlas, kept in the project (what is painted stays \
                     where it is on the map)",
            )
            .clicked()
        {
            desk.ask(crate::mesh_jobs::ask_unwrap(desk.doc));
        }
    });
}

/// Files dropped on the window: a project opens, a mesh or an image comes in (an image into
/// `channel`, the one the canvas shows).
pub(crate) fn dropped_files(ctx: &egui::Context, channel: Channel, desk: &mut Desk) {
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
            "kapaint" => desk.ask(Ask::Open(path)),
            "obj" | "gltf" | "glb" => desk.job(crate::mesh_jobs::import_mesh(desk.doc, path)),
            "png" | "jpg" | "jpeg" | "tga" | "exr" => {
                desk.job(crate::jobs::import_image(desk.doc, path, channel));
            }
            _ => desk.notice(notice(
                format!(
                    "{}: drop a project (.kapaint), a mesh (.obj, .gltf, .glb) or an image",
                    path.display()
                ),
                true,
            )),
        }
    }
}

/// The notices in the corner, each until it expires.
pub(crate) fn notices_ui(notices: &mut Notices, ctx: &egui::Context) {
    notices.expire();
    if notices.is_empty() {
        return;
    }
    egui::Area::new(egui::Id::new("notices"))
        .anchor(egui::Align2::RIGHT_BOTTOM, egui::vec2(-12.0, -36.0))
        .show(ctx, |ui| {
            for n in notices.iter() {
                egui::Frame::popup(ui.style()).show(ui, |ui| {
                    ui.colored_label(
                        n.level.colour(),
                        format!("{} {}", n.level.mark(), n.shown()),
                    );
                });
            }
        });
    // Woken when the next one is due to go, not twice a second: each frame of the window
    // costs a software renderer about 0.1 s of CPU.
    if let Some(wait) = notices.next_expiry() {
        ctx.request_repaint_after(wait + Duration::from_millis(10));
    }
}

/// A job's progress text: "Export: encode", or only "Open" where the stage repeats the label.
fn job_text(label: &str, stage: &str) -> String {
    if stage.is_empty() || stage.eq_ignore_ascii_case(label) {
        label.to_string()
    } else {
        format!("{label}: {stage}")
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_stage_that_repeats_the_label_is_said_once() {
        assert_eq!(super::job_text("Open", "open"), "Open");
        assert_eq!(super::job_text("Export", "encode"), "Export: encode");
        assert_eq!(super::job_text("Save", ""), "Save");
    }
}
