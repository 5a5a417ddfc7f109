//! Image > Project image: an image painted through a projection (planar, cylindrical,
//! spherical, tri-planar or straight into UV space) into the selected layer, one undo step a
//! Project, as the scripts' `ProjectImage` does. The projection starts from the view: a
//! planar one faces the camera over the mesh's middle.

use glam::{Vec2, Vec3};

use kapaint_core::render::Camera;
use kapaint_model::layers::LayerContent;
use kapaint_model::layers::projected::ProjectionFill;
use kapaint_model::paint::projection::Projection;
use kapaint_model::paint_image::PaintImage;
use kapaint_model::{Channels, Command, Document, LayerCommand, PaintCommand};

use crate::desk::{Ask, Desk, centred};
use crate::files::FilePurpose;

/// The kinds of projection, as the dialog names them.
const KINDS: [&str; 5] = ["Planar", "Cylindrical", "Spherical", "Tri-planar", "UV"];

/// The Project image dialog's choices.
#[derive(Clone, Debug)]
pub struct ProjectDialog {
    /// The image (none until one is chosen).
    pub image: Option<PaintImage>,
    /// How it is laid.
    pub projection: Projection,
    /// The channels it paints.
    pub channels: Channels,
    /// Its strength.
    pub opacity: f32,
}

impl ProjectDialog {
    /// The selected projection fill's choices, or a planar projection facing `camera` over
    /// the middle of `doc`'s mesh, as wide as it.
    pub fn new(doc: &Document, camera: &Camera) -> Self {
        if let Some(fill) = selected_fill(doc) {
            return Self {
                image: Some(fill.image.clone()),
                projection: fill.projection,
                channels: fill.channels,
                opacity: 1.0,
            };
        }
        Self {
            image: None,
            projection: kind_from_view(0, doc, camera),
            channels: Channels::ALL,
            opacity: 1.0,
        }
    }
}

impl ProjectDialog {
    /// Takes `image`; a planar projection takes its aspect (its height from its width), so
    /// the picture lands unstretched.
    pub fn choose(&mut self, image: PaintImage) {
        if let (Projection::Planar { width, height, .. }, Ok(pixels)) =
            (&mut self.projection, image.pixels())
        {
            *height = *width * pixels.aspect();
        }
        self.image = Some(image);
    }
}

/// The selected layer's projection, when it is a projection fill.
fn selected_fill(doc: &Document) -> Option<&ProjectionFill> {
    match &doc.selected_layer()?.content {
        LayerContent::Projected(p) => Some(p.fill()),
        _ => None,
    }
}

/// The name of a projection fill of `image`: its file's stem.
fn fill_name(image: &PaintImage) -> String {
    let stem = image
        .path()
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    kapaint_model::check::fit_name(&stem, " (projection)", "Projection")
}

/// A projection's kind, as the dialog names it.
pub(crate) fn kind_name(projection: &Projection) -> &'static str {
    KINDS[kind_of(projection)]
}

/// The mesh's middle and size (the origin and 1 without a mesh).
fn bounds(doc: &Document) -> (Vec3, f32) {
    doc.surface()
        .map(|s| s.mesh.bounds())
        .filter(|(lo, hi)| lo.is_finite() && hi.is_finite())
        .map_or((Vec3::ZERO, 1.0), |(lo, hi)| {
            ((lo + hi) * 0.5, lo.distance(hi).max(1e-3))
        })
}

