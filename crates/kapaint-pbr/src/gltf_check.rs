//! The checks a glTF material passes before any of it is read, on the JSON as written: the
//! `gltf` crate panics on an image with neither `uri` nor `bufferView` (or a `bufferView`
//! without `mimeType`), wraps an index past `u32` onto another texture, and hands factors and
//! texture transforms over as they are, out of range or infinite.

use serde_json::Value;

/// Checks every image, texture and material of a glTF's JSON: an error names the first
/// field that is not as the glTF specification requires.
///
/// # Errors
/// JSON that does not parse; an image without a source (or with both), a `bufferView` image
/// without `mimeType`; a texture or image index past its array; a factor outside `[0, 1]`; a
/// texture transform that is not finite.
pub fn check_materials(json: &[u8]) -> Result<(), String> {
    let root: Value =
        serde_json::from_slice(json).map_err(|e| format!("its JSON does not parse: {e}"))?;
    let count = |key: &str| root.get(key).and_then(Value::as_array).map_or(0, Vec::len);
    let (images, textures, samplers) = (count("images"), count("textures"), count("samplers"));
    for (i, image) in items(&root, "images") {
        let (uri, view) = (image.get("uri"), image.get("bufferView"));
        match (uri, view) {
            (Some(_), Some(_)) => {
                return Err(format!("image {i} has both a uri and a bufferView"));
            }
            (None, None) => {
                return Err(format!("image {i} has neither a uri nor a bufferView"));
            }
            (None, Some(_)) if image.get("mimeType").is_none() => {
                return Err(format!("image {i} is in a bufferView but has no mimeType"));
            }
            _ => {}
        }
    }
    for (i, texture) in items(&root, "textures") {
        index_within(texture.get("source"), images, || {
            format!("texture {i}'s source")
        })?;
        index_within(texture.get("sampler"), samplers, || {
            format!("texture {i}'s sampler")
        })?;
    }
    for (i, material) in items(&root, "materials") {
        let name = || {
            material
                .get("name")
                .and_then(Value::as_str)
                .map_or_else(|| format!("material {i}"), |n| format!("material {n:?}"))
        };
        let pbr = material.get("pbrMetallicRoughness");
        if let Some(f) = pbr.and_then(|p| p.get("baseColorFactor")) {
            let values = f
                .as_array()
                .filter(|a| a.len() == 4)
                .ok_or_else(|| format!("{}: baseColorFactor is not four numbers", name()))?;
            for v in values {
                unit(Some(v), || format!("{}: baseColorFactor", name()))?;
            }
        }
        unit(pbr.and_then(|p| p.get("metallicFactor")), || {
            format!("{}: metallicFactor", name())
        })?;
        unit(pbr.and_then(|p| p.get("roughnessFactor")), || {
            format!("{}: roughnessFactor", name())
        })?;
        let slots = [
            (
                "baseColorTexture",
                pbr.and_then(|p| p.get("baseColorTexture")),
            ),
            (
                "metallicRoughnessTexture",
                pbr.and_then(|p| p.get("metallicRoughnessTexture")),
            ),
            ("normalTexture", material.get("normalTexture")),
            ("occlusionTexture", material.get("occlusionTexture")),
            ("emissiveTexture", material.get("emissiveTexture")),
        ];
        for (slot, info) in slots {
            let Some(info) = info else { continue };
            let what = || format!("{}: {slot}", name());
            let index = info
                .get("index")
                .ok_or_else(|| format!("{} has no index", what()))?;
            index_within(Some(index), textures, || format!("{}'s index", what()))?;
            if let Some(t) = info
                .get("extensions")
                .and_then(|e| e.get("KHR_texture_transform"))
            {
                finite(t.get("rotation"), 1, || {
                    format!("{}'s texture rotation", what())
                })?;
                finite(t.get("offset"), 2, || {
                    format!("{}'s texture offset", what())
                })?;
                finite(t.get("scale"), 2, || format!("{}'s texture scale", what()))?;
            }
        }
    }
    Ok(())
}

