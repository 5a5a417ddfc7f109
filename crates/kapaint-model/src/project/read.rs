//! Reading a project: the zip, the manifest, each channel's PNG or constant, into tiles.

use std::io::{Read, Seek};

use rayon::prelude::*;

use super::{
    ChannelEntry, MAX_MANIFEST_BYTES, N_ENCODING, RGB_ENCODING, Raster, parse_manifest,
    valid_n_bits,
};
use crate::document::Document;
use crate::maps::MaterialMaps;
use crate::texel::MaterialValue;
use crate::tile::{Plane, TILE_SIZE, Tile};

/// Loads and validates a project from any seekable reader; the error is a reason text.
///
/// A project with generator masks has them laid on the mesh it keeps or names built in, and
/// its composite made from the layers there; one on a mesh file needs [`super::load`], which
/// finds the file beside the project.
pub fn from_reader(reader: impl Read + Seek) -> Result<Document, String> {
    let read = read(reader)?;
    let mut doc = read.doc;
    if read.needs_mesh {
        let mesh = match doc.settings().mesh.clone() {
            crate::MeshRef::Embedded(_) => doc.embedded_mesh().map(|m| (**m).clone()),
            crate::MeshRef::Sphere => kapaint_mesh::builtin("sphere"),
            crate::MeshRef::Builtin(name) => kapaint_mesh::builtin(&name),
            crate::MeshRef::File(path) => {
                return Err(format!(
                    "its generator masks are laid on the mesh file {path}, which only opening \
                     the project from its folder finds"
                ));
            }
        };
        let mesh = mesh.ok_or("its generator masks need its mesh, which it does not hold")?;
        let name = doc.settings().mesh.spec().to_string();
        super::attach_loaded(&mut doc, mesh, &name).map_err(|e| e.to_string())?;
    }
    Ok(doc)
}

/// A project as read, before its mesh is attached.
pub(super) struct ReadProject {
    /// The document, its composite made from the layers (generator masks not yet on their
    /// mesh).
    pub(super) doc: Document,
    /// Whether its layers need its mesh (generator masks): its composite is only right once
    /// the mesh is attached.
    pub(super) needs_mesh: bool,
}

/// The first texel (column, row) where `a` and `b` differ, if any.
fn first_difference(a: &MaterialMaps, b: &MaterialMaps) -> Option<(u32, u32)> {
    let differs = |id: usize| -> Option<(u32, u32)> {
        let (ta, tb) = (a.tile(id), b.tile(id));
        let r = a.tile_rect(id);
        (r.y0..r.y1).find_map(|y| {
            (r.x0..r.x1).find_map(|x| {
                let i = (y - r.y0) as usize * TILE_SIZE + (x - r.x0) as usize;
                (ta.texel(i) != tb.texel(i)).then_some((x, y))
            })
        })
    };
    (0..a.tile_count())
        .into_par_iter()
        .filter_map(differs)
        .min_by_key(|&(x, y)| (y, x))
}

