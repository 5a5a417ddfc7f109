//! What a journal record holds, written from a snapshot of the document and replayed back.
//!
//! A record describes the whole document: its identity, settings, selection and the layer
//! stack's structure as JSON, each layer's tiles as a list of tile stamps (0 where a paint
//! layer has nothing). It then carries only what the journal does not hold yet: the tile lists
//! and tiles the record before it did not refer to, and the normal map and the kept mesh when
//! they changed. The
//! first record of a journal refers to nothing before it, so it is the whole document; every
//! later one costs what changed. Replay ([`super::replay`]) keeps what the last record refers
//! to, exactly as the writer does, so the two always agree on what is known.

use std::collections::HashSet;
use std::hash::Hasher as _;
use std::io::Write;
use std::sync::Arc;

use bytemuck::Pod;
use serde::{Deserialize, Serialize};

use crate::document::{Document, DocumentId, DocumentSettings};
use crate::layers::projected::ProjectionFill;
use crate::layers::{Layer, LayerContent, LayerStack, Selection, SharedMaskTile, SharedPaintTile};
use crate::normal::NormalMap;
use crate::paint_image::Pixels;
use crate::project::SelectionEntry;
use crate::project::layers::{BlendEntry, KindEntry};
use crate::texel::MaterialValue;
use crate::tile::Plane;

/// Largest description a record may have (bytes).
pub(super) const MAX_META_BYTES: u64 = 16 << 20;

/// Everything a record is written from: a copy of the document that shares its tiles.
pub(super) struct Snapshot {
    id: DocumentId,
    settings: DocumentSettings,
    selection: Selection,
    stack: LayerStack,
    normal: Option<Arc<NormalMap>>,
    mesh: Option<Arc<kapaint_mesh::Mesh>>,
}

impl Snapshot {
    /// The document as it is now (its tiles shared, not copied).
    pub(super) fn of(doc: &Document) -> Self {
        Self {
            id: doc.id(),
            settings: doc.settings().clone(),
            selection: doc.selection(),
            stack: doc.stack().clone(),
            normal: doc.normal().cloned(),
            mesh: doc.embedded_mesh().cloned(),
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
    mesh: Option<Arc<kapaint_mesh::Mesh>>,
    /// The projection fills' images, by key: held, so that no other image takes a key while
    /// the journal refers to it.
    images: Vec<(u64, Arc<Pixels>)>,
}

/// The key a record names an image by: where it lives while the journal holds it.
fn image_key(image: &Arc<Pixels>) -> u64 {
    Arc::as_ptr(image) as usize as u64
}

/// A record's description of the document.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Meta {
    pub(super) id: String,
    pub(super) settings: DocumentSettings,
    pub(super) base: MaterialValue,
    pub(super) selection: SelectionEntry,
    pub(super) normal: bool,
    pub(super) layers: Vec<LayerMeta>,
    /// The mesh the project keeps, when it keeps one: the bytes of its OBJ text that follow
    /// the normal map, 0 where it is the one the record before carried. Absent otherwise, so
    /// a record without one reads and writes as before.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) mesh: Option<u64>,
    /// The keys of the projection fills' images whose pixels follow the mesh, in order (the
    /// images the record before did not carry).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub(super) images: Vec<u64>,
}

/// A projection fill in a record: its parameters and its image's key.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ProjectionMeta {
    #[serde(deserialize_with = "crate::check::projection")]
    pub(super) projection: crate::paint::projection::Projection,
    pub(super) channels: crate::texel::Channels,
    pub(super) source: String,
    pub(super) image: u64,
    pub(super) width: u32,
    pub(super) height: u32,
}

/// One layer in a record: its settings, and its tiles and mask as tile-list keys.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LayerMeta {
    #[serde(default)]
    pub(super) id: Option<u64>,
    #[serde(deserialize_with = "crate::check::layer_name")]
    pub(super) name: String,
    pub(super) kind: KindEntry,
    pub(super) visible: bool,
    pub(super) locked: bool,
    #[serde(deserialize_with = "crate::check::layer_opacity")]
    pub(super) opacity: f32,
    pub(super) channels: [BlendEntry; 3],
    #[serde(default)]
    pub(super) fill: Option<MaterialValue>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) projection: Option<ProjectionMeta>,
    #[serde(default)]
    pub(super) tiles: Option<u64>,
    #[serde(default)]
    pub(super) mask: Option<MaskMeta>,
    #[serde(default)]
    pub(super) children: Vec<LayerMeta>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MaskMeta {
    pub(super) enabled: bool,
    pub(super) inverted: bool,
    pub(super) tiles: u64,
    /// The generator that makes it (absent from records of painted masks, whose bytes stay
    /// as they were).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) generator: Option<crate::generator::Generator>,
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
    /// The images the record refers to, and of those the ones it carries.
    images: Vec<(u64, Arc<Pixels>)>,
    carried: Vec<Arc<Pixels>>,
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
            LayerContent::Projected(_) => (KindEntry::Fill, None, None, vec![]),
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
                generator: m.generator().cloned(),
            }
        });
        let projection = match &l.content {
            LayerContent::Projected(p) => self.projection(known, p.fill()),
            _ => None,
        };
        LayerMeta {
            id: Some(l.props.id.0),
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
            projection,
            tiles,
            mask,
            children,
        }
    }

    /// A projection fill's description; its image is carried unless the journal holds it.
    fn projection(&mut self, known: &Known, fill: &ProjectionFill) -> Option<ProjectionMeta> {
        let image = fill.image.pixels().ok()?;
        let key = image_key(image);
        if self.images.iter().all(|(k, _)| *k != key) {
            self.images.push((key, Arc::clone(image)));
            if known.images.iter().all(|(k, _)| *k != key) {
                self.carried.push(Arc::clone(image));
            }
        }
        Some(ProjectionMeta {
            projection: fill.projection,
            channels: fill.channels,
            source: fill.image.path().to_string_lossy().into_owned(),
            image: key,
            width: image.width(),
            height: image.height(),
        })
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
    let mesh_changed = match (&snap.mesh, &known.mesh) {
        (Some(a), Some(b)) => !Arc::ptr_eq(a, b),
        (a, b) => a.is_some() != b.is_some(),
    };
    let obj = snap
        .mesh
        .as_deref()
        .filter(|_| mesh_changed)
        .map(kapaint_mesh::write_obj);
    let meta = Meta {
        id: snap.id.to_hex(),
        settings: snap.settings.clone(),
        base: snap.stack.base,
        selection: SelectionEntry::of(&snap.selection),
        normal: snap.normal.is_some(),
        layers,
        mesh: snap
            .mesh
            .as_ref()
            .map(|_| obj.as_ref().map_or(0, |o| o.len() as u64)),
        images: gathered.carried.iter().map(image_key).collect(),
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
    if let Some(obj) = &obj {
        out.write_all(obj.as_bytes())?;
    }
    for image in &gathered.carried {
        let (rgba, gray) = image.raw();
        write_le(out, &rgba)?;
        write_le(out, &gray)?;
    }
    Ok(Known {
        tiles: gathered.tiles,
        lists: gathered.list_keys,
        normal: snap.normal.clone(),
        mesh: snap.mesh.clone(),
        images: gathered.images,
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
pub(super) fn swap_pairs(bytes: &mut [u8], size: usize) {
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
