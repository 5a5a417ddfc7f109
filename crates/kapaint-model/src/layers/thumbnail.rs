//! Small pictures of a layer's content and mask for the Layers panel: what an artist reads
//! at a glance, sampled (nearest texel), not filtered.

use super::{Layer, LayerContent, LayerStack};
use crate::texel::{MaterialValue, Texel, linear_to_srgb8, n_to_blend};
use crate::tile::TILE_SIZE;

/// A `size x size` RGBA8 (sRGB, unpremultiplied) picture of `layer`'s content, sampled at the
/// centres of a grid over the map: `k_d` where it covers `k_d`, else the grey of `k_s` or of
/// `n` (on the brushes' log scale); alpha is its coverage. Groups give `None` (the panel shows
/// a folder).
pub fn content(stack: &LayerStack, layer: &Layer, size: u32) -> Option<Vec<[u8; 4]>> {
    let picture = |value: MaterialValue, cover: [u16; 3]| -> [u8; 4] {
        let grey = |v: f32| {
            let g = linear_to_srgb8(v);
            [g, g, g]
        };
        let rgb = if cover[0] > 0 {
            value.kd.to_array().map(linear_to_srgb8)
        } else if cover[1] > 0 {
            grey(value.ks.element_sum() / 3.0)
        } else {
            grey(n_to_blend(value.n))
        };
        let alpha = cover.into_iter().max().unwrap_or(0) >> 8;
        [
            rgb[0],
            rgb[1],
            rgb[2],
            u8::try_from(alpha).unwrap_or(u8::MAX),
        ]
    };
    match &layer.content {
        LayerContent::Group(_) => None,
        LayerContent::Fill(value) => Some(vec![picture(*value, [u16::MAX; 3]); pixels(size)]),
        LayerContent::Paint(_) | LayerContent::Projected(_) => {
            Some(sample(stack, size, |id, i| {
                let tile = match &layer.content {
                    LayerContent::Paint(tiles) => tiles.get(id).and_then(Option::as_ref),
                    LayerContent::Projected(p) => p.tile(id),
                    _ => None,
                };
                tile.map_or([0; 4], |t| {
                    let t = t.get();
                    picture(
                        Texel::decode(t.value.texel(i)),
                        t.alpha.each_ref().map(|a| a.get(i)),
                    )
                })
            }))
        }
    }
}

/// A `size x size` RGBA8 picture of `layer`'s mask as it applies (inversion included), or
/// `None` when it has none.
pub fn mask(stack: &LayerStack, layer: &Layer, size: u32) -> Option<Vec<[u8; 4]>> {
    let mask = layer.mask.as_ref()?;
    Some(sample(stack, size, |id, i| {
        let v = if id < mask.tiles.len() {
            mask.sample(id, i)
        } else {
            0
        };
        let v = if mask.inverted { u16::MAX - v } else { v };
        let g = u8::try_from(v >> 8).unwrap_or(u8::MAX);
        [g, g, g, 255]
    }))
}

fn pixels(size: u32) -> usize {
    usize::try_from(size).unwrap_or(0).pow(2)
}

/// `at(tile, texel index)` at the centre of each cell of a `size x size` grid over the map.
fn sample(stack: &LayerStack, size: u32, at: impl Fn(usize, usize) -> [u8; 4]) -> Vec<[u8; 4]> {
    let size = size.max(1);
    let tiles_x = stack.tiles_x();
    let coord = |cell: u32, extent: u32| {
        let t = (u64::from(cell) * 2 + 1) * u64::from(extent) / (u64::from(size) * 2);
        usize::try_from(t.min(u64::from(extent.saturating_sub(1)))).unwrap_or(0)
    };
    let mut out = Vec::with_capacity(pixels(size));
    for row in 0..size {
        let y = coord(row, stack.height);
        for col in 0..size {
            let x = coord(col, stack.width);
            let id = (y / TILE_SIZE) * tiles_x + x / TILE_SIZE;
            out.push(at(id, (y % TILE_SIZE) * TILE_SIZE + x % TILE_SIZE));
        }
    }
    out
}
