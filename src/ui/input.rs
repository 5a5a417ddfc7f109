//! Pointer input on the UV canvas and the 3D viewport: each frame's primary-button press,
//! drag and release become [`ToolEvent`]s for the active tool, whose commands are applied to
//! the document; the camera and the light drag stay here. Space (canvas) and Alt (viewport)
//! keep the primary button for panning and orbiting.

use egui::Key;
use glam::Vec2;

use super::{EditorState, Tab, brush_outline};
use crate::model::brush::SurfacePos;
use crate::render::FrameSettings;
use crate::tools::{Place, ToolEvent, ToolKind};

impl EditorState {
    /// The texel under a map-space position, if inside.
    fn texel_at(&self, p: Vec2) -> Option<(u32, u32)> {
        Place::Canvas(p).texel_index((self.doc.maps().width(), self.doc.maps().height()))
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

    /// Makes `kind` the active tool (ending what the old one had under way).
    pub(super) fn select_tool(&mut self, kind: ToolKind) {
        for command in self.tools.select(kind, &self.doc) {
            self.apply(command);
        }
    }

    /// Hands an event to the active tool and applies its commands.
    pub(super) fn tool_event(&mut self, event: ToolEvent) {
        for command in self.tools.handle(event, &self.doc) {
            self.apply(command);
        }
    }

    /// The tool events of one view this frame: a press where the primary button went down
    /// on it (not while `reserved`, the modifier that gives the button to the camera), drags
    /// while it is held, a release where it came up. A press off the map or the mesh still
    /// holds the button, so a drag that reaches them starts there.
    fn pointer_input(
        &mut self,
        tab: Tab,
        response: &egui::Response,
        at: Option<Place>,
        reserved: bool,
    ) {
        let primary = response.ctx.input(|i| i.pointer.primary_down());
        let down = primary && response.is_pointer_button_down_on();
        let pressure = self.pressure;
        if self.held.is_none() && (down || response.clicked()) && !reserved {
            self.held = Some(tab);
            if let Some(at) = at {
                self.tool_event(ToolEvent::Press { at, pressure });
            }
        } else if self.held == Some(tab)
            && down
            && let Some(at) = at
        {
            self.tool_event(ToolEvent::Drag { at, pressure });
        }
        if self.held == Some(tab) && (!down || response.drag_stopped()) {
            self.held = None;
            self.pressure = 1.0;
            self.tool_event(ToolEvent::Release);
        }
    }

    /// The canvas: hover readout, tool events, the gradient being dragged.
    pub(super) fn canvas_input(&mut self, response: &egui::Response, rect: egui::Rect) {
        let size = (self.doc.maps().width(), self.doc.maps().height());
        let pointer = response.interact_pointer_pos().or(response.hover_pos());
        let pos = pointer.map(|p| self.canvas.to_texel(rect, p, size));
        if response.hovered() {
            self.hover = pos.and_then(|p| self.texel_at(p));
            self.hover_tab = Some(Tab::Canvas);
        }
        let space = response.ctx.input(|i| i.key_down(Key::Space));
        self.pointer_input(Tab::Canvas, response, pos.map(Place::Canvas), space);
        if self.tools.active() == ToolKind::Gradient
            && let Some((start, end)) = self.tools.gradient.drag()
        {
            let at = |p: Vec2| {
                rect.min + egui::vec2(p.x / size.0 as f32, p.y / size.1 as f32) * rect.size()
            };
            response.ctx.layer_painter(response.layer_id).arrow(
                at(start),
                at(end) - at(start),
                egui::Stroke::new(2.0, egui::Color32::WHITE),
            );
        }
    }

    /// The viewport: hover readout, tool events on the mesh (left button, not with Alt), the
    /// brush outline.
    pub(super) fn viewport_input(&mut self, response: &egui::Response, rect: egui::Rect) {
        let alt = response.ctx.input(|i| i.modifiers.alt);
        let pointer = response.interact_pointer_pos().or(response.hover_pos());
        let hit =
            pointer.and_then(|p| self.viewport.pick(rect, p, &self.mesh.mesh, &self.mesh.bvh));
        let (w, h) = (
            self.doc.maps().width() as f32,
            self.doc.maps().height() as f32,
        );
        let place = hit.as_ref().map(|hit| Place::Surface {
            pos: SurfacePos {
                point: hit.position,
                normal: hit.normal,
            },
            texel: hit.uv.map(|uv| Vec2::new(uv.x * w, (1.0 - uv.y) * h)),
        });
        if response.hovered() {
            self.hover_tab = Some(Tab::Viewport);
            self.hover = place.and_then(Place::texel).and_then(|p| self.texel_at(p));
        }
        self.pointer_input(Tab::Viewport, response, place, alt);
        // The brush circle, projected on the surface: a circle of the dab's world radius in
        // the tangent plane under the cursor, drawn through the camera.
        if let (Some(p), Some(surface)) = (response.hover_pos(), self.doc.surface())
            && self.tools.active().strokes()
            && let Some(hit) = self.viewport.pick(rect, p, &self.mesh.mesh, &self.mesh.bvh)
        {
            let world = self.doc.settings().brush.radius_px * surface.units_per_texel;
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
            model: self.doc.settings().model,
            approx: self.doc.settings().approx,
            view: self.view,
            lighting: self.lighting,
            camera: self.viewport.camera,
        }
    }
}
