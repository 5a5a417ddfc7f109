//! A glTF file opened: its JSON parsed (a texture that names its KTX2 image only through
//! `KHR_texture_basisu` given that image as its source, which the `gltf` crate requires), its
//! references checked, and its buffers read from the GLB blob, `data:` URIs or files confined
//! to its folder.

use std::path::Path;

use crate::MeshError;

/// The glTF extension for Basis Universal (KTX2) textures.
pub const KHR_TEXTURE_BASISU: &str = "KHR_texture_basisu";

/// Whether the bytes `json` name [`KHR_TEXTURE_BASISU`] anywhere (a quick look before
/// parsing).
pub fn names_basisu(json: &[u8]) -> bool {
    json.windows(KHR_TEXTURE_BASISU.len())
        .any(|w| w == KHR_TEXTURE_BASISU.as_bytes())
}

/// A glTF file opened and checked: its document, its buffers' bytes and its folder.
pub struct Opened {
    /// The document, validated.
    pub document: gltf::Document,
    /// Every buffer's bytes, by index.
    pub buffers: Vec<Vec<u8>>,
    /// The folder that relative URIs are taken from.
    pub dir: std::path::PathBuf,
    /// The file's JSON as written (the `gltf` crate reads some fields lossily: an index past
    /// `u32` wraps), for checks that need the numbers as they are.
    pub json: Vec<u8>,
}

/// Opens a `.gltf` or `.glb` file: its references checked and its buffers loaded (from the
/// GLB blob, data: URIs, or files beside it). Errors are one line.
pub fn open_gltf(path: &Path) -> Result<Opened, MeshError> {
    let invalid = |reason: String| MeshError::Invalid {
        path: path.to_path_buf(),
        reason,
    };
    let bytes = crate::read_mesh_file(path)?;
    let not_gltf = |e: gltf::Error| invalid(format!("not a valid glTF file: {e}"));
    let json = if bytes.starts_with(b"glTF") {
        gltf::binary::Glb::from_slice(&bytes)
            .map_err(not_gltf)?
            .json
            .into_owned()
    } else {
        bytes.clone()
    };
    let gltf::Gltf { document, blob } = match basisu_sources(&json) {
        // The gltf crate requires a texture's `source`: one named only by its
        // KHR_texture_basisu extension (a KTX2 image with no fallback) gets that one.
        Some(patched) => {
            let blob = if bytes.starts_with(b"glTF") {
                gltf::binary::Glb::from_slice(&bytes)
                    .map_err(not_gltf)?
                    .bin
                    .map(std::borrow::Cow::into_owned)
            } else {
                None
            };
            let root = gltf::json::deserialize::from_slice(&patched)
                .map_err(|e| invalid(format!("not a valid glTF file: {e}")))?;
            gltf::Gltf {
                document: gltf::Document::from_json_without_validation(root),
                blob,
            }
        }
        None => gltf::Gltf::from_slice_without_validation(&bytes).map_err(not_gltf)?,
    };
    // gltf-json 1.4.1's own validation indexes the accessor list with the POSITION
    // attribute unchecked (and panics on a dangling one): check references first.
    check_references(document.as_json()).map_err(&invalid)?;
    let document = gltf::Document::from_json(document.into_json()).map_err(not_gltf)?;
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
        .to_path_buf();
    let buffers = load_buffers(&document, &dir, blob).map_err(&invalid)?;
    Ok(Opened {
        document,
        buffers,
        dir,
        json,
    })
}

/// The JSON `json` with `KHR_texture_basisu` out of `extensionsRequired` and each texture
/// that has no `source` but the extension's given that one; `None` where nothing needed it
/// (or the JSON does not parse: the gltf crate says why).
fn basisu_sources(json: &[u8]) -> Option<Vec<u8>> {
    if !names_basisu(json) {
        return None;
    }
    let mut root: serde_json::Value = serde_json::from_slice(json).ok()?;
    // The gltf crate refuses a required extension it does not know; the material's reader
    // decides (it reads KTX2 images where it was handed a reader, and refuses them else).
    let mut changed = false;
    if let Some(required) = root
        .get_mut("extensionsRequired")
        .and_then(serde_json::Value::as_array_mut)
    {
        let before = required.len();
        required.retain(|e| e != KHR_TEXTURE_BASISU);
        changed = required.len() != before;
    }
    let textures = root
        .get_mut("textures")
        .and_then(serde_json::Value::as_array_mut)
        .map_or(&mut [][..], |t| t.as_mut_slice());
    for texture in textures
        .iter_mut()
        .filter_map(serde_json::Value::as_object_mut)
    {
        if texture.contains_key("source") {
            continue;
        }
        let source = texture
            .get("extensions")
            .and_then(|e| e.get(KHR_TEXTURE_BASISU))
            .and_then(|b| b.get("source"))
            .cloned();
        if let Some(source) = source {
            texture.insert("source".into(), source);
            changed = true;
        }
    }
    if changed {
        serde_json::to_vec(&root).ok()
    } else {
        None
    }
}