/// Projection `kind` (an index of [`KINDS`]) as the view suggests it.
fn kind_from_view(kind: usize, doc: &Document, camera: &Camera) -> Projection {
    let (middle, size) = bounds(doc);
    let toward = (camera.eye() - camera.target).normalize_or(Vec3::Z);
    let across = |v: Vec3, axis: Vec3| (v - axis * v.dot(axis)).normalize_or(Vec3::Z);
    match kind {
        1 => Projection::Cylindrical {
            origin: middle,
            axis: Vec3::Y,
            front: across(toward, Vec3::Y),
            height: size,
        },
        2 => Projection::Spherical {
            origin: middle,
            up: Vec3::Y,
            front: across(toward, Vec3::Y),
        },
        3 => Projection::Triplanar {
            scale: 2.0 / size,
            blend: 0.5,
        },
        4 => Projection::Uv {
            offset: Vec2::ZERO,
            scale: Vec2::ONE,
            rotation: 0.0,
        },
        _ => {
            let up = if toward.dot(Vec3::Y).abs() > 0.99 {
                Vec3::NEG_Z
            } else {
                Vec3::Y
            };
            Projection::Planar {
                origin: middle,
                normal: toward,
                up: across(up, toward),
                width: 0.5 * size,
                height: 0.5 * size,
            }
        }
    }
}

/// The index in [`KINDS`] of `projection`'s kind.
fn kind_of(projection: &Projection) -> usize {
    match projection {
        Projection::Planar { .. } => 0,
        Projection::Cylindrical { .. } => 1,
        Projection::Spherical { .. } => 2,
        Projection::Triplanar { .. } => 3,
        Projection::Uv { .. } => 4,
    }
}

/// Three numbers in a row.
fn vec3_ui(ui: &mut egui::Ui, label: &str, v: &mut Vec3) {
    ui.horizontal(|ui| {
        for a in 0..3 {
            ui.add(egui::DragValue::new(&mut v[a]).speed(0.01).max_decimals(3));
        }
        ui.label(label);
    });
}

/// One number.
fn number_ui(ui: &mut egui::Ui, label: &str, v: &mut f32) {
    ui.horizontal(|ui| {
        ui.add(egui::DragValue::new(v).speed(0.01).max_decimals(3));
        ui.label(label);
    });
}

/// The fields of `projection`'s kind.
fn fields_ui(ui: &mut egui::Ui, projection: &mut Projection) {
    match projection {
        Projection::Planar {
            origin,
            normal,
            up,
            width,
            height,
        } => {
            vec3_ui(ui, "Centre", origin);
            vec3_ui(ui, "From (normal)", normal);
            vec3_ui(ui, "Up", up);
            number_ui(ui, "Width", width);
            number_ui(ui, "Height", height);
        }
        Projection::Cylindrical {
            origin,
            axis,
            front,
            height,
        } => {
            vec3_ui(ui, "Centre", origin);
            vec3_ui(ui, "Axis", axis);
            vec3_ui(ui, "Front", front);
            number_ui(ui, "Height", height);
        }
        Projection::Spherical { origin, up, front } => {
            vec3_ui(ui, "Centre", origin);
            vec3_ui(ui, "Up", up);
            vec3_ui(ui, "Front", front);
        }
        Projection::Triplanar { scale, blend } => {
            number_ui(ui, "Repeats per unit", scale);
            ui.add(egui::Slider::new(blend, 0.01..=1.0).text("Blend"));
        }
        Projection::Uv {
            offset,
            scale,
            rotation,
        } => {
            ui.horizontal(|ui| {
                ui.add(egui::DragValue::new(&mut offset.x).speed(0.01));
                ui.add(egui::DragValue::new(&mut offset.y).speed(0.01));
                ui.label("Offset (images)");
            });
            ui.horizontal(|ui| {
                ui.add(egui::DragValue::new(&mut scale.x).speed(0.01));
                ui.add(egui::DragValue::new(&mut scale.y).speed(0.01));
                ui.label("Repeats per map");
            });
            ui.add(egui::Slider::new(rotation, -180.0..=180.0).text("Rotation"));
        }
    }
}

/// What the window's buttons do.
#[derive(Clone, Copy, Debug)]
enum Action {
    /// Paint into the selected layer.
    Project,
    /// Add a projection fill.
    NewFill,
    /// Change the selected projection fill.
    UpdateFill,
}

