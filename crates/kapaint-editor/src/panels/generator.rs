//! The Layers tab's mask generator: what makes the selected layer's mask (paint alone, a bake
//! through levels, noise, a gradient, facing, or a smart mask), its parameters, a live
//! thumbnail, and the smart masks to apply or save. Dragging a parameter previews coarsely
//! (`PreviewMaskGenerator`); letting go sets it (`SetMaskGenerator`), the drag one undo step.

use kapaint_model::generator::{Axis, BlendOp, Generator, Levels, Noise, NoiseKind, Space};
use kapaint_model::layers::{Layer, thumbnail};
use kapaint_model::{Document, MaskCommand};

use super::layers::LayersPanel;
use super::presets::{Naming, Presets};
use crate::desk::{Ask, Desk};

/// The live thumbnail's side in texels and on screen.
const THUMB: u32 = 96;

/// The kinds the panel offers, with a generator of each to start from.
fn kinds() -> [(&'static str, Option<Generator>); 7] {
    let levels = |black, white, invert| Levels {
        black,
        white,
        gamma: 1.0,
        invert,
        relative: false,
    };
    [
        ("Paint only", None),
        ("AO bake", Some(Generator::Ao(levels(0.4, 0.9, true)))),
        (
            "Curvature bake",
            Some(Generator::Curvature(levels(0.52, 0.62, false))),
        ),
        (
            "Thickness bake",
            Some(Generator::Thickness(levels(0.0, 0.5, true))),
        ),
        (
            "Noise",
            Some(Generator::Noise(Noise {
                kind: NoiseKind::Perlin,
                scale: 8.0,
                octaves: 4,
                seed: 1,
                space: Space::Object,
            })),
        ),
        (
            "Gradient",
            Some(Generator::Gradient {
                axis: Axis::Y,
                from: 0.0,
                to: 1.0,
            }),
        ),
        (
            "Facing",
            Some(Generator::Facing {
                axis: Axis::Y,
                levels: levels(0.7, 0.95, false),
            }),
        ),
    ]
}

/// The name of what makes a mask.
fn kind_name(g: Option<&Generator>) -> &'static str {
    match g {
        None => "Paint only",
        Some(Generator::Ao(_)) => "AO bake",
        Some(Generator::Curvature(_)) => "Curvature bake",
        Some(Generator::Thickness(_)) => "Thickness bake",
        Some(Generator::Noise(_)) => "Noise",
        Some(Generator::Gradient { .. }) => "Gradient",
        Some(Generator::Facing { .. }) => "Facing",
        Some(Generator::Remap { .. }) => "Levels of a generator",
        Some(Generator::Blend { .. }) => "Blend (a smart mask)",
    }
}

/// What the widgets did this frame.
#[derive(Default)]
struct Edit {
    changed: bool,
    dragging: bool,
    released: bool,
}

impl Edit {
    fn read(&mut self, r: &egui::Response) {
        self.changed |= r.changed();
        self.dragging |= r.dragged();
        self.released |= r.drag_stopped();
    }
}

/// Black, white, gamma and invert; for a bake (`bake`), whether they are relative to the
/// mesh.
fn levels_ui(ui: &mut egui::Ui, l: &mut Levels, bake: bool, edit: &mut Edit) {
    edit.read(&ui.add(egui::Slider::new(&mut l.black, 0.0..=0.999).text("Black")));
    edit.read(&ui.add(egui::Slider::new(&mut l.white, 0.001..=1.0).text("White")));
    edit.read(
        &ui.add(
            egui::Slider::new(&mut l.gamma, 0.05..=20.0)
                .logarithmic(true)
                .text("Gamma"),
        ),
    );
    edit.read(&ui.checkbox(&mut l.invert, "Invert"));
    if bake {
        edit.read(&ui.checkbox(&mut l.relative, "Relative to this mesh").on_hover_text(
            "Black and white are places in the mesh's own spread of the bake (0.9: the value \
             90 % of the surface lies below), so the same levels fit any mesh",
        ));
    }
    // Black stays below white, whichever moved.
    if l.black >= l.white {
        if l.white >= 0.999 {
            l.black = l.white - 0.001;
        } else {
            l.white = (l.black + 0.001).min(1.0);
        }
    }
}