/// Every accessor a primitive names exists.
fn check_references(root: &gltf::json::Root) -> Result<(), String> {
    let count = root.accessors.len();
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (k, primitive) in mesh.primitives.iter().enumerate() {
            let named = primitive
                .attributes
                .values()
                .chain(primitive.indices.as_ref());
            if let Some(bad) = named.map(gltf::json::Index::value).find(|&i| i >= count) {
                return Err(format!(
                    "mesh {m} primitive {k} uses accessor {bad}, but there are {count}"
                ));
            }
        }
    }
    Ok(())
}

/// Reads every buffer: the GLB's binary chunk, `data:` URIs, and files beside the glTF. A file
/// must be a regular file inside the glTF's folder (no absolute paths, no `..`, no other URI
/// schemes), and at least as long as the buffer's declared `byteLength`, of which no more is
/// read.
fn load_buffers(
    document: &gltf::Document,
    dir: &Path,
    mut blob: Option<Vec<u8>>,
) -> Result<Vec<Vec<u8>>, String> {
    use gltf::buffer::{Data, Source};
    let mut total: u64 = 0;
    let mut out = Vec::new();
    for buffer in document.buffers() {
        let declared = buffer.length() as u64;
        total = total.saturating_add(declared);
        if total > crate::MAX_FILE_BYTES {
            return Err(format!(
                "the buffers declare more than the {} bytes supported",
                crate::MAX_FILE_BYTES
            ));
        }
        let what = format!("buffer {}", buffer.index());
        let data = match buffer.source() {
            Source::Uri(uri) if !uri.starts_with("data:") => {
                read_buffer_file(dir, uri, declared).map_err(|e| format!("{what}: {e}"))?
            }
            source => {
                Data::from_source_and_blob(source, None, &mut blob)
                    .map_err(|e| format!("{what}: {e}"))?
                    .0
            }
        };
        if (data.len() as u64) < declared {
            return Err(format!(
                "{what} holds {} bytes but its byteLength is {declared} (truncated?)",
                data.len()
            ));
        }
        out.push(data);
    }
    Ok(out)
}

/// A buffer file named by a relative `uri`, confined to `dir`; at most `declared` bytes.
fn read_buffer_file(dir: &Path, uri: &str, declared: u64) -> Result<Vec<u8>, String> {
    use std::io::Read as _;
    let file = file_beside(dir, uri)?;
    let len = kapaint_base::file_check::regular_file(&file, crate::MAX_FILE_BYTES)
        .map_err(|e| format!("{}: {e}", file.display()))?;
    if len < declared {
        return Err(format!(
            "{} holds {len} bytes but the buffer's byteLength is {declared} (truncated?)",
            file.display()
        ));
    }
    let mut data = Vec::with_capacity(declared as usize);
    std::fs::File::open(&file)
        .and_then(|f| f.take(declared).read_to_end(&mut data))
        .map_err(|e| format!("{}: {e}", file.display()))?;
    Ok(data)
}

/// The file a relative `uri` names, confined to `dir` (no URI schemes, no absolute paths,
/// no `..`, no links out of it).
pub fn file_beside(dir: &Path, uri: &str) -> Result<std::path::PathBuf, String> {
    use std::path::Component;
    if uri.contains(':') {
        return Err(format!(
            "{uri:?}: only files beside the glTF are read (no URI schemes)"
        ));
    }
    let decoded = urlencoding::decode(uri).map_err(|_| format!("{uri:?} is not a valid URI"))?;
    let relative = Path::new(decoded.as_ref());
    if relative
        .components()
        .any(|c| !matches!(c, Component::Normal(_) | Component::CurDir))
    {
        return Err(format!(
            "{uri:?} leaves the glTF's folder (absolute paths and .. are not followed)"
        ));
    }
    let file = dir.join(relative);
    let inside = match (file.canonicalize(), dir.canonicalize()) {
        (Ok(f), Ok(d)) => f.starts_with(d),
        (Err(e), _) | (_, Err(e)) => return Err(format!("{}: {e}", file.display())),
    };
    if !inside {
        return Err(format!(
            "{uri:?} links outside the glTF's folder, which is not followed"
        ));
    }
    Ok(file)
}
