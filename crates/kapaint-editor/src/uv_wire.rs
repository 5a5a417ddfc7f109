//! The canvas's UV wireframe, tessellated once for a view and kept: a frame whose view did
//! not change draws it as one mesh (one shape, no per-edge work); a pan or zoom tessellates
//! again, only the edges inside the panel. Drawing every edge as its own shape each frame took
//! a lock per edge and grew with the mesh (a sphere's 6,000 edges were a sixth of a frame).

use std::sync::Arc;

use egui::epaint::{Mesh, TessellationOptions, Tessellator};
use egui::{Color32, Rect, Stroke};
use glam::Vec2;

/// The mesh's UV edges in map fractions (u, 1 - v), shared with the mesh state they came from.
pub(crate) type UvLines = Arc<[[Vec2; 2]]>;

/// The edges' stroke: one point, faint white.
fn stroke() -> Stroke {
    Stroke::new(1.0, Color32::from_white_alpha(70))
}

/// What a tessellated wireframe was made for.
struct Made {
    lines: UvLines,
    /// The map's rect and the panel's, and the points' pixel size, as bits.
    view: [u32; 9],
    /// The context's tessellation options (feathering, rounding to pixels).
    options: TessellationOptions,
}

impl Made {
    fn same(&self, lines: &UvLines, view: &[u32; 9], options: &TessellationOptions) -> bool {
        Arc::ptr_eq(&self.lines, lines) && &self.view == view && &self.options == options
    }
}

/// The wireframe last tessellated, and for what.
#[derive(Default)]
pub(crate) struct WireCache {
    made: Option<(Made, Arc<Mesh>)>,
}

impl WireCache {
    /// The wireframe of `lines` drawn over the map at `map` within `panel` (the edges outside
    /// the panel left out), made again only when the lines or the view differ from the last.
    pub(crate) fn mesh(
        &mut self,
        ctx: &egui::Context,
        lines: &UvLines,
        (map, panel): (Rect, Rect),
    ) -> Arc<Mesh> {
        let ppp = ctx.pixels_per_point();
        let view = [
            map.min.x,
            map.min.y,
            map.max.x,
            map.max.y,
            panel.min.x,
            panel.min.y,
            panel.max.x,
            panel.max.y,
            ppp,
        ]
        .map(f32::to_bits);
        let options = ctx.tessellation_options(|o| *o);
        if let Some((made, mesh)) = &self.made
            && made.same(lines, &view, &options)
        {
            return Arc::clone(mesh);
        }
        // The tessellator leaves out the edges outside its clip rect (the panel): asked for
        // here whatever the context's setting.
        let culling = TessellationOptions {
            coarse_tessellation_culling: true,
            ..options
        };
        let mut tessellator = Tessellator::new(ppp, culling, [1, 1], Vec::new());
        tessellator.set_clip_rect(panel);
        let at = |uv: Vec2| map.min + egui::Vec2::new(uv.x, uv.y) * map.size();
        let mut mesh = Mesh::default();
        let stroke = stroke();
        for [a, b] in lines.iter() {
            tessellator.tessellate_line_segment([at(*a), at(*b)], stroke, &mut mesh);
        }
        let mesh = Arc::new(mesh);
        let made = Made {
            lines: Arc::clone(lines),
            view,
            options,
        };
        self.made = Some((made, Arc::clone(&mesh)));
        mesh
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use egui::Pos2;

    fn lines(n: usize) -> UvLines {
        (0..n)
            .map(|k| {
                let t = k as f32 / n as f32;
                [Vec2::new(t, 0.0), Vec2::new(t, 1.0)]
            })
            .collect()
    }

    #[test]
    fn the_wireframe_is_kept_while_the_view_stays_and_made_again_when_it_moves() {
        let ctx = egui::Context::default();
        let (map, panel) = (
            Rect::from_min_size(Pos2::ZERO, egui::vec2(400.0, 400.0)),
            Rect::from_min_size(Pos2::ZERO, egui::vec2(500.0, 500.0)),
        );
        let wire = lines(40);
        let mut cache = WireCache::default();
        let first = cache.mesh(&ctx, &wire, (map, panel));
        assert!(!first.is_empty(), "the edges are drawn");
        let again = cache.mesh(&ctx, &wire, (map, panel));
        assert!(Arc::ptr_eq(&first, &again), "the same view: the same mesh");
        // Other lines with the same count and view: made again (the cache is checked by the
        // lines it was made from, not trusted by a count).
        let other = lines(40);
        let for_other = cache.mesh(&ctx, &other, (map, panel));
        assert!(!Arc::ptr_eq(&first, &for_other));
        // Panned so that half the edges leave the panel: fewer triangles.
        let panned = map.translate(egui::vec2(250.0, 0.0));
        let half = cache.mesh(&ctx, &other, (panned, panel));
        assert!(half.indices.len() < first.indices.len(), "culled");
        assert!(half.vertices.iter().all(|v| v.pos.x >= 240.0));
        // Other tessellation options (no feathering): made again, not the feathered mesh.
        let feathered = cache.mesh(&ctx, &other, (panned, panel));
        ctx.tessellation_options_mut(|o| o.feathering = false);
        let sharp = cache.mesh(&ctx, &other, (panned, panel));
        assert!(!Arc::ptr_eq(&feathered, &sharp), "made for the new options");
        assert!(
            sharp.vertices.len() < feathered.vertices.len(),
            "no feathering"
        );
    }

    #[test]
    fn an_edge_lies_where_its_uv_points_on_the_map() {
        let ctx = egui::Context::default();
        let map = Rect::from_min_size(Pos2::new(10.0, 20.0), egui::vec2(200.0, 100.0));
        let edge: UvLines = Arc::from(vec![[Vec2::new(0.5, 0.0), Vec2::new(0.5, 1.0)]]);
        let mesh = WireCache::default().mesh(&ctx, &edge, (map, map.expand(50.0)));
        let x = map.center().x;
        assert!(
            mesh.vertices.iter().all(|v| (v.pos.x - x).abs() <= 1.5),
            "a vertical edge at u = 0.5 stays within a pixel of x = {x}"
        );
    }
}
