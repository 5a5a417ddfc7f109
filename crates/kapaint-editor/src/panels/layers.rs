//! The Layers dock tab: the stack, top layer first, as Krita and Substance show it. Each row
//! has an eye, a lock, a drag handle, a thumbnail of the content and of the mask, the name and
//! the memory the layer holds. Below the list: adding, duplicating, deleting and merging
//! layers, and the selected layer's opacity, channel blends and mask. Every change is a
//! [`Command`]; the panel only reads the document.

pub use crate::layer_view::LayerView;

mod rename;
use rename::Rename;
use std::collections::HashMap;
use std::time::{Duration, Instant};

use egui::{Color32, Rect, Sense, Vec2};

use super::presets::Presets;
use crate::desk::Desk;
use kapaint_model::layers::{Layer, LayerContent, thumbnail};
use kapaint_model::{Command, Document, LayerKind, LayerPlace};
use kapaint_model::{LayerCommand, MaskCommand};

/// Thumbnails' side in texels.
const THUMB: u32 = 32;
/// Thumbnails' side on screen, in points.
const THUMB_POINTS: f32 = 28.0;
/// While a stroke goes on, thumbnails are made at most this often.
const STROKE_REFRESH: Duration = Duration::from_millis(300);

/// A layer being dragged in the panel: its path.
#[derive(Clone, Debug)]
struct DraggedLayer(Vec<usize>);

/// The panel's thumbnails and per-layer memory, made again when the document changes (at most
/// every [`STROKE_REFRESH`] during a stroke).
#[derive(Default)]
struct LayerThumbs {
    /// The document (its instance) and its version they show.
    shows: Option<(u64, u64)>,
    made: Option<Instant>,
    content: HashMap<Vec<usize>, egui::TextureHandle>,
    masks: HashMap<Vec<usize>, egui::TextureHandle>,
    bytes: HashMap<Vec<usize>, usize>,
}

impl LayerThumbs {
    fn refresh(&mut self, ctx: &egui::Context, doc: &Document) {
        let key = (doc.instance(), doc.version());
        let recent = self.made.is_some_and(|t| t.elapsed() < STROKE_REFRESH);
        let same_document = self.shows.is_some_and(|(instance, _)| instance == key.0);
        if self.shows == Some(key) || (same_document && doc.stroking() && recent) {
            return;
        }
        self.shows = Some(key);
        self.made = Some(Instant::now());
        let stack = doc.stack();
        let walk = stack.walk();
        let side = usize::try_from(THUMB).unwrap_or(1);
        let texture = |map: &mut HashMap<Vec<usize>, egui::TextureHandle>,
                       path: &[usize],
                       kind: &str,
                       pixels: Option<Vec<[u8; 4]>>| {
            let Some(pixels) = pixels else {
                map.remove(path);
                return;
            };
            let image =
                egui::ColorImage::from_rgba_unmultiplied([side, side], pixels.as_flattened());
            if let Some(handle) = map.get_mut(path) {
                handle.set(image, egui::TextureOptions::NEAREST);
            } else {
                let name = format!("layer {kind} {path:?}");
                let handle = ctx.load_texture(name, image, egui::TextureOptions::NEAREST);
                map.insert(path.to_vec(), handle);
            }
        };
        let paths: Vec<&Vec<usize>> = walk.iter().map(|(p, _)| p).collect();
        self.content.retain(|p, _| paths.contains(&p));
        self.masks.retain(|p, _| paths.contains(&p));
        self.bytes.clear();
        for (path, layer) in &walk {
            texture(
                &mut self.content,
                path,
                "content",
                thumbnail::content(stack, layer, THUMB),
            );
            texture(
                &mut self.masks,
                path,
                "mask",
                thumbnail::mask(stack, layer, THUMB),
            );
            self.bytes.insert(path.clone(), layer.heap_bytes());
        }
    }
}

