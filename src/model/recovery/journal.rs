//! What a journal record holds, written from a snapshot of the document and replayed back.
//!
//! A record describes the whole document: its identity, settings, selection and the layer
//! stack's structure as JSON, each layer's tiles as a list of tile stamps (0 where a paint
//! layer has nothing). It then carries only what the journal does not hold yet: the tile lists
//! and tiles the record before it did not refer to, and the normal map when it changed. The
//! first record of a journal refers to nothing before it, so it is the whole document; every
//! later one costs what changed. Replay keeps what the last record refers to, exactly as the
//! writer does, so the two always agree on what is known.

use std::collections::{HashMap, HashSet};
use std::hash::Hasher as _;
use std::io::{Read, Write};
use std::sync::Arc;

use bytemuck::Pod;
use serde::{Deserialize, Serialize};

use crate::model::document::{Document, DocumentId, DocumentSettings};
use crate::model::layers::{
    ChannelBlend, Layer, LayerContent, LayerProps, LayerStack, Mask, PaintTile, Selection,
    SharedMaskTile, SharedPaintTile, Stamped,
};
use crate::model::normal::NormalMap;
use crate::model::project::SelectionEntry;
use crate::model::project::layers::{BlendEntry, KindEntry, MAX_DEPTH, MAX_LAYERS};
use crate::model::texel::{Channel, MaterialValue};
use crate::model::tile::{Plane, TILE_TEXELS, Tile};

use super::record::Payload;

/// Largest description a record may have (bytes).
const MAX_META_BYTES: u64 = 16 << 20;

/// Everything a record is written from: a copy of the document that shares its tiles.
pub(super) struct Snapshot {
    id: DocumentId,
    settings: DocumentSettings,
    selection: Selection,
    stack: LayerStack,
    normal: Option<Arc<NormalMap>>,
}

impl Snapshot {
    /// The document as it is now (its tiles shared, not copied).
    pub(super) fn of(doc: &Document) -> Self {
        Self {
            id: doc.id(),
            settings: doc.settings().clone(),
            selection: doc.selection().clone(),
            stack: doc.stack().clone(),
            normal: doc.normal().cloned(),
        }
    }
}

/// What a journal holds as of its last record: the tiles and lists that record refers to.
/// A writer sends only what is not in it.
#[derive(Default)]
pub(super) struct Known {
    tiles: HashSet<u64>,
    lists: HashSet<u64>,
    normal: Option<Arc<NormalMap>>,
}

/// A record's description of the document.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Meta {
    id: String,
    settings: DocumentSettings,
    base: MaterialValue,
    selection: SelectionEntry,
    normal: bool,
    layers: Vec<LayerMeta>,
}

/// One layer in a record: its settings, and its tiles and mask as tile-list keys.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct LayerMeta {
    #[serde(deserialize_with = "crate::model::check::layer_name")]
    name: String,
    kind: KindEntry,
    visible: bool,
    locked: bool,
    #[serde(deserialize_with = "crate::model::check::layer_opacity")]
    opacity: f32,
    channels: [BlendEntry; 3],
    #[serde(default)]
    fill: Option<MaterialValue>,
    #[serde(default)]
    tiles: Option<u64>,
    #[serde(default)]
    mask: Option<MaskMeta>,
    #[serde(default)]
    children: Vec<LayerMeta>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct MaskMeta {
    enabled: bool,
    inverted: bool,
    tiles: u64,
}

/// The key of a list of stamps (what a record refers to it by).
fn list_key(stamps: &[u64]) -> u64 {
    let mut h = std::hash::DefaultHasher::new();
    for s in stamps {
        h.write_u64(*s);
    }
    // 0 never names a list.
    h.finish().max(1)
}

/// What a snapshot refers to, gathered while its description is made.
#[derive(Default)]
struct Gathered<'a> {
    lists: Vec<(u64, Vec<u64>)>,
    list_keys: HashSet<u64>,
    paint: Vec<&'a SharedPaintTile>,
    masks: Vec<&'a SharedMaskTile>,
    tiles: HashSet<u64>,
}

impl<'a> Gathered<'a> {
    fn list(&mut self, known: &Known, stamps: Vec<u64>) -> u64 {
        let key = list_key(&stamps);
        if self.list_keys.insert(key) && !known.lists.contains(&key) {
            self.lists.push((key, stamps));
        }
        key
    }

    fn layers(&mut self, known: &Known, layers: &'a [Layer]) -> Vec<LayerMeta> {
        layers.iter().map(|l| self.layer(known, l)).collect()
    }

