//! Layers and masks: the stack a [`super::Document`] paints on, and its composite.
//!
//! A [`LayerStack`] is a base material under an ordered list of layers, bottom first. A layer
//! is a paint layer (its own `k_d`, `k_s`, `n` and per-channel coverage in 64 x 64
//! copy-on-write tiles; a tile nobody painted is `None` and costs nothing), a fill layer (one
//! material, shaped only by its mask) or a group (its children composited first, then laid
//! over what is below like one layer). Every layer has a name, visibility, a lock, an opacity,
//! per channel an enable and a blend mode, and optionally a grayscale mask.
//!
//! The composite flattens the stack into the [`MaterialMaps`](super::MaterialMaps) the
//! renderer, the `k_a` derivation and the exporter read, so `k_a` is always derived from the
//! composited `k_d`, `k_s` and `n`, never blended. See [`composite`].

mod blend;
pub mod composite;
pub mod edit;
pub mod history;
mod mask;
pub mod ops;
pub mod paint;
pub mod projected;
pub mod thumbnail;

pub use blend::{Covered, LayerBlend};
pub use composite::{Compositor, composite_tile, merge_tile};
pub use history::{Selected, Selection, StackHistory, State};
pub use mask::{Mask, lay_generators, neutral_tile};
pub use paint::{LayerStroke, LayerValue};

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use super::texel::{Channel, MaterialValue, Texel};
use super::tile::{Plane, Tile};

/// Something shared between the stack and history, stamped with a number no other content
/// ever had: what the compositor compares to find the tiles that changed.
#[derive(Debug, PartialEq)]
pub struct Stamped<T> {
    stamp: u64,
    data: T,
}

/// The next stamp (starts at 1; 0 stands for "nothing there").
pub(crate) fn next_stamp() -> u64 {
    static NEXT: AtomicU64 = AtomicU64::new(1);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

impl<T: Clone> Clone for Stamped<T> {
    /// A copy is new content: it gets its own stamp.
    fn clone(&self) -> Self {
        Self::new(self.data.clone())
    }
}

impl<T: Clone> Stamped<T> {
    /// `data` with a fresh stamp.
    pub fn new(data: T) -> Self {
        Self {
            stamp: next_stamp(),
            data,
        }
    }

    /// The stamp.
    pub fn stamp(&self) -> u64 {
        self.stamp
    }

    /// The content.
    pub fn get(&self) -> &T {
        &self.data
    }

    /// The content to write: copied first if history still shares it, and stamped anew.
    pub fn write(this: &mut Arc<Self>) -> &mut T {
        let inner = Arc::make_mut(this);
        inner.stamp = next_stamp();
        &mut inner.data
    }
}

/// One tile of a paint layer: its values and, per channel (`k_d`, `k_s`, `n`), its coverage
/// as unorm16.
#[derive(Clone, Debug, PartialEq)]
pub struct PaintTile {
    /// The painted values.
    pub value: Tile,
    /// Coverage of `k_d`, `k_s` and `n`.
    pub alpha: [Plane<u16>; 3],
}

impl PaintTile {
    /// A tile of `value` covering the channels in `cover` fully, the others not at all.
    pub fn filled(value: MaterialValue, cover: [bool; 3]) -> Self {
        Self {
            value: Tile::uniform(Texel::encode(value.sanitized())),
            alpha: cover.map(|c| Plane::Uniform(if c { u16::MAX } else { 0 })),
        }
    }

    /// Heap bytes (uniform planes cost nothing).
    pub fn heap_bytes(&self) -> usize {
        self.value.heap_bytes() + self.alpha.iter().map(Plane::heap_bytes).sum::<usize>()
    }
}

/// A shared, stamped paint tile.
pub type SharedPaintTile = Arc<Stamped<PaintTile>>;
/// A shared, stamped mask tile (unorm16, 65535 shows the layer fully).
pub type SharedMaskTile = Arc<Stamped<Plane<u16>>>;

/// A channel's part in a layer: whether the layer changes it, and how.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ChannelBlend {
    /// The layer changes this channel.
    pub enabled: bool,
    /// How.
    pub mode: LayerBlend,
}

