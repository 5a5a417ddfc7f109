//! The blur tool on a layer: each texel moves towards the box average of the planes around it
//! (premultiplied by coverage on a paint layer), from the planes as they were before the dab.

use rayon::prelude::*;

use super::{Planes, PrePlanes, RANGES, component, decode, empty_paint_tile, encode};
use crate::layers::Stamped;
use crate::texel::{decode_unorm, encode_unorm};
use crate::tile::TILE_SIZE;

/// A blur of one dab: each texel moves towards the box average (premultiplied by coverage on a
/// paint layer) of the planes around it by its weight. `weights` lists, per tile, the texels
/// and weights the dab covers; `pre` is the planes before the dab.
pub fn blur(
    planes: Planes<'_>,
    pre: PrePlanes<'_>,
    (width, height): (u32, u32),
    channels: [bool; 3],
    kernel_px: u32,
    weights: Vec<(usize, Vec<(usize, f32)>)>,
) {
    let tiles_x = (width as usize).div_ceil(TILE_SIZE);
    let k = i64::from(kernel_px.max(1));
    let locate = |x: i64, y: i64| {
        let (x, y) = (x as usize, y as usize);
        (
            (y / TILE_SIZE) * tiles_x + x / TILE_SIZE,
            (y % TILE_SIZE) * TILE_SIZE + x % TILE_SIZE,
        )
    };
    // Eight sums: seven premultiplied components and, per channel, its coverage.
    let average = |x: i64, y: i64| -> ([f32; 7], [f32; 3]) {
        let mut sum = [0.0_f32; 7];
        let mut cover = [0.0_f32; 3];
        let mut count = 0.0;
        for yy in (y - k).max(0)..=(y + k).min(i64::from(height) - 1) {
            for xx in (x - k).max(0)..=(x + k).min(i64::from(width) - 1) {
                let (id, i) = locate(xx, yy);
                count += 1.0;
                match pre {
                    PrePlanes::Paint(tiles) => {
                        let Some(t) = &tiles[id] else { continue };
                        for (ch, range) in RANGES.iter().enumerate() {
                            let a = decode_unorm(t.get().alpha[ch].get(i));
                            cover[ch] += a;
                            for kk in range.clone() {
                                sum[kk] += a * decode(ch, component(&t.get().value, kk, i));
                            }
                        }
                    }
                    PrePlanes::Mask(tiles) => sum[0] += decode_unorm(tiles[id].get().get(i)),
                }
            }
        }
        (sum.map(|s| s / count), cover.map(|c| c / count))
    };
    // Blurred texels are computed from `pre`, then written by direct assignment.
    let results: Blurred = weights
        .into_par_iter()
        .map(|(id, texels)| {
            let x0 = ((id % tiles_x) * TILE_SIZE) as i64;
            let y0 = ((id / tiles_x) * TILE_SIZE) as i64;
            let out = texels
                .into_iter()
                .map(|(i, w)| {
                    let (avg, cover) =
                        average(x0 + (i % TILE_SIZE) as i64, y0 + (i / TILE_SIZE) as i64);
                    (i, avg, cover, w.clamp(0.0, 1.0))
                })
                .collect();
            (id, out)
        })
        .collect();
    edit_blurred(planes, pre, channels, results);
}

/// Per tile, its blurred texels: index, premultiplied averages, coverage averages, weight.
type Blurred = Vec<(usize, Vec<(usize, [f32; 7], [f32; 3], f32)>)>;

/// Writes blurred texels: premultiplied values and coverages move towards their averages.
fn edit_blurred(planes: Planes<'_>, pre: PrePlanes<'_>, channels: [bool; 3], work: Blurred) {
    match (planes, pre) {
        (Planes::Paint(tiles), PrePlanes::Paint(pre)) => {
            for (id, texels) in work {
                let slot = &mut tiles[id];
                let pre_tile = pre[id].as_ref();
                let tile = Stamped::write(slot.get_or_insert_with(empty_paint_tile));
                for (i, avg, cover, w) in texels {
                    for (ch, range) in RANGES.iter().enumerate() {
                        if !channels[ch] {
                            continue;
                        }
                        let a0 = pre_tile.map_or(0.0, |p| decode_unorm(p.get().alpha[ch].get(i)));
                        let a1 = a0 + (cover[ch] - a0) * w;
                        tile.alpha[ch].data_mut()[i] = encode_unorm(a1);
                        for kk in range.clone() {
                            let v0 = pre_tile
                                .map_or(0.0, |p| decode(ch, component(&p.get().value, kk, i)));
                            let pm = a0 * v0 + (avg[kk] - a0 * v0) * w;
                            let v = if a1 > 0.0 {
                                (pm / a1).clamp(0.0, 1.0)
                            } else {
                                v0
                            };
                            let bits = encode(ch, v);
                            match kk {
                                0..3 => tile.value.kd.data_mut()[i][kk] = bits,
                                3..6 => tile.value.ks.data_mut()[i][kk - 3] = bits,
                                _ => tile.value.n.data_mut()[i] = bits,
                            }
                        }
                    }
                }
            }
        }
        (Planes::Mask(tiles), PrePlanes::Mask(pre)) => {
            for (id, texels) in work {
                let plane = Stamped::write(&mut tiles[id]);
                for (i, avg, _, w) in texels {
                    let p = decode_unorm(pre[id].get().get(i));
                    plane.data_mut()[i] = encode_unorm(p + (avg[0] - p) * w);
                }
            }
        }
        _ => {}
    }
}