/// Reads a project: its document composited from the layers, and the composite it stored
/// where that can only be checked once its mesh is attached.
pub(super) fn read(reader: impl Read + Seek) -> Result<ReadProject, String> {
    let mut zip = zip::ZipArchive::new(reader).map_err(|e| format!("not a zip archive ({e})"))?;
    let manifest = {
        let entry = zip
            .by_name("manifest.json")
            .map_err(|e| format!("manifest.json: {e}"))?;
        if entry.size() > MAX_MANIFEST_BYTES {
            return Err(format!(
                "manifest.json is {} bytes, more than the limit",
                entry.size()
            ));
        }
        let mut text = Vec::new();
        entry
            .take(MAX_MANIFEST_BYTES)
            .read_to_end(&mut text)
            .map_err(|e| format!("manifest.json: {e}"))?;
        parse_manifest(&text)?
    };
    check_declared(&manifest)?;
    let (w, h) = (manifest.width, manifest.height);
    if let Some(entries) = &manifest.layers {
        let tile_count = MaterialMaps::new(w, h, MaterialValue::default())
            .map_err(|e| e.to_string())?
            .tile_count();
        let mut read = |k: usize, e: &super::layers::LayerEntry| read_layer(&mut zip, k, e, w, h);
        let layers = super::layers::build(entries, &mut 0, (tile_count, (w, h)), &mut read)?;
        let stack = crate::layers::LayerStack {
            width: w,
            height: h,
            base: manifest.base.unwrap_or(manifest.settings.base).sanitized(),
            layers,
        };
        // The kept mesh and bakes are read before the settings move into the document.
        let mesh = read_mesh(&mut zip, &manifest)?;
        let bakes = super::bakes::read(&mut zip, &manifest)?;
        // The stored composite is read too: every entry's checksum is checked.
        let kd = read_channel(&mut zip, &manifest.kd, "kd", w, h, 3)?;
        let ks = read_channel(&mut zip, &manifest.ks, "ks", w, h, 3)?;
        let n = read_channel(&mut zip, &manifest.n, "n", w, h, 1)?;
        check_n(&n)?;
        let mut stored =
            MaterialMaps::new(w, h, MaterialValue::default()).map_err(|e| e.to_string())?;
        fill_maps(&mut stored, &kd, &ks, &n);
        let needs_mesh = super::layers::any_on_mesh(entries);
        let mut stack = stack;
        if needs_mesh {
            // Generator masks and projection fills wait for the mesh the project names
            // (nothing is computed for them until it is attached): its hash where the project says, else one no mesh
            // has.
            let hash = match (&mesh, &manifest.settings.mesh) {
                (Some(m), _) => m.content_hash(),
                (None, crate::MeshRef::Sphere | crate::MeshRef::Builtin(_)) => {
                    kapaint_mesh::builtin(manifest.settings.mesh.spec())
                        .map_or(0, |m| m.content_hash())
                }
                _ => bakes.first().map_or(0, |b| b.mesh_hash),
            };
            let source = crate::generator::tiles::Source::expecting(Some(hash), &bakes, w, h);
            crate::layers::lay_generators(&mut stack.layers, &source);
        }
        let doc = Document::from_stack(stack, manifest.settings).map_err(|e| e.to_string())?;
        // The stored composite is a cache, never taken as it is: the document's is made from
        // the layers. Without generator masks the two must agree (a difference is a damaged
        // or edited file); with them, the masks are laid on the mesh once it is attached, and
        // what they make there stands (a project an older build saved may hold a composite
        // its masks made on another surface).
        if !needs_mesh && let Some((x, y)) = first_difference(&stored, doc.maps()) {
            return Err(format!(
                "the stored composite differs from what the layers composite to (first at \
                 texel {x}, {y})"
            ));
        }
        let normal = read_normal(&mut zip, manifest.normal.as_ref())?;
        let doc = doc
            .with_normal(normal)
            .with_embedded_mesh(mesh)
            .with_bakes(bakes)
            .with_selection(
                manifest
                    .selection
                    .as_ref()
                    .map(super::SelectionEntry::selection)
                    .unwrap_or_default(),
            );
        return Ok(ReadProject {
            doc: with_id(doc, manifest.id.as_deref()),
            needs_mesh,
        });
    }
    let kd = read_channel(&mut zip, &manifest.kd, "kd", w, h, 3)?;
    let ks = read_channel(&mut zip, &manifest.ks, "ks", w, h, 3)?;
    let n = read_channel(&mut zip, &manifest.n, "n", w, h, 1)?;
    check_n(&n)?;
    let settings = manifest.settings;
    let mut maps = MaterialMaps::new(w, h, MaterialValue::default()).map_err(|e| e.to_string())?;
    fill_maps(&mut maps, &kd, &ks, &n);
    let doc = Document::from_parts(maps, settings)
        .with_normal(read_normal(&mut zip, manifest.normal.as_ref())?);
    Ok(ReadProject {
        doc: with_id(doc, manifest.id.as_deref()),
        needs_mesh: false,
    })
}