/// A combo box of `options` for `value`.
fn choice<T: Copy + PartialEq>(
    ui: &mut egui::Ui,
    label: &str,
    value: &mut T,
    options: &[(T, &str)],
    edit: &mut Edit,
) {
    let shown = options
        .iter()
        .find(|(v, _)| v == value)
        .map_or("", |(_, n)| n);
    egui::ComboBox::from_label(label)
        .selected_text(shown)
        .show_ui(ui, |ui| {
            for (v, name) in options {
                if ui.selectable_label(v == value, *name).clicked() && v != value {
                    *value = *v;
                    edit.changed = true;
                }
            }
        });
}

const AXES: [(Axis, &str); 3] = [(Axis::X, "X"), (Axis::Y, "Y (up)"), (Axis::Z, "Z")];

/// The parameters of `g`, edited in place.
fn parameters_ui(ui: &mut egui::Ui, g: &mut Generator, edit: &mut Edit) {
    match g {
        Generator::Ao(l) | Generator::Curvature(l) | Generator::Thickness(l) => {
            levels_ui(ui, l, true, edit);
        }
        Generator::Noise(n) => {
            choice(
                ui,
                "Noise",
                &mut n.kind,
                &[
                    (NoiseKind::Perlin, "Perlin fBm"),
                    (NoiseKind::Simplex, "Simplex fBm"),
                    (NoiseKind::Worley, "Worley cells"),
                ],
                edit,
            );
            edit.read(
                &ui.add(
                    egui::Slider::new(&mut n.scale, 0.25..=256.0)
                        .logarithmic(true)
                        .text("Scale"),
                ),
            );
            edit.read(&ui.add(egui::Slider::new(&mut n.octaves, 1..=8).text("Octaves")));
            ui.horizontal(|ui| {
                ui.label("Seed");
                edit.read(&ui.add(egui::DragValue::new(&mut n.seed).range(0..=u32::MAX)));
            });
            choice(
                ui,
                "Space",
                &mut n.space,
                &[
                    (Space::Object, "Object (no seams)"),
                    (Space::Triplanar, "Triplanar"),
                    (Space::Uv, "UV"),
                ],
                edit,
            );
        }
        Generator::Gradient { axis, from, to } => {
            choice(ui, "Axis", axis, &AXES, edit);
            edit.read(&ui.add(egui::Slider::new(from, -1.0..=2.0).text("From")));
            edit.read(&ui.add(egui::Slider::new(to, -1.0..=2.0).text("To")));
            if from == to {
                *to = *from + 0.001;
            }
        }
        Generator::Facing { axis, levels } => {
            choice(ui, "Faces along", axis, &AXES, edit);
            levels_ui(ui, levels, false, edit);
        }
        Generator::Remap { levels, of } => {
            levels_ui(ui, levels, false, edit);
            ui.collapsing("Of", |ui| parameters_ui(ui, of, edit));
        }
        Generator::Blend { op, a, b } => {
            choice(
                ui,
                "Blend",
                op,
                &[
                    (BlendOp::Multiply, "Multiply"),
                    (BlendOp::Min, "Min"),
                    (BlendOp::Max, "Max"),
                    (BlendOp::Add, "Add"),
                ],
                edit,
            );
            ui.collapsing(format!("A: {}", kind_name(Some(a))), |ui| {
                parameters_ui(ui, a, edit);
            });
            ui.collapsing(format!("B: {}", kind_name(Some(b))), |ui| {
                parameters_ui(ui, b, edit);
            });
        }
    }
}

