//! The 2D UV canvas: one channel of the maps (or the derived `k_a`) as an egui texture kept
//! up to date tile by tile, with pan, zoom, a UV wireframe and painting in texel space.

use egui::{Color32, ColorImage, Pos2, Rect, Sense, TextureHandle, TextureOptions, Vec2};

use kapaint_core::render::n_false_colour;
use kapaint_mesh::bakes::BakeMap;
use kapaint_model::texel::{MaterialValue, linear_to_srgb};
use kapaint_model::{Document, MaterialMaps};
use kapaint_pbr::round_trip::RoundTrip;
use kapaint_reflectance as reflectance;

/// The canvas's accessible name (tests and screen readers find it by this).
pub const CANVAS_LABEL: &str = "UV canvas painting area";

/// What the canvas shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CanvasChannel {
    /// Diffuse colour.
    Kd,
    /// Specular colour.
    Ks,
    /// Exponent, false colour on a log scale.
    N,
    /// Derived ambient coefficient.
    Ka,
    /// What each texel loses as a glTF PBR material: its round-trip error against the
    /// Cook-Torrance shading of its PBR reading, as a heatmap (0 to 100 %).
    PbrError,
    /// A map baked from the mesh (grey, or RGB for position and normal), when the project
    /// keeps one: offered after the channels above.
    Bake(BakeMap),
}

impl CanvasChannel {
    /// Every choice, in menu order.
    pub const ALL: [Self; 5] = [Self::Kd, Self::Ks, Self::N, Self::Ka, Self::PbrError];

    /// Label for menus.
    pub fn label(self) -> &'static str {
        match self {
            Self::Kd => "k_d",
            Self::Ks => "k_s",
            Self::N => "n",
            Self::Ka => "k_a",
            Self::PbrError => "PBR error",
            Self::Bake(BakeMap::Ao) => "AO bake",
            Self::Bake(BakeMap::Curvature) => "curvature bake",
            Self::Bake(BakeMap::Thickness) => "thickness bake",
            Self::Bake(BakeMap::Position) => "position bake",
            Self::Bake(BakeMap::Normal) => "normal bake",
        }
    }
}

/// The top of the "PBR error" heatmap's scale (relative error; 1 = 100 %).
pub const PBR_ERROR_TOP: f32 = 1.0;

/// The accessible name of the "PBR error" scale bar.
pub const PBR_ERROR_SCALE_LABEL: &str = "PBR error scale, 0 to 100 %";

/// The canvas's state: its texture, which map version it mirrors, and the view.
pub struct Canvas {
    /// Channel shown.
    pub channel: CanvasChannel,
    /// Texels per screen point.
    pub zoom: f32,
    /// Offset of the map's centre from the panel's centre, in points.
    pub pan: Vec2,
    /// Draw the UV wireframe.
    pub wireframe: bool,
    texture: Option<TextureHandle>,
    /// The stencil's picture.
    pub(crate) stencil: crate::stencil_view::StencilOverlay,
    /// What the texture shows.
    mirrored: Option<Mirrored>,
    /// The UV wireframe as last tessellated.
    wire: crate::uv_wire::WireCache,
}

/// What the canvas texture shows: which maps at which version, in which channel and shading,
/// and whether as one texel (the maps were one value everywhere).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Mirrored {
    maps: u64,
    version: u64,
    channel: CanvasChannel,
    size: (u32, u32),
    shading: u64,
    uniform: bool,
}

impl Mirrored {
    /// The same maps, size, channel and shading (the version aside).
    fn same_maps(&self, other: &Self) -> bool {
        (self.maps, self.channel, self.size, self.shading)
            == (other.maps, other.channel, other.size, other.shading)
    }
}

impl Default for Canvas {
    fn default() -> Self {
        Self {
            channel: CanvasChannel::Kd,
            zoom: 0.0,
            pan: Vec2::ZERO,
            wireframe: true,
            texture: None,
            stencil: crate::stencil_view::StencilOverlay::default(),
            mirrored: None,
            wire: crate::uv_wire::WireCache::default(),
        }
    }
}

/// The document's PBR round trip (its model and mapping), for the "PBR error" canvas.
fn round_trip_of(doc: &Document) -> &'static RoundTrip {
    RoundTrip::for_model(doc.settings().model, doc.settings().n_mapping())
}

/// Display colour of one texel for `channel` (`round_trip`: the document's PBR round trip
/// where the caller looked it up once for many texels).
fn colour(
    doc: &Document,
    channel: CanvasChannel,
    round_trip: Option<&RoundTrip>,
    v: MaterialValue,
) -> Color32 {
    let rgb = match channel {
        CanvasChannel::Kd => v.kd,
        CanvasChannel::Ks => v.ks,
        CanvasChannel::N => n_false_colour(v.n),
        CanvasChannel::Ka => {
            reflectance::ka(doc.settings().model, doc.settings().approx, v.kd, v.ks, v.n)
        }
        CanvasChannel::PbrError => {
            let round_trip = round_trip.unwrap_or_else(|| round_trip_of(doc));
            kapaint_core::render::heat_ramp(round_trip.error(v) / PBR_ERROR_TOP)
        }
        // Read per texel from the bake (see `tile_image`); mid grey where there is none.
        CanvasChannel::Bake(_) => glam::Vec3::splat(0.5),
    };
    let c = |x: f32| (linear_to_srgb(x.clamp(0.0, 1.0)) * 255.0).round() as u8;
    Color32::from_rgb(c(rgb.x), c(rgb.y), c(rgb.z))
}