impl Action {
    fn command(self, dialog: &ProjectDialog, image: PaintImage) -> Command {
        let (projection, channels) = (dialog.projection, dialog.channels);
        match self {
            Self::Project => PaintCommand::ProjectImage {
                image,
                projection,
                channels,
                opacity: dialog.opacity,
            }
            .into(),
            Self::NewFill => LayerCommand::AddProjectionFill {
                name: fill_name(&image),
                image,
                projection,
                channels,
            }
            .into(),
            Self::UpdateFill => LayerCommand::SetLayerProjection {
                image,
                projection,
                channels,
            }
            .into(),
        }
    }
}

/// Project, New fill layer and (with a projection fill selected) Update the fill: the one
/// clicked, enabled once an image is chosen.
fn actions_ui(ui: &mut egui::Ui, ready: bool, editing: bool) -> Option<Action> {
    let buttons = [
        (
            Action::Project,
            "Project",
            "Paint the image into the selected layer through the projection (one undo step)",
        ),
        (
            Action::NewFill,
            "New fill layer",
            "Add a fill layer that keeps this projection, laid again when the mesh changes",
        ),
        (
            Action::UpdateFill,
            "Update the fill",
            "Give the selected projection fill these choices (one undo step)",
        ),
    ];
    let mut go = None;
    ui.horizontal(|ui| {
        for (action, text, hover) in buttons {
            let shown = !matches!(action, Action::UpdateFill) || editing;
            if shown
                && ui
                    .add_enabled(ready, egui::Button::new(text))
                    .on_hover_text(hover)
                    .clicked()
            {
                go = Some(action);
            }
        }
    });
    go
}

/// The Project image window, while `open`: the image, the projection and its fields (from
/// the view of `camera`), the channels, the opacity, Project.
pub(crate) fn project_window(
    open: &mut Option<ProjectDialog>,
    camera: &Camera,
    ctx: &egui::Context,
    desk: &mut Desk,
) {
    let Some(dialog) = open else {
        return;
    };
    let doc = desk.doc;
    let mut shown = true;
    let mut go: Option<Action> = None;
    let editing = selected_fill(doc).is_some();
    centred(egui::Window::new("Project image"), ctx)
        .open(&mut shown)
        .collapsible(false)
        .resizable(false)
        .show(ctx, |ui| {
            ui.horizontal(|ui| {
                ui.label("Image");
                let name = dialog
                    .image
                    .as_ref()
                    .and_then(|i| i.path().file_name())
                    .map_or("none".into(), |n| n.to_string_lossy().into_owned());
                ui.label(name);
                if ui.button("Choose…").clicked() {
                    desk.ask(Ask::ChooseFile(FilePurpose::ProjectImage));
                }
            });
            let mut kind = kind_of(&dialog.projection);
            egui::ComboBox::from_label("Projection")
                .selected_text(KINDS[kind])
                .show_ui(ui, |ui| {
                    for (k, name) in KINDS.iter().enumerate() {
                        ui.selectable_value(&mut kind, k, *name);
                    }
                });
            if kind != kind_of(&dialog.projection) {
                dialog.projection = kind_from_view(kind, doc, camera);
            }
            fields_ui(ui, &mut dialog.projection);
            if ui
                .button("From the view")
                .on_hover_text("Centre it on the mesh, facing the camera")
                .clicked()
            {
                dialog.projection = kind_from_view(kind, doc, camera);
            }
            ui.horizontal(|ui| {
                ui.checkbox(&mut dialog.channels.kd, "k_d");
                ui.checkbox(&mut dialog.channels.ks, "k_s");
                ui.checkbox(&mut dialog.channels.n, "n");
            });
            ui.add(egui::Slider::new(&mut dialog.opacity, 0.0..=1.0).text("Opacity"));
            go = actions_ui(ui, dialog.image.is_some(), editing);
        });
    if let (Some(action), Some(image)) = (go, dialog.image.clone()) {
        desk.command(action.command(dialog, image));
    }
    if !shown {
        *open = None;
    }
}