    fn layer(&mut self, known: &Known, l: &'a Layer) -> LayerMeta {
        let (kind, fill, tiles, children) = match &l.content {
            LayerContent::Paint(tiles) => {
                let stamps = tiles
                    .iter()
                    .map(|t| {
                        t.as_ref().map_or(0, |t| {
                            if self.tiles.insert(t.stamp()) && !known.tiles.contains(&t.stamp()) {
                                self.paint.push(t);
                            }
                            t.stamp()
                        })
                    })
                    .collect();
                (
                    KindEntry::Paint,
                    None,
                    Some(self.list(known, stamps)),
                    vec![],
                )
            }
            LayerContent::Fill(v) => (KindEntry::Fill, Some(*v), None, vec![]),
            LayerContent::Group(children) => {
                (KindEntry::Group, None, None, self.layers(known, children))
            }
        };
        let mask = l.mask.as_ref().map(|m| {
            let stamps = m
                .tiles
                .iter()
                .map(|t| {
                    if self.tiles.insert(t.stamp()) && !known.tiles.contains(&t.stamp()) {
                        self.masks.push(t);
                    }
                    t.stamp()
                })
                .collect();
            MaskMeta {
                enabled: m.enabled,
                inverted: m.inverted,
                tiles: self.list(known, stamps),
            }
        });
        LayerMeta {
            name: l.props.name.clone(),
            kind,
            visible: l.props.visible,
            locked: l.props.locked,
            opacity: l.props.opacity,
            channels: l.props.channels.map(|c| BlendEntry {
                enabled: c.enabled,
                mode: c.mode,
            }),
            fill,
            tiles,
            mask,
            children,
        }
    }
}

/// Writes the record of `snap` for a journal that holds `known`; returns what the journal
/// holds once it is written.
pub(super) fn write_record(
    out: &mut dyn Write,
    snap: &Snapshot,
    known: &Known,
) -> std::io::Result<Known> {
    let mut gathered = Gathered::default();
    let layers = gathered.layers(known, &snap.stack.layers);
    let normal_changed = match (&snap.normal, &known.normal) {
        (Some(a), Some(b)) => !Arc::ptr_eq(a, b),
        (a, b) => a.is_some() != b.is_some(),
    };
    let meta = Meta {
        id: snap.id.to_hex(),
        settings: snap.settings.clone(),
        base: snap.stack.base,
        selection: SelectionEntry::of(&snap.selection),
        normal: snap.normal.is_some(),
        layers,
    };
    let json = serde_json::to_vec(&meta).map_err(std::io::Error::other)?;
    out.write_all(&snap.stack.width.to_le_bytes())?;
    out.write_all(&snap.stack.height.to_le_bytes())?;
    out.write_all(&(json.len() as u32).to_le_bytes())?;
    out.write_all(&json)?;
    out.write_all(&(gathered.lists.len() as u32).to_le_bytes())?;
    for (key, stamps) in &gathered.lists {
        out.write_all(&key.to_le_bytes())?;
        out.write_all(&(stamps.len() as u32).to_le_bytes())?;
        write_le(out, stamps)?;
    }
    out.write_all(&(gathered.paint.len() as u32).to_le_bytes())?;
    for t in &gathered.paint {
        out.write_all(&t.stamp().to_le_bytes())?;
        let tile = t.get();
        write_plane(out, &tile.value.kd)?;
        write_plane(out, &tile.value.ks)?;
        write_plane(out, &tile.value.n)?;
        for a in &tile.alpha {
            write_plane(out, a)?;
        }
    }
    out.write_all(&(gathered.masks.len() as u32).to_le_bytes())?;
    for t in &gathered.masks {
        out.write_all(&t.stamp().to_le_bytes())?;
        write_plane(out, t.get())?;
    }
    match snap.normal.as_ref().filter(|_| normal_changed) {
        Some(n) => {
            out.write_all(&[1])?;
            out.write_all(&n.width().to_le_bytes())?;
            out.write_all(&n.height().to_le_bytes())?;
            out.write_all(n.image().as_raw())?;
        }
        None => out.write_all(&[0])?,
    }
    Ok(Known {
        tiles: gathered.tiles,
        lists: gathered.list_keys,
        normal: snap.normal.clone(),
    })
}

/// `values` as little-endian bytes.
fn write_le<T: Pod>(out: &mut dyn Write, values: &[T]) -> std::io::Result<()> {
    if cfg!(target_endian = "little") {
        return out.write_all(bytemuck::cast_slice(values));
    }
    let mut bytes: Vec<u8> = bytemuck::cast_slice(values).to_vec();
    swap_pairs(&mut bytes, std::mem::size_of::<T>());
    out.write_all(&bytes)
}

