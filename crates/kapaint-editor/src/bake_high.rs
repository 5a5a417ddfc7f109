//! Mesh > Bake from high poly: maps baked from high-poly meshes (and a cage) onto the project's
//! mesh on a worker, with one progress bar and Cancel, kept as one undo step: the normal map
//! (tangent space), or the project's bakes of AO, thickness, curvature, position and
//! object-space normal (what generator masks read), in place of the mesh's own.

use std::path::PathBuf;

use super::notice;
use crate::desk::{Ask, Desk, JobStart, centred};
use crate::files::FilePurpose;
use kapaint_gpu::rays::{GpuCaster, RaysOn};
use kapaint_mesh::Mesh;
use kapaint_mesh::bakes::{
    CpuCaster, HighMap, HighOptions, HighRays, HighSource, Matching, NormalSpace, RayCaster,
    SAMPLES, bake_from_high_on,
};
use kapaint_model::surface::Surface;
use kapaint_model::{Document, ImportCommand};

/// The maps kept as the project's bakes, with their names in the dialog.
pub const BAKE_MAPS: [(&str, HighMap); 5] = [
    ("Ambient occlusion", HighMap::Ao),
    ("Thickness", HighMap::Thickness),
    ("Curvature", HighMap::Curvature),
    ("Position", HighMap::Position),
    (
        "Normal (object space)",
        HighMap::Normal(NormalSpace::Object),
    ),
];

/// The dialog's choices.
#[derive(Clone, Debug, PartialEq)]
pub struct HighDialog {
    /// The high meshes, baked as one.
    pub highs: Vec<PathBuf>,
    /// The cage, if the rays start on one.
    pub cage: Option<PathBuf>,
    /// The cage as read (on a worker once chosen), drawn in the viewport.
    pub cage_mesh: Option<std::sync::Arc<Mesh>>,
    /// Bake the normal map (tangent space) rather than the maps `bakes` checks.
    pub normal_map: bool,
    /// The maps of [`BAKE_MAPS`] to bake, when not the normal map.
    pub bakes: [bool; BAKE_MAPS.len()],
    /// Ray distances (object units); `None`: the default.
    pub front: Option<f32>,
    /// Ray distances (object units); `None`: the default.
    pub rear: Option<f32>,
    /// Samples per texel.
    pub samples: u32,
    /// Rays per sample (AO, thickness).
    pub rays: u32,
    /// Pair `X_low` parts with `X_high` ones, so parts never bake onto each other.
    pub by_name: bool,
}

impl Default for HighDialog {
    fn default() -> Self {
        Self {
            highs: Vec::new(),
            cage: None,
            cage_mesh: None,
            normal_map: true,
            bakes: [true, false, true, false, false],
            front: None,
            rear: None,
            samples: 1,
            rays: 64,
            by_name: false,
        }
    }
}

impl HighDialog {
    /// The maps it bakes.
    pub fn maps(&self) -> Vec<HighMap> {
        if self.normal_map {
            return vec![HighMap::Normal(NormalSpace::Tangent)];
        }
        BAKE_MAPS
            .iter()
            .zip(self.bakes)
            .filter_map(|((_, m), on)| on.then_some(*m))
            .collect()
    }
}

/// What a bake from the high meshes made: the step that keeps it, and a line per map on
/// what its rays found.
pub(super) struct Made {
    keep: ImportCommand,
    lines: Vec<String>,
}

/// The job baking `dialog`'s maps of `doc`'s mesh, or why there is none.
pub(super) fn bake(doc: &Document, dialog: &HighDialog) -> Ask {
    let Some(surface) = doc.surface().cloned() else {
        return Ask::Notice(notice("there is no mesh to bake onto", true));
    };
    if dialog.highs.is_empty() {
        return Ask::Notice(notice("choose a high-poly mesh to bake from", true));
    }
    let maps = dialog.maps();
    if maps.is_empty() {
        return Ask::Notice(notice("no map is checked to bake", true));
    }
    let dialog = dialog.clone();
    Ask::Job(JobStart::new(
        "Bake from high poly",
        move |progress| {
            let open =
                |p: &PathBuf| kapaint_mesh::open(p).map_err(|e| format!("{}: {e}", p.display()));
            let high = Mesh::merged(dialog.highs.iter().map(open).collect::<Result<_, _>>()?)?;
            let mut lines = Vec::new();
            let cage = dialog.cage.as_ref().map(open).transpose()?;
            // One set of BVHs for every map (the high mesh checked first by each bake).
            let matching = if dialog.by_name {
                Matching::ByName
            } else {
                Matching::All
            };
            let rays = HighRays::new(&surface.mesh, &high, matching).map_err(|e| e.to_string())?;
            if matching == Matching::ByName {
                lines.push(format!(
                    "matched by name: {} pairs ({}); {} low and {} high triangles in no pair",
                    rays.pairs.len(),
                    rays.pairs.join(", "),
                    rays.unpaired_low,
                    rays.unpaired_high
                ));
            }
            let bakes = bake_maps(
                (&surface, &high, cage.as_ref(), &rays),
                &maps,
                &dialog,
                progress,
                &mut lines,
            )?;
            let source = HighSource::of(&high, cage.as_ref());
            let keep = ImportCommand::keep_high(bakes, surface.mesh_hash, &source)?;
            Ok(Made { keep, lines })
        },
        kept,
    ))
}