/// The Layers tab: its own state (thumbnails, a rename under way, the layer view chosen), and
/// what it draws from the document.
#[derive(Default)]
pub struct LayersPanel {
    thumbs: LayerThumbs,
    /// A layer's new name being typed in its row.
    pub(super) rename: Option<Rename>,
    /// Whether the next frame takes the keyboard from whichever field has it (a rename that
    /// Tab ended).
    release_keyboard: bool,
    /// The maps a layer view shows.
    pub(crate) view_maps: crate::layer_view::ViewMaps,
    /// The mask generator's live thumbnail and the document (instance and version) it shows.
    pub(super) generator_thumb: Option<((u64, u64), egui::TextureHandle)>,
    /// What the viewport and canvas show of the layers, as chosen.
    pub(crate) view: LayerView,
}

/// What a row asked for this frame.
enum RowAction {
    Select {
        mask: bool,
        alone: bool,
    },
    Toggle(Command),
    Rename,
    /// The name typed is done: committed (`Some`) or cancelled; `tabbed` when Tab ended it.
    Renamed {
        name: Option<String>,
        tabbed: bool,
    },
    Drop(Vec<usize>, LayerPlace),
}

/// A new layer of `kind`, named after how many layers there are.
pub(crate) fn new_layer(doc: &Document, kind: LayerKind) -> LayerCommand {
    let count = doc.stack().walk().len();
    let name = match kind {
        LayerKind::Paint => format!("Layer {}", count + 1),
        LayerKind::Fill => format!("Fill {}", count + 1),
        LayerKind::Group => format!("Group {}", count + 1),
    };
    LayerCommand::AddLayer { kind, name }
}

impl LayersPanel {
    /// What the viewport and canvas show of the layers: the chosen view, except that a mask
    /// tools paint shows alone, in grey, while the chosen view is the whole stack.
    pub(crate) fn shown_view(&self, doc: &Document) -> LayerView {
        if doc.painting_mask() && self.view == LayerView::Composite {
            LayerView::Mask
        } else {
            self.view
        }
    }

    /// What tools paint (a layer or its mask) and which layer view is shown, as the viewport
    /// and canvas say it.
    pub(crate) fn painting_text(&self, doc: &Document) -> Option<String> {
        let layer = doc.selected_layer()?;
        let mut text = if doc.painting_mask() {
            format!("Painting the mask of \"{}\"", layer.props.name)
        } else {
            format!("Painting \"{}\"", layer.props.name)
        };
        let shown = self.shown_view(doc);
        if shown != LayerView::Composite {
            text.push_str(" · showing ");
            text.push_str(&shown.label().to_lowercase());
        }
        Some(text)
    }

    /// Says in a corner of the viewport or canvas (`rect`) what tools paint (a layer or its
    /// mask) and which layer view is shown.
    pub(crate) fn painting_label(&self, doc: &Document, ui: &egui::Ui, rect: Rect) {
        let Some(text) = self.painting_text(doc) else {
            return;
        };
        let colour = if doc.painting_mask() {
            Color32::from_rgb(255, 200, 120)
        } else {
            Color32::from_gray(220)
        };
        let painter = ui.painter_at(rect);
        let galley = painter.layout_no_wrap(text, egui::FontId::proportional(13.0), colour);
        let at = rect.left_bottom() + Vec2::new(8.0, -8.0 - galley.size().y);
        painter.rect_filled(
            Rect::from_min_size(at, galley.size()).expand(4.0),
            3.0,
            Color32::from_black_alpha(150),
        );
        painter.galley(at, galley, colour);
    }

    /// The Layers tab.
    pub(crate) fn ui(&mut self, ui: &mut egui::Ui, desk: &mut Desk, presets: &mut Presets) {
        let doc = desk.doc;
        if std::mem::take(&mut self.release_keyboard) {
            ui.memory_mut(egui::Memory::stop_text_input);
        }
        self.thumbs.refresh(ui.ctx(), doc);
        Self::layer_buttons_ui(ui, desk);
        ui.separator();
        let mut actions = Vec::new();
        // A rename of a layer that is gone (deleted, undone, another document opened) ends
        // with it.
        let mut rename = self
            .rename
            .take()
            .filter(|r| r.document == doc.instance() && doc.stack().path_of(r.id).is_some());
        egui::ScrollArea::vertical()
            .id_salt("layers")
            .max_height((ui.available_height() - 230.0).max(120.0))
            .show(ui, |ui| {
                let layers = &doc.stack().layers;
                self.rows_ui(ui, doc, layers, &[], &mut rename, &mut actions);
                ui.label(
                    egui::RichText::new(format!("Base material (n {:.0})", doc.stack().base.n))
                        .weak(),
                );
                if let Some(normal) = doc.normal() {
                    ui.label(
                        egui::RichText::new(format!(
                            "Normal map {}x{} (imported; lighting only, never in k_a)",
                            normal.width(),
                            normal.height()
                        ))
                        .weak(),
                    )
                    .on_hover_text(
                        "A tangent-space normal map from the imported material: the preview \
                         lights with it, the gltf-pbr export passes it through. It is not painted.",
                    );
                }
            });
        self.rename = rename;
        for (path, action) in actions {
            self.row_action(desk, path, action);
        }
        ui.separator();
        self.selected_layer_ui(ui, desk, presets);
    }

