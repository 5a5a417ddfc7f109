//! The layer stack in a version 2 project: per layer its settings in the manifest, and for
//! each painted plane and mask a 16-bit PNG (or a constant when uniform), named by the layer's
//! place in the stack.
//!
//! A paint layer stores its values as the maps store them (`layerK_kd.png`, `layerK_ks.png`,
//! `layerK_n.png`) and its coverage per channel as one RGB image (`layerK_alpha.png`: red
//! `k_d`, green `k_s`, blue `n`); a mask is a gray written as RGB (`layerK_mask.png`). A
//! paint layer nobody painted stores nothing.

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use super::ChannelEntry;
use crate::model::layers::{
    ChannelBlend, Layer, LayerBlend, LayerContent, LayerProps, LayerStack, Mask, PaintTile, Stamped,
};
use crate::model::maps::MaterialMaps;
use crate::model::texel::{Channel, MaterialValue};
use crate::model::tile::{Plane, TILE_TEXELS, Tile};

/// The most layers a project may hold.
pub const MAX_LAYERS: usize = crate::model::document::MAX_LAYERS;

/// The deepest nesting of groups a project may hold.
pub const MAX_DEPTH: usize = 16;

/// A layer's kind in the manifest.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum KindEntry {
    /// Painted planes.
    Paint,
    /// One material.
    Fill,
    /// A folder.
    Group,
}

/// A channel's switch and blend mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlendEntry {
    /// Laid over the layers below.
    pub enabled: bool,
    /// How.
    pub mode: LayerBlend,
}

/// A paint layer's planes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanesEntry {
    /// `k_d` values.
    pub kd: ChannelEntry,
    /// `k_s` values.
    pub ks: ChannelEntry,
    /// `n` values.
    pub n: ChannelEntry,
    /// Coverage of `k_d`, `k_s` and `n` as RGB.
    pub alpha: ChannelEntry,
}

/// A mask.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaskEntry {
    /// Whether it shapes the layer.
    pub enabled: bool,
    /// Whether it is read inverted.
    pub inverted: bool,
    /// Its gray, as RGB.
    pub gray: ChannelEntry,
}

/// One layer in the manifest.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LayerEntry {
    /// Name.
    #[serde(deserialize_with = "crate::model::check::layer_name")]
    pub name: String,
    /// Kind.
    pub kind: KindEntry,
    /// Shown.
    pub visible: bool,
    /// Locked against painting.
    pub locked: bool,
    /// Opacity.
    #[serde(deserialize_with = "crate::model::check::layer_opacity")]
    pub opacity: f32,
    /// `k_d`, `k_s`, `n`.
    pub channels: [BlendEntry; 3],
    /// A fill layer's material.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fill: Option<MaterialValue>,
    /// A paint layer's planes (none: nothing painted).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub planes: Option<PlanesEntry>,
    /// The mask.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mask: Option<MaskEntry>,
    /// A group's layers, bottom first.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub children: Vec<LayerEntry>,
}

/// Maps of `width x height` holding `tiles`.
fn maps_of(
    width: u32,
    height: u32,
    tiles: impl Iterator<Item = Tile>,
) -> Result<MaterialMaps, String> {
    let mut maps =
        MaterialMaps::new(width, height, MaterialValue::default()).map_err(|e| e.to_string())?;
    for (id, tile) in tiles.enumerate() {
        maps.replace_tile(id, Arc::new(tile));
    }
    Ok(maps)
}

/// A tile whose `k_d` holds three gray planes (coverages, or a mask three times).
fn gray_tile(planes: [&Plane<u16>; 3]) -> Tile {
    let mut tile = Tile::uniform(crate::model::texel::Texel {
        kd: [0; 3],
        ks: [0; 3],
        n: 0,
    });
    let uniform = planes.map(Plane::uniform);
    tile.kd = if let [Some(a), Some(b), Some(c)] = uniform {
        Plane::Uniform([a, b, c])
    } else {
        Plane::Data((0..TILE_TEXELS).map(|i| planes.map(|p| p.get(i))).collect())
    };
    tile
}