/// The job reading the cage at `path` and checking it is `doc`'s mesh pushed out; the dialog
/// draws it once read.
pub(super) fn read_cage(doc: &Document, path: PathBuf) -> Ask {
    let Some(surface) = doc.surface().cloned() else {
        return Ask::Notice(notice("there is no mesh for a cage to fit", true));
    };
    Ask::Job(JobStart::new(
        "Cage",
        move |progress| {
            progress.start("read the cage", 1);
            let cage = kapaint_mesh::open(&path).map_err(|e| format!("{}: {e}", path.display()))?;
            kapaint_mesh::bakes::check_cage(&surface.mesh, &cage).map_err(|e| e.to_string())?;
            Ok((path, std::sync::Arc::new(cage)))
        },
        |(path, cage), desk| desk.ask(Ask::CageRead(path, cage)),
    ))
}

/// Each of `maps` baked onto `surface` from `high` through `rays`, a line each on what its
/// rays found into `lines`. AO and thickness rays run on a hardware GPU where this machine has
/// one (a device of the bake's own), else on every core.
fn bake_maps(
    (surface, high, cage, rays): (&Surface, &Mesh, Option<&Mesh>, &HighRays),
    maps: &[HighMap],
    dialog: &HighDialog,
    progress: &kapaint_base::task::Progress,
    lines: &mut Vec<String>,
) -> Result<Vec<kapaint_mesh::bakes::HighBake>, String> {
    let gpu = match rays.single() {
        Some(_) if maps.iter().any(|m| m.casts_rays()) => RaysOn::Auto.open().ok().flatten(),
        _ => None,
    };
    let on_gpu = match (&gpu, rays.single()) {
        (Some(gpu), Some(one)) => GpuCaster::new(gpu, one).ok(),
        _ => None,
    };
    let cpu = CpuCaster(rays.meshes());
    let caster: &dyn RayCaster = on_gpu.as_ref().map_or(&cpu, |g| g);
    let mut bakes = Vec::with_capacity(maps.len());
    for &map in maps {
        let options = HighOptions {
            front: dialog.front,
            rear: dialog.rear,
            rays: dialog.rays,
            samples: dialog.samples,
            ..HighOptions::new(map)
        };
        let start = std::time::Instant::now();
        let b = bake_from_high_on(
            &surface.mesh,
            &surface.bake,
            (high, rays),
            cage,
            options,
            caster,
            Some(progress),
        )
        .map_err(|e| e.to_string())?;
        let share = b.missed as f64 / b.covered.max(1) as f64 * 100.0;
        let on = if b.cast_on.is_empty() {
            String::new()
        } else {
            format!(" on {}", b.cast_on)
        };
        lines.push(format!(
            "baked {} from {}: {} texels, front {:.4} rear {:.4}, missed {} ({share:.3} %), {:.1} s{on}",
            name(b.map),
            high.name,
            b.covered,
            b.front,
            b.rear,
            b.missed,
            start.elapsed().as_secs_f64()
        ));
        bakes.push(b);
    }
    Ok(bakes)
}

/// The maps baked: into the document as one step, with a line each on what the rays found.
fn kept(made: Made, desk: &mut Desk) {
    let lines = made
        .lines
        .into_iter()
        .map(|line| notice(line, false))
        .collect();
    desk.command_saying(made.keep, lines);
}

