//! The canvas's UV wireframe, drawn into an image of the panel's visible pixels once for a
//! view and kept: a frame whose view did not change draws one textured rectangle, whatever
//! the mesh; a pan or zoom draws the edges again (those outside the panel cost a box test).
//!
//! Tessellating every edge as an egui line grew with the mesh twice over: a 1M-triangle mesh's
//! 1.6M edges made 12.6M vertices and 47M indices (~440 MB) on every pan, and egui copied and
//! uploaded all of them every frame, though most edges were smaller than a pixel. The image is
//! bounded by the panel's pixels, and its edges are drawn as the tessellated lines looked: one
//! point wide, faint white, overlapping edges blending as stacked strokes do.

use std::sync::Arc;

use egui::{Color32, ColorImage, Rect, TextureHandle, TextureOptions};
use glam::Vec2;
use rayon::prelude::*;

/// The mesh's UV edges in map fractions (u, 1 - v), shared with the mesh state they came from.
pub(crate) type UvLines = Arc<[[Vec2; 2]]>;

/// How much one point-wide stroke covers of what lies below it (the old strokes' white at
/// alpha 70).
const EDGE_ALPHA: f32 = 70.0 / 255.0;

/// What a drawn wireframe was made for.
struct Made {
    lines: UvLines,
    /// The map's size (points) and the points' pixel size, as bits: a pan keeps them.
    scale: [u32; 3],
    /// The part of the map's surroundings drawn, from the map's top-left corner (points).
    region: Rect,
}

/// The wireframe last drawn, and for what.
#[derive(Default)]
pub(crate) struct WireCache {
    made: Option<(Made, Option<TextureHandle>)>,
    /// Wireframes drawn (for the tests: a kept one is not drawn again).
    draws: u64,
}

impl WireCache {
    /// The wireframe of `lines` over the map at `map` within `panel`, as a texture and the
    /// rect it covers (`None`: nothing to draw).
    ///
    /// Drawn around the panel, half a panel more each way (within the texture size limit),
    /// and kept while the lines, the zoom and the pixel size stay and the panel's part of the
    /// map stays inside what was drawn: a pan draws nothing until it leaves that margin.
    pub(crate) fn image(
        &mut self,
        ctx: &egui::Context,
        lines: &UvLines,
        (map, panel): (Rect, Rect),
    ) -> Option<(egui::TextureId, Rect)> {
        let ppp = ctx.pixels_per_point();
        let need = map.expand(1.0).intersect(panel);
        if !need.is_positive() {
            return None;
        }
        let corner = map.min.to_vec2();
        let scale = [map.width(), map.height(), ppp].map(f32::to_bits);
        let kept = self.made.as_ref().is_some_and(|(made, _)| {
            Arc::ptr_eq(&made.lines, lines)
                && made.scale == scale
                && made.region.contains_rect(need.translate(-corner))
        });
        if !kept {
            let side = ctx.input(|i| i.max_texture_side) as f32;
            let margin = ((egui::Vec2::splat(side / ppp) - panel.size()) * 0.5)
                .max(egui::Vec2::ZERO)
                .min(panel.size() * 0.5);
            let texture = self.made.take().and_then(|(_, texture)| texture);
            let drawn = rasterize(lines, (map, panel.expand2(margin)), ppp, side);
            self.draws += 1;
            let Some((image, rect)) = drawn else {
                self.made = None;
                return None;
            };
            // Linear: a pan by part of a pixel moves the lines by that part.
            let options = TextureOptions::LINEAR;
            let texture = match texture {
                Some(mut handle) => {
                    handle.set(image, options);
                    handle
                }
                None => ctx.load_texture("uv-wireframe", image, options),
            };
            let made = Made {
                lines: Arc::clone(lines),
                scale,
                region: rect.translate(-corner),
            };
            self.made = Some((made, Some(texture)));
        }
        let (made, texture) = self.made.as_ref()?;
        texture
            .as_ref()
            .map(|t| (t.id(), made.region.translate(corner)))
    }
}