/// The pixels of one tile of the maps.
fn tile_image(
    doc: &Document,
    maps: &MaterialMaps,
    id: usize,
    channel: CanvasChannel,
) -> ColorImage {
    let kapaint_model::maps::TexelRect { x0, y0, x1, y1 } = maps.tile_rect(id);
    let (w, h) = (x1 - x0, y1 - y0);
    let mut pixels = Vec::with_capacity((w * h) as usize);
    let bake = match channel {
        CanvasChannel::Bake(map) => doc
            .bake_of(map)
            .filter(|b| (b.width, b.height) == (maps.width(), maps.height())),
        _ => None,
    };
    let round_trip = (channel == CanvasChannel::PbrError).then(|| round_trip_of(doc));
    for y in y0..y1 {
        for x in x0..x1 {
            pixels.push(match bake {
                // A bake holds data values (AO, position, ...): shown as they are, not as
                // linear colour.
                Some(b) => {
                    let i = (y * maps.width() + x) as usize;
                    let c = |k: usize| (b.value(i, k) * 255.0).round() as u8;
                    if b.map.channels() == 3 {
                        Color32::from_rgb(c(0), c(1), c(2))
                    } else {
                        Color32::from_gray(c(0))
                    }
                }
                None => colour(doc, channel, round_trip, maps.value(x, y)),
            });
        }
    }
    ColorImage::new([w as usize, h as usize], pixels)
}

impl Canvas {
    /// Brings the texture up to date with `maps` (the document's composite, or a layer view's
    /// maps, `source` their identity, [`MaterialMaps::id`]): changed tiles only, unless the
    /// maps, size, channel or shading settings changed (another document's maps of the same
    /// size are uploaded whole). Maps that are one value everywhere are one texel, stretched:
    /// an unpainted 8192^2 canvas costs 4 bytes, not 256 MB. Returns the tiles uploaded (all
    /// of them for a whole upload).
    pub fn sync(
        &mut self,
        ctx: &egui::Context,
        doc: &Document,
        maps: &MaterialMaps,
        source: u64,
    ) -> usize {
        let now = Mirrored {
            maps: source,
            version: maps.version(),
            channel: self.channel,
            size: (maps.width(), maps.height()),
            // k_a depends on the model and approximation too, a bake on which one is kept.
            shading: match self.channel {
                CanvasChannel::Bake(map) => doc
                    .bake_of(map)
                    .map_or(0, |b| std::sync::Arc::as_ptr(b) as u64),
                _ => {
                    u64::from(doc.settings().n_mapping() as u8) << 16
                        | u64::from(doc.settings().model as u8) << 8
                        | doc.settings().approx as u64
                }
            },
            uniform: false,
        };
        let options = TextureOptions::NEAREST;
        if let (Some(tex), Some(was)) = (&mut self.texture, self.mirrored)
            && was.same_maps(&now)
        {
            if was.version == now.version {
                return 0;
            }
            if !was.uniform {
                let dirty = maps.tiles_changed_since(was.version);
                for &id in &dirty {
                    let kapaint_model::maps::TexelRect { x0: x, y0: y, .. } = maps.tile_rect(id);
                    tex.set_partial(
                        [x as usize, y as usize],
                        tile_image(doc, maps, id, self.channel),
                        options,
                    );
                }
                self.mirrored = Some(now);
                return dirty.len();
            }
        }
        // Maps of another size (a resize, or its undo): the same extent on screen.
        if let Some(was) = self.mirrored
            && was.size != now.size
            && self.zoom > 0.0
        {
            self.zoom *= was.size.0 as f32 / now.size.0 as f32;
        }
        let (w, h) = now.size;
        let image = if maps.uniform_texel().is_some()
            && !matches!(self.channel, CanvasChannel::Bake(_))
        {
            ColorImage::new(
                [1, 1],
                vec![colour(doc, self.channel, None, maps.value(0, 0))],
            )
        } else {
            let mut image = ColorImage::filled([w as usize, h as usize], Color32::BLACK);
            for id in 0..maps.tile_count() {
                let kapaint_model::maps::TexelRect { x0, y0, x1, .. } = maps.tile_rect(id);
                let tw = (x1 - x0) as usize;
                let tile = tile_image(doc, maps, id, self.channel);
                for y in 0..tile.size[1] {
                    let row = (y0 as usize + y) * w as usize + x0 as usize;
                    image.pixels[row..row + tw].copy_from_slice(&tile.pixels[y * tw..(y + 1) * tw]);
                }
            }
            image
        };
        let uniform = image.size == [1, 1] && (w, h) != (1, 1);
        self.texture = Some(ctx.load_texture("uv-canvas", image, options));
        self.mirrored = Some(Mirrored { uniform, ..now });
        maps.tile_count()
    }

