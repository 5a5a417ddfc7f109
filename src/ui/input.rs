//! Pointer input on the UV canvas and the 3D viewport: strokes (one undo step from press to
//! release), clicks for fill and picker, gradients, the camera and the light drag. Each
//! gesture becomes [`Command`]s on the document.

use egui::Key;
use glam::Vec2;

use super::{EditorState, Tab, Tool, brush_outline};
use crate::model::brush::{StrokePoint, SurfacePos};
use crate::model::{Command, FillRegion, StrokeTool};
use crate::render::FrameSettings;

impl EditorState {
    /// The texel under a map-space position, if inside.
    fn texel_at(&self, p: Vec2) -> Option<(u32, u32)> {
        let (w, h) = (self.doc.maps.width(), self.doc.maps.height());
        (p.x >= 0.0 && p.y >= 0.0 && p.x < w as f32 && p.y < h as f32)
            .then_some((p.x as u32, p.y as u32))
    }

    /// The fill region for a click at a texel: its UV island when the mesh covers it, else
    /// the whole map.
    fn fill_region(&self, (x, y): (u32, u32)) -> FillRegion {
        let on_island = self.doc.surface().is_some_and(|s| {
            let k = (y * s.bake.width + x) as usize;
            s.bake.island.get(k).is_some_and(|i| *i != u32::MAX)
        });
        if on_island {
            FillRegion::Island { x, y }
        } else {
            FillRegion::All
        }
    }

    fn stroke_tool(&self) -> Option<StrokeTool> {
        match self.tool {
            Tool::Brush => Some(StrokeTool::Brush),
            Tool::Eraser => Some(StrokeTool::Eraser),
            Tool::Fill | Tool::Picker | Tool::Gradient => None,
        }
    }

    /// Follows the pen's pressure where the platform delivers it (egui reports a tablet pen's
    /// force with its touch events); kept until the stroke ends, 1 for a mouse.
    pub(super) fn track_pressure(&mut self, ctx: &egui::Context) {
        let force = ctx.input(|i| {
            i.events.iter().rev().find_map(|e| match e {
                egui::Event::Touch { force: Some(f), .. } if f.is_finite() => {
                    Some(f.clamp(0.0, 1.0))
                }
                _ => None,
            })
        });
        if let Some(f) = force {
            self.pressure = f;
        }
    }

    /// A click of the fill or picker tool on texel `t`.
    fn click_texel(&mut self, t: (u32, u32)) {
        match self.tool {
            Tool::Fill => {
                let region = self.fill_region(t);
                self.apply(Command::Fill(region));
            }
            _ => self.apply(Command::Pick { x: t.0, y: t.1 }),
        }
    }

    /// Ends the stroke that `tab` is painting once its button is released.
    fn end_stroke_on_release(&mut self, tab: Tab, response: &egui::Response) {
        if self.stroking == Some(tab)
            && (response.drag_stopped() || !response.is_pointer_button_down_on())
        {
            self.end_stroke();
        }
    }

    fn end_stroke(&mut self) {
        self.pressure = 1.0;
        if self.stroking.take().is_some() {
            self.apply(Command::EndStroke);
        }
    }

    fn begin_stroke(&mut self, tab: Tab, tool: StrokeTool) {
        if self.stroking.is_none() {
            self.stroking = Some(tab);
            self.apply(Command::BeginStroke(tool));
        }
    }

    /// Paints from a canvas response.
    pub(super) fn canvas_input(&mut self, response: &egui::Response, rect: egui::Rect) {
        let size = (self.doc.maps.width(), self.doc.maps.height());
        let pointer = response.interact_pointer_pos().or(response.hover_pos());
        let pos = pointer.map(|p| self.canvas.to_texel(rect, p, size));
        if response.hovered() {
            self.hover = pos.and_then(|p| self.texel_at(p));
            self.hover_tab = Some(Tab::Canvas);
        }
        let space = response.ctx.input(|i| i.key_down(Key::Space));
        let primary = response.dragged_by(egui::PointerButton::Primary) && !space;
        if self.tool == Tool::Gradient {
            self.gradient_input(response, pos, rect, primary);
            return;
        }
        match (self.stroke_tool(), pos) {
            (Some(tool), Some(p)) if primary || (response.clicked() && !space) => {
                self.begin_stroke(Tab::Canvas, tool);
                let pressure = self.pressure;
                self.apply(Command::StrokeTo(StrokePoint {
                    pos: glam::Vec2::new(p.x, p.y),
                    pressure,
                }));
                if response.clicked() {
                    self.end_stroke();
                }
            }
            (None, Some(p)) if response.clicked() => {
                if let Some(t) = self.texel_at(p) {
                    self.click_texel(t);
                }
            }
            _ => {}
        }
        self.end_stroke_on_release(Tab::Canvas, response);
    }