/// The wireframe of `lines` over the map at `map`, as an image of the pixels of `panel` it
/// can reach (the map grown by a point, clipped to the panel, on the pixel grid, at most
/// `side` pixels each way), and the rect (points) the image covers; `None` when that is
/// empty.
fn rasterize(
    lines: &[[Vec2; 2]],
    (map, panel): (Rect, Rect),
    ppp: f32,
    side: f32,
) -> Option<(ColorImage, Rect)> {
    let visible = map.expand(1.0).intersect(panel);
    if !(visible.is_positive() && ppp.is_finite() && ppp > 0.0) {
        return None;
    }
    // Whole pixels: the image's pixel (0, 0) is the screen's pixel `origin`.
    let origin = (Vec2::new(visible.min.x, visible.min.y) * ppp).floor();
    let end = (Vec2::new(visible.max.x, visible.max.y) * ppp).ceil();
    let size = (end - origin).clamp(Vec2::ONE, Vec2::splat(side.max(1.0)));
    let (w, h) = (size.x as usize, size.y as usize);
    let scale = Vec2::new(map.width(), map.height()) * ppp;
    let offset = Vec2::new(map.min.x, map.min.y) * ppp - origin;
    // The edges in a share per worker, each into its own buffer; the buffers are then
    // multiplied (what shows through is a product, in any order).
    let share = lines.len().div_ceil(rayon::current_num_threads()).max(4096);
    let canvas = lines
        .par_chunks(share)
        .map(|part| {
            let mut canvas = Coverage::new(w, h, ppp);
            for [a, b] in part {
                canvas.line(*a * scale + offset, *b * scale + offset);
            }
            canvas
        })
        .reduce_with(|a, b| a.under(&b))
        .unwrap_or_else(|| Coverage::new(w, h, ppp));
    let image = canvas.image();
    let min = egui::Pos2::new(origin.x, origin.y) / ppp;
    Some((
        image,
        Rect::from_min_size(min, egui::vec2(size.x, size.y) / ppp),
    ))
}

/// `v` rounded down, for `v` within the `i32`s (beyond, some value past them: the callers
/// clamp to the image), without the C library's `floorf`, which the baseline x86-64 target
/// calls out to.
#[inline]
fn floor(v: f32) -> f32 {
    let t = v as i32 as f32;
    if t > v { t - 1.0 } else { t }
}

/// What still shows through each pixel of the wireframe's image (1: no edge), edge after
/// edge: an edge covering a fraction `c` of a pixel leaves `1 - EDGE_ALPHA * c` of it, as a
/// stroke blended over it would.
struct Coverage {
    through: Vec<f32>,
    w: usize,
    h: usize,
    /// An edge's width in pixels (one point).
    width: f32,
}

impl Coverage {
    fn new(w: usize, h: usize, ppp: f32) -> Self {
        Self {
            through: vec![1.0; w * h],
            w,
            h,
            width: ppp,
        }
    }

    /// What shows through both `self` and `other` (of one size), one over the other.
    fn under(mut self, other: &Self) -> Self {
        for (t, o) in self.through.iter_mut().zip(&other.through) {
            *t *= o;
        }
        self
    }

    /// Draws the edge from `a` to `b` (pixels; pixel (x, y) spans `[x, x + 1) x [y, y + 1)`):
    /// column by column along its longer axis (see [`Self::run`]). An edge outside the image
    /// costs one box test; one crossing it touches at most the image's width or height.
    fn line(&mut self, a: Vec2, b: Vec2) {
        let (lo, hi) = (a.min(b), a.max(b));
        let (w, h) = (self.w as f32, self.h as f32);
        if !(hi.x >= -1.0 && hi.y >= -1.0 && lo.x <= w + 1.0 && lo.y <= h + 1.0) {
            // Outside, or not finite.
            return;
        }
        let d = b - a;
        if d.x.abs() >= d.y.abs() {
            self.run(a, b, false);
        } else {
            self.run(Vec2::new(a.y, a.x), Vec2::new(b.y, b.x), true);
        }
    }

    /// [`Self::line`] along x (along y when `transposed`, `a` and `b` given as (y, x)): in
    /// each column the edge is a band `width` wide across it, so `width` times its length per
    /// unit of x high, centred on the edge; each pixel of the column takes its overlap with
    /// the band times the edge's length in the column.
    fn run(&mut self, a: Vec2, b: Vec2, transposed: bool) {
        let (a, b) = if a.x <= b.x { (a, b) } else { (b, a) };
        let dx = b.x - a.x;
        let slope = (b.y - a.y) / dx;
        let half = 0.5 * self.width * (1.0 + slope * slope).sqrt();
        if !(dx > 0.0 && half.is_finite() && a.y.is_finite()) {
            return;
        }
        let (columns, rows) = if transposed {
            (self.h, self.w)
        } else {
            (self.w, self.h)
        };
        let last_row = rows as f32 - 1.0;
        let last = floor(b.x).min(columns as f32 - 1.0);
        let mut col = floor(a.x).max(0.0);
        while col <= last {
            let (x0, x1) = (a.x.max(col), b.x.min(col + 1.0));
            let length = x1 - x0;
            let y = a.y + ((x0 + x1) * 0.5 - a.x) * slope;
            let (top, bottom) = (y - half, y + half);
            let mut row = floor(top).max(0.0);
            let end = floor(bottom).min(last_row);
            while row <= end {
                let overlap = bottom.min(row + 1.0) - top.max(row);
                self.add(col, row, overlap * length, transposed);
                row += 1.0;
            }
            col += 1.0;
        }
    }

