//! The stencil in the editor: its picture over the UV canvas, or over the 3D viewport's
//! picture when it lies on the screen (hidden while a stroke paints), moved by a right-drag,
//! scaled by Shift+right-drag and turned by Ctrl+right-drag (in the viewport, a drag that
//! starts on the stencil; elsewhere the right button still orbits); and its section of the
//! tool panel (load, where it lies, size, rotation, opacity, tiling, clear). The stencil
//! itself is the document's: every change is a `SetStencil` naming its image again, and a
//! stencil on the screen follows the viewport's camera the same way.

use std::sync::Arc;

use egui::{Color32, Pos2, Rect, TextureHandle};
use glam::Vec2;

use kapaint_core::render::Camera;
use kapaint_model::paint::{ScreenView, Stencil};
use kapaint_model::paint_image::Pixels;
use kapaint_model::{Document, SettingsCommand};
use kapaint_tools::ToolKind;

use crate::desk::{Ask, Desk};
use crate::files::FilePurpose;

/// Largest side of the stencil's picture on the canvas (it is a guide, not the stencil).
const PICTURE_SIDE: u32 = 512;

/// The tools that paint through a stencil.
pub(crate) fn paints_through(tool: ToolKind) -> bool {
    [ToolKind::BRUSH, ToolKind::ERASER, ToolKind::CLONE].contains(&tool)
}

/// The stencil's placement as the panel and the drags change it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Placement {
    pub(crate) center: Vec2,
    pub(crate) size: f32,
    pub(crate) rotation: f32,
    pub(crate) opacity: f32,
    pub(crate) tiled: bool,
    /// The view whose screen it lies on (none: the canvas).
    pub(crate) view: Option<ScreenView>,
}

impl Placement {
    fn of(stencil: &Stencil) -> Self {
        Self {
            center: stencil.center,
            size: stencil.size,
            rotation: stencil.rotation,
            opacity: stencil.opacity,
            tiled: stencil.tiled,
            view: stencil.view,
        }
    }

    /// Over the middle of the map, half its width wide.
    pub(crate) fn on_canvas(doc: &Document) -> Self {
        let (w, h) = (doc.maps().width() as f32, doc.maps().height() as f32);
        Self {
            center: Vec2::new(w, h) * 0.5,
            size: 0.5 * w,
            rotation: 0.0,
            opacity: 1.0,
            tiled: false,
            view: None,
        }
    }

    /// Over the middle of the viewport's picture, half its width wide.
    pub(crate) fn on_screen(view: ScreenView) -> Self {
        Self {
            center: view.size * 0.5,
            size: 0.5 * view.size.x,
            rotation: 0.0,
            opacity: 1.0,
            tiled: false,
            view: Some(view),
        }
    }
}

/// The view a picture of the viewport shows: `camera`'s, onto `picture` (points).
pub(crate) fn screen_view(camera: &Camera, picture: Rect) -> ScreenView {
    ScreenView {
        eye: camera.eye(),
        target: camera.target,
        up: glam::Vec3::Y,
        fov: camera.fov_y.to_degrees(),
        size: Vec2::new(picture.width().max(1.0), picture.height().max(1.0)),
    }
}

/// The command that keeps a stencil on the screen on the viewport's `view` as the camera
/// moves (none for a stencil on the canvas, or one already there).
pub(crate) fn follow(doc: &Document, view: ScreenView) -> Option<SettingsCommand> {
    let stencil = doc.stencil()?;
    let mut p = Placement::of(stencil);
    if p.view.is_none() || p.view == Some(view) {
        return None;
    }
    p.view = Some(view);
    place(doc, p)
}

/// Whether a right-drag from `at` (points from the picture's corner) takes hold of a stencil
/// on the screen: it starts inside the stencil's frame.
pub(crate) fn holds(stencil: &Stencil, at: Vec2) -> bool {
    let uv = stencil.uv(at);
    stencil.view.is_some() && (0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y)
}

/// The command that places the document's stencil as `placement` says (none without one).
pub(crate) fn place(doc: &Document, placement: Placement) -> Option<SettingsCommand> {
    Some(placed(doc.stencil_image()?.clone(), placement))
}

/// The command that places a stencil of `image` as `placement` says.
pub(crate) fn placed(
    image: kapaint_model::paint_image::PaintImage,
    placement: Placement,
) -> SettingsCommand {
    SettingsCommand::SetStencil {
        image,
        center: placement.center,
        size: placement.size,
        rotation: placement.rotation,
        opacity: placement.opacity,
        tiled: placement.tiled,
        view: placement.view,
    }
}

