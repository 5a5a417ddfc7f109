//! Pointer input on the UV canvas and the 3D viewport: every pointer event egui delivers in a
//! frame (press, each move, release, in order, with their positions) becomes a [`ToolEvent`]
//! for the active tool, whose commands are applied to the document, so a quick stroke keeps
//! its shape and its tail up to the release point however few frames it spans. The camera
//! and the light drag stay here. Space (canvas) and Alt (viewport) keep the primary button
//! for panning and orbiting.

use egui::Key;
use glam::Vec2;

use super::screen_brush::points_per_world;
use super::{EditorState, Tab, brush_outline};
use kapaint_core::render::FrameSettings;
use kapaint_model::{HistoryCommand, LayerCommand, SettingsCommand};
use kapaint_tools::{Overlay, Place, ToolCursor, ToolEvent, ToolKind};

use crate::dialogs::NewDialog;
use crate::export_dialog::ExportDialog;
use crate::files::FilePurpose;
use crate::keys::{self, Action};
use kapaint_model::brush::SurfacePos;
use kapaint_model::paint::ScreenView;

/// Where the pointer is and what it holds.
pub(super) struct Pointer {
    /// The view the primary button went down on, until it goes up.
    pub(super) held: Option<Tab>,
    /// The texel under the cursor, in either view.
    pub(super) hover: Option<(u32, u32)>,
    /// `hover` as of the last frame (the status bar is drawn before the tabs).
    pub(super) shown_hover: Option<(u32, u32)>,
    /// The tab under the cursor.
    pub(super) hover_tab: Option<Tab>,
    /// Texels per screen point under the cursor (canvas zoom, or the surface's scale).
    pub(super) texels_per_point: Option<f32>,
    /// The brush circle drawn on the UV canvas this frame: centre and radius in points.
    pub(super) canvas_outline: Option<(egui::Pos2, f32)>,
    /// The mesh clone source's marker drawn in the viewport this frame.
    pub(super) viewport_clone_marker: Option<egui::Pos2>,
    /// The view the viewport's picture showed last frame (its size in points).
    pub(super) screen_view: Option<ScreenView>,
    /// The pen's last pressure in the current stroke (1 with a mouse).
    pub(super) pressure: f32,
}

impl Default for Pointer {
    fn default() -> Self {
        Self {
            held: None,
            hover: None,
            shown_hover: None,
            hover_tab: None,
            texels_per_point: None,
            canvas_outline: None,
            viewport_clone_marker: None,
            screen_view: None,
            pressure: 1.0,
        }
    }
}

impl Pointer {
    /// What the panels and jobs may know of the views.
    pub(super) fn seen(&self) -> crate::desk::Seen {
        crate::desk::Seen {
            texels_per_point: self.texels_per_point,
            screen_view: self.screen_view,
        }
    }
}

impl EditorState {
    /// Runs the actions of the keys pressed this frame (none while a text field has the
    /// keyboard).
    pub(super) fn hotkeys(&mut self, ctx: &egui::Context) {
        // Nor while a file dialog is open: its keys are its own.
        if ctx.egui_wants_keyboard_input()
            || self.dialogs.files.open_for().is_some()
            || self.modal_job().is_some()
            || self.prompts.recovery_offer.is_some()
        {
            return;
        }
        let actions: Vec<Action> = ctx.input_mut(|i| keys::pressed_actions(&mut i.events));
        self.act(&actions);
        // Enter commits what the active tool is placing (a decal). Not a binding of the
        // keymap, which takes the keys it matches out of the frame's events: Enter stays for
        // a prompt or a field that answers to it.
        if self.tools.busy() && ctx.input(|i| i.key_pressed(Key::Enter)) {
            self.tool_event(ToolEvent::Commit);
        }
    }