/// A map's name in notices.
fn name(map: HighMap) -> &'static str {
    match map {
        HighMap::Normal(NormalSpace::Tangent) => "the normal map",
        HighMap::Normal(NormalSpace::Object) => "object-space normal",
        HighMap::Height => "height",
        HighMap::Ao => "ambient occlusion",
        HighMap::Thickness => "thickness",
        HighMap::Curvature => "curvature",
        HighMap::Position => "position",
        HighMap::Id(_) => "IDs",
    }
}

/// The dialog, while `open`: the high meshes and the cage (each chosen through the file
/// chooser), what to bake, the distances, samples and rays, Bake.
pub(super) fn high_window(open: &mut Option<HighDialog>, ctx: &egui::Context, desk: &mut Desk) {
    let Some(dialog) = open else {
        return;
    };
    let doc = desk.doc;
    let (mut shown, mut go) = (true, false);
    centred(egui::Window::new("Bake from high poly"), ctx)
        .open(&mut shown)
        .collapsible(false)
        .resizable(false)
        .show(ctx, |ui| {
            let (w, h) = (doc.maps().width(), doc.maps().height());
            ui.label(format!("Onto {}, at {w}x{h}", doc.settings().mesh.spec()));
            ui.separator();
            ui.label("High-poly meshes (baked as one):");
            for p in &dialog.highs {
                ui.label(format!("  {}", p.display()));
            }
            ui.horizontal(|ui| {
                if ui.button("Add high mesh…").clicked() {
                    desk.ask(Ask::ChooseFile(FilePurpose::HighMesh));
                }
                if ui
                    .add_enabled(!dialog.highs.is_empty(), egui::Button::new("Clear"))
                    .clicked()
                {
                    dialog.highs.clear();
                }
            });
            meshes_and_distances(ui, dialog, desk);
            ui.separator();
            ui.radio_value(&mut dialog.normal_map, true, "Normal map (tangent space)");
            ui.radio_value(&mut dialog.normal_map, false, "Maps for the masks:");
            ui.add_enabled_ui(!dialog.normal_map, |ui| {
                for ((label, _), on) in BAKE_MAPS.iter().zip(&mut dialog.bakes) {
                    ui.checkbox(on, *label);
                }
            });
            ui.horizontal(|ui| {
                egui::ComboBox::from_label("Samples a texel")
                    .selected_text(dialog.samples.to_string())
                    .show_ui(ui, |ui| {
                        for s in SAMPLES {
                            ui.selectable_value(&mut dialog.samples, s, s.to_string());
                        }
                    });
                ui.add(
                    egui::DragValue::new(&mut dialog.rays)
                        .range(1..=4096)
                        .prefix("rays "),
                )
                .on_hover_text("Rays a sample for ambient occlusion and thickness");
            });
            go = ui
                .add_enabled(
                    doc.surface().is_some() && !dialog.highs.is_empty(),
                    egui::Button::new("Bake"),
                )
                .clicked();
        });
    if go {
        desk.ask(bake(doc, dialog));
    }
    if !shown || go {
        *open = None;
    }
}

/// The cage and the ray distances (automatic, or dragged).
fn meshes_and_distances(ui: &mut egui::Ui, dialog: &mut HighDialog, desk: &mut Desk) {
    ui.horizontal(|ui| {
        let cage = dialog
            .cage
            .as_ref()
            .map_or("none: rays along the normals".to_string(), |p| {
                p.display().to_string()
            });
        ui.label(format!("Cage: {cage}"));
        if ui.button("Choose…").clicked() {
            desk.ask(Ask::ChooseFile(FilePurpose::Cage));
        }
        if dialog.cage.is_some() && ui.button("None").clicked() {
            dialog.cage = None;
            dialog.cage_mesh = None;
        }
    });
    ui.checkbox(
        &mut dialog.by_name,
        "Match parts by name (X_low with X_high)",
    )
    .on_hover_text(
        "Each low object or group bakes only from the high ones of its name, so parts \
             never bake onto each other; the rest bake from the high parts of no pair",
    );
    for (label, value) in [("Front", &mut dialog.front), ("Rear", &mut dialog.rear)] {
        ui.horizontal(|ui| {
            let mut auto = value.is_none();
            ui.checkbox(&mut auto, format!("{label}: automatic (2 % of the size)"));
            if auto {
                *value = None;
            } else {
                let v = value.get_or_insert(0.05);
                ui.add(
                    egui::DragValue::new(v)
                        .range(1e-6..=1e6)
                        .speed(0.001)
                        .max_decimals(4),
                );
            }
        });
    }
}