/// The document's stencil moved by a right-drag of `delta` points on a canvas showing
/// `texels_per_point`: moved, or with Shift scaled (right grows it), or with Ctrl turned
/// (right turns it clockwise).
pub(crate) fn dragged(
    doc: &Document,
    delta: egui::Vec2,
    texels_per_point: f32,
    modifiers: egui::Modifiers,
) -> Option<SettingsCommand> {
    let stencil = doc.stencil()?;
    let mut p = Placement::of(stencil);
    if modifiers.command {
        p.rotation += delta.x * 0.5;
    } else if modifiers.shift {
        p.size = (p.size * (delta.x * 0.01).exp()).max(1.0);
    } else {
        p.center += Vec2::new(delta.x, delta.y) * texels_per_point;
    }
    (p != Placement::of(stencil))
        .then(|| place(doc, p))
        .flatten()
}

/// The stencil's picture on the canvas, made once per image.
#[derive(Default)]
pub(crate) struct StencilOverlay {
    /// The image shown (held, so it is known by itself, never by an address another image
    /// may come to have) and its picture.
    texture: Option<(Arc<Pixels>, TextureHandle)>,
}

impl StencilOverlay {
    /// The picture of `stencil`'s image, made when the image is not the one shown.
    fn texture(&mut self, ctx: &egui::Context, stencil: &Stencil) -> &TextureHandle {
        let shown = &stencil.image;
        if self
            .texture
            .as_ref()
            .is_some_and(|(image, _)| !Arc::ptr_eq(image, shown))
        {
            self.texture = None;
        }
        let (_, texture) = self.texture.get_or_insert_with(|| {
            let picture = picture(stencil);
            let texture = ctx.load_texture("stencil", picture, egui::TextureOptions::LINEAR);
            (Arc::clone(shown), texture)
        });
        texture
    }

    /// Draws `stencil` over what `map` shows (a map of `size` texels, or a viewport's picture
    /// of `size` points): its picture, translucent, and its frame.
    pub(crate) fn draw(
        &mut self,
        painter: &egui::Painter,
        map: Rect,
        size: Vec2,
        stencil: &Stencil,
    ) {
        let texture = self.texture(painter.ctx(), stencil).id();
        let to_screen = |p: Vec2| map.min + egui::vec2(p.x / size.x, p.y / size.y) * map.size();
        let (sin, cos) = stencil.rotation.to_radians().sin_cos();
        let half = Vec2::new(stencil.size, stencil.size * stencil.image.aspect()) * 0.5;
        let corner = |sx: f32, sy: f32| {
            let l = Vec2::new(sx * half.x, sy * half.y);
            to_screen(stencil.center + Vec2::new(l.x * cos - l.y * sin, l.x * sin + l.y * cos))
        };
        let corners = [
            corner(-1.0, -1.0),
            corner(1.0, -1.0),
            corner(1.0, 1.0),
            corner(-1.0, 1.0),
        ];
        {
            let mut mesh = egui::Mesh::with_texture(texture);
            let uvs = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
            for (pos, (u, v)) in corners.into_iter().zip(uvs) {
                mesh.vertices.push(egui::epaint::Vertex {
                    pos,
                    uv: Pos2::new(u, v),
                    color: Color32::from_white_alpha(110),
                });
            }
            mesh.add_triangle(0, 1, 2);
            mesh.add_triangle(0, 2, 3);
            painter.add(egui::Shape::mesh(mesh));
        }
        for (width, colour) in [(3.0, Color32::BLACK), (1.0, Color32::WHITE)] {
            painter.add(egui::Shape::closed_line(
                corners.to_vec(),
                egui::Stroke::new(width, colour),
            ));
        }
    }
}

/// What the stencil lets through, as a grey picture at most [`PICTURE_SIDE`] a side: white
/// where it paints, clear where it holds the paint back.
fn picture(stencil: &Stencil) -> egui::ColorImage {
    let image = &stencil.image;
    let scale = (PICTURE_SIDE as f32 / image.width().max(image.height()) as f32).min(1.0);
    let w = ((image.width() as f32 * scale).round() as usize).max(1);
    let h = ((image.height() as f32 * scale).round() as usize).max(1);
    let mut pixels = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let uv = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
            let s = image.sample(uv, false);
            let weight = (s.gray * s.alpha).clamp(0.0, 1.0);
            pixels.push(Color32::from_white_alpha((weight * 255.0 + 0.5) as u8));
        }
    }
    egui::ColorImage::new([w, h], pixels)
}