impl LayersPanel {
    /// What makes the selected layer's mask, its parameters and thumbnail, and smart masks.
    pub(super) fn generator_ui(
        &mut self,
        ui: &mut egui::Ui,
        desk: &mut Desk,
        layer: &Layer,
        presets: &mut Presets,
    ) {
        let doc = desk.doc;
        let current = layer.mask.as_ref().and_then(|m| m.generator()).cloned();
        let mut commands = Vec::new();
        // A generator to lay, baking first what it reads and the project lacks.
        let mut baking: Option<Generator> = None;
        ui.separator();
        ui.horizontal(|ui| {
            egui::ComboBox::from_label("Mask made by")
                .selected_text(kind_name(current.as_ref()))
                .show_ui(ui, |ui| {
                    for (name, g) in kinds() {
                        let on = name == kind_name(current.as_ref());
                        if ui.selectable_label(on, name).clicked() && !on {
                            match g {
                                Some(g) => baking = Some(g),
                                None => commands.push(MaskCommand::SetMaskGenerator(None)),
                            }
                        }
                    }
                });
        });
        ui.horizontal(|ui| {
            let mut chosen = None;
            egui::ComboBox::from_label("Smart mask")
                .selected_text(
                    presets
                        .masks
                        .iter()
                        .find(|p| Some(&p.mask) == current.as_ref())
                        .map_or("(apply one)", |p| p.name.as_str()),
                )
                .show_ui(ui, |ui| {
                    for p in &presets.masks {
                        if ui.selectable_label(false, &p.name).clicked() {
                            chosen = Some(p.mask.clone());
                        }
                    }
                });
            if let Some(g) = chosen {
                baking = Some(g);
            }
        });
        if let Some(g) = &current {
            let mut edited = g.clone();
            let mut edit = Edit::default();
            // Room to drag a parameter finely.
            ui.spacing_mut().slider_width = ui.spacing().slider_width.max(160.0);
            parameters_ui(ui, &mut edited, &mut edit);
            let missing: Vec<&str> = edited
                .bakes_needed()
                .into_iter()
                .filter(|&m| doc.bake_of(m).is_none())
                .map(kapaint_mesh::bakes::BakeMap::name)
                .collect();
            if edit.released || (edit.changed && (!edit.dragging || !missing.is_empty())) {
                baking = Some(edited);
            } else if edit.changed {
                commands.push(MaskCommand::PreviewMaskGenerator(edited));
            }
            if !missing.is_empty() {
                ui.label(
                    egui::RichText::new(format!(
                        "No {} bake yet: it is baked before the mask is laid",
                        missing.join(" or ")
                    ))
                    .weak(),
                );
            }
            self.generator_thumb_ui(ui, doc, layer);
            presets.naming_ui(ui, desk, Naming::Mask, "Save as smart mask…");
        }
        for c in commands {
            desk.command(c);
        }
        if let Some(g) = baking {
            desk.ask(Ask::LayGenerator(g));
        }
    }

    /// The selected layer's mask as it applies, made again when the document changes.
    fn generator_thumb_ui(&mut self, ui: &mut egui::Ui, doc: &Document, layer: &Layer) {
        let version = (doc.instance(), doc.version());
        let thumb = &mut self.generator_thumb;
        if thumb.as_ref().is_none_or(|(v, _)| *v != version)
            && let Some(pixels) = thumbnail::mask(doc.stack(), layer, THUMB)
        {
            let side = usize::try_from(THUMB).unwrap_or(1);
            let image =
                egui::ColorImage::from_rgba_unmultiplied([side, side], pixels.as_flattened());
            if let Some((v, handle)) = thumb {
                handle.set(image, egui::TextureOptions::LINEAR);
                *v = version;
            } else {
                let handle =
                    ui.ctx()
                        .load_texture("mask generator", image, egui::TextureOptions::LINEAR);
                *thumb = Some((version, handle));
            }
        }
        if let Some((_, handle)) = thumb {
            ui.add(
                egui::Image::new((handle.id(), egui::Vec2::splat(THUMB as f32)))
                    .alt_text("The mask as it applies"),
            );
        }
    }
}
