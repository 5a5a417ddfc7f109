//! What the tools draw over the 3D viewport: the decal being placed (its outline and
//! handles) and the stencil on the screen, on each picture; and the clone source's marker,
//! which the canvas and the viewport draw; and the cage a bake from a high mesh would cast from.

use egui::Rect;
use glam::Vec2;
use kapaint_model::paint::Stencil;
use kapaint_tools::Overlay;

use crate::stencil_view::StencilOverlay;
use crate::viewport::Viewport;

/// The painter over the viewport's response, clipped to it.
fn painter(response: &egui::Response) -> egui::Painter {
    response
        .ctx
        .layer_painter(response.layer_id)
        .with_clip_rect(response.rect)
}

/// The decal being placed (`overlay`, the active tool's): its outline and handles on each
/// picture, drawn through the camera (dark under light, so they show on any material).
pub(crate) fn decal_outline(
    response: &egui::Response,
    viewport: &Viewport,
    rect: Rect,
    overlay: Option<Overlay>,
) {
    let Some(Overlay::Decal { corners, handles }) = overlay else {
        return;
    };
    let painter = painter(response);
    for picture in viewport.pictures(rect) {
        let view_proj = viewport
            .camera
            .view_proj(picture.width() / picture.height().max(1.0));
        let on_screen = |p| crate::project(view_proj, picture, p);
        let Some(outline) = corners
            .iter()
            .map(|&c| on_screen(c))
            .collect::<Option<Vec<_>>>()
        else {
            continue;
        };
        for (width, colour) in [(3.0, egui::Color32::BLACK), (1.0, egui::Color32::WHITE)] {
            painter.add(egui::Shape::closed_line(
                outline.clone(),
                egui::Stroke::new(width, colour),
            ));
        }
        let [scale, turn] = handles.map(on_screen);
        if let (Some(turn), Some(top)) = (turn, on_screen((corners[0] + corners[1]) * 0.5)) {
            painter.line_segment([top, turn], egui::Stroke::new(1.0, egui::Color32::WHITE));
        }
        for handle in [scale, turn].into_iter().flatten() {
            painter.circle(
                handle,
                5.0,
                egui::Color32::WHITE,
                egui::Stroke::new(1.5, egui::Color32::BLACK),
            );
        }
    }
}

/// A stencil on the screen over each picture of the viewport.
pub(crate) fn screen_stencil(
    response: &egui::Response,
    (viewport, rect): (&Viewport, Rect),
    overlay: &mut StencilOverlay,
    stencil: &Stencil,
) {
    let painter = painter(response);
    for picture in viewport.pictures(rect) {
        let size = Vec2::new(picture.width(), picture.height());
        overlay.draw(&painter.with_clip_rect(picture), picture, size, stencil);
    }
}

/// The clone source's marker at `c`: a circle and a cross, white over black.
pub(crate) fn clone_marker(painter: &egui::Painter, c: egui::Pos2) {
    for (width, colour) in [(3.0, egui::Color32::BLACK), (1.0, egui::Color32::WHITE)] {
        let stroke = egui::Stroke::new(width, colour);
        painter.circle_stroke(c, 6.0, stroke);
        painter.line_segment(
            [c - egui::vec2(10.0, 0.0), c + egui::vec2(10.0, 0.0)],
            stroke,
        );
        painter.line_segment(
            [c - egui::vec2(0.0, 10.0), c + egui::vec2(0.0, 10.0)],
            stroke,
        );
    }
}

/// Most triangles the cage preview draws (spread over the mesh): a wireframe stays light on
/// any mesh.
const CAGE_TRIANGLES: usize = 20_000;

/// Mesh > Bake from high poly's cage while its dialog (`dialog`) is open: the chosen cage file
/// once read, else `mesh` pushed out along its normals by the front distance (the dialog's, or
/// by default 2 % of the mesh's diagonal, as the bake's default reads the meshes' size), drawn
/// as a wireframe of the faces turned to the camera on each picture, so the distance is seen
/// while it is dragged.
pub(crate) fn cage_preview(
    response: &egui::Response,
    viewport: &Viewport,
    rect: Rect,
    mesh: &kapaint_mesh::Mesh,
    dialog: Option<&crate::bake_high::HighDialog>,
) {
    let Some(dialog) = dialog else {
        return;
    };
    let front = dialog.front.unwrap_or_else(|| {
        let (lo, hi) = mesh.bounds();
        (hi - lo).length() * kapaint_mesh::bakes::DEFAULT_DISTANCE
    });
    let painter = painter(response);
    let stride = mesh.triangles.len().div_ceil(CAGE_TRIANGLES).max(1);
    let colour = egui::Color32::from_rgba_unmultiplied(255, 190, 60, 150);
    // A chosen cage, once read, as it is; else the mesh pushed out by the front distance.
    let cage = dialog
        .cage_mesh
        .as_deref()
        .filter(|c| c.positions.len() == mesh.positions.len());
    let pushed = |v: u32| {
        let v = v as usize;
        match cage {
            Some(c) => c.positions[v],
            None => mesh.positions[v] + mesh.normals.get(v).copied().unwrap_or_default() * front,
        }
    };
    for picture in viewport.pictures(rect) {
        let view_proj = viewport
            .camera
            .view_proj(picture.width() / picture.height().max(1.0));
        for t in mesh.triangles.iter().step_by(stride) {
            let Some(corners) = t
                .iter()
                .map(|&v| crate::project(view_proj, picture, pushed(v)))
                .collect::<Option<Vec<_>>>()
            else {
                continue;
            };
            let (a, b) = (corners[1] - corners[0], corners[2] - corners[0]);
            // A face turned to the camera winds one way on the screen (y grows down), and a
            // corner with no finite place (a normal that is not one) draws nothing.
            let facing = a.x * b.y - a.y * b.x > 0.0;
            let span = picture.size().length();
            if !facing || a.length() > span || b.length() > span {
                continue;
            }
            // Segments, not a closed path: a thin triangle's path joins spike far out.
            for k in 0..3 {
                painter.line_segment(
                    [corners[k], corners[(k + 1) % 3]],
                    egui::Stroke::new(1.0, colour),
                );
            }
        }
    }
}