/// `doc` with the identity the manifest names (`id`) (a project written before projects had one
/// keeps the new one it was given).
fn with_id(doc: Document, id: Option<&str>) -> Document {
    match id.and_then(crate::document::DocumentId::from_hex) {
        Some(id) => doc.with_id(id),
        None => doc,
    }
}

/// What the manifest declares, checked before a byte of an image is decoded: no image entry is
/// named twice (a writer never shares one; a manifest naming one 8192^2 PNG in 256 layers
/// would decode it 256 times), and everything it declares fits in the memory available
/// (decoded rasters, and the tiles made from them).
fn check_declared(manifest: &super::Manifest) -> Result<(), String> {
    let mut names = std::collections::HashSet::new();
    let mut texel_bytes: u64 = 0;
    let mut name = |entry: &ChannelEntry| -> Result<(), String> {
        match entry {
            ChannelEntry::Image { file, .. } if !names.insert(file.clone()) => Err(format!(
                "the manifest names the image {file} more than once (a project stores each image once)"
            )),
            _ => Ok(()),
        }
    };
    let (w, h) = (u64::from(manifest.width), u64::from(manifest.height));
    for e in [&manifest.kd, &manifest.ks, &manifest.n] {
        name(e)?;
    }
    // The composite: its rasters (14 bytes a texel) and its tiles (14 more).
    texel_bytes += w * h * 28;
    let atlas_texels = |tiles: &Option<Vec<u32>>| -> u64 {
        tiles.as_ref().map_or(w * h, |t| {
            let (aw, ah) = super::layers::atlas_size(t.len());
            u64::from(aw) * u64::from(ah)
        })
    };
    let mut stack = manifest.layers.iter().flatten().collect::<Vec<_>>();
    while let Some(e) = stack.pop() {
        stack.extend(&e.children);
        if let Some(p) = &e.planes {
            for c in [&p.kd, &p.ks, &p.n, &p.alpha] {
                name(c)?;
            }
            // Values and coverage: rasters (20 bytes a texel) and maps (20 more).
            texel_bytes += atlas_texels(&p.tiles) * 40;
        }
        if let Some(m) = &e.mask {
            name(&m.gray)?;
            texel_bytes += atlas_texels(&m.tiles) * 20;
        }
        if let Some(p) = &e.projection {
            for file in [&p.rgba, &p.gray] {
                name(&ChannelEntry::Image {
                    file: file.clone(),
                    encoding: String::new(),
                })?;
            }
            // The PNGs' samples (12 bytes a pixel) and the pixels kept (12 more).
            texel_bytes += u64::from(p.width) * u64::from(p.height) * 24;
        }
    }
    kapaint_base::memory::check_fits("opening it", texel_bytes)
}

/// The most bytes of OBJ text a triangle of a kept mesh takes: three vertices (`v`, `vt` and
/// `vn` lines of at most about 60 bytes each, numbers in full precision) and a face line.
const MAX_OBJ_BYTES_PER_TRIANGLE: u64 = 3 * 180 + 80;

/// Bytes a parsed triangle of a kept mesh takes while it is read, measured high (the reader's
/// vectors and the mesh made from them).
const MESH_BYTES_PER_TRIANGLE: u64 = 400;