/// What every layer and group has.
#[derive(Clone, Debug, PartialEq)]
pub struct LayerProps {
    /// Which layer this is: kept through moves, grouping, undo and saves; a copy gets its own.
    pub id: LayerId,
    /// Display name.
    pub name: String,
    /// Shown (and composited).
    pub visible: bool,
    /// Locked against painting.
    pub locked: bool,
    /// Opacity in `[0, 1]`.
    pub opacity: f32,
    /// `k_d`, `k_s` and `n`, in that order.
    pub channels: [ChannelBlend; 3],
}

/// A layer's identity within its document (never reused while the process runs): what
/// scripts may address a layer by (`SelectLayer((id: 7))`) and what `kapaint layers` prints.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct LayerId(pub u64);

/// The next fresh [`LayerId`]: above every id made or read in this process.
static NEXT_LAYER_ID: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);

impl LayerId {
    /// A new id, unlike any made or read before in this process.
    pub fn fresh() -> Self {
        Self(NEXT_LAYER_ID.fetch_add(1, std::sync::atomic::Ordering::Relaxed))
    }

    /// An id read from a file: fresh ids stay above it from now on.
    pub fn loaded(id: u64) -> Self {
        NEXT_LAYER_ID.fetch_max(id.saturating_add(1), std::sync::atomic::Ordering::Relaxed);
        Self(id)
    }
}

impl std::fmt::Display for LayerId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0)
    }
}

impl Layer {
    /// This layer, and every layer in it, with fresh ids (a copy).
    #[must_use]
    pub fn with_fresh_ids(mut self) -> Self {
        fn refresh(layer: &mut Layer) {
            layer.props.id = LayerId::fresh();
            if let LayerContent::Group(children) = &mut layer.content {
                children.iter_mut().for_each(refresh);
            }
        }
        refresh(&mut self);
        self
    }
}

impl LayerProps {
    /// A visible, unlocked, opaque layer of every channel in normal mode (its name fitted to
    /// what a project can hold, see [`crate::check::fit_name`]).
    pub fn named(name: impl Into<String>) -> Self {
        Self {
            id: LayerId::fresh(),
            name: crate::check::fit_name(&name.into(), "", "Layer"),
            visible: true,
            locked: false,
            opacity: 1.0,
            channels: [ChannelBlend {
                enabled: true,
                mode: LayerBlend::Normal,
            }; 3],
        }
    }

    /// The part of `channel`.
    pub fn channel(&self, channel: Channel) -> ChannelBlend {
        self.channels[channel_index(channel)]
    }
}

/// The index of a channel in per-channel arrays.
pub fn channel_index(channel: Channel) -> usize {
    match channel {
        Channel::Kd => 0,
        Channel::Ks => 1,
        Channel::N => 2,
    }
}

/// What a layer holds.
#[derive(Clone, Debug, PartialEq)]
pub enum LayerContent {
    /// Painted tiles (`None`: nothing painted there).
    Paint(Vec<Option<SharedPaintTile>>),
    /// One material everywhere.
    Fill(MaterialValue),
    /// A fill of an image through a projection (a fill layer's other kind).
    Projected(Arc<projected::Projected>),
    /// Layers composited first, bottom first.
    Group(Vec<Layer>),
}

/// A layer, a fill or a group.
#[derive(Clone, Debug, PartialEq)]
pub struct Layer {
    /// Name, visibility, lock, opacity, channels.
    pub props: LayerProps,
    /// What it holds.
    pub content: LayerContent,
    /// Its mask, if it has one.
    pub mask: Option<Mask>,
}

impl Layer {
    /// An empty paint layer of `tile_count` tiles (costs no tile memory).
    pub fn paint(name: impl Into<String>, tile_count: usize) -> Self {
        Self {
            props: LayerProps::named(name),
            content: LayerContent::Paint(vec![None; tile_count]),
            mask: None,
        }
    }

    /// A fill layer of `value`.
    pub fn fill(name: impl Into<String>, value: MaterialValue) -> Self {
        Self {
            props: LayerProps::named(name),
            content: LayerContent::Fill(value.sanitized()),
            mask: None,
        }
    }

    /// A group of `children`, bottom first.
    pub fn group(name: impl Into<String>, children: Vec<Layer>) -> Self {
        Self {
            props: LayerProps::named(name),
            content: LayerContent::Group(children),
            mask: None,
        }
    }

