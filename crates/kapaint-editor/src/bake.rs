//! Mesh > Bake: a map of the mesh (AO, curvature, thickness, position, normal) baked on a
//! worker at the map size, with progress and Cancel in the status bar, and kept in the
//! project as one undo step (a cache of the mesh: never painted, never exported as material).

use std::sync::Arc;

use super::EditorState;
use super::dialogs::centred;
use kapaint_mesh::bakes::{BakeMap, BakeOptions, bake_map};
use kapaint_model::MaskCommand;
use kapaint_model::generator::Generator;
use kapaint_model::layers::LayerId;

/// The Bake dialog's choices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BakeDialog {
    /// The map to bake.
    pub map: BakeMap,
    /// Rays per texel (AO and thickness).
    pub rays: u32,
    /// How far rays look, if bounded (object units).
    pub max_distance: Option<f32>,
    /// The maps "Bake all" bakes, in [`BakeMap::ALL`] order.
    pub all: [bool; BakeMap::ALL.len()],
}

impl Default for BakeDialog {
    fn default() -> Self {
        Self {
            map: BakeMap::Ao,
            rays: BakeOptions::default().rays,
            max_distance: None,
            // The maps the smart masks read.
            all: BakeMap::ALL
                .map(|(_, m)| matches!(m, BakeMap::Ao | BakeMap::Curvature | BakeMap::Thickness)),
        }
    }
}

/// The bakes the editor starts on its own, so that no generator mask ever reads a flat
/// stand-in for a bake the project lacks.
#[derive(Default)]
pub(super) struct OnDemand {
    /// A generator set while a bake it reads was missing, on the layer selected then: laid
    /// when the bakes arrive.
    pending: Option<(Option<LayerId>, Generator)>,
    /// The document version last looked at for missing bakes (each version is looked at
    /// once: a bake that fails is not started again for it).
    looked_at: Option<u64>,
}

/// Ray counts the dialog offers.
const RAY_CHOICES: [u32; 6] = [16, 32, 64, 128, 256, 1024];

impl EditorState {
    /// Opens Mesh > Bake.
    pub fn open_bake(&mut self) {
        self.dialogs.bake = Some(BakeDialog::default());
    }

    /// The Bake dialog's choices, while it is open.
    pub fn bake_dialog(&self) -> Option<BakeDialog> {
        self.dialogs.bake
    }

    /// Sets `generator` on the selected layer's mask; where it reads a bake the project
    /// lacks, bakes that first (one job, with progress and Cancel) and sets it when the bake
    /// arrives.
    pub(super) fn set_generator_baking(&mut self, generator: Generator) {
        let missing: Vec<BakeMap> = generator
            .bakes_needed()
            .into_iter()
            .filter(|&m| self.doc.bake_of(m).is_none())
            .collect();
        if missing.is_empty() {
            self.apply(MaskCommand::SetMaskGenerator(Some(generator)));
            return;
        }
        let names: Vec<&str> = missing.iter().map(|m| m.name()).collect();
        self.notices.push(super::notice(
            format!("baking {} first: the mask reads it", names.join(" and ")),
            false,
        ));
        self.jobs.bake_on_demand.pending = Some((self.doc.selected_id(), generator));
        let dialog = BakeDialog {
            all: BakeMap::ALL.map(|(_, m)| missing.contains(&m)),
            ..BakeDialog::default()
        };
        self.bake_all(dialog);
    }

    /// Starts a bake of the maps the document's generator masks read and lack (a project
    /// opened without them, a mesh changed under them), once per document version, when no
    /// other job runs.
    pub(super) fn bake_missing(&mut self) {
        let version = self.doc.version();
        if self.jobs.current.is_some() || self.jobs.bake_on_demand.looked_at == Some(version) {
            return;
        }
        self.jobs.bake_on_demand.looked_at = Some(version);
        let missing = self.doc.missing_bakes();
        if missing.is_empty() || self.doc.surface().is_none() {
            return;
        }
        let names: Vec<&str> = missing.iter().map(|(m, _)| m.name()).collect();
        self.notices.push(super::notice(
            format!(
                "baking {}: the masks read it and the project lacks it",
                names.join(" and ")
            ),
            false,
        ));
        let dialog = BakeDialog {
            all: BakeMap::ALL.map(|(_, m)| missing.iter().any(|(x, _)| *x == m)),
            ..BakeDialog::default()
        };
        self.bake_all(dialog);
    }

