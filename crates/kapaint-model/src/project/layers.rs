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
use crate::layers::projected::{Projected, ProjectionFill};
use crate::layers::{
    ChannelBlend, Layer, LayerBlend, LayerContent, LayerId, LayerProps, LayerStack, Mask,
    PaintTile, Stamped,
};
use crate::maps::MaterialMaps;
use crate::paint_image::PaintImage;
use crate::texel::{Channel, MaterialValue};
use crate::tile::{Plane, TILE_SIZE, TILE_TEXELS, Tile};

/// The most layers a project may hold.
pub const MAX_LAYERS: usize = crate::document::MAX_LAYERS;

pub use crate::check::MAX_DEPTH;

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
    /// The painted tiles, ascending: the images are then atlases of those tiles alone (see
    /// [`atlas_size`]), and every other tile is transparent. Absent: the images are the
    /// whole map.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tiles: Option<Vec<u32>>,
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
    /// The tiles stored, ascending: the image is then an atlas of those tiles alone (see
    /// [`atlas_size`]), and every other tile is `fill`. Absent: the image is the whole map.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tiles: Option<Vec<u32>>,
    /// The gray of the tiles not stored.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fill: Option<u16>,
    /// The generator that makes it (version 4): its parameters, checked as they are read;
    /// `gray` is then the paint over it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub generator: Option<crate::generator::Generator>,
}

/// A projection fill (version 5): how its image is laid, and the image, kept in the project.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProjectionEntry {
    /// How the image is laid (checked as it is read).
    #[serde(deserialize_with = "crate::check::projection")]
    pub projection: crate::paint::projection::Projection,
    /// The channels it fills.
    pub channels: crate::texel::Channels,
    /// The file the image was chosen from (what the editor names; the pixels are kept here).
    pub source: String,
    /// Its colour and coverage: a 16-bit RGBA PNG in the archive (linear, premultiplied).
    pub rgba: String,
    /// Its gray and exponent: a 16-bit gray-alpha PNG in the archive (premultiplied).
    pub gray: String,
    /// Its size in pixels.
    pub width: u32,
    /// Its size in pixels.
    pub height: u32,
}