/// Turns each value of `size` bytes around (big-endian machines only).
fn swap_pairs(bytes: &mut [u8], size: usize) {
    for value in bytes.chunks_exact_mut(size) {
        value.reverse();
    }
}

/// A plane: kind 0 and one value, or kind 1 and every texel's.
fn write_plane<T: Pod>(out: &mut dyn Write, plane: &Plane<T>) -> std::io::Result<()> {
    match plane {
        Plane::Uniform(v) => {
            out.write_all(&[0])?;
            write_le(out, std::slice::from_ref(v))
        }
        Plane::Data(d) => {
            out.write_all(&[1])?;
            write_le(out, d)
        }
    }
}

/// Reads `count` values of `T`, made of `u16`s or a `u64`, written by [`write_le`].
fn read_le<T: Pod, R: Read>(r: &mut Payload<'_, R>, count: usize) -> Result<Vec<T>, String> {
    let bytes = (count * std::mem::size_of::<T>()) as u64;
    if bytes > r.left() {
        return Err("the record ends early".into());
    }
    let mut values = vec![T::zeroed(); count];
    r.read_exact(bytemuck::cast_slice_mut(&mut values))
        .map_err(|e| e.to_string())?;
    if cfg!(target_endian = "big") {
        let unit = if std::mem::size_of::<T>() == 8 { 8 } else { 2 };
        swap_pairs(bytemuck::cast_slice_mut(&mut values), unit);
    }
    Ok(values)
}

fn read_u32<R: Read>(r: &mut Payload<'_, R>) -> Result<u32, String> {
    let mut b = [0_u8; 4];
    r.read_exact(&mut b).map_err(|e| e.to_string())?;
    Ok(u32::from_le_bytes(b))
}

fn read_u64<R: Read>(r: &mut Payload<'_, R>) -> Result<u64, String> {
    let mut b = [0_u8; 8];
    r.read_exact(&mut b).map_err(|e| e.to_string())?;
    Ok(u64::from_le_bytes(b))
}

fn read_plane<T: Pod, R: Read>(r: &mut Payload<'_, R>) -> Result<Plane<T>, String> {
    let mut kind = [0_u8];
    r.read_exact(&mut kind).map_err(|e| e.to_string())?;
    match kind[0] {
        0 => Ok(Plane::Uniform(read_le::<T, R>(r, 1)?[0])),
        1 => Ok(Plane::Data(read_le(r, TILE_TEXELS)?.into_boxed_slice())),
        k => Err(format!("unknown plane kind {k}")),
    }
}

/// A record as read: its description and what it carried.
pub(super) struct Decoded {
    width: u32,
    height: u32,
    meta: Meta,
    lists: HashMap<u64, Vec<u64>>,
    paint: HashMap<u64, SharedPaintTile>,
    masks: HashMap<u64, SharedMaskTile>,
    normal: Option<Arc<NormalMap>>,
}