    fn layer_buttons_ui(ui: &mut egui::Ui, desk: &mut Desk) {
        let doc = desk.doc;
        ui.horizontal_wrapped(|ui| {
            let add = |ui: &mut egui::Ui, text: &str, tip: &str| {
                ui.button(text).on_hover_text(tip).clicked()
            };
            if add(
                ui,
                "+ Paint",
                "A new paint layer above the selected one (Ctrl+Shift+N)",
            ) {
                desk.command(new_layer(doc, LayerKind::Paint));
            }
            if add(
                ui,
                "+ Fill",
                "A fill layer of the primary material, shaped by its mask",
            ) {
                desk.command(new_layer(doc, LayerKind::Fill));
            }
            if add(ui, "+ Group", "A new, empty group") {
                desk.command(new_layer(doc, LayerKind::Group));
            }
            if add(ui, "Duplicate", "Duplicate the selected layer (Ctrl+J)") {
                desk.command(LayerCommand::DuplicateLayer);
            }
            if add(ui, "Delete", "Delete the selected layer") {
                desk.command(LayerCommand::DeleteLayer);
            }
            if add(ui, "Merge down", "Merge into the layer below (Ctrl+E)") {
                desk.command(LayerCommand::MergeDown);
            }
            if add(ui, "Flatten", "Every layer into one paint layer") {
                desk.command(LayerCommand::Flatten);
            }
        });
    }

    /// Rows of `layers` (top first), groups' children indented under them.
    fn rows_ui(
        &self,
        ui: &mut egui::Ui,
        doc: &Document,
        layers: &[Layer],
        parent: &[usize],
        rename: &mut Option<Rename>,
        actions: &mut Vec<(Vec<usize>, RowAction)>,
    ) {
        for (i, layer) in layers.iter().enumerate().rev() {
            let path = [parent, &[i]].concat();
            if let Some(action) = self.row_ui(ui, doc, layer, &path, rename) {
                actions.push((path.clone(), action));
            }
            if let LayerContent::Group(children) = &layer.content {
                self.rows_ui(ui, doc, children, &path, rename, actions);
            }
        }
    }

