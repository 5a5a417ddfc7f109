//! What the tools draw over the 3D viewport: the stencil on the screen (kept on the
//! camera's view, moved by a right-drag that starts on it), the decal being placed (its
//! outline and handles) and the mesh clone source's marker; and the clone marker's shape,
//! which the canvas draws too.

use glam::Vec2;
use kapaint_tools::Overlay;

use super::EditorState;

impl EditorState {
    /// The decal being placed: its outline and handles on each picture, drawn through the
    /// camera (dark under light, so they show on any material).
    pub(super) fn draw_decal_outline(&self, response: &egui::Response, rect: egui::Rect) {
        let Some(Overlay::Decal { corners, handles }) = self.tools.overlay() else {
            return;
        };
        let painter = response
            .ctx
            .layer_painter(response.layer_id)
            .with_clip_rect(response.rect);
        let columns = self.viewport.comparison.mode.columns();
        for k in 0..columns {
            let x = rect.min.x + rect.width() * (k as f32 + 0.5) / columns as f32;
            let picture = self
                .viewport
                .picture_at(rect, egui::pos2(x, rect.center().y));
            let view_proj = self
                .viewport
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

    /// The stencil on the viewport's screen: kept on the camera's view, moved (scaled, turned)
    /// by a right-drag that starts on it, drawn over each picture unless a stroke paints.
    pub(super) fn screen_stencil(&mut self, response: &egui::Response, rect: egui::Rect) {
        let view = crate::stencil_view::screen_view(
            &self.viewport.camera,
            self.viewport.picture_at(rect, rect.min),
        );
        self.pointer.screen_view = Some(view);
        if let Some(command) = crate::stencil_view::follow(&self.doc, view) {
            self.apply(command);
        }
        let stencil = self
            .doc
            .stencil()
            .filter(|s| {
                s.view.is_some() && crate::stencil_view::paints_through(self.tools.active())
            })
            .cloned();
        self.viewport.stencil.clone_from(&stencil);
        let Some(stencil) = stencil else {
            return;
        };
        if response.dragged_by(egui::PointerButton::Secondary)
            && self.viewport.stencil_held(&response.ctx, rect)
        {
            let modifiers = response.ctx.input(|i| i.modifiers);
            if let Some(command) =
                crate::stencil_view::dragged(&self.doc, response.drag_delta(), 1.0, modifiers)
            {
                self.apply(command);
            }
        }
        if self.pointer.held.is_some() {
            return;
        }
        let painter = response
            .ctx
            .layer_painter(response.layer_id)
            .with_clip_rect(response.rect);
        let columns = self.viewport.comparison.mode.columns();
        for k in 0..columns {
            let x = rect.min.x + rect.width() * (k as f32 + 0.5) / columns as f32;
            let picture = self
                .viewport
                .picture_at(rect, egui::pos2(x, rect.center().y));
            let stencil_size = Vec2::new(picture.width(), picture.height());
            self.canvas.stencil.draw(
                &painter.with_clip_rect(picture),
                picture,
                stencil_size,
                &stencil,
            );
        }
    }

    /// The mesh clone source's marker in the viewport: at the source on the surface; once a
    /// stroke fixed the offset, at the surface under the pointer plus that offset.
    pub(super) fn draw_viewport_clone_marker(
        &mut self,
        response: &egui::Response,
        rect: egui::Rect,
    ) {
        self.pointer.viewport_clone_marker = None;
        let Some((source, offset)) = self.doc.surface_clone_source() else {
            return;
        };
        if self.tools.overlay() != Some(Overlay::CloneSource) {
            return;
        }
        let hover = response.hover_pos();
        let hit = hover.and_then(|p| self.viewport.pick(rect, p, &self.mesh.mesh, &self.mesh.bvh));
        let world = match (offset, hit) {
            (Some(offset), Some(hit)) => hit.position + offset,
            _ => source,
        };
        let picture = self
            .viewport
            .picture_at(rect, hover.unwrap_or(rect.center()));
        let view_proj = self
            .viewport
            .camera
            .view_proj(picture.width() / picture.height().max(1.0));
        if let Some(c) = crate::project(view_proj, picture, world) {
            let painter = response
                .ctx
                .layer_painter(response.layer_id)
                .with_clip_rect(response.rect);
            clone_marker(&painter, c);
            self.pointer.viewport_clone_marker = Some(c);
        }
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