/// The stencil's section of the tool panel.
pub(crate) fn panel_ui(ui: &mut egui::Ui, desk: &mut Desk) {
    let doc = desk.doc;
    ui.horizontal(|ui| {
        ui.label("Stencil");
        let name = doc
            .stencil_image()
            .and_then(|i| i.path().file_name())
            .map_or("none".into(), |n| n.to_string_lossy().into_owned());
        ui.label(name);
        if ui
            .button("Load stencil…")
            .on_hover_text(
                "Paint through an image: its light parts let the paint through. On the canvas, \
                 right-drag moves it, Shift+right-drag scales it, Ctrl+right-drag turns it",
            )
            .clicked()
        {
            desk.ask(Ask::ChooseFile(FilePurpose::StencilImage));
        }
        if doc.stencil().is_some() && ui.button("Clear").clicked() {
            desk.command(SettingsCommand::ClearStencil);
        }
    });
    let Some(stencil) = doc.stencil() else {
        return;
    };
    let before = Placement::of(stencil);
    let mut p = before;
    ui.horizontal(|ui| {
        ui.label("Lies on");
        if ui
            .selectable_label(p.view.is_none(), "Canvas")
            .on_hover_text("On the UV canvas: strokes on the mesh read it where their texels lie")
            .clicked()
            && p.view.is_some()
        {
            p = Placement {
                opacity: p.opacity,
                tiled: p.tiled,
                ..Placement::on_canvas(doc)
            };
        }
        let screen = ui
            .add_enabled(
                desk.screen_view.is_some(),
                egui::Button::selectable(p.view.is_some(), "Viewport"),
            )
            .on_hover_text(
                "On the 3D viewport's screen, projected through the view onto the mesh \
                 (right-drag on it moves it there)",
            )
            .on_disabled_hover_text("Needs the 3D viewport shown");
        if screen.clicked()
            && p.view.is_none()
            && let Some(view) = desk.screen_view
        {
            p = Placement {
                opacity: p.opacity,
                tiled: p.tiled,
                ..Placement::on_screen(view)
            };
        }
    });
    let width = match p.view {
        Some(view) => view.size.x,
        None => doc.maps().width() as f32,
    };
    ui.add(
        egui::Slider::new(&mut p.size, 1.0..=4.0 * width)
            .logarithmic(true)
            .text("Stencil size"),
    )
    .on_hover_text("Its width in texels (on the viewport, in points)");
    ui.add(egui::Slider::new(&mut p.rotation, -180.0..=180.0).text("Stencil rotation"));
    ui.add(egui::Slider::new(&mut p.opacity, 0.0..=1.0).text("Stencil opacity"))
        .on_hover_text("How much it holds the paint back (0: not at all)");
    ui.checkbox(&mut p.tiled, "Tile the stencil")
        .on_hover_text("Repeat the image beyond its edges");
    if p != before
        && let Some(command) = place(doc, p)
    {
        desk.command(command);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stencil of an 8 x 8 image of one grey.
    fn stencil(grey: u8) -> Stencil {
        let image = image::DynamicImage::ImageLuma8(image::GrayImage::from_pixel(
            8,
            8,
            image::Luma([grey]),
        ));
        let image = kapaint_model::paint_image::PaintImage::decoded(
            std::path::Path::new("stencil.png"),
            &image,
        )
        .expect("decoded");
        let pixels = Arc::clone(image.pixels().expect("loaded"));
        Stencil::new(pixels, Vec2::ZERO, 8.0, 0.0)
    }

    /// Regression: the picture was known by the address of the image it showed, and a new
    /// image allocated where a dropped one had been kept the old picture.
    #[test]
    fn a_new_image_gets_its_own_picture_even_where_the_old_one_lay() {
        let ctx = egui::Context::default();
        let mut overlay = StencilOverlay::default();
        let first = stencil(255);
        let shown = overlay.texture(&ctx, &first).id();
        assert_eq!(overlay.texture(&ctx, &first).id(), shown, "made once");
        drop(first);
        // The same size of image again, as often as it takes the allocator to reuse the
        // old place (it usually does at once).
        for _ in 0..64 {
            let next = stencil(0);
            assert_ne!(
                overlay.texture(&ctx, &next).id(),
                shown,
                "another image, the old picture"
            );
        }
    }
}