    /// The gradient tool on the canvas: drag from start to end, applied on release.
    fn gradient_input(
        &mut self,
        response: &egui::Response,
        pos: Option<Vec2>,
        rect: egui::Rect,
        primary: bool,
    ) {
        if response.drag_started_by(egui::PointerButton::Primary) {
            self.gradient_start = pos;
        }
        if let (Some(start), Some(end)) = (self.gradient_start, pos) {
            if primary {
                let size = (self.doc.maps.width(), self.doc.maps.height());
                let at = |p: Vec2| {
                    rect.min + egui::vec2(p.x / size.0 as f32, p.y / size.1 as f32) * rect.size()
                };
                response.ctx.layer_painter(response.layer_id).arrow(
                    at(start),
                    at(end) - at(start),
                    egui::Stroke::new(2.0, egui::Color32::WHITE),
                );
            }
            if response.drag_stopped() {
                self.gradient_start = None;
                self.apply(Command::Gradient {
                    shape: crate::model::paint::GradientShape::Linear,
                    start,
                    end,
                });
            }
        }
    }

    /// Paints from a viewport response (left button, not with Alt).
    pub(super) fn viewport_input(&mut self, response: &egui::Response, rect: egui::Rect) {
        let alt = response.ctx.input(|i| i.modifiers.alt);
        let pointer = response.interact_pointer_pos().or(response.hover_pos());
        let hit =
            pointer.and_then(|p| self.viewport.pick(rect, p, &self.mesh.mesh, &self.mesh.bvh));
        if response.hovered() {
            self.hover_tab = Some(Tab::Viewport);
            self.hover = hit.as_ref().and_then(|h| h.uv).and_then(|uv| {
                self.texel_at(Vec2::new(
                    uv.x * self.doc.maps.width() as f32,
                    (1.0 - uv.y) * self.doc.maps.height() as f32,
                ))
            });
        }
        let primary = response.dragged_by(egui::PointerButton::Primary) && !alt;
        match (self.stroke_tool(), hit) {
            (Some(tool), Some(hit)) if primary || (response.clicked() && !alt) => {
                self.begin_stroke(Tab::Viewport, tool);
                let pressure = self.pressure;
                self.apply(Command::SurfaceStrokeTo(StrokePoint {
                    pos: SurfacePos {
                        point: hit.position,
                        normal: hit.normal,
                    },
                    pressure,
                }));
                if response.clicked() {
                    self.end_stroke();
                }
            }
            (None, Some(_)) if response.clicked() && !alt => {
                if let Some(t) = self.hover {
                    self.click_texel(t);
                }
            }
            _ => {}
        }
        self.end_stroke_on_release(Tab::Viewport, response);
        // The brush circle, projected on the surface: a circle of the dab's world radius in
        // the tangent plane under the cursor, drawn through the camera.
        if let (Some(p), Some(surface)) = (response.hover_pos(), self.doc.surface())
            && self.stroke_tool().is_some()
            && let Some(hit) = self.viewport.pick(rect, p, &self.mesh.mesh, &self.mesh.bvh)
        {
            let world = self.doc.settings.brush.radius_px * surface.units_per_texel;
            let picture = self.viewport.picture_at(rect, p);
            let points = brush_outline(
                &self.viewport.camera,
                picture,
                hit.position,
                hit.normal,
                world,
            );
            response
                .ctx
                .layer_painter(response.layer_id)
                .add(egui::Shape::closed_line(
                    points,
                    egui::Stroke::new(1.0, egui::Color32::WHITE),
                ));
        }
    }

    pub(super) fn frame_settings(&self) -> FrameSettings {
        FrameSettings {
            model: self.doc.settings.model,
            approx: self.doc.settings.approx,
            view: self.view,
            lighting: self.lighting,
            camera: self.viewport.camera,
        }
    }
}
