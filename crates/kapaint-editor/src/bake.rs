//! Mesh > Bake: a map of the mesh (AO, curvature, thickness, position, normal) baked on a
//! worker at the map size, with progress and Cancel in the status bar, and kept in the
//! project as one undo step (a cache of the mesh: never painted, never exported as material).

use std::sync::Arc;

use super::notice;
use crate::desk::{Ask, Desk, JobStart, centred};
use kapaint_mesh::bakes::{BakeMap, BakeOptions, bake_map};
use kapaint_model::Document;
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

/// A map baked from the mesh, what it holds and how many seconds it took.
pub(super) type Baked = (
    Arc<kapaint_mesh::bakes::Baked>,
    kapaint_mesh::bakes::BakeStats,
    f64,
);

/// Ray counts the dialog offers.
const RAY_CHOICES: [u32; 6] = [16, 32, 64, 128, 256, 1024];

impl OnDemand {
    /// Asks for `generator` on the selected layer's mask; where it reads a bake the project
    /// lacks, asks for that bake first (one job, with progress and Cancel) and keeps the
    /// generator until the bake arrives.
    pub(super) fn lay(&mut self, generator: Generator, desk: &mut Desk) {
        let doc = desk.doc;
        let missing: Vec<BakeMap> = generator
            .bakes_needed()
            .into_iter()
            .filter(|&m| doc.bake_of(m).is_none())
            .collect();
        if missing.is_empty() {
            desk.command(MaskCommand::SetMaskGenerator(Some(generator)));
            return;
        }
        let names: Vec<&str> = missing.iter().map(|m| m.name()).collect();
        desk.notice(notice(
            format!("baking {} first: the mask reads it", names.join(" and ")),
            false,
        ));
        self.pending = Some((doc.selected_id(), generator));
        let dialog = BakeDialog {
            all: BakeMap::ALL.map(|(_, m)| missing.contains(&m)),
            ..BakeDialog::default()
        };
        desk.ask(bake_all(doc, dialog));
    }

    /// Asks for a bake of the maps the document's generator masks read and lack (a project
    /// opened without them, a mesh changed under them), once per document version, when no
    /// other job runs (`busy`).
    pub(super) fn look(&mut self, busy: bool, desk: &mut Desk) {
        let doc = desk.doc;
        let version = doc.version();
        if busy || self.looked_at == Some(version) {
            return;
        }
        self.looked_at = Some(version);
        let missing = doc.missing_bakes();
        if missing.is_empty() || doc.surface().is_none() {
            return;
        }
        let names: Vec<&str> = missing.iter().map(|(m, _)| m.name()).collect();
        desk.notice(notice(
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
        desk.ask(bake_all(doc, dialog));
    }

    /// What bakes kept just now unlock: the generator waiting for them, if its layer is still
    /// the one selected and `doc` now holds every bake it reads (read from the document,
    /// never assumed from the job).
    pub(super) fn baked(&mut self, doc: &Document) -> Option<MaskCommand> {
        let (layer, generator) = self.pending.take()?;
        let ready = generator
            .bakes_needed()
            .into_iter()
            .all(|m| doc.bake_of(m).is_some());
        (ready && layer == doc.selected_id())
            .then_some(MaskCommand::SetMaskGenerator(Some(generator)))
    }

    /// A bake job that failed or was cancelled: the generator waiting for it is dropped.
    pub(super) fn failed(&mut self) {
        self.pending = None;
    }
}

/// Bakes `dialog.map` of `doc`'s mesh on a worker; it is kept when it arrives.
pub(super) fn bake(doc: &Document, dialog: BakeDialog) -> Ask {
    bake_maps(doc, dialog, vec![dialog.map])
}

/// Bakes the maps `dialog.all` checks, one after the other in one job (one progress bar, one
/// Cancel); they are kept together as one undo step when the last arrives.
pub(super) fn bake_all(doc: &Document, dialog: BakeDialog) -> Ask {
    let maps = BakeMap::ALL
        .iter()
        .zip(dialog.all)
        .filter_map(|((_, m), on)| on.then_some(*m))
        .collect();
    bake_maps(doc, dialog, maps)
}

/// The job baking `maps` of `doc`'s mesh, or why there is none.
fn bake_maps(doc: &Document, dialog: BakeDialog, maps: Vec<BakeMap>) -> Ask {
    let Some(surface) = doc.surface().cloned() else {
        return Ask::Notice(notice("there is no mesh to bake", true));
    };
    if maps.is_empty() {
        return Ask::Notice(notice("no map is checked to bake", true));
    }
    let options = BakeOptions {
        rays: dialog.rays,
        max_distance: dialog.max_distance,
    };
    Ask::Job(JobStart::new(
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
        baked,
    ))
}

/// Maps baked from the mesh (one, or "Bake all"'s), what each holds and how many seconds it
/// took: into the document, then the generator mask that waited for them.
fn baked(baked: Vec<Baked>, desk: &mut Desk) {
    let lines = baked
        .iter()
        .map(|(b, stats, seconds)| {
            notice(
                format!(
                    "baked {}: {} texels, mean {:.3}, min {:.3}, {seconds:.1} s",
                    b.map.name(),
                    stats.texels,
                    stats.mean,
                    stats.min
                ),
                false,
            )
        })
        .collect();
    let bakes = baked
        .into_iter()
        .map(|(b, _, _)| kapaint_model::document::AttachedBake(b))
        .collect();
    desk.command_saying(kapaint_model::ImportCommand::SetBakes(bakes), lines);
    desk.ask(Ask::BakedOnDemand);
}

/// The Bake dialog, while `open`: the map, its rays and distance, the bakes kept, Bake; the
/// maps to bake together, Bake all checked.
pub(super) fn bake_window(open: &mut Option<BakeDialog>, ctx: &egui::Context, desk: &mut Desk) {
    let Some(mut dialog) = *open else {
        return;
    };
    let doc = desk.doc;
    let (mut shown, mut go, mut all) = (true, false, false);
    let (w, h) = (doc.maps().width(), doc.maps().height());
    centred(egui::Window::new("Bake mesh maps"), ctx)
        .open(&mut shown)
        .collapsible(false)
        .resizable(false)
        .show(ctx, |ui| {
            let mesh = doc.settings().mesh.spec().to_string();
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
            if !doc.bakes().is_empty() {
                ui.separator();
                ui.label("Kept:");
                for b in doc.bakes() {
                    let rays = if b.map.casts_rays() {
                        format!(", {} rays", b.options.rays)
                    } else {
                        String::new()
                    };
                    let from = b
                        .from_high
                        .as_ref()
                        .map(|h| format!(", from {}", h.mesh))
                        .unwrap_or_default();
                    ui.label(format!("{}{rays}{from}", b.map.name()));
                }
            }
            go = ui
                .add_enabled(doc.surface().is_some(), egui::Button::new("Bake"))
                .clicked();
            ui.separator();
            ui.horizontal_wrapped(|ui| {
                for ((name, _), on) in BakeMap::ALL.iter().zip(&mut dialog.all) {
                    ui.checkbox(on, *name);
                }
            });
            all = ui
                .add_enabled(
                    doc.surface().is_some() && dialog.all.contains(&true),
                    egui::Button::new("Bake all checked"),
                )
                .on_hover_text("One job, one progress bar; kept as one undo step")
                .clicked();
        });
    *open = (shown && !go && !all).then_some(dialog);
    if go {
        desk.ask(bake(doc, dialog));
    } else if all {
        desk.ask(bake_all(doc, dialog));
    }
}
