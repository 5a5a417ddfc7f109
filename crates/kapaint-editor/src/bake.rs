//! Mesh > Bake: a map of the mesh (AO, curvature, thickness, position, normal) baked on a
//! worker at the map size, with progress and Cancel in the status bar, and kept in the
//! project as one undo step (a cache of the mesh: never painted, never exported as material).

use std::sync::Arc;

use super::EditorState;
use super::dialogs::centred;
use super::jobs::JobResult;
use kapaint_core::mesh::bakes::{BakeMap, BakeOptions, bake_map};

/// The Bake dialog's choices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BakeDialog {
    /// The map to bake.
    pub map: BakeMap,
    /// Rays per texel (AO and thickness).
    pub rays: u32,
    /// How far rays look, if bounded (object units).
    pub max_distance: Option<f32>,
}

impl Default for BakeDialog {
    fn default() -> Self {
        Self {
            map: BakeMap::Ao,
            rays: BakeOptions::default().rays,
            max_distance: None,
        }
    }
}

/// Ray counts the dialog offers.
const RAY_CHOICES: [u32; 6] = [16, 32, 64, 128, 256, 1024];

impl EditorState {
    /// Opens Mesh > Bake.
    pub fn open_bake(&mut self) {
        self.bake_dialog = Some(BakeDialog::default());
    }

    /// The Bake dialog's choices, while it is open.
    pub fn bake_dialog(&self) -> Option<BakeDialog> {
        self.bake_dialog
    }

    /// Bakes `dialog.map` of the project's mesh on a worker; it is kept when it arrives.
    pub fn bake(&mut self, dialog: BakeDialog) {
        let Some(surface) = self.doc.surface().cloned() else {
            self.notices
                .push(super::notice("there is no mesh to bake", true));
            return;
        };
        let options = BakeOptions {
            rays: dialog.rays,
            max_distance: dialog.max_distance,
        };
        self.start_job("Bake", move |progress| {
            match bake_map(
                &surface.mesh,
                &surface.bake,
                dialog.map,
                options,
                Some(progress),
            ) {
                Ok(baked) => {
                    let stats = baked.stats(&surface.bake);
                    JobResult::Baked(Arc::new(baked), stats)
                }
                Err(e) => JobResult::Failed(format!("bake {}: {e}", dialog.map.name())),
            }
        });
    }

    /// The Bake dialog: the map, its rays and distance, the bakes kept, Bake.
    pub(super) fn bake_window(&mut self, ctx: &egui::Context) {
        let Some(mut dialog) = self.bake_dialog else {
            return;
        };
        let (mut open, mut go) = (true, false);
        let (w, h) = (self.doc.maps().width(), self.doc.maps().height());
        centred(egui::Window::new("Bake mesh maps"), ctx)
            .open(&mut open)
            .collapsible(false)
            .resizable(false)
            .show(ctx, |ui| {
                let mesh = self.doc.settings().mesh.spec().to_string();
                ui.label(format!("{mesh}, at {w}x{h}"));
                egui::ComboBox::from_label("Map")
                    .selected_text(dialog.map.name())
                    .show_ui(ui, |ui| {
                        for (name, map) in BakeMap::ALL {
                            ui.selectable_value(&mut dialog.map, map, name);
                        }
                    });
                ui.add_enabled_ui(dialog.map.casts_rays(), |ui| {
                    egui::ComboBox::from_label("Rays per texel")
                        .selected_text(dialog.rays.to_string())
                        .show_ui(ui, |ui| {
                            for rays in RAY_CHOICES {
                                ui.selectable_value(&mut dialog.rays, rays, rays.to_string());
                            }
                        });
                    let mut bounded = dialog.max_distance.is_some();
                    ui.checkbox(&mut bounded, "Limit the ray distance");
                    if bounded {
                        let mut d = dialog.max_distance.unwrap_or(1.0);
                        ui.add(
                            egui::DragValue::new(&mut d)
                                .range(1e-4..=1e6)
                                .speed(0.01)
                                .prefix("distance "),
                        );
                        dialog.max_distance = Some(d);
                    } else {
                        dialog.max_distance = None;
                    }
                });
                if !self.doc.bakes().is_empty() {
                    ui.separator();
                    ui.label("Kept:");
                    for b in self.doc.bakes() {
                        let rays = if b.map.casts_rays() {
                            format!(", {} rays", b.options.rays)
                        } else {
                            String::new()
                        };
                        ui.label(format!("{}{rays}", b.map.name()));
                    }
                }
                go = ui
                    .add_enabled(self.doc.surface().is_some(), egui::Button::new("Bake"))
                    .clicked();
            });
        if go {
            self.bake_dialog = None;
            self.bake(dialog);
        } else if open {
            self.bake_dialog = Some(dialog);
        } else {
            self.bake_dialog = None;
        }
    }
}