/// The mesh the project keeps, if its settings name one (and then the archive must hold it).
fn read_mesh<R: Read + Seek>(
    zip: &mut zip::ZipArchive<R>,
    manifest: &super::Manifest,
) -> Result<Option<std::sync::Arc<kapaint_mesh::Mesh>>, String> {
    let name = match (&manifest.settings.mesh, &manifest.mesh) {
        (crate::MeshRef::Embedded(name), Some(_)) => name,
        (crate::MeshRef::Embedded(name), None) => {
            return Err(format!(
                "the settings name the kept mesh {name:?}, but the manifest lists none"
            ));
        }
        (_, Some(e)) => {
            return Err(format!(
                "{} is listed, but the settings name another mesh",
                e.file
            ));
        }
        (_, None) => return Ok(None),
    };
    let Some(e) = &manifest.mesh else {
        return Ok(None);
    };
    if e.file != super::MESH_FILE {
        return Err(format!(
            "the kept mesh is {:?}, expected {:?}",
            e.file,
            super::MESH_FILE
        ));
    }
    if e.triangles == 0 || e.triangles > kapaint_mesh::MAX_TRIANGLES as u64 {
        return Err(format!(
            "the kept mesh declares {} triangles, outside 1 to {}",
            e.triangles,
            kapaint_mesh::MAX_TRIANGLES
        ));
    }
    // An OBJ written by kapaint holds at most three new vertices (position, UV, normal lines)
    // and a face line per triangle: an entry larger than that, declared or as it inflates,
    // is refused before it is read, and what it will take once parsed must fit in memory.
    let limit =
        (e.triangles * MAX_OBJ_BYTES_PER_TRIANGLE + (1 << 20)).min(kapaint_mesh::MAX_FILE_BYTES);
    kapaint_base::memory::check_fits(
        &format!("reading the kept mesh of {} triangles", e.triangles),
        limit + e.triangles * MESH_BYTES_PER_TRIANGLE,
    )?;
    let file = zip
        .by_name(&e.file)
        .map_err(|err| format!("{}: {err}", e.file))?;
    let too_large = |size: u64| {
        format!(
            "{} is {size} bytes or more, more than an OBJ of the {} triangles the manifest \
             declares can be ({limit} bytes)",
            e.file, e.triangles
        )
    };
    if file.size() > limit {
        return Err(too_large(file.size()));
    }
    let mut bytes = Vec::new();
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(|err| format!("{}: {err}", e.file))?;
    if bytes.len() as u64 > limit {
        // The entry declared less than it inflates to.
        return Err(too_large(bytes.len() as u64));
    }
    let mesh = kapaint_mesh::parse_obj(&bytes, name.clone(), std::path::Path::new(&e.file))
        .map_err(|err| err.to_string())?;
    if mesh.triangles.len() as u64 != e.triangles {
        return Err(format!(
            "{} holds {} triangles, the manifest says {}",
            e.file,
            mesh.triangles.len(),
            e.triangles
        ));
    }
    Ok(Some(std::sync::Arc::new(mesh)))
}

fn read_normal<R: Read + Seek>(
    zip: &mut zip::ZipArchive<R>,
    entry: Option<&super::NormalEntry>,
) -> Result<Option<std::sync::Arc<crate::normal::NormalMap>>, String> {
    let Some(e) = entry else {
        return Ok(None);
    };
    if e.encoding != super::NORMAL_ENCODING {
        return Err(format!(
            "{}: encoding {:?} is not supported for the normal map",
            e.file, e.encoding
        ));
    }
    let max = crate::maps::MAX_SIDE;
    if e.width == 0 || e.height == 0 || e.width > max || e.height > max {
        return Err(format!(
            "{}: size {}x{} is outside 1..={max}",
            e.file, e.width, e.height
        ));
    }
    let mut file = zip
        .by_name(&e.file)
        .map_err(|err| format!("{}: {err}", e.file))?;
    let limit = u64::from(e.width) * u64::from(e.height) * 3 * 2 + (1 << 20);
    if file.size() > limit {
        return Err(format!(
            "{} claims {} bytes, more than a {}x{} map can need",
            e.file,
            file.size(),
            e.width,
            e.height
        ));
    }
    let mut bytes = Vec::new();
    (&mut file)
        .take(limit)
        .read_to_end(&mut bytes)
        .map_err(|err| format!("{}: {err}", e.file))?;
    let map =
        crate::normal::NormalMap::from_png(&bytes).map_err(|err| format!("{}: {err}", e.file))?;
    if (map.width(), map.height()) != (e.width, e.height) {
        return Err(format!(
            "{} is {}x{}, the manifest says {}x{}",
            e.file,
            map.width(),
            map.height(),
            e.width,
            e.height
        ));
    }
    Ok(Some(std::sync::Arc::new(map)))
}