    /// What bakes kept just now unlock: the generator waiting for them, laid if its layer is
    /// still the one selected.
    pub(super) fn baked_on_demand(&mut self) {
        if let Some((layer, generator)) = self.jobs.bake_on_demand.pending.take()
            && layer == self.doc.selected_id()
        {
            self.apply(MaskCommand::SetMaskGenerator(Some(generator)));
        }
    }

    /// A bake job that failed or was cancelled: the generator waiting for it is dropped.
    pub(super) fn bake_failed(&mut self) {
        self.jobs.bake_on_demand.pending = None;
    }

    /// Bakes `dialog.map` of the project's mesh on a worker; it is kept when it arrives.
    pub fn bake(&mut self, dialog: BakeDialog) {
        self.bake_maps(dialog, vec![dialog.map]);
    }

    /// Bakes the maps `dialog.all` checks, one after the other in one job (one progress bar,
    /// one Cancel); they are kept together as one undo step when the last arrives.
    pub fn bake_all(&mut self, dialog: BakeDialog) {
        let maps = BakeMap::ALL
            .iter()
            .zip(dialog.all)
            .filter_map(|((_, m), on)| on.then_some(*m))
            .collect();
        self.bake_maps(dialog, maps);
    }

    fn bake_maps(&mut self, dialog: BakeDialog, maps: Vec<BakeMap>) {
        let Some(surface) = self.doc.surface().cloned() else {
            self.notices
                .push(super::notice("there is no mesh to bake", true));
            return;
        };
        if maps.is_empty() {
            self.notices
                .push(super::notice("no map is checked to bake", true));
            return;
        }
        let options = BakeOptions {
            rays: dialog.rays,
            max_distance: dialog.max_distance,
        };
        self.start_job(
            "Bake",
            move |progress| {
                let mut baked = Vec::with_capacity(maps.len());
                for map in maps {
                    let start = std::time::Instant::now();
                    match bake_map(&surface.mesh, &surface.bake, map, options, Some(progress)) {
                        Ok(b) => {
                            let stats = b.stats(&surface.bake);
                            baked.push((Arc::new(b), stats, start.elapsed().as_secs_f64()));
                        }
                        Err(e) => return Err(format!("bake {}: {e}", map.name())),
                    }
                }
                Ok(baked)
            },
            Self::baked,
        );
    }

    /// The Bake dialog: the map, its rays and distance, the bakes kept, Bake; the maps to
    /// bake together, Bake all checked.
    pub(super) fn bake_window(&mut self, ctx: &egui::Context) {
        let Some(mut dialog) = self.dialogs.bake else {
            return;
        };
        let (mut open, mut go, mut all) = (true, false, false);
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
                ui.separator();
                ui.horizontal_wrapped(|ui| {
                    for ((name, _), on) in BakeMap::ALL.iter().zip(&mut dialog.all) {
                        ui.checkbox(on, *name);
                    }
                });
                all = ui
                    .add_enabled(
                        self.doc.surface().is_some() && dialog.all.contains(&true),
                        egui::Button::new("Bake all checked"),
                    )
                    .on_hover_text("One job, one progress bar; kept as one undo step")
                    .clicked();
            });
        if go {
            self.dialogs.bake = None;
            self.bake(dialog);
        } else if all {
            self.dialogs.bake = None;
            self.bake_all(dialog);
        } else if open {
            self.dialogs.bake = Some(dialog);
        } else {
            self.dialogs.bake = None;
        }
    }
}