    /// The paint tile to write at `id`, made (transparent) if nothing was painted there; `None`
    /// for a layer that is not a paint layer.
    pub fn paint_tile_mut(&mut self, id: usize) -> Option<&mut PaintTile> {
        let LayerContent::Paint(tiles) = &mut self.content else {
            return None;
        };
        let slot = tiles.get_mut(id)?;
        let tile = slot.get_or_insert_with(edit::empty_paint_tile);
        Some(Stamped::write(tile))
    }

    /// Heap bytes of its tiles and mask (children's included).
    pub fn heap_bytes(&self) -> usize {
        let own = match &self.content {
            LayerContent::Paint(tiles) => {
                tiles.iter().flatten().map(|t| t.get().heap_bytes()).sum()
            }
            LayerContent::Fill(_) => 0,
            LayerContent::Projected(p) => p.heap_bytes(),
            LayerContent::Group(children) => children.iter().map(Layer::heap_bytes).sum(),
        };
        own + self.mask.as_ref().map_or(0, Mask::heap_bytes)
    }
}

/// A base material under layers, bottom first, at a map size.
#[derive(Clone, Debug, PartialEq)]
pub struct LayerStack {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// What shows where no layer covers.
    pub base: MaterialValue,
    /// The layers, bottom first.
    pub layers: Vec<Layer>,
}

impl LayerStack {
    /// A base material with one empty paint layer, "Layer 1" (a new document's stack).
    pub fn new(width: u32, height: u32, base: MaterialValue) -> Self {
        let mut stack = Self {
            width,
            height,
            base: base.sanitized(),
            layers: Vec::new(),
        };
        stack
            .layers
            .push(Layer::paint("Layer 1", stack.tile_count()));
        stack
    }

    /// The same size and base with no layers.
    #[must_use]
    pub fn without_layers(&self) -> Self {
        Self {
            width: self.width,
            height: self.height,
            base: self.base,
            layers: Vec::new(),
        }
    }

    /// Tiles across.
    pub fn tiles_x(&self) -> usize {
        (self.width as usize).div_ceil(super::tile::TILE_SIZE)
    }

    /// Tiles in all.
    pub fn tile_count(&self) -> usize {
        self.tiles_x() * (self.height as usize).div_ceil(super::tile::TILE_SIZE)
    }

    /// Heap bytes of every layer's tiles and masks.
    pub fn heap_bytes(&self) -> usize {
        self.layers.iter().map(Layer::heap_bytes).sum()
    }
}

impl LayerStack {
    /// Whether the stack is one plain paint layer (visible, opaque, every channel in the
    /// normal mode, no mask): then its composite says everything about it.
    pub fn is_flat(&self) -> bool {
        match self.layers.as_slice() {
            [l] => {
                matches!(l.content, LayerContent::Paint(_))
                    && l.mask.is_none()
                    && l.props.visible
                    && l.props.opacity >= 1.0
                    && l.props
                        .channels
                        .iter()
                        .all(|c| c.enabled && c.mode == LayerBlend::Normal)
            }
            _ => false,
        }
    }

    /// The layer at `path` (indices from the top-level list down into groups).
    pub fn layer(&self, path: &[usize]) -> Option<&Layer> {
        let (&last, parents) = path.split_last()?;
        self.list(parents)?.get(last)
    }

    /// The layer at `path`, to change.
    pub fn layer_mut(&mut self, path: &[usize]) -> Option<&mut Layer> {
        let (&last, parents) = path.split_last()?;
        self.list_mut(parents)?.get_mut(last)
    }

    /// The list of layers inside the group at `path` (the top level for an empty path).
    pub fn list(&self, path: &[usize]) -> Option<&Vec<Layer>> {
        let mut list = &self.layers;
        for &i in path {
            match &list.get(i)?.content {
                LayerContent::Group(children) => list = children,
                _ => return None,
            }
        }
        Some(list)
    }

    /// The list of layers inside the group at `path`, to change.
    pub fn list_mut(&mut self, path: &[usize]) -> Option<&mut Vec<Layer>> {
        let mut list = &mut self.layers;
        for &i in path {
            match &mut list.get_mut(i)?.content {
                LayerContent::Group(children) => list = children,
                _ => return None,
            }
        }
        Some(list)
    }

