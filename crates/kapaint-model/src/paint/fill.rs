//! The flood fill's region: the texels connected to a seed whose channel stays within a
//! tolerance (the layer engine fills it: `model::document`).

use super::n_bits_to_blend;
use crate::maps::MaterialMaps;
use crate::texel::{Texel, decode_unorm};

/// The 4-connected region around `(x, y)` whose `channel` stays within `tolerance` of the
/// seed's (in blend space, max over colour components), as a bit per texel.
pub fn flood_region(
    maps: &MaterialMaps,
    x: u32,
    y: u32,
    channel: crate::texel::Channel,
    tolerance: f32,
) -> Vec<bool> {
    use crate::texel::Channel;
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
