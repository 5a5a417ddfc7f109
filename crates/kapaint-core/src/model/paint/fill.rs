//! Fills: the whole map, a flood-filled region of similar texels, or any mask.

use super::{PaintTarget, n_bits_from_blend, n_bits_to_blend, pre_tile};
use crate::model::brush::BlendMode;
use crate::model::history::History;
use crate::model::maps::MaterialMaps;
use crate::model::texel::{MaterialValue, Texel, decode_unorm, n_from_blend};
use crate::model::tile::{TILE_SIZE, TILE_TEXELS, Tile};

/// Writes `target` over every texel of the maps at alpha `opacity`. A full-opacity normal
/// fill makes the written planes uniform: no per-texel work and no memory.
pub fn fill_all(
    maps: &mut MaterialMaps,
    history: &mut History,
    target: &PaintTarget,
    opacity: f32,
) {
    use crate::model::tile::Plane;
    let uniform = opacity >= 1.0 && target.mode == BlendMode::Normal && !target.energy_guard;
    let value = Texel::encode(MaterialValue {
        kd: target.kd,
        ks: target.ks,
        n: n_from_blend(target.n_blend),
    });
    let value = Texel {
        n: n_bits_from_blend(target.n_blend),
        ..value
    };
    for id in 0..maps.tile_count() {
        if uniform {
            // Build the new tile from the old one's untouched planes: no copy of what is
            // overwritten.
            let old = maps.tile(id);
            let tile = Tile {
                kd: if target.channels.kd {
                    Plane::Uniform(value.kd)
                } else {
                    old.kd.clone()
                },
                ks: if target.channels.ks {
                    Plane::Uniform(value.ks)
                } else {
                    old.ks.clone()
                },
                n: if target.channels.n {
                    Plane::Uniform(value.n)
                } else {
                    old.n.clone()
                },
            };
            history.replace_for_write(maps, id, tile);
        } else {
            let pre = pre_tile(history, maps, id);
            let tile = history.tile_for_write(maps, id);
            for i in 0..TILE_TEXELS {
                tile.set_texel(i, target.blend(pre.texel(i), opacity));
            }
        }
    }
}

/// The 4-connected region around `(x, y)` whose `channel` stays within `tolerance` of the
/// seed's (in blend space, max over colour components), as a bit per texel.
pub fn flood_region(
    maps: &MaterialMaps,
    x: u32,
    y: u32,
    channel: crate::model::texel::Channel,
    tolerance: f32,
) -> Vec<bool> {
    use crate::model::texel::Channel;
    let (w, h) = (maps.width(), maps.height());
    let key = |t: Texel| -> [f32; 3] {
        match channel {
            Channel::Kd => t.kd.map(decode_unorm),
            Channel::Ks => t.ks.map(decode_unorm),
            Channel::N => [n_bits_to_blend(t.n); 3],
        }
    };
    let seed = key(maps.texel(x, y));
    let within = |t: Texel| {
        key(t)
            .iter()
            .zip(&seed)
            .all(|(a, b)| (a - b).abs() <= tolerance)
    };
    let mut inside = vec![false; (w * h) as usize];
    let mut stack = vec![(x, y)];
    while let Some((sx, sy)) = stack.pop() {
        // Scanline fill: extend left and right, queue the rows above and below.
        let row = (sy * w) as usize;
        if inside[row + sx as usize] || !within(maps.texel(sx, sy)) {
            continue;
        }
        let mut l = sx;
        while l > 0 && !inside[row + l as usize - 1] && within(maps.texel(l - 1, sy)) {
            l -= 1;
        }
        let mut r = sx;
        while r + 1 < w && !inside[row + r as usize + 1] && within(maps.texel(r + 1, sy)) {
            r += 1;
        }
        for xx in l..=r {
            inside[row + xx as usize] = true;
            if sy > 0 && !inside[row - w as usize + xx as usize] {
                stack.push((xx, sy - 1));
            }
            if sy + 1 < h && !inside[row + w as usize + xx as usize] {
                stack.push((xx, sy + 1));
            }
        }
    }
    inside
}

/// Writes `target` at alpha `opacity` over the texels of `mask` (row-major, one per texel).
pub fn fill_mask(
    maps: &mut MaterialMaps,
    history: &mut History,
    target: &PaintTarget,
    opacity: f32,
    mask: &[bool],
) {
    let w = maps.width() as usize;
    for id in 0..maps.tile_count() {
        let crate::model::maps::TexelRect { x0, y0, x1, y1 } = maps.tile_rect(id);
        let any = (y0..y1).any(|y| {
            mask[y as usize * w + x0 as usize..y as usize * w + x1 as usize].contains(&true)
        });
        if !any {
            continue;
        }
        let pre = pre_tile(history, maps, id);
        let tile = history.tile_for_write(maps, id);
        for y in y0..y1 {
            for x in x0..x1 {
                if mask[y as usize * w + x as usize] {
                    let i = (y - y0) as usize * TILE_SIZE + (x - x0) as usize;
                    tile.set_texel(i, target.blend(pre.texel(i), opacity));
                }
            }
        }
    }
}