/// The entries of the array `key` of `root`, numbered.
fn items<'a>(root: &'a Value, key: &str) -> impl Iterator<Item = (usize, &'a Value)> {
    root.get(key)
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .enumerate()
}

/// An index, when given, is a whole number below `len`.
fn index_within(v: Option<&Value>, len: usize, what: impl Fn() -> String) -> Result<(), String> {
    match v {
        None => Ok(()),
        Some(v) => match v.as_u64() {
            Some(i) if i < len as u64 => Ok(()),
            _ => Err(format!(
                "{} ({v}) is not one of the {len} there are",
                what()
            )),
        },
    }
}

/// A factor, when given, is a number in `[0, 1]`, as f32 reads it.
fn unit(v: Option<&Value>, what: impl Fn() -> String) -> Result<(), String> {
    let Some(v) = v else { return Ok(()) };
    match v.as_f64() {
        Some(x) if (0.0..=1.0).contains(&x) => Ok(()),
        _ => Err(format!("{} is {v}, outside [0, 1]", what())),
    }
}

/// A number (`n` = 1) or an array of `n` numbers, when given, finite as f32 reads them.
fn finite(v: Option<&Value>, n: usize, what: impl Fn() -> String) -> Result<(), String> {
    let Some(v) = v else { return Ok(()) };
    let ok = |x: &Value| x.as_f64().is_some_and(|f| (f as f32).is_finite());
    let fine = if n == 1 {
        ok(v)
    } else {
        v.as_array()
            .is_some_and(|a| a.len() == n && a.iter().all(ok))
    };
    if fine {
        Ok(())
    } else {
        Err(format!("{} is {v}, not finite", what()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn material(extra: &str) -> String {
        format!(
            r#"{{"asset": {{"version": "2.0"}},
            "images": [{{"uri": "a.png"}}, {{"bufferView": 0, "mimeType": "image/png"}}],
            "textures": [{{"source": 0}}, {{"source": 1}}],
            "materials": [{{"name": "m", {extra}}}]}}"#
        )
    }

    #[test]
    fn what_the_crate_would_panic_on_or_misread_is_refused() {
        let ok = material(
            r#""pbrMetallicRoughness": {"baseColorTexture": {"index": 1}, "metallicFactor": 0.5}"#,
        );
        assert_eq!(check_materials(ok.as_bytes()), Ok(()));
        let cases = [
            (
                material("\"doubleSided\": true").replace(r#"{"uri": "a.png"}"#, "{}"),
                "neither",
            ),
            (
                material("\"doubleSided\": true").replace(r#", "mimeType": "image/png""#, ""),
                "no mimeType",
            ),
            (
                material(r#""pbrMetallicRoughness": {"baseColorTexture": {"index": 4294967297}}"#),
                "baseColorTexture's index",
            ),
            (
                material(r#""pbrMetallicRoughness": {"metallicFactor": 2}"#),
                "metallicFactor",
            ),
            (
                material(r#""pbrMetallicRoughness": {"metallicFactor": -1}"#),
                "metallicFactor",
            ),
            (
                material(r#""pbrMetallicRoughness": {"metallicFactor": 1e39}"#),
                "metallicFactor",
            ),
            (
                material(r#""pbrMetallicRoughness": {"roughnessFactor": -1}"#),
                "roughnessFactor",
            ),
            (
                material(r#""pbrMetallicRoughness": {"baseColorFactor": [1, 1e39, 1, 1]}"#),
                "baseColorFactor",
            ),
            (
                material(
                    r#""pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"scale": [1e39, 1]}}}}"#,
                ),
                "texture scale",
            ),
            (
                material(
                    r#""pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"rotation": 1e300}}}}"#,
                ),
                "texture rotation",
            ),
        ];
        for (json, says) in cases {
            let err = check_materials(json.as_bytes()).expect_err(says);
            assert!(err.contains(says), "{err}");
        }
    }
}