    /// Covers a fraction `c` (at most all) of pixel (`col`, `row`), swapped when `transposed`.
    #[inline]
    fn add(&mut self, col: f32, row: f32, c: f32, transposed: bool) {
        let (x, y) = if transposed { (row, col) } else { (col, row) };
        if !(x >= 0.0 && y >= 0.0 && x < self.w as f32 && y < self.h as f32 && c > 0.0) {
            return;
        }
        let at = y as usize * self.w + x as usize;
        self.through[at] *= 1.0 - EDGE_ALPHA * c.min(1.0);
    }

    /// The image: white, as opaque as the edges left nothing through.
    fn image(&self) -> ColorImage {
        let pixels = self
            .through
            .iter()
            .map(|t| Color32::from_white_alpha(((1.0 - t) * 255.0).round() as u8))
            .collect();
        ColorImage::new([self.w, self.h], pixels)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use egui::Pos2;

    fn lines(n: usize) -> UvLines {
        (0..n)
            .map(|k| {
                let t = (k as f32 + 0.5) / n as f32;
                [Vec2::new(t, 0.0), Vec2::new(t, 1.0)]
            })
            .collect()
    }

    /// The image's columns (x, points) where some pixel shows an edge.
    fn lit_columns(image: &ColorImage, rect: Rect) -> Vec<f32> {
        let [w, h] = image.size;
        (0..w)
            .filter(|&x| (0..h).any(|y| image.pixels[y * w + x].a() > 0))
            .map(|x| rect.min.x + (x as f32 + 0.5) * rect.width() / w as f32)
            .collect()
    }

    #[test]
    fn the_wireframe_is_kept_while_the_view_stays_or_pans_within_its_margin() {
        let ctx = egui::Context::default();
        let (map, panel) = (
            Rect::from_min_size(Pos2::ZERO, egui::vec2(2000.0, 2000.0)),
            Rect::from_min_size(Pos2::ZERO, egui::vec2(500.0, 400.0)),
        );
        let wire = lines(40);
        let mut cache = WireCache::default();
        let (first, rect) = cache.image(&ctx, &wire, (map, panel)).expect("drawn");
        assert_eq!(cache.draws, 1);
        // Drawn around the panel: half a panel more each way, within the map (and the point
        // around it an edge on its border reaches).
        assert_eq!(
            rect,
            Rect::from_min_max(Pos2::new(-1.0, -1.0), Pos2::new(750.0, 600.0))
        );
        assert_eq!(cache.image(&ctx, &wire, (map, panel)), Some((first, rect)));
        assert_eq!(cache.draws, 1, "the same view: not drawn again");
        // Panned within the margin: the same texture, moved with the map.
        let step = egui::vec2(-200.0, -150.0);
        let panned = cache.image(&ctx, &wire, (map.translate(step), panel));
        assert_eq!(panned, Some((first, rect.translate(step))));
        assert_eq!(cache.draws, 1, "a pan within the margin draws nothing");
        // Panned past it: drawn again, into the same texture.
        let far = map.translate(egui::vec2(-600.0, 0.0));
        let (again, moved) = cache.image(&ctx, &wire, (far, panel)).expect("drawn");
        assert_eq!((again, cache.draws), (first, 2));
        assert!(moved.min.x <= -250.0 && moved.max.x >= 500.0, "{moved:?}");
        // Zoomed: drawn again.
        let zoomed = Rect::from_min_size(Pos2::ZERO, egui::vec2(2100.0, 2100.0));
        cache.image(&ctx, &wire, (zoomed, panel));
        assert_eq!(cache.draws, 3);
        // Other lines with the same count and view: drawn again (the cache is checked by the
        // lines it was made from, not trusted by a count).
        let other = lines(40);
        cache.image(&ctx, &other, (zoomed, panel));
        assert_eq!(cache.draws, 4);
        // The map out of the panel: nothing to draw.
        let away = map.translate(egui::vec2(900.0, 0.0));
        assert_eq!(cache.image(&ctx, &other, (away, panel)), None);
    }

    #[test]
    fn an_edge_lies_where_its_uv_points_on_the_map() {
        for ppp in [1.0, 2.0] {
            let map = Rect::from_min_size(Pos2::new(10.0, 20.0), egui::vec2(200.0, 100.0));
            let edge = [[Vec2::new(0.5, 0.0), Vec2::new(0.5, 1.0)]];
            let (image, rect) =
                rasterize(&edge, (map, map.expand(50.0)), ppp, 8192.0).expect("drawn");
            let x = map.center().x;
            let lit = lit_columns(&image, rect);
            assert!(!lit.is_empty(), "drawn at {ppp}");
            assert!(
                lit.iter().all(|c| (c - x).abs() <= 1.0),
                "a vertical edge at u = 0.5 stays within a point of x = {x}: {lit:?}"
            );
            // Along its whole length, as opaque as the old one-point stroke.
            let column = (((x - rect.min.x) * ppp) as usize).min(image.size[0] - 1);
            let [w, h] = image.size;
            let alpha: u32 = (0..w)
                .filter(|&c| c.abs_diff(column) <= 2)
                .map(|c| u32::from(image.pixels[(h / 2) * w + c].a()))
                .sum();
            let expected = (EDGE_ALPHA * 255.0 * ppp).round() as u32;
            assert!(
                alpha.abs_diff(expected) <= 2,
                "{alpha} vs {expected} at {ppp}"
            );
        }
    }

    #[test]
    fn a_diagonal_edge_covers_its_length_and_stacked_edges_blend_as_strokes() {
        let map = Rect::from_min_size(Pos2::ZERO, egui::vec2(100.0, 100.0));
        let diagonal = [[Vec2::ZERO, Vec2::ONE]];
        let (image, _) = rasterize(&diagonal, (map, map), 1.0, 8192.0).expect("drawn");
        // A one-point-wide band along the diagonal: its area is its length.
        let total: f32 = image.pixels.iter().map(|p| f32::from(p.a())).sum();
        let area = total / (EDGE_ALPHA * 255.0);
        assert!((area - 100.0 * 2.0_f32.sqrt()).abs() < 3.0, "{area}");
        // Ten edges on one line: what ten strokes of alpha 70 blended leave through.
        let stacked = [[Vec2::new(0.505, 0.0), Vec2::new(0.505, 1.0)]; 10];
        let (image, _) = rasterize(&stacked, (map, map), 1.0, 8192.0).expect("drawn");
        let a = image.pixels.iter().map(Color32::a).max().unwrap_or(0);
        let expected = ((1.0 - (1.0 - EDGE_ALPHA).powi(10)) * 255.0).round() as u8;
        assert!(a.abs_diff(expected) <= 1, "{a} vs {expected}");
    }

    #[test]
    fn the_image_is_bounded_by_the_panel_however_far_the_map_is_zoomed() {
        // A 4096^2 map at 64 points a texel (the canvas's deepest zoom): the map is 262,144
        // points wide, the image the panel's 500 x 400 pixels, and an edge across the whole
        // map is drawn only where it crosses the panel.
        let panel = Rect::from_min_size(Pos2::ZERO, egui::vec2(500.0, 400.0));
        let map = Rect::from_center_size(Pos2::new(250.0, 200.0), egui::vec2(262_144.0, 262_144.0));
        let across = [[Vec2::new(0.0, 0.5), Vec2::new(1.0, 0.5)]];
        let (image, rect) = rasterize(&across, (map, panel), 1.0, 8192.0).expect("drawn");
        assert_eq!(image.size, [500, 400]);
        assert_eq!(rect, panel);
        let lit = image.pixels.iter().filter(|p| p.a() > 0).count();
        assert!((500..=1000).contains(&lit), "{lit}");
        // Never more pixels than a texture may hold.
        let (image, _) = rasterize(&across, (map, panel), 2.0, 256.0).expect("drawn");
        assert_eq!(image.size, [256, 256]);
        // Edges that are not finite draw nothing and do not panic.
        let bad = [
            [Vec2::splat(f32::NAN), Vec2::ONE],
            [Vec2::splat(f32::INFINITY), Vec2::ZERO],
        ];
        let (image, _) = rasterize(&bad, (map, panel), 1.0, 8192.0).expect("drawn");
        assert!(image.pixels.iter().all(|p| p.a() == 0));
    }
}