    /// Gives a fresh id to every layer whose id an earlier layer (depth first) already has: a
    /// stack read from a file holds each id once.
    pub fn make_ids_unique(&mut self) {
        fn go(list: &mut [Layer], seen: &mut std::collections::HashSet<LayerId>) {
            for layer in list {
                if !seen.insert(layer.props.id) {
                    layer.props.id = LayerId::fresh();
                    seen.insert(layer.props.id);
                }
                if let LayerContent::Group(children) = &mut layer.content {
                    go(children, seen);
                }
            }
        }
        go(&mut self.layers, &mut std::collections::HashSet::new());
    }

    /// The path of the layer with `id`, at any depth.
    pub fn path_of(&self, id: LayerId) -> Option<Vec<usize>> {
        fn find(list: &[Layer], id: LayerId, path: &mut Vec<usize>) -> bool {
            for (i, layer) in list.iter().enumerate() {
                path.push(i);
                if layer.props.id == id {
                    return true;
                }
                if let LayerContent::Group(children) = &layer.content
                    && find(children, id, path)
                {
                    return true;
                }
                path.pop();
            }
            false
        }
        let mut path = Vec::new();
        find(&self.layers, id, &mut path).then_some(path)
    }

    /// Whether anything is painted over the base: a fill layer, or a painted tile in any paint
    /// layer (groups included). A new document's stack holds none.
    pub fn holds_paint(&self) -> bool {
        self.walk().iter().any(|(_, l)| match &l.content {
            LayerContent::Paint(tiles) => tiles.iter().any(Option::is_some),
            LayerContent::Fill(_) | LayerContent::Projected(_) => true,
            LayerContent::Group(_) => false,
        })
    }

    /// Every layer, depth first, bottom first within each list, with its path.
    pub fn walk(&self) -> Vec<(Vec<usize>, &Layer)> {
        fn go<'a>(
            list: &'a [Layer],
            prefix: &mut Vec<usize>,
            out: &mut Vec<(Vec<usize>, &'a Layer)>,
        ) {
            for (i, layer) in list.iter().enumerate() {
                prefix.push(i);
                out.push((prefix.clone(), layer));
                if let LayerContent::Group(children) = &layer.content {
                    go(children, prefix, out);
                }
                prefix.pop();
            }
        }
        let mut out = Vec::new();
        go(&self.layers, &mut Vec::new(), &mut out);
        out
    }

    /// A stack of one opaque paint layer holding `maps` (how a version 1 project opens, and
    /// what flattening leaves).
    pub fn from_maps(maps: &super::maps::MaterialMaps, base: MaterialValue, name: &str) -> Self {
        let tiles = (0..maps.tile_count())
            .map(|id| {
                Some(Arc::new(Stamped::new(PaintTile {
                    value: (**maps.tile(id)).clone(),
                    alpha: std::array::from_fn(|_| Plane::Uniform(u16::MAX)),
                })))
            })
            .collect();
        Self {
            width: maps.width(),
            height: maps.height(),
            base: base.sanitized(),
            layers: vec![Layer {
                props: LayerProps::named(name),
                content: LayerContent::Paint(tiles),
                mask: None,
            }],
        }
    }
}

impl Layer {
    /// The planes tools write: the mask's when `mask` is set, else a paint layer's tiles.
    pub fn planes_mut(&mut self, mask: bool) -> Option<edit::Planes<'_>> {
        if mask {
            return self.mask.as_mut().map(|m| edit::Planes::Mask(&mut m.tiles));
        }
        match &mut self.content {
            LayerContent::Paint(tiles) => Some(edit::Planes::Paint(tiles)),
            _ => None,
        }
    }

    /// The same planes, to read.
    pub fn planes(&self, mask: bool) -> Option<edit::PrePlanes<'_>> {
        if mask {
            return self.mask.as_ref().map(|m| edit::PrePlanes::Mask(&m.tiles));
        }
        match &self.content {
            LayerContent::Paint(tiles) => Some(edit::PrePlanes::Paint(tiles)),
            _ => None,
        }
    }

    /// The layer's kind as the CLI and scripts name it.
    pub fn kind_name(&self) -> &'static str {
        match self.content {
            LayerContent::Paint(_) => "paint",
            LayerContent::Fill(_) | LayerContent::Projected(_) => "fill",
            LayerContent::Group(_) => "group",
        }
    }
}