    fn row_ui(
        &self,
        ui: &mut egui::Ui,
        doc: &Document,
        layer: &Layer,
        path: &[usize],
        rename: &mut Option<Rename>,
    ) -> Option<RowAction> {
        let selected = doc.selected_id() == Some(layer.props.id);
        let mut action = None;
        let row = ui.horizontal(|ui| {
            ui.add_space(14.0 * (path.len() - 1) as f32);
            let p = &layer.props;
            let (eye, tip) = if p.visible {
                ("👁", "Hide")
            } else {
                ("–", "Show")
            };
            if icon_button(ui, eye, tip) {
                action = Some(RowAction::Toggle(
                    LayerCommand::SetLayerVisible(!p.visible).into(),
                ));
            }
            let (lock, tip) = if p.locked {
                ("🔒", "Unlock")
            } else {
                ("🔓", "Lock")
            };
            if icon_button(ui, lock, tip) {
                action = Some(RowAction::Toggle(
                    LayerCommand::SetLayerLocked(!p.locked).into(),
                ));
            }
            let handle = egui::Id::new(("layer drag", path));
            ui.dnd_drag_source(handle, DraggedLayer(path.to_vec()), |ui| {
                ui.label("☰").on_hover_text("Drag to move");
            });
            let content = Self::thumb_ui(
                ui,
                self.thumbs.content.get(path),
                selected && !doc.painting_mask(),
                &format!("Content of {}", p.name),
            );
            if content.clicked() {
                action = Some(RowAction::Select {
                    mask: false,
                    alone: false,
                });
            }
            if let Some(mask) = &layer.mask {
                let r = Self::thumb_ui(
                    ui,
                    self.thumbs.masks.get(path),
                    selected && doc.painting_mask(),
                    &format!("Mask of {}", p.name),
                )
                .on_hover_text("Paint the mask (Alt + click: show it alone)");
                if !mask.enabled {
                    ui.painter().line_segment(
                        [r.rect.left_bottom(), r.rect.right_top()],
                        egui::Stroke::new(2.0, Color32::RED),
                    );
                }
                if r.clicked() {
                    let alone = ui.input(|i| i.modifiers.alt);
                    action = Some(RowAction::Select { mask: true, alone });
                }
            }
            if let Some(a) = Self::name_ui(ui, layer, selected, rename) {
                action = Some(a);
            }
            let bytes = self.thumbs.bytes.get(path).copied().unwrap_or(0);
            ui.label(
                egui::RichText::new(super::view_panel::megabytes(bytes))
                    .weak()
                    .small(),
            )
            .on_hover_text("Memory this layer's tiles and mask hold");
        });
        drop_target(ui, row.response.rect, path, &layer.content).or(action)
    }

    /// A thumbnail over a checkerboard (transparent is unpainted), framed when selected.
    fn thumb_ui(
        ui: &mut egui::Ui,
        texture: Option<&egui::TextureHandle>,
        selected: bool,
        label: &str,
    ) -> egui::Response {
        let (rect, response) = ui.allocate_exact_size(Vec2::splat(THUMB_POINTS), Sense::click());
        response.widget_info(|| egui::WidgetInfo::labeled(egui::WidgetType::Button, true, label));
        let painter = ui.painter_at(rect);
        match texture {
            Some(t) => {
                let cell = THUMB_POINTS / 4.0;
                for k in 0..16 {
                    let (cx, cy) = ((k % 4) as f32, (k / 4) as f32);
                    let grey = if (k % 4 + k / 4) % 2 == 0 { 90 } else { 140 };
                    let min = rect.min + Vec2::new(cx * cell, cy * cell);
                    painter.rect_filled(
                        Rect::from_min_size(min, Vec2::splat(cell)),
                        0.0,
                        Color32::from_gray(grey),
                    );
                }
                painter.image(
                    t.id(),
                    rect,
                    Rect::from_min_max(egui::Pos2::ZERO, egui::Pos2::new(1.0, 1.0)),
                    Color32::WHITE,
                );
            }
            None => {
                painter.text(
                    rect.center(),
                    egui::Align2::CENTER_CENTER,
                    "🗀",
                    egui::FontId::proportional(20.0),
                    ui.visuals().text_color(),
                );
            }
        }
        if selected {
            painter.rect_stroke(
                rect,
                0.0,
                egui::Stroke::new(2.0, ui.visuals().selection.stroke.color),
                egui::StrokeKind::Inside,
            );
        }
        response
    }

    /// What a row asked, as commands (read against the document as the frame found it).
    fn row_action(&mut self, desk: &mut Desk, path: Vec<usize>, action: RowAction) {
        let doc = desk.doc;
        match action {
            RowAction::Select { mask, alone } => {
                desk.command(LayerCommand::SelectPath(path));
                if mask {
                    desk.command(MaskCommand::SelectMask);
                }
                if alone {
                    self.view = LayerView::Mask;
                }
            }
            RowAction::Toggle(command) => {
                // The eye and the lock act on their row's layer, leaving the selection be.
                let before = doc.selection();
                desk.command(LayerCommand::SelectPath(path));
                desk.command(command);
                if doc.stack().layer(&before.path).is_some() {
                    desk.command(LayerCommand::SelectPath(before.path));
                    if before.mask {
                        desk.command(MaskCommand::SelectMask);
                    }
                }
            }
            RowAction::Rename => {
                self.rename = doc.stack().layer(&path).map(|l| Rename {
                    document: doc.instance(),
                    id: l.props.id,
                    text: l.props.name.clone(),
                    focused: false,
                });
                desk.command(LayerCommand::SelectPath(path));
            }
            RowAction::Renamed { name, tabbed } => {
                self.rename = None;
                // Tab handed the keyboard to the next field: the next frame gives it back to
                // the editor instead, so the shortcuts are live again.
                self.release_keyboard = tabbed;
                if let Some(name) = name {
                    desk.command(LayerCommand::SelectPath(path));
                    desk.command(LayerCommand::RenameLayer(name));
                }
            }
            RowAction::Drop(from, place) => {
                desk.command(LayerCommand::SelectPath(from));
                desk.command(LayerCommand::MoveLayerTo {
                    target: path,
                    place,
                });
            }
        }
    }
}

