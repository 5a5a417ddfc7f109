//! Whole-stack operations the layer commands build on: merging layers into one paint
//! layer's tiles, and a mask from a channel's values.

use std::sync::Arc;

use rayon::prelude::*;

use glam::Vec3;

use super::{Layer, LayerStack, Mask, SharedMaskTile, SharedPaintTile, Stamped, merge_tile};
use crate::maps::MaterialMaps;
use crate::texel::{Channel, MaterialValue, N_MAX, decode_n, decode_rgb};
use crate::tile::{Plane, TILE_TEXELS};

/// `layers` merged tile by tile into one paint layer's tiles.
pub fn merged(layers: &[Layer], tile_count: usize) -> Vec<Option<SharedPaintTile>> {
    (0..tile_count)
        .into_par_iter()
        .map(|id| merge_tile(layers, id).map(|t| Arc::new(Stamped::new(t))))
        .collect()
}

/// A mask white where `channel` of the composite is above `threshold`.
pub fn mask_from_channel(
    maps: &MaterialMaps,
    channel: Channel,
    threshold: f32,
) -> Vec<SharedMaskTile> {
    (0..maps.tile_count())
        .into_par_iter()
        .map(|id| {
            let tile = maps.tile(id);
            let mut plane = Plane::Data(
                (0..TILE_TEXELS)
                    .map(|i| {
                        let v = match channel {
                            Channel::Kd => decode_rgb(tile.kd.get(i)).element_sum() / 3.0,
                            Channel::Ks => decode_rgb(tile.ks.get(i)).element_sum() / 3.0,
                            Channel::N => decode_n(tile.n.get(i)),
                        };
                        if v > threshold { u16::MAX } else { 0 }
                    })
                    .collect(),
            );
            plane.compact();
            Arc::new(Stamped::new(plane))
        })
        .collect()
}

/// What the "selected layer only" view shows: the base and the layer at `path` alone, shown
/// (its group's settings left out). `None` if no layer is there.
pub fn layer_alone(stack: &LayerStack, path: &[usize]) -> Option<LayerStack> {
    let mut layer = stack.layer(path)?.clone();
    layer.props.visible = true;
    Some(LayerStack {
        layers: vec![layer],
        ..stack.without_layers()
    })
}

/// What the "mask" view shows: the mask of the layer at `path` as it applies (inversion
/// included, even when disabled) in `k_d`, `k_s` and `n`, white showing the layer. `None` if
/// that layer has no mask.
pub fn mask_alone(stack: &LayerStack, path: &[usize]) -> Option<LayerStack> {
    let mask = stack.layer(path)?.mask.clone()?;
    let mut white = Layer::fill("mask", MaterialValue::new(Vec3::ONE, Vec3::ONE, N_MAX));
    white.mask = Some(Mask {
        enabled: true,
        ..mask
    });
    Some(LayerStack {
        base: MaterialValue::new(Vec3::ZERO, Vec3::ZERO, 0.0),
        layers: vec![white],
        ..stack.without_layers()
    })
}
