//! Reading a journal back: each record decoded as it streams (every count checked against
//! what the record still holds), and replayed on what the record before left.

use std::collections::HashMap;
use std::io::Read;
use std::sync::Arc;

use bytemuck::Pod;
use serde::Deserialize;

use super::journal::{LayerMeta, MAX_META_BYTES, Meta, ProjectionMeta, swap_pairs};
use super::record::Payload;
use crate::document::{Document, DocumentId};
use crate::layers::projected::{Projected, ProjectionFill};
use crate::layers::{
    ChannelBlend, Layer, LayerContent, LayerId, LayerProps, LayerStack, Mask, PaintTile,
    SharedMaskTile, SharedPaintTile, Stamped,
};
use crate::normal::NormalMap;
use crate::paint_image::{PaintImage, Pixels};
use crate::project::layers::{KindEntry, MAX_DEPTH, MAX_LAYERS};
use crate::texel::Channel;
use crate::tile::{Plane, TILE_TEXELS, Tile};

/// Reads `count` values of `T`, made of `u16`s or a `u64`, written by `journal::write_le`.
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
    mesh: Option<Arc<kapaint_mesh::Mesh>>,
    images: HashMap<u64, Arc<Pixels>>,
}

/// The size its projection fills give image `key`, if one names it.
fn image_size(layers: &[LayerMeta], key: u64) -> Option<(u32, u32)> {
    layers.iter().find_map(|l| match &l.projection {
        Some(p) if p.image == key => Some((p.width, p.height)),
        _ => image_size(&l.children, key),
    })
}

/// The images a record carries (after its mesh), each of the size a layer names it by.
fn read_images<R: Read>(
    r: &mut Payload<'_, R>,
    meta: &Meta,
) -> Result<HashMap<u64, Arc<Pixels>>, String> {
    let mut images = HashMap::new();
    for &key in &meta.images {
        let (w, h) =
            image_size(&meta.layers, key).ok_or("the record carries an image no layer names")?;
        let count = w as usize * h as usize;
        if count as u64 * 12 > r.left() {
            return Err("an image is larger than the record".into());
        }
        let rgba: Vec<u16> = read_le(r, count * 4)?;
        let gray: Vec<u16> = read_le(r, count * 2)?;
        images.insert(key, Arc::new(Pixels::from_raw(w, h, &rgba, &gray)?));
    }
    Ok(images)
}

/// Reads one record's payload (checked as it goes; the checksum is the caller's).
pub(super) fn decode<R: Read>(r: &mut Payload<'_, R>) -> Result<Decoded, String> {
    let (width, height) = (read_u32(r)?, read_u32(r)?);
    let max = crate::maps::MAX_SIDE;
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
            Plane::Uniform(v) => crate::project::valid_n_bits(*v),
            Plane::Data(d) => d.iter().all(|v| crate::project::valid_n_bits(*v)),
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
    let mesh = match meta.mesh {
        Some(bytes) if bytes > 0 => {
            if bytes > r.left().min(kapaint_mesh::MAX_FILE_BYTES) {
                return Err("the kept mesh is larger than the record".into());
            }
            let mut obj = vec![0_u8; bytes as usize];
            r.read_exact(&mut obj).map_err(|e| e.to_string())?;
            let name = meta.settings.mesh.spec().to_string();
            let mesh = kapaint_mesh::parse_obj(&obj, name, "mesh.obj".as_ref())
                .map_err(|e| e.to_string())?;
            Some(Arc::new(mesh))
        }
        _ => None,
    };
    let images = read_images(r, &meta)?;
    Ok(Decoded {
        width,
        height,
        meta,
        lists,
        paint,
        masks,
        normal,
        mesh,
        images,
    })
}

fn tile_count(width: u32, height: u32) -> usize {
    let side = crate::tile::TILE_SIZE;
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
            KindEntry::Fill => {
                l.tiles.is_none()
                    && l.fill.is_some() != l.projection.is_some()
                    && l.children.is_empty()
            }
            KindEntry::Group => l.tiles.is_none() && l.fill.is_none(),
        } && (l.kind == KindEntry::Fill || l.projection.is_none());
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
    mesh: Option<Arc<kapaint_mesh::Mesh>>,
    images: HashMap<u64, Arc<Pixels>>,
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
        let mut images = d.images;
        let normal = match (d.meta.normal, d.normal) {
            (false, _) => None,
            (true, Some(n)) => Some(n),
            (true, None) => Some(self.normal.clone().ok_or("the normal map is missing")?),
        };
        let mesh = match (d.meta.mesh, d.mesh) {
            (None, _) => None,
            (Some(_), Some(m)) => Some(m),
            (Some(_), None) => Some(self.mesh.clone().ok_or("the kept mesh is missing")?),
        };
        let mut take = Taken {
            tile_count,
            size: (d.width, d.height),
            old: self,
            lists: &mut lists,
            paint: &mut paint,
            masks: &mut masks,
            images: &mut images,
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
            .with_embedded_mesh(mesh.clone())
            .with_id(id);
        keep.normal = normal;
        keep.mesh = mesh;
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
    size: (u32, u32),
    old: &'a Replay,
    lists: &'a mut HashMap<u64, Vec<u64>>,
    paint: &'a mut HashMap<u64, SharedPaintTile>,
    masks: &'a mut HashMap<u64, SharedMaskTile>,
    images: &'a mut HashMap<u64, Arc<Pixels>>,
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
            KindEntry::Fill => match &m.projection {
                Some(p) => LayerContent::Projected(Arc::new(self.projected(p)?)),
                None => LayerContent::Fill(m.fill.unwrap_or_default().sanitized()),
            },
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
                    generator: mm.generator.clone().map(|g| {
                        Arc::new(crate::generator::tiles::Generated::new(
                            g,
                            crate::generator::tiles::Source::new(
                                None,
                                &[],
                                self.size.0,
                                self.size.1,
                            ),
                            false,
                        ))
                    }),
                })
            }
        };
        Ok(Layer {
            props: LayerProps {
                id: m.id.map_or_else(LayerId::fresh, LayerId::loaded),
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

impl Taken<'_> {
    /// A projection fill, its image from the record or the journal, laid on the map alone
    /// until the document attaches its mesh.
    fn projected(&mut self, p: &ProjectionMeta) -> Result<Projected, String> {
        let image = self
            .images
            .get(&p.image)
            .or_else(|| self.old.images.get(&p.image))
            .cloned()
            .filter(|i| (i.width(), i.height()) == (p.width, p.height))
            .ok_or("the record refers to an image the journal does not hold")?;
        self.keep.images.insert(p.image, Arc::clone(&image));
        let fill = ProjectionFill {
            image: PaintImage::of_pixels(&p.source, image),
            projection: p.projection,
            channels: p.channels,
        };
        let source = crate::generator::tiles::Source::new(None, &[], self.size.0, self.size.1);
        Ok(Projected::new(fill, source))
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