/// A frameless icon button; whether it was clicked.
fn icon_button(ui: &mut egui::Ui, icon: &str, tip: &str) -> bool {
    ui.add(
        egui::Button::new(icon)
            .frame(false)
            .min_size(Vec2::splat(18.0)),
    )
    .on_hover_text(tip)
    .clicked()
}

/// A row as a drop target for a dragged layer: a line above or below it, or a frame around a
/// group, while one hovers; where it lands when released.
fn drop_target(
    ui: &egui::Ui,
    rect: Rect,
    path: &[usize],
    content: &LayerContent,
) -> Option<RowAction> {
    let response = ui.interact(rect, egui::Id::new(("layer row", path)), Sense::hover());
    let place = |pointer: egui::Pos2| drop_place(rect, pointer, content);
    if let (Some(_), Some(pointer)) = (
        response.dnd_hover_payload::<DraggedLayer>(),
        ui.input(|i| i.pointer.hover_pos()),
    ) {
        let stroke = egui::Stroke::new(2.0, ui.visuals().selection.stroke.color);
        match place(pointer) {
            LayerPlace::Above => {
                ui.painter().hline(rect.x_range(), rect.top(), stroke);
            }
            LayerPlace::Below => {
                ui.painter().hline(rect.x_range(), rect.bottom(), stroke);
            }
            LayerPlace::Into => {
                ui.painter()
                    .rect_stroke(rect, 2.0, stroke, egui::StrokeKind::Inside);
            }
        }
    }
    if let (Some(dragged), Some(pointer)) = (
        response.dnd_release_payload::<DraggedLayer>(),
        ui.input(|i| i.pointer.interact_pos()),
    ) {
        return Some(RowAction::Drop(dragged.0.clone(), place(pointer)));
    }
    None
}

/// Where a layer dropped at `pointer` on a row lands: the row's top third above it, its bottom
/// third below, the middle into it when it is a group.
fn drop_place(rect: Rect, pointer: egui::Pos2, content: &LayerContent) -> LayerPlace {
    let t = (pointer.y - rect.top()) / rect.height().max(1.0);
    match content {
        LayerContent::Group(_) if (0.3..0.7).contains(&t) => LayerPlace::Into,
        _ if t < 0.5 => LayerPlace::Above,
        _ => LayerPlace::Below,
    }
}

#[cfg(test)]
mod tests {
    use super::LayerThumbs;
    use kapaint_model::{Document, DocumentSettings};

    /// Regression: the thumbnails were kept by the document's version alone, and a document
    /// opened in place of another starts its versions again, so the list showed the old
    /// document's layers until something reset it by hand.
    #[test]
    fn thumbnails_follow_another_document_of_the_same_version() -> Result<(), String> {
        let ctx = egui::Context::default();
        let first =
            Document::new(16, 16, DocumentSettings::default()).map_err(|e| e.to_string())?;
        let second =
            Document::new(16, 16, DocumentSettings::default()).map_err(|e| e.to_string())?;
        assert_eq!(first.version(), second.version());
        assert_ne!(first.instance(), second.instance());
        let mut thumbs = LayerThumbs::default();
        thumbs.refresh(&ctx, &first);
        assert_eq!(thumbs.shows, Some((first.instance(), first.version())));
        thumbs.refresh(&ctx, &second);
        assert_eq!(thumbs.shows, Some((second.instance(), second.version())));
        Ok(())
    }
}