/// Reads one record's payload (checked as it goes; the checksum is the caller's).
pub(super) fn decode<R: Read>(r: &mut Payload<'_, R>) -> Result<Decoded, String> {
    let (width, height) = (read_u32(r)?, read_u32(r)?);
    let max = crate::model::maps::MAX_SIDE;
    if width == 0 || height == 0 || width > max || height > max {
        return Err(format!("map size {width}x{height} is out of range"));
    }
    let tile_count = tile_count(width, height);
    let meta_len = u64::from(read_u32(r)?);
    if meta_len > MAX_META_BYTES.min(r.left()) {
        return Err("the record's description is too long".into());
    }
    let mut json = vec![0_u8; meta_len as usize];
    r.read_exact(&mut json).map_err(|e| e.to_string())?;
    let meta: Meta = serde_json::from_slice(&json).map_err(|e| e.to_string())?;
    check_layers(&meta.layers, 0, &mut 0)?;
    let list_count = read_u32(r)? as usize;
    if list_count > 2 * MAX_LAYERS {
        return Err("the record holds too many tile lists".into());
    }
    let mut lists = HashMap::new();
    for _ in 0..list_count {
        let key = read_u64(r)?;
        if read_u32(r)? as usize != tile_count {
            return Err("a tile list is not as long as the map has tiles".into());
        }
        lists.insert(key, read_le::<u64, R>(r, tile_count)?);
    }
    let paint_count = read_u32(r)?;
    let mut paint = HashMap::new();
    for _ in 0..paint_count {
        let stamp = read_u64(r)?;
        let value = Tile {
            kd: read_plane(r)?,
            ks: read_plane(r)?,
            n: read_plane(r)?,
        };
        let valid = match &value.n {
            Plane::Uniform(v) => crate::model::project::valid_n_bits(*v),
            Plane::Data(d) => d.iter().all(|v| crate::model::project::valid_n_bits(*v)),
        };
        if !valid {
            return Err("a tile holds an invalid exponent".into());
        }
        let alpha = [read_plane(r)?, read_plane(r)?, read_plane(r)?];
        paint.insert(stamp, Arc::new(Stamped::new(PaintTile { value, alpha })));
    }
    let mask_count = read_u32(r)?;
    let mut masks = HashMap::new();
    for _ in 0..mask_count {
        let stamp = read_u64(r)?;
        masks.insert(stamp, Arc::new(Stamped::new(read_plane(r)?)));
    }
    let mut flag = [0_u8];
    r.read_exact(&mut flag).map_err(|e| e.to_string())?;
    let normal = match flag[0] {
        0 => None,
        1 => {
            let (w, h) = (read_u32(r)?, read_u32(r)?);
            let bytes = u64::from(w) * u64::from(h) * 3;
            if bytes > r.left() {
                return Err("the normal map is larger than the record".into());
            }
            let mut raw = vec![0_u8; bytes as usize];
            r.read_exact(&mut raw).map_err(|e| e.to_string())?;
            let image = image::RgbImage::from_raw(w, h, raw).ok_or("normal map size")?;
            Some(Arc::new(NormalMap::new(image)?))
        }
        k => return Err(format!("unknown normal flag {k}")),
    };
    Ok(Decoded {
        width,
        height,
        meta,
        lists,
        paint,
        masks,
        normal,
    })
}

fn tile_count(width: u32, height: u32) -> usize {
    let side = crate::model::tile::TILE_SIZE;
    (width as usize).div_ceil(side) * (height as usize).div_ceil(side)
}

/// The limits and kinds a project's layers keep, for a record's.
fn check_layers(layers: &[LayerMeta], depth: usize, count: &mut usize) -> Result<(), String> {
    if depth > MAX_DEPTH {
        return Err(format!("layer groups nest deeper than {MAX_DEPTH}"));
    }
    for l in layers {
        *count += 1;
        if *count > MAX_LAYERS {
            return Err(format!("more than {MAX_LAYERS} layers"));
        }
        let shape_ok = match l.kind {
            KindEntry::Paint => l.tiles.is_some() && l.fill.is_none() && l.children.is_empty(),
            KindEntry::Fill => l.tiles.is_none() && l.fill.is_some() && l.children.is_empty(),
            KindEntry::Group => l.tiles.is_none() && l.fill.is_none(),
        };
        if !shape_ok {
            return Err(format!("the layer {:?} does not match its kind", l.name));
        }
        if Channel::ALL
            .into_iter()
            .zip(&l.channels)
            .any(|(c, b)| !b.mode.allowed_for(c))
        {
            return Err(format!(
                "the layer {:?} has a blend mode it does not take",
                l.name
            ));
        }
        check_layers(&l.children, depth + 1, count)?;
    }
    Ok(())
}

/// A journal being replayed: what its last record refers to.
#[derive(Default)]
pub(super) struct Replay {
    lists: HashMap<u64, Vec<u64>>,
    paint: HashMap<u64, SharedPaintTile>,
    masks: HashMap<u64, SharedMaskTile>,
    normal: Option<Arc<NormalMap>>,
    /// The document as of the last record applied.
    doc: Option<Document>,
}

impl Replay {
    /// Applies a record: the document becomes what it describes. A record that refers to
    /// something neither it nor the one before holds is refused, and nothing changes.
    pub(super) fn apply(&mut self, d: Decoded) -> Result<(), String> {
        let tile_count = tile_count(d.width, d.height);
        let mut lists = d.lists;
        let mut paint = d.paint;
        let mut masks = d.masks;
        let normal = match (d.meta.normal, d.normal) {
            (false, _) => None,
            (true, Some(n)) => Some(n),
            (true, None) => Some(self.normal.clone().ok_or("the normal map is missing")?),
        };
        let mut take = Taken {
            tile_count,
            old: self,
            lists: &mut lists,
            paint: &mut paint,
            masks: &mut masks,
            keep: Replay::default(),
        };
        let layers = take.layers(&d.meta.layers)?;
        let mut keep = take.keep;
        let id = DocumentId::from_hex(&d.meta.id).ok_or("the record's identity is not valid")?;
        let stack = LayerStack {
            width: d.width,
            height: d.height,
            base: d.meta.base.sanitized(),
            layers,
        };
        let doc = Document::from_stack(stack, d.meta.settings)
            .map_err(|e| e.to_string())?
            .with_selection(d.meta.selection.selection())
            .with_normal(normal.clone())
            .with_id(id);
        keep.normal = normal;
        keep.doc = Some(doc);
        *self = keep;
        Ok(())
    }