/// What a writer stores for one layer: its maps to rasterise, named.
pub struct LayerMaps {
    /// File stem (`layerK`).
    pub stem: String,
    /// Values, coverages, mask.
    pub values: Option<MaterialMaps>,
    /// Coverage as `k_d`.
    pub alpha: Option<MaterialMaps>,
    /// Mask as `k_d`.
    pub mask: Option<MaterialMaps>,
}

/// The stack's layers as maps to store, in the order [`entries`] names them.
pub fn layer_maps(stack: &LayerStack) -> Result<Vec<LayerMaps>, String> {
    let (w, h) = (stack.width, stack.height);
    let empty = PaintTile::filled(MaterialValue::default(), [false; 3]);
    stack
        .walk()
        .into_iter()
        .enumerate()
        .map(|(k, (_, layer))| {
            let mut out = LayerMaps {
                stem: format!("layer{k}"),
                values: None,
                alpha: None,
                mask: None,
            };
            if let LayerContent::Paint(tiles) = &layer.content
                && tiles.iter().any(Option::is_some)
            {
                let tile = |t: &Option<crate::model::layers::SharedPaintTile>| {
                    t.as_ref().map_or(&empty, |t| t.get()).clone()
                };
                out.values = Some(maps_of(w, h, tiles.iter().map(|t| tile(t).value))?);
                out.alpha = Some(maps_of(
                    w,
                    h,
                    tiles.iter().map(|t| {
                        let t = tile(t);
                        gray_tile([&t.alpha[0], &t.alpha[1], &t.alpha[2]])
                    }),
                )?);
            }
            if let Some(mask) = &layer.mask {
                out.mask = Some(maps_of(
                    w,
                    h,
                    mask.tiles.iter().map(|t| gray_tile([t.get(); 3])),
                )?);
            }
            Ok(out)
        })
        .collect()
}

/// The manifest's entries for `layers`, given each layer's stored channels in walk order
/// (`stored(k)` gives layer `k`'s planes and mask entries).
pub fn entries(
    layers: &[Layer],
    next: &mut usize,
    stored: &impl Fn(usize) -> (Option<PlanesEntry>, Option<ChannelEntry>),
) -> Vec<LayerEntry> {
    layers
        .iter()
        .map(|layer| {
            let k = *next;
            *next += 1;
            let (planes, mask_gray) = stored(k);
            let p = &layer.props;
            LayerEntry {
                name: p.name.clone(),
                kind: match layer.content {
                    LayerContent::Paint(_) => KindEntry::Paint,
                    LayerContent::Fill(_) => KindEntry::Fill,
                    LayerContent::Group(_) => KindEntry::Group,
                },
                visible: p.visible,
                locked: p.locked,
                opacity: p.opacity,
                channels: p.channels.map(|c| BlendEntry {
                    enabled: c.enabled,
                    mode: c.mode,
                }),
                fill: match layer.content {
                    LayerContent::Fill(v) => Some(v),
                    _ => None,
                },
                planes,
                mask: layer
                    .mask
                    .as_ref()
                    .zip(mask_gray)
                    .map(|(m, gray)| MaskEntry {
                        enabled: m.enabled,
                        inverted: m.inverted,
                        gray,
                    }),
                children: match &layer.content {
                    LayerContent::Group(children) => entries(children, next, stored),
                    _ => Vec::new(),
                },
            }
        })
        .collect()
}