/// Reads the maps of layer `k`: values and coverage for a painted paint layer, and its mask.
fn read_layer<R: Read + Seek>(
    zip: &mut zip::ZipArchive<R>,
    k: usize,
    e: &super::layers::LayerEntry,
    w: u32,
    h: u32,
) -> Result<super::layers::LayerMaps, String> {
    let name = |part: &str| format!("layer {k} ({:?}) {part}", e.name);
    let zero3 = Raster::Uniform(vec![0; 3]);
    let zero1 = Raster::Uniform(vec![0]);
    let mut out = super::layers::LayerMaps::empty(k);
    let tile_count = MaterialMaps::new(w, h, MaterialValue::default())
        .map_err(|e| e.to_string())?
        .tile_count();
    // The images are atlases of the listed tiles, or (without a list) the whole map, whose
    // tile `j` is tile `j`.
    let layout = |tiles: &Option<Vec<u32>>, what: &str| -> Result<(Vec<u32>, u32, u32), String> {
        match tiles {
            Some(t) => {
                super::layers::check_tiles(t, tile_count, &name(what))?;
                let (aw, ah) = super::layers::atlas_size(t.len());
                Ok((t.clone(), aw, ah))
            }
            None => Ok(((0..tile_count as u32).collect(), w, h)),
        }
    };
    let new_maps = |w: u32, h: u32| {
        MaterialMaps::new(w, h, MaterialValue::default()).map_err(|e| e.to_string())
    };
    if let Some(p) = &e.planes {
        let (tiles, aw, ah) = layout(&p.tiles, "planes")?;
        let kd = read_channel(zip, &p.kd, &name("kd"), aw, ah, 3)?;
        let ks = read_channel(zip, &p.ks, &name("ks"), aw, ah, 3)?;
        let n = read_channel(zip, &p.n, &name("n"), aw, ah, 1)?;
        check_n(&n)?;
        let alpha = read_channel(zip, &p.alpha, &name("coverage"), aw, ah, 3)?;
        let mut values = new_maps(aw, ah)?;
        fill_maps(&mut values, &kd, &ks, &n);
        let mut cover = new_maps(aw, ah)?;
        fill_maps(&mut cover, &alpha, &zero3, &zero1);
        out.tiles = tiles;
        out.values = Some(values);
        out.alpha = Some(cover);
    }
    if let Some(m) = &e.mask {
        let (tiles, aw, ah) = layout(&m.tiles, "mask")?;
        let gray = read_channel(zip, &m.gray, &name("mask"), aw, ah, 3)?;
        let mut mask = new_maps(aw, ah)?;
        fill_maps(&mut mask, &gray, &zero3, &zero1);
        out.mask_tiles = tiles;
        out.mask_fill = m.fill.unwrap_or(u16::MAX);
        out.mask = Some(mask);
    }
    if let Some(p) = &e.projection {
        out.projection = Some(super::images::read(zip, p, &name("projection"))?);
    }
    Ok(out)
}

/// Refuses stored exponents that are not valid half floats in range.
fn check_n(n: &Raster) -> Result<(), String> {
    let n_samples = match n {
        Raster::Uniform(v) | Raster::Gray(v) | Raster::Rgb(v) => v,
    };
    if let Some(bad) = n_samples.par_iter().find_any(|&&bits| !valid_n_bits(bits)) {
        return Err(format!(
            "n holds an invalid exponent (half-float bits {bad:#06x})"
        ));
    }
    Ok(())
}