    /// Does what key bindings (or the menu entries showing them) do, in order; the brush's
    /// changes among them are one command.
    pub(super) fn act(&mut self, actions: &[Action]) {
        let mut brush = self.doc.settings().brush.clone();
        for &action in actions {
            match action {
                Action::Undo => self.apply(HistoryCommand::Undo),
                Action::Redo => self.apply(HistoryCommand::Redo),
                Action::Save => self.save(),
                Action::SaveAs => self.choose_file(FilePurpose::SaveProject),
                Action::Open => self.choose_file(FilePurpose::OpenProject),
                Action::New => {
                    let dialog = NewDialog::starting(&self.doc, &self.presets.materials);
                    self.dialogs.new = Some(dialog);
                }
                Action::Export => {
                    let path = self.project.path.as_deref();
                    let last = self.dialogs.export_choice.as_ref();
                    self.dialogs.export = Some(ExportDialog::new(last, path));
                }
                Action::NewLayer => self.apply(crate::panels::layers::new_layer(
                    &self.doc,
                    kapaint_model::LayerKind::Paint,
                )),
                Action::DuplicateLayer => self.apply(LayerCommand::DuplicateLayer),
                Action::MergeDown => self.apply(LayerCommand::MergeDown),
                Action::Quit => self.prompts.quit.asked = true,
                Action::Tool(kind) => self.select_tool(kind),
                Action::FillOrFrame => {
                    if self.pointer.hover_tab == Some(Tab::Canvas) {
                        self.select_tool(ToolKind::FILL);
                    } else {
                        self.viewport.frame(&self.mesh.mesh);
                    }
                }
                Action::FitCanvas => self.canvas.fit(),
                Action::Shortcuts => self.dialogs.shortcuts_open = !self.dialogs.shortcuts_open,
                Action::SwapMaterials => self.apply(SettingsCommand::SwapMaterials),
                Action::SofterBrush => brush.hardness = (brush.hardness - 0.1).max(0.0),
                Action::HarderBrush => brush.hardness = (brush.hardness + 0.1).min(1.0),
                Action::SmallerBrush => self.tool_panel.brush_size.scale(&mut brush, 1.0 / 1.25),
                Action::LargerBrush => self.tool_panel.brush_size.scale(&mut brush, 1.25),
                Action::Abort => {
                    self.tool_event(ToolEvent::Escape);
                    // The button stays with nobody until it is released and pressed again:
                    // the rest of the drag and its release paint nothing.
                    self.pointer.held = None;
                    self.pointer.pressure = 1.0;
                }
            }
        }
        if brush != self.doc.settings().brush {
            self.apply(SettingsCommand::SetBrush(brush));
        }
    }

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
            self.pointer.pressure = f;
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
            let lays = self.tools.lays_material(&command);
            self.apply(command);
            if lays {
                let value = self.doc.settings().primary;
                self.tool_panel.remember_material(value);
            }
        }
    }

    /// The tool events of one view this frame, from `samples` (this frame's primary-button
    /// events, in order, each with the place under it): a press on the view (not while
    /// `reserved`, the modifier that gives the button to the camera, nor under a window over
    /// it), a drag for every move while it is held, a drag to where it came up and the
    /// release. A press off the map or the mesh still holds the button, so a drag that reaches
    /// them starts there.
    fn pointer_input(
        &mut self,
        tab: Tab,
        response: &egui::Response,
        samples: Vec<(Sample, Option<Place>)>,
        reserved: bool,
    ) {
        let pressure = self.pointer.pressure;
        for (sample, at) in samples {
            match sample {
                Sample::Down(p) => {
                    let on_view = response.interact_rect.contains(p)
                        && response.ctx.layer_id_at(p) == Some(response.layer_id);
                    let ctrl = response.ctx.input(|i| i.modifiers.command);
                    if self.pointer.held.is_none() && on_view && !reserved && ctrl {
                        // Ctrl+click picks a source (clone's); nothing is held.
                        if let Some(at) = at {
                            self.tool_event(ToolEvent::PickSource { at });
                        }
                    } else if self.pointer.held.is_none() && on_view && !reserved {
                        self.pointer.held = Some(tab);
                        if self.tools.active_meta().cursor == ToolCursor::BrushOutline {
                            let brush = &self.doc.settings().brush;
                            if let Some(brush) = self
                                .tool_panel
                                .brush_size
                                .fitted_brush(brush, self.pointer.texels_per_point)
                            {
                                self.apply(SettingsCommand::SetBrush(brush));
                            }
                        }
                        if let Some(at) = at {
                            self.tool_event(ToolEvent::Press { at, pressure });
                        }
                    }
                }
                Sample::Move(_) | Sample::Up(_) if self.pointer.held == Some(tab) => {
                    if let Some(at) = at {
                        self.tool_event(ToolEvent::Drag { at, pressure });
                    }
                    if matches!(sample, Sample::Up(_)) {
                        self.release();
                    }
                }
                Sample::Move(_) | Sample::Up(_) => {}
            }
        }
        // A release egui never reported (the pointer left the window): end the stroke.
        if self.pointer.held == Some(tab) && !response.ctx.input(|i| i.pointer.primary_down()) {
            self.release();
        }
    }

    /// The active tool's cursor over a view (not while `reserved` gives the pointer to the
    /// camera).
    fn tool_cursor(&self, response: &egui::Response, reserved: bool) {
        if response.hovered() && !reserved {
            response
                .ctx
                .set_cursor_icon(match self.tools.active_meta().cursor {
                    ToolCursor::BrushOutline | ToolCursor::Crosshair => egui::CursorIcon::Crosshair,
                    ToolCursor::Cell => egui::CursorIcon::Cell,
                });
        }
    }

    /// Ends the stroke under way.
    fn release(&mut self) {
        self.pointer.held = None;
        self.pointer.pressure = 1.0;
        self.tool_event(ToolEvent::Release);
    }

    /// The canvas: hover readout, tool events, the gradient being dragged.
    pub(super) fn canvas_input(&mut self, response: &egui::Response, rect: egui::Rect) {
        let size = (self.doc.maps().width(), self.doc.maps().height());
        let pointer = response.interact_pointer_pos().or(response.hover_pos());
        let pos = pointer.map(|p| self.canvas.to_texel(rect, p, size));
        if response.hovered() {
            self.pointer.hover = pos.and_then(|p| self.texel_at(p));
            self.pointer.hover_tab = Some(Tab::Canvas);
        }
        if pointer.is_some() && (response.hovered() || self.pointer.held == Some(Tab::Canvas)) {
            self.pointer.texels_per_point = Some(size.0 as f32 / rect.width().max(1e-3));
        }
        let space = response.ctx.input(|i| i.key_down(Key::Space));
        let samples = pointer_samples(&response.ctx)
            .into_iter()
            .map(|s| {
                let at = Place::Canvas(self.canvas.to_texel(rect, s.pos(), size));
                (s, Some(at))
            })
            .collect();
        self.pointer_input(Tab::Canvas, response, samples, space);
        self.tool_cursor(response, space);
        // The overlays stay inside the canvas (a clone source near the map's edge, a stencil
        // larger than the view).
        let painter = response
            .ctx
            .layer_painter(response.layer_id)
            .with_clip_rect(response.rect);
        // The stencil on the canvas: a right-drag places it; shown unless a stroke is painting.
        let on_canvas = self.doc.stencil().is_some_and(|s| s.view.is_none());
        if on_canvas && response.dragged_by(egui::PointerButton::Secondary) {
            let modifiers = response.ctx.input(|i| i.modifiers);
            let per_point = size.0 as f32 / rect.width().max(1e-3);
            if let Some(command) =
                crate::stencil_view::dragged(&self.doc, response.drag_delta(), per_point, modifiers)
            {
                self.apply(command);
            }
        }
        if let Some(stencil) = self.doc.stencil().cloned()
            && on_canvas
            && self.pointer.held.is_none()
            && crate::stencil_view::paints_through(self.tools.active())
        {
            let map_size = Vec2::new(size.0 as f32, size.1 as f32);
            self.canvas.stencil.draw(&painter, rect, map_size, &stencil);
        }
        // The brush circle: the dab's radius in texels, at the canvas's zoom.
        self.pointer.canvas_outline = None;
        if let Some(p) = response.hover_pos()
            && self.tools.active_meta().cursor == ToolCursor::BrushOutline
            && !space
        {
            let radius = if self.tool_panel.brush_size.on_screen {
                self.tool_panel.brush_size.screen_radius
            } else {
                self.doc.settings().brush.radius_px * rect.width() / size.0 as f32
            };
            // Dark under light, so it shows on any material.
            painter.circle_stroke(
                p,
                radius + 1.0,
                egui::Stroke::new(1.0, egui::Color32::BLACK),
            );
            painter.circle_stroke(p, radius, egui::Stroke::new(1.0, egui::Color32::WHITE));
            self.pointer.canvas_outline = Some((p, radius));
        }
        let at =
            |p: Vec2| rect.min + egui::vec2(p.x / size.0 as f32, p.y / size.1 as f32) * rect.size();
        match self.tools.overlay() {
            Some(Overlay::Arrow { from, to }) => {
                painter.arrow(
                    at(from),
                    at(to) - at(from),
                    egui::Stroke::new(2.0, egui::Color32::WHITE),
                );
            }
            Some(Overlay::CloneSource) => {
                // At the source; once a stroke fixed the offset, where the brush copies from.
                if let Some((source, offset)) = self.doc.clone_source() {
                    let marker = match (offset, pos) {
                        (Some(offset), Some(p)) if response.hovered() => p + offset,
                        _ => source,
                    };
                    crate::tool_overlays::clone_marker(&painter, at(marker));
                }
            }
            Some(Overlay::Decal { .. }) | None => {}
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
        let place_of = |hit: &kapaint_mesh::pick::Hit| Place::Surface {
            pos: SurfacePos {
                point: hit.position,
                normal: hit.normal,
            },
            texel: hit.uv.map(|uv| Vec2::new(uv.x * w, (1.0 - uv.y) * h)),
        };
        let place = hit.as_ref().map(place_of);
        if response.hovered() {
            self.pointer.hover_tab = Some(Tab::Viewport);
            self.pointer.hover = place.and_then(Place::texel).and_then(|p| self.texel_at(p));
        }
        // A screen point's size on the surface under the cursor, in texels.
        if let (Some(p), Some(hit), Some(surface)) = (pointer, &hit, self.doc.surface())
            && (response.hovered() || self.pointer.held == Some(Tab::Viewport))
        {
            let picture = self.viewport.picture_at(rect, p);
            self.pointer.texels_per_point =
                points_per_world(&self.viewport.camera, picture, hit.position)
                    .map(|ppw| 1.0 / (ppw * surface.units_per_texel));
        }
        // Picking every sample costs a ray each; only while a stroke may start or is held.
        let samples = pointer_samples(&response.ctx)
            .into_iter()
            .filter(|_| self.pointer.held.is_none() || self.pointer.held == Some(Tab::Viewport))
            .map(|s| {
                let hit = self
                    .viewport
                    .pick(rect, s.pos(), &self.mesh.mesh, &self.mesh.bvh);
                (s, hit.as_ref().map(place_of))
            })
            .collect();
        self.pointer_input(Tab::Viewport, response, samples, alt);
        self.tool_cursor(response, alt);
        self.screen_stencil(response, rect);
        // Shift + right drag turns the light: across for its yaw, up and down for its height.
        if response.dragged_by(egui::PointerButton::Secondary)
            && !self.viewport.stencil_held(&response.ctx, rect)
            && response.ctx.input(|i| i.modifiers.shift)
        {
            let d = response.drag_delta();
            self.turn_light(d.x * 0.01, -d.y * 0.01);
        }
        // The brush circle, projected on the surface: a circle of the dab's world radius in
        // the tangent plane under the cursor, drawn through the camera.
        if let (Some(p), Some(surface)) = (response.hover_pos(), self.doc.surface())
            && self.tools.active_meta().cursor == ToolCursor::BrushOutline
            && let Some(hit) = self.viewport.pick(rect, p, &self.mesh.mesh, &self.mesh.bvh)
        {
            let picture = self.viewport.picture_at(rect, p);
            let world = if self.tool_panel.brush_size.on_screen {
                points_per_world(&self.viewport.camera, picture, hit.position)
                    .map_or(0.0, |ppw| self.tool_panel.brush_size.screen_radius / ppw)
            } else {
                self.doc.settings().brush.radius_px * surface.units_per_texel
            };
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
        self.draw_viewport_clone_marker(response, rect);
        crate::tool_overlays::decal_outline(response, &self.viewport, rect, self.tools.overlay());
        let cage = self.dialogs.bake_high.as_ref();
        crate::tool_overlays::cage_preview(response, &self.viewport, rect, &self.mesh.mesh, cage);
    }

    /// The stencil on the viewport's screen: kept on the camera's view, moved (scaled,
    /// turned) by a right-drag that starts on it, drawn over each picture unless a stroke
    /// paints.
    fn screen_stencil(&mut self, response: &egui::Response, rect: egui::Rect) {
        let picture = self.viewport.picture_at(rect, rect.min);
        let view = crate::stencil_view::screen_view(&self.viewport.camera, picture);
        self.pointer.screen_view = Some(view);
        if let Some(command) = crate::stencil_view::follow(&self.doc, view) {
            self.apply(command);
        }
        let through = crate::stencil_view::paints_through(self.tools.active());
        let stencil = (self.doc.stencil())
            .filter(|s| s.view.is_some() && through)
            .cloned();
        self.viewport.stencil.clone_from(&stencil);
        let Some(stencil) = stencil else {
            return;
        };
        if response.dragged_by(egui::PointerButton::Secondary)
            && self.viewport.stencil_held(&response.ctx, rect)
        {
            let modifiers = response.ctx.input(|i| i.modifiers);
            let delta = response.drag_delta();
            if let Some(command) = crate::stencil_view::dragged(&self.doc, delta, 1.0, modifiers) {
                self.apply(command);
            }
        }
        if self.pointer.held.is_none() {
            let at = (&self.viewport, rect);
            crate::tool_overlays::screen_stencil(response, at, &mut self.canvas.stencil, &stencil);
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
            crate::tool_overlays::clone_marker(&painter, c);
            self.pointer.viewport_clone_marker = Some(c);
        }
    }

    /// What the viewport draws this frame: the light in the world (turned with the camera
    /// when it follows the camera).
    pub fn frame_settings(&self) -> FrameSettings {
        let mut lighting = self.look.lighting;
        if self.look.light_follows_camera {
            lighting.light = self.viewport.camera.rotation() * lighting.direction();
        }
        FrameSettings {
            model: self.doc.settings().model,
            approx: self.doc.settings().approx,
            view: self.look.mode,
            lighting,
            camera: self.viewport.camera,
        }
    }

    /// Turns the light by `yaw` about the vertical and raises it by `pitch` (radians; its
    /// height stays within 89 degrees of the horizon).
    pub(super) fn turn_light(&mut self, yaw: f32, pitch: f32) {
        let (around, height) = self.look.lighting.angles();
        let limit = 89f32.to_radians();
        self.look
            .lighting
            .set_angles(around + yaw, (height + pitch).clamp(-limit, limit));
    }

    /// Makes the light follow the camera (kept relative to the view, so turning the model
    /// never leaves it dark) or stay put in the world; it does not jump either way.
    pub fn set_light_follows_camera(&mut self, follow: bool) {
        if follow == self.look.light_follows_camera {
            return;
        }
        let turn = self.viewport.camera.rotation();
        let l = self.look.lighting.direction();
        self.look.lighting.light = if follow { turn.inverse() * l } else { turn * l };
        self.look.light_follows_camera = follow;
    }
}

/// One primary-button pointer event of a frame, with its position in points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Sample {
    /// The button went down.
    Down(egui::Pos2),
    /// The pointer moved.
    Move(egui::Pos2),
    /// The button came up.
    Up(egui::Pos2),
}

impl Sample {
    fn pos(self) -> egui::Pos2 {
        match self {
            Self::Down(p) | Self::Move(p) | Self::Up(p) => p,
        }
    }
}

/// This frame's pointer events, in the order egui delivered them: presses and releases of
/// the primary button and every move.
fn pointer_samples(ctx: &egui::Context) -> Vec<Sample> {
    ctx.input(|i| {
        i.events
            .iter()
            .filter_map(|e| match e {
                egui::Event::PointerMoved(p) => Some(Sample::Move(*p)),
                egui::Event::PointerButton {
                    pos,
                    button: egui::PointerButton::Primary,
                    pressed,
                    ..
                } => Some(if *pressed {
                    Sample::Down(*pos)
                } else {
                    Sample::Up(*pos)
                }),
                _ => None,
            })
            .collect()
    })
}
