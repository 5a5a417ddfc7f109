//! Blur dabs: the enabled channels pulled towards their local box average.

use glam::Vec3;

use super::{Footprint, PaintTarget, n_bits_to_blend};
use crate::model::brush::BlendMode;
use crate::model::history::History;
use crate::model::maps::{MaterialMaps, TileId};
use crate::model::texel::{Texel, decode_unorm};
use crate::model::tile::TILE_SIZE;

/// Applies one blur dab: enabled channels move towards their local box average by the dab
/// weight times `strength`.
pub fn blur_dab(
    maps: &mut MaterialMaps,
    history: &mut History,
    channels: crate::model::texel::Channels,
    kernel_px: u32,
    strength: f32,
    fp: &impl Footprint,
) {
    if channels.is_empty() || strength <= 0.0 {
        return;
    }
    let k = i64::from(kernel_px.max(1));
    let (w, h) = (i64::from(maps.width()), i64::from(maps.height()));
    // Blurred values are computed from the state before this dab, then written.
    let mut writes: Vec<(TileId, usize, Texel)> = Vec::new();
    for id in fp.tiles(maps) {
        let rect = maps.tile_rect(id);
        fp.visit_tile(id, rect, |i, weight| {
            let x = i64::from(rect.x0) + (i % TILE_SIZE) as i64;
            let y = i64::from(rect.y0) + (i / TILE_SIZE) as i64;
            let mut sum = [0.0_f32; 7];
            let mut count = 0.0;
            for yy in (y - k).max(0)..=(y + k).min(h - 1) {
                for xx in (x - k).max(0)..=(x + k).min(w - 1) {
                    let t = maps.texel(xx as u32, yy as u32);
                    for c in 0..3 {
                        sum[c] += decode_unorm(t.kd[c]);
                        sum[3 + c] += decode_unorm(t.ks[c]);
                    }
                    sum[6] += n_bits_to_blend(t.n);
                    count += 1.0;
                }
            }
            let avg = sum.map(|s| s / count);
            let target = PaintTarget {
                kd: Vec3::new(avg[0], avg[1], avg[2]),
                ks: Vec3::new(avg[3], avg[4], avg[5]),
                n_blend: avg[6],
                channels,
                mode: BlendMode::Normal,
                energy_guard: false,
            };
            let pre = maps.tile(id).texel(i);
            writes.push((id, i, target.blend(pre, (weight * strength).min(1.0))));
        });
    }
    for (id, i, t) in writes {
        history.tile_for_write(maps, id).set_texel(i, t);
    }
}