fn read_channel<R: Read + Seek>(
    zip: &mut zip::ZipArchive<R>,
    entry: &ChannelEntry,
    name: &str,
    w: u32,
    h: u32,
    components: usize,
) -> Result<Raster, String> {
    match entry {
        ChannelEntry::Uniform { value } => {
            if value.len() != components {
                return Err(format!(
                    "{name}: uniform value has {} components, expected {components}",
                    value.len()
                ));
            }
            Ok(Raster::Uniform(value.clone()))
        }
        ChannelEntry::Image { file, encoding } => {
            let expected = if components == 3 {
                RGB_ENCODING
            } else {
                N_ENCODING
            };
            if encoding != expected {
                return Err(format!(
                    "{file}: encoding {encoding:?} is not supported for {name}"
                ));
            }
            let mut entry = zip.by_name(file).map_err(|e| format!("{file}: {e}"))?;
            // A 16-bit PNG of this size can never need more than this.
            let limit = u64::from(w) * u64::from(h) * components as u64 * 2 * 2 + (1 << 20);
            if entry.size() > limit {
                return Err(format!(
                    "{file} claims {} bytes, more than a {w}x{h} map can need",
                    entry.size()
                ));
            }
            let mut bytes = Vec::with_capacity(entry.size() as usize);
            (&mut entry)
                .take(limit)
                .read_to_end(&mut bytes)
                .map_err(|e| format!("{file}: {e}"))?;
            let mut reader = image::ImageReader::with_format(
                std::io::Cursor::new(bytes),
                image::ImageFormat::Png,
            );
            let mut limits = image::Limits::default();
            limits.max_image_width = Some(w);
            limits.max_image_height = Some(h);
            limits.max_alloc = Some(limit);
            reader.limits(limits);
            let image = reader.decode().map_err(|e| format!("{file}: {e}"))?;
            if (image.width(), image.height()) != (w, h) {
                return Err(format!(
                    "{file} is {}x{}, the manifest says {w}x{h}",
                    image.width(),
                    image.height()
                ));
            }
            match (components, image) {
                (3, image::DynamicImage::ImageRgb16(img)) => Ok(Raster::Rgb(img.into_raw())),
                (1, image::DynamicImage::ImageLuma16(img)) => Ok(Raster::Gray(img.into_raw())),
                (_, other) => Err(format!(
                    "{file} has colour type {:?}, expected 16-bit {}",
                    other.color(),
                    if components == 3 { "RGB" } else { "gray" }
                )),
            }
        }
    }
}

fn fill_maps(maps: &mut MaterialMaps, kd: &Raster, ks: &Raster, n: &Raster) {
    let w = maps.width() as usize;
    let rgb_plane =
        |r: &Raster, x0: usize, y0: usize, cols: usize, rows: usize| -> Plane<[u16; 3]> {
            match r {
                Raster::Uniform(v) => Plane::Uniform([v[0], v[1], v[2]]),
                Raster::Rgb(d) | Raster::Gray(d) => {
                    let mut p = Plane::Uniform([0; 3]);
                    let data = p.data_mut();
                    for y in 0..rows {
                        for x in 0..cols {
                            let at = ((y0 + y) * w + x0 + x) * 3;
                            data[y * TILE_SIZE + x] = [d[at], d[at + 1], d[at + 2]];
                        }
                    }
                    p.compact();
                    p
                }
            }
        };
    let tiles: Vec<Tile> = (0..maps.tile_count())
        .into_par_iter()
        .map(|id| {
            let crate::maps::TexelRect { x0, y0, x1, y1 } = maps.tile_rect(id);
            let (x0, y0, cols, rows) = (
                x0 as usize,
                y0 as usize,
                (x1 - x0) as usize,
                (y1 - y0) as usize,
            );
            let n_plane = match n {
                Raster::Uniform(v) => Plane::Uniform(v[0]),
                Raster::Gray(d) | Raster::Rgb(d) => {
                    let mut p = Plane::Uniform(0);
                    let data = p.data_mut();
                    for y in 0..rows {
                        data[y * TILE_SIZE..y * TILE_SIZE + cols]
                            .copy_from_slice(&d[(y0 + y) * w + x0..(y0 + y) * w + x0 + cols]);
                    }
                    p.compact();
                    p
                }
            };
            Tile {
                kd: rgb_plane(kd, x0, y0, cols, rows),
                ks: rgb_plane(ks, x0, y0, cols, rows),
                n: n_plane,
            }
        })
        .collect();
    for (id, tile) in tiles.into_iter().enumerate() {
        *maps.tile_mut(id) = tile;
    }
}