    /// The document as of the last record applied.
    pub(super) fn into_document(self) -> Option<Document> {
        self.doc
    }
}

/// Resolving a record's references: from what it carried, else from what the journal held.
struct Taken<'a> {
    tile_count: usize,
    old: &'a Replay,
    lists: &'a mut HashMap<u64, Vec<u64>>,
    paint: &'a mut HashMap<u64, SharedPaintTile>,
    masks: &'a mut HashMap<u64, SharedMaskTile>,
    /// What the record refers to: the journal as of it.
    keep: Replay,
}

impl Taken<'_> {
    fn list(&mut self, key: u64) -> Result<Vec<u64>, String> {
        let list = self
            .lists
            .get(&key)
            .or_else(|| self.old.lists.get(&key))
            .filter(|l| l.len() == self.tile_count)
            .cloned()
            .ok_or("the record refers to a tile list the journal does not hold")?;
        self.keep.lists.insert(key, list.clone());
        Ok(list)
    }

    fn layers(&mut self, metas: &[LayerMeta]) -> Result<Vec<Layer>, String> {
        metas.iter().map(|m| self.layer(m)).collect()
    }

    fn layer(&mut self, m: &LayerMeta) -> Result<Layer, String> {
        let missing = || "the record refers to a tile the journal does not hold".to_string();
        let content = match m.kind {
            KindEntry::Paint => {
                let list = self.list(m.tiles.ok_or_else(missing)?)?;
                let mut tiles = Vec::with_capacity(list.len());
                for stamp in list {
                    if stamp == 0 {
                        tiles.push(None);
                        continue;
                    }
                    let tile = self
                        .paint
                        .get(&stamp)
                        .or_else(|| self.old.paint.get(&stamp))
                        .cloned()
                        .ok_or_else(missing)?;
                    self.keep.paint.insert(stamp, Arc::clone(&tile));
                    tiles.push(Some(tile));
                }
                LayerContent::Paint(tiles)
            }
            KindEntry::Fill => LayerContent::Fill(m.fill.unwrap_or_default().sanitized()),
            KindEntry::Group => LayerContent::Group(self.layers(&m.children)?),
        };
        let mask = match &m.mask {
            None => None,
            Some(mm) => {
                let list = self.list(mm.tiles)?;
                let mut tiles = Vec::with_capacity(list.len());
                for stamp in list {
                    let tile = self
                        .masks
                        .get(&stamp)
                        .or_else(|| self.old.masks.get(&stamp))
                        .cloned()
                        .ok_or_else(missing)?;
                    self.keep.masks.insert(stamp, Arc::clone(&tile));
                    tiles.push(tile);
                }
                Some(Mask {
                    tiles,
                    enabled: mm.enabled,
                    inverted: mm.inverted,
                })
            }
        };
        Ok(Layer {
            props: LayerProps {
                name: m.name.clone(),
                visible: m.visible,
                locked: m.locked,
                opacity: m.opacity,
                channels: m.channels.map(|b| ChannelBlend {
                    enabled: b.enabled,
                    mode: b.mode,
                }),
            },
            content,
            mask,
        })
    }
}

/// The identity a record's description names, read from the start of its payload (`len`
/// bytes) alone: a cheap look at a journal, not a check of it.
pub(super) fn peek_id(r: &mut impl Read, len: u64) -> Result<DocumentId, String> {
    #[derive(Deserialize)]
    struct Id {
        id: String,
    }
    let mut head = [0_u8; 12];
    r.read_exact(&mut head).map_err(|e| e.to_string())?;
    let meta_len = u64::from(u32::from_le_bytes([head[8], head[9], head[10], head[11]]));
    if meta_len > MAX_META_BYTES.min(len.saturating_sub(12)) {
        return Err("the record's description is too long".into());
    }
    let mut json = vec![0_u8; meta_len as usize];
    r.read_exact(&mut json).map_err(|e| e.to_string())?;
    let id: Id = serde_json::from_slice(&json).map_err(|e| e.to_string())?;
    DocumentId::from_hex(&id.id).ok_or_else(|| "the record's identity is not valid".into())
}