    /// Fits the whole map in the panel at the next frame, centred.
    pub fn fit(&mut self) {
        self.zoom = 0.0;
        self.pan = Vec2::ZERO;
    }

    /// Screen rectangle of the map inside `panel`.
    pub fn map_rect(&mut self, panel: Rect, size: (u32, u32)) -> Rect {
        if self.zoom <= 0.0 {
            // Fit on first show.
            self.zoom = (panel.width() / size.0 as f32).min(panel.height() / size.1 as f32) * 0.95;
        }
        let extent = Vec2::new(size.0 as f32, size.1 as f32) * self.zoom;
        Rect::from_center_size(panel.center() + self.pan, extent)
    }

    /// Texel coordinates (continuous) under a screen position.
    pub fn to_texel(&self, rect: Rect, pos: Pos2, size: (u32, u32)) -> glam::Vec2 {
        let uv = (pos - rect.min) / rect.size();
        glam::Vec2::new(uv.x * size.0 as f32, uv.y * size.1 as f32)
    }

    /// Draws the canvas into `ui`; returns the response (drags paint) and the map's rect.
    pub fn show(
        &mut self,
        ui: &mut egui::Ui,
        doc: &Document,
        (maps, source): (&MaterialMaps, u64),
        uv_lines: &crate::uv_wire::UvLines,
    ) -> (egui::Response, Rect) {
        self.sync(ui.ctx(), doc, maps, source);
        let (panel, response) =
            ui.allocate_exact_size(ui.available_size(), Sense::click_and_drag());
        response
            .widget_info(|| egui::WidgetInfo::labeled(egui::WidgetType::Other, true, CANVAS_LABEL));
        let size = (maps.width(), maps.height());
        // Zoom about the cursor; pan with the middle button or space + drag.
        if response.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0
                && let Some(cursor) = response.hover_pos()
            {
                let factor = (scroll * 0.002).exp();
                let before = cursor - (panel.center() + self.pan);
                self.zoom = (self.zoom * factor).clamp(0.01, 64.0);
                self.pan += before - before * factor;
            }
        }
        let space = ui.input(|i| i.key_down(egui::Key::Space));
        if response.dragged_by(egui::PointerButton::Middle)
            || (space && response.dragged_by(egui::PointerButton::Primary))
        {
            self.pan += response.drag_delta();
        }
        let rect = self.map_rect(panel, size);
        let painter = ui.painter_at(panel);
        painter.rect_filled(panel, 0.0, Color32::from_gray(30));
        if let Some(tex) = &self.texture {
            painter.image(
                tex.id(),
                rect,
                Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0)),
                Color32::WHITE,
            );
        }
        if self.channel == CanvasChannel::PbrError {
            // Along the top: the bottom left holds the painting label.
            let top = Rect::from_min_size(panel.min, Vec2::new(panel.width(), 52.0));
            crate::viewport::overlay::heat_bar(&painter, top, "0 %", "100 %+");
            ui.interact(
                crate::viewport::overlay::scale_bar(top),
                ui.id().with("pbr error scale"),
                Sense::hover(),
            )
            .on_hover_text(
                "Per texel, the box-average difference between this material's shading and the \
                 Cook-Torrance shading of its glTF PBR reading (base colour, metallic, roughness \
                 in 8 bits), over the Cook-Torrance mean: what it loses as a PBR material",
            )
            .widget_info(|| {
                egui::WidgetInfo::labeled(egui::WidgetType::Other, true, PBR_ERROR_SCALE_LABEL)
            });
        }
        if self.wireframe
            && let Some((wire, at)) = self.wire.image(ui.ctx(), uv_lines, (rect, panel))
        {
            let whole = Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0));
            painter.image(wire, at, whole, Color32::WHITE);
        }
        (response, rect)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kapaint_model::PaintCommand;
    use kapaint_model::{DocumentSettings, FillRegion};

    #[test]
    fn another_document_of_the_same_size_is_mirrored_whole() {
        let ctx = egui::Context::default();
        let mut canvas = Canvas::default();
        let mut painted = Document::new(256, 256, DocumentSettings::default()).unwrap();
        painted.apply(PaintCommand::Fill(FillRegion::All)).unwrap();
        let all = painted.maps().tile_count();
        let sync = |canvas: &mut Canvas, doc: &Document| {
            canvas.sync(&ctx, doc, doc.maps(), doc.maps().id())
        };
        assert_eq!(sync(&mut canvas, &painted), all);
        assert_eq!(sync(&mut canvas, &painted), 0, "nothing changed");
        // File > New (or Open) at the same size: its maps have lower versions than the ones
        // shown, so the dirty tiles of a version comparison were none: the old paint stayed.
        let fresh = Document::new(256, 256, DocumentSettings::default()).unwrap();
        assert_eq!(
            sync(&mut canvas, &fresh),
            all,
            "the new document is mirrored whole"
        );
    }
}