/// One layer in the manifest.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LayerEntry {
    /// The layer's id (files written before ids were kept have none: the layer gets a new one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub id: Option<u64>,
    /// Name.
    #[serde(deserialize_with = "crate::check::layer_name")]
    pub name: String,
    /// Kind.
    pub kind: KindEntry,
    /// Shown.
    pub visible: bool,
    /// Locked against painting.
    pub locked: bool,
    /// Opacity.
    #[serde(deserialize_with = "crate::check::layer_opacity")]
    pub opacity: f32,
    /// `k_d`, `k_s`, `n`.
    pub channels: [BlendEntry; 3],
    /// A fill layer's material.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fill: Option<MaterialValue>,
    /// A projection fill's projection and image (a fill layer has this or `fill`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub projection: Option<ProjectionEntry>,
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
    let mut tile = Tile::uniform(crate::texel::Texel {
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

/// Tiles a row of an atlas holds.
const ATLAS_COLUMNS: usize = 128;

/// The size in texels of an atlas of `count` tiles: up to 128 tiles a row, row-major, so the
/// atlas of every tile of the largest map is still within the largest map size.
pub fn atlas_size(count: usize) -> (u32, u32) {
    let columns = count.clamp(1, ATLAS_COLUMNS);
    let rows = count.div_ceil(columns).max(1);
    ((columns * TILE_SIZE) as u32, (rows * TILE_SIZE) as u32)
}

/// What a writer stores for one layer, or a reader found: its maps, named. The maps are
/// atlases: their tile `j` is the layer's tile `tiles[j]` (or `mask_tiles[j]`).
pub struct LayerMaps {
    /// File stem (`layerK`).
    pub stem: String,
    /// The painted tiles the value and coverage atlases hold, ascending.
    pub tiles: Vec<u32>,
    /// Values.
    pub values: Option<MaterialMaps>,
    /// Coverage as `k_d`.
    pub alpha: Option<MaterialMaps>,
    /// The mask tiles the mask atlas holds, ascending; every other is `mask_fill`.
    pub mask_tiles: Vec<u32>,
    /// The gray of the mask tiles not held.
    pub mask_fill: u16,
    /// Mask as `k_d`.
    pub mask: Option<MaterialMaps>,
    /// A projection fill's image.
    pub projection: Option<Arc<crate::paint_image::Pixels>>,
}

impl LayerMaps {
    /// Nothing stored yet for layer `k`.
    pub fn empty(k: usize) -> Self {
        Self {
            stem: format!("layer{k}"),
            tiles: Vec::new(),
            values: None,
            alpha: None,
            mask_tiles: Vec::new(),
            mask_fill: u16::MAX,
            mask: None,
            projection: None,
        }
    }
}

/// The most common uniform gray of a mask's tiles (white where none is uniform): the tiles
/// of that gray are not stored.
fn mask_fill(mask: &Mask) -> u16 {
    let mut counts = std::collections::HashMap::new();
    for t in &mask.tiles {
        if let Some(v) = t.get().uniform() {
            *counts.entry(v).or_insert(0_usize) += 1;
        }
    }
    counts
        .into_iter()
        .max_by_key(|&(v, n)| (n, v))
        .map_or(u16::MAX, |(v, _)| v)
}

/// The stack's layers as atlases to store, in the order [`entries`] names them: only painted
/// tiles and mask tiles other than the mask's fill take room.
pub fn layer_maps(stack: &LayerStack) -> Result<Vec<LayerMaps>, String> {
    stack
        .walk()
        .into_iter()
        .enumerate()
        .map(|(k, (_, layer))| {
            let mut out = LayerMaps::empty(k);
            if let LayerContent::Projected(p) = &layer.content {
                out.projection = Some(Arc::clone(
                    p.fill().image.pixels().map_err(|e| e.to_string())?,
                ));
            }
            if let LayerContent::Paint(tiles) = &layer.content {
                let painted: Vec<(u32, &PaintTile)> = (0u32..)
                    .zip(tiles)
                    .filter_map(|(id, t)| Some((id, t.as_ref()?.get())))
                    .collect();
                if !painted.is_empty() {
                    out.tiles = painted.iter().map(|(id, _)| *id).collect();
                    let (w, h) = atlas_size(painted.len());
                    out.values = Some(maps_of(w, h, painted.iter().map(|(_, t)| t.value.clone()))?);
                    out.alpha = Some(maps_of(
                        w,
                        h,
                        painted
                            .iter()
                            .map(|(_, t)| gray_tile([&t.alpha[0], &t.alpha[1], &t.alpha[2]])),
                    )?);
                }
            }
            if let Some(mask) = &layer.mask {
                let fill = mask_fill(mask);
                let stored: Vec<(u32, &Plane<u16>)> = (0u32..)
                    .zip(&mask.tiles)
                    .map(|(id, t)| (id, t.get()))
                    .filter(|(_, p)| p.uniform() != Some(fill))
                    .collect();
                out.mask_fill = fill;
                out.mask_tiles = stored.iter().map(|(id, _)| *id).collect();
                let (w, h) = atlas_size(stored.len());
                out.mask = Some(maps_of(
                    w,
                    h,
                    stored.iter().map(|(_, p)| gray_tile([p; 3])),
                )?);
            }
            Ok(out)
        })
        .collect()
}

/// Checks that `tiles` (ids listed for an atlas) ascend without repeats inside a map of
/// `tile_count` tiles.
pub fn check_tiles(tiles: &[u32], tile_count: usize, what: &str) -> Result<(), String> {
    if tiles.windows(2).any(|w| w[0] >= w[1]) {
        return Err(format!("{what}: the tile list is not ascending"));
    }
    if let Some(&last) = tiles.last()
        && last as usize >= tile_count
    {
        return Err(format!(
            "{what}: tile {last} is outside the map's {tile_count} tiles"
        ));
    }
    Ok(())
}

/// The manifest's entries for `layers`, given each layer's stored channels in walk order
/// (`stored(k)` gives layer `k`'s planes and mask entries).
pub fn entries(
    layers: &[Layer],
    next: &mut usize,
    stored: &impl Fn(usize) -> (Option<PlanesEntry>, Option<MaskEntry>),
) -> Vec<LayerEntry> {
    layers
        .iter()
        .map(|layer| {
            let k = *next;
            *next += 1;
            let (planes, mask_stored) = stored(k);
            let p = &layer.props;
            LayerEntry {
                id: Some(p.id.0),
                name: p.name.clone(),
                kind: match layer.content {
                    LayerContent::Paint(_) => KindEntry::Paint,
                    LayerContent::Fill(_) | LayerContent::Projected(_) => KindEntry::Fill,
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
                projection: match &layer.content {
                    LayerContent::Projected(laid) => Some(projection_entry(laid.fill(), k)),
                    _ => None,
                },
                planes,
                mask: layer
                    .mask
                    .as_ref()
                    .zip(mask_stored)
                    .map(|(m, stored)| MaskEntry {
                        enabled: m.enabled,
                        inverted: m.inverted,
                        generator: m.generator().cloned(),
                        ..stored
                    }),
                children: match &layer.content {
                    LayerContent::Group(children) => entries(children, next, stored),
                    _ => Vec::new(),
                },
            }
        })
        .collect()
}

/// The archive's names of a projection fill's two images, for the layer stored as `stem`.
pub fn projection_files(stem: &str) -> [String; 2] {
    [
        format!("{stem}_projection_rgba.png"),
        format!("{stem}_projection_gray.png"),
    ]
}

/// The entry of a projection fill stored as layer `k`.
fn projection_entry(fill: &ProjectionFill, k: usize) -> ProjectionEntry {
    // The names the writer stores its images under (see `LayerMaps::stem`).
    let [rgba, gray] = projection_files(&LayerMaps::empty(k).stem);
    let (width, height) = fill
        .image
        .pixels()
        .map_or((0, 0), |p| (p.width(), p.height()));
    ProjectionEntry {
        projection: fill.projection,
        channels: fill.channels,
        source: fill.image.path().to_string_lossy().into_owned(),
        rgba,
        gray,
        width,
        height,
    }
}

/// Whether a layer among `entries` (at any depth) is a projection fill.
pub fn any_projection(entries: &[LayerEntry]) -> bool {
    entries
        .iter()
        .any(|e| e.projection.is_some() || any_projection(&e.children))
}

/// Whether a layer among `entries` (at any depth) is laid on the mesh: a generator mask, or a
/// projection fill that projects onto the surface.
pub fn any_on_mesh(entries: &[LayerEntry]) -> bool {
    entries.iter().any(|e| {
        e.mask.as_ref().is_some_and(|m| m.generator.is_some())
            || e.projection
                .as_ref()
                .is_some_and(|p| p.projection.needs_surface())
            || any_on_mesh(&e.children)
    })
}

/// Whether a mask among `entries` (at any depth) is made by a generator.
pub fn any_generator(entries: &[LayerEntry]) -> bool {
    entries.iter().any(|e| {
        e.mask.as_ref().is_some_and(|m| m.generator.is_some()) || any_generator(&e.children)
    })
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
            (KindEntry::Fill, None, _, _) if e.projection.is_none() => {
                return Err(format!("the fill layer {:?} has no fill material", e.name));
            }
            (KindEntry::Fill, Some(_), _, _) if e.projection.is_some() => {
                return Err(format!(
                    "the fill layer {:?} has both a material and a projection",
                    e.name
                ));
            }
            (KindEntry::Paint | KindEntry::Group, _, _, _) if e.projection.is_some() => {
                return Err(format!(
                    "the layer {:?} is not a fill layer but has a projection",
                    e.name
                ));
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
    (tile_count, size): (usize, (u32, u32)),
    read: &mut impl FnMut(usize, &LayerEntry) -> Result<LayerMaps, String>,
) -> Result<Vec<Layer>, String> {
    entries
        .iter()
        .map(|e| {
            let k = *next;
            *next += 1;
            let stored = read(k, e)?;
            let props = LayerProps {
                id: e.id.map_or_else(LayerId::fresh, LayerId::loaded),
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
                KindEntry::Fill => match (&e.projection, &stored.projection) {
                    (Some(p), Some(pixels)) => LayerContent::Projected(Arc::new(Projected::new(
                        ProjectionFill {
                            image: PaintImage::of_pixels(&p.source, Arc::clone(pixels)),
                            projection: p.projection,
                            channels: p.channels,
                        },
                        // Laid on the map alone for now, as a generator is.
                        crate::generator::tiles::Source::new(None, &[], size.0, size.1),
                    ))),
                    (Some(_), None) => {
                        return Err(format!("the projection fill {:?} has no image", e.name));
                    }
                    (None, _) => LayerContent::Fill(e.fill.unwrap_or_default().sanitized()),
                },
                KindEntry::Group => {
                    LayerContent::Group(build(&e.children, next, (tile_count, size), read)?)
                }
            };
            let mask = e.mask.as_ref().map(|m| {
                let fill = Arc::new(Stamped::new(Plane::Uniform(stored.mask_fill)));
                let mut tiles = vec![fill; tile_count];
                if let Some(maps) = &stored.mask {
                    for (j, &id) in stored.mask_tiles.iter().enumerate() {
                        tiles[id as usize] = Arc::new(Stamped::new(gray_plane(maps.tile(j), 0)));
                    }
                }
                Mask {
                    tiles,
                    enabled: m.enabled,
                    inverted: m.inverted,
                    // Laid on the map alone for now: the document lays it again on its mesh
                    // and bakes as they are attached.
                    generator: m.generator.clone().map(|g| {
                        Arc::new(crate::generator::tiles::Generated::new(
                            g,
                            crate::generator::tiles::Source::new(None, &[], size.0, size.1),
                            false,
                        ))
                    }),
                }
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
) -> Vec<Option<crate::layers::SharedPaintTile>> {
    let mut out = vec![None; tile_count];
    let (Some(values), Some(alpha)) = (&stored.values, &stored.alpha) else {
        return out;
    };
    for (j, &id) in stored.tiles.iter().enumerate() {
        let a = alpha.tile(j);
        let alpha = [0, 1, 2].map(|c| gray_plane(a, c));
        if alpha.iter().all(|p| p.uniform() == Some(0)) {
            continue;
        }
        out[id as usize] = Some(Arc::new(Stamped::new(PaintTile {
            value: (**values.tile(j)).clone(),
            alpha,
        })));
    }
    out
}