/// Counts the layers and the deepest nesting of `entries`, refusing more than the limits.
pub fn check_shape(entries: &[LayerEntry], depth: usize, count: &mut usize) -> Result<(), String> {
    if depth > MAX_DEPTH {
        return Err(format!("layer groups nest deeper than {MAX_DEPTH}"));
    }
    for e in entries {
        *count += 1;
        if *count > MAX_LAYERS {
            return Err(format!("the project holds more than {MAX_LAYERS} layers"));
        }
        match (e.kind, &e.fill, &e.planes, e.children.is_empty()) {
            (KindEntry::Fill, None, _, _) => {
                return Err(format!("the fill layer {:?} has no fill material", e.name));
            }
            (KindEntry::Paint | KindEntry::Group, Some(_), _, _) => {
                return Err(format!(
                    "the layer {:?} is not a fill layer but has a fill",
                    e.name
                ));
            }
            (KindEntry::Fill | KindEntry::Group, _, Some(_), _) => {
                return Err(format!(
                    "the layer {:?} is not a paint layer but has planes",
                    e.name
                ));
            }
            (KindEntry::Paint | KindEntry::Fill, _, _, false) => {
                return Err(format!(
                    "the layer {:?} is not a group but has layers",
                    e.name
                ));
            }
            _ => {}
        }
        for (c, b) in Channel::ALL.into_iter().zip(&e.channels) {
            if !b.mode.allowed_for(c) {
                return Err(format!(
                    "the layer {:?} blends {} with {}, which it does not take",
                    e.name,
                    c.name(),
                    b.mode.name(c)
                ));
            }
        }
        check_shape(&e.children, depth + 1, count)?;
    }
    Ok(())
}

/// Rebuilds layers from their entries; `read(k)` gives layer `k`'s values, coverage and mask
/// maps as stored.
pub fn build(
    entries: &[LayerEntry],
    next: &mut usize,
    tile_count: usize,
    read: &mut impl FnMut(usize, &LayerEntry) -> Result<LayerMaps, String>,
) -> Result<Vec<Layer>, String> {
    entries
        .iter()
        .map(|e| {
            let k = *next;
            *next += 1;
            let stored = read(k, e)?;
            let props = LayerProps {
                name: e.name.clone(),
                visible: e.visible,
                locked: e.locked,
                opacity: e.opacity,
                channels: e.channels.map(|b| ChannelBlend {
                    enabled: b.enabled,
                    mode: b.mode,
                }),
            };
            let content = match e.kind {
                KindEntry::Paint => LayerContent::Paint(paint_tiles(&stored, tile_count)),
                KindEntry::Fill => LayerContent::Fill(e.fill.unwrap_or_default().sanitized()),
                KindEntry::Group => {
                    LayerContent::Group(build(&e.children, next, tile_count, read)?)
                }
            };
            let mask = e.mask.as_ref().map(|m| Mask {
                tiles: (0..tile_count)
                    .map(|id| {
                        let plane = stored
                            .mask
                            .as_ref()
                            .map_or(Plane::Uniform(u16::MAX), |maps| {
                                gray_plane(maps.tile(id), 0)
                            });
                        Arc::new(Stamped::new(plane))
                    })
                    .collect(),
                enabled: m.enabled,
                inverted: m.inverted,
            });
            Ok(Layer {
                props,
                content,
                mask,
            })
        })
        .collect()
}

/// Component `c` of a tile's `k_d` as a plane.
fn gray_plane(tile: &Tile, c: usize) -> Plane<u16> {
    let mut plane = match &tile.kd {
        Plane::Uniform(v) => Plane::Uniform(v[c]),
        Plane::Data(d) => Plane::Data(d.iter().map(|v| v[c]).collect()),
    };
    plane.compact();
    plane
}

fn paint_tiles(
    stored: &LayerMaps,
    tile_count: usize,
) -> Vec<Option<crate::model::layers::SharedPaintTile>> {
    let (Some(values), Some(alpha)) = (&stored.values, &stored.alpha) else {
        return vec![None; tile_count];
    };
    (0..tile_count)
        .map(|id| {
            let a = alpha.tile(id);
            let alpha = [0, 1, 2].map(|c| gray_plane(a, c));
            if alpha.iter().all(|p| p.uniform() == Some(0)) {
                return None;
            }
            Some(Arc::new(Stamped::new(PaintTile {
                value: (**values.tile(id)).clone(),
                alpha,
            })))
        })
        .collect()
}
