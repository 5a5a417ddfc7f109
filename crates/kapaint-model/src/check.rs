//! Checks on values read from files: projects, sets, presets and paint scripts.
//!
//! Every type with a range or a shape that can come from a file is deserialised through one
//! of these checks (`#[serde(deserialize_with)]` on a field, or `#[serde(try_from)]` on the
//! type), so no file can build a value the model would refuse, and a save can never write a
//! value that would not load back. A failed check is an error that names the field and says
//! what it must be.

use serde::de::Error as _;
use serde::{Deserialize, Deserializer};

/// Longest name accepted in a file (a preset or material name), in bytes.
pub const MAX_NAME_BYTES: usize = 1024;

/// Longest path accepted in a file (a mesh reference), in bytes.
pub const MAX_PATH_BYTES: usize = 4096;

/// `v` when it is finite and in `[lo, hi]`, else an error naming `field`.
pub fn in_range(field: &str, v: f32, lo: f32, hi: f32) -> Result<f32, String> {
    if v.is_finite() && (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(format!("{field} must be a number in [{lo}, {hi}], got {v}"))
    }
}

/// [`in_range`] for an `f64` (manifest fields), with the same message.
pub fn in_range_f64(field: &str, v: f64, lo: f64, hi: f64) -> Result<f64, String> {
    if v.is_finite() && (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(format!("{field} must be a number in [{lo}, {hi}], got {v}"))
    }
}

/// Every component of `v` finite and in `[lo, hi]`.
pub fn all_in_range<const N: usize>(
    field: &str,
    v: [f32; N],
    lo: f32,
    hi: f32,
) -> Result<[f32; N], String> {
    if v.iter().all(|c| c.is_finite() && (lo..=hi).contains(c)) {
        Ok(v)
    } else {
        Err(format!(
            "{field} components must be numbers in [{lo}, {hi}], got {v:?}"
        ))
    }
}

/// `v` when it is in `[lo, hi]`, else an error naming `field`.
pub fn int_in_range<T: PartialOrd + std::fmt::Display + Copy>(
    field: &str,
    v: T,
    lo: T,
    hi: T,
) -> Result<T, String> {
    if v >= lo && v <= hi {
        Ok(v)
    } else {
        Err(format!("{field} must be in [{lo}, {hi}], got {v}"))
    }
}

/// A name: not empty (after trimming), at most [`MAX_NAME_BYTES`], no control characters.
pub fn name(field: &str, text: &str) -> Result<(), String> {
    if text.trim().is_empty() {
        return Err(format!("{field} is empty"));
    }
    bounded_text(field, text, MAX_NAME_BYTES)
}

/// `text` made a name [`name`] accepts: control characters as spaces, cut at a character
/// boundary to leave room for `suffix` within [`MAX_NAME_BYTES`], then `suffix`; `fallback`
/// where nothing is left.
pub fn fit_name(text: &str, suffix: &str, fallback: &str) -> String {
    let clean: String = text
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    let room = MAX_NAME_BYTES.saturating_sub(suffix.len());
    let mut end = clean.len().min(room);
    while !clean.is_char_boundary(end) {
        end -= 1;
    }
    let fitted = format!("{}{suffix}", &clean[..end]);
    if fitted.trim().is_empty() {
        fallback.to_string()
    } else {
        fitted
    }
}

/// Text of at most `max_bytes` without control characters.
pub fn bounded_text(field: &str, text: &str, max_bytes: usize) -> Result<(), String> {
    if text.len() > max_bytes {
        return Err(format!(
            "{field} is {} bytes long, more than the {max_bytes} allowed",
            text.len()
        ));
    }
    if text.chars().any(char::is_control) {
        return Err(format!("{field} holds control characters"));
    }
    Ok(())
}

/// Defines a `deserialize_with` function for an `f32` field that must be finite and in a
/// range; the error names the field.
macro_rules! ranged_f32 {
    ($(#[$doc:meta])* $fn_name:ident, $field:literal, $lo:expr, $hi:expr) => {
        $(#[$doc])*
        pub fn $fn_name<'de, D: Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
            let v = f32::deserialize(d)?;
            in_range($field, v, $lo, $hi).map_err(D::Error::custom)
        }
    };
}

ranged_f32!(
    /// Brush radius in texels, `[0.5, 4096]`.
    radius_px, "radius_px", 0.5, 4096.0
);
ranged_f32!(
    /// Brush hardness, `[0, 1]`.
    hardness, "hardness", 0.0, 1.0
);
ranged_f32!(
    /// Brush opacity, `[0, 1]`.
    opacity, "opacity", 0.0, 1.0
);
ranged_f32!(
    /// Brush flow, `[0, 1]`.
    flow, "flow", 0.0, 1.0
);
ranged_f32!(
    /// Dab spacing in percent of the radius, `[1, 1000]`.
    spacing_percent, "spacing_percent", 1.0, 1000.0
);
ranged_f32!(
    /// Jitter as a fraction of the radius, `[0, 1]`.
    jitter, "jitter", 0.0, 1.0
);
ranged_f32!(
    /// Lazy-mouse radius in texels, `[0, 1000]`.
    smoothing_px, "smoothing_px", 0.0, 1000.0
);
ranged_f32!(
    /// Pen pressure, `[0, 1]`.
    pressure, "pressure", 0.0, 1.0
);
ranged_f32!(
    /// Fill tolerance in blend space, `[0, 1]`.
    tolerance, "tolerance", 0.0, 1.0
);

/// Blur kernel radius in texels, `[1, 16]`.
pub fn blur_radius_px<'de, D: Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    let v = u32::deserialize(d)?;
    int_in_range("blur_radius_px", v, 1, 16).map_err(D::Error::custom)
}

/// A 2D point whose coordinates are finite (texel units; off the map is allowed).
pub fn finite_vec2<'de, D: Deserializer<'de>>(d: D) -> Result<glam::Vec2, D::Error> {
    let v = glam::Vec2::deserialize(d)?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(D::Error::custom(format!(
            "a point must have finite coordinates, got {v}"
        )))
    }
}

/// A 3D point or direction whose coordinates are finite.
pub fn finite_vec3<'de, D: Deserializer<'de>>(d: D) -> Result<glam::Vec3, D::Error> {
    let v = glam::Vec3::deserialize(d)?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(D::Error::custom(format!(
            "a point must have finite coordinates, got {v}"
        )))
    }
}

ranged_f32!(
    /// A layer's opacity, `[0, 1]`.
    layer_opacity, "opacity", 0.0, 1.0
);

/// A finite number.
pub fn finite_f32<'de, D: Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
    let v = f32::deserialize(d)?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(D::Error::custom(format!(
            "expected a finite number, got {v}"
        )))
    }
}

/// A projection whose numbers make a frame ([`Projection::check`](crate::paint::projection::Projection::check)).
pub fn projection<'de, D: Deserializer<'de>>(
    d: D,
) -> Result<crate::paint::projection::Projection, D::Error> {
    let v = crate::paint::projection::Projection::deserialize(d)?;
    v.check().map_err(D::Error::custom)?;
    Ok(v)
}

/// The most layers (groups and their children included) a document holds.
pub const MAX_LAYERS: usize = 256;

/// The deepest layer groups nest.
pub const MAX_DEPTH: usize = 16;

/// A layer's name ([`name`]).
pub fn layer_name<'de, D: Deserializer<'de>>(d: D) -> Result<String, D::Error> {
    let v = String::deserialize(d)?;
    name("the layer name", &v).map_err(D::Error::custom)?;
    Ok(v)
}

/// A path of indices into layer groups: at most one index per level a project may nest, each
/// under the most layers a project may hold.
pub fn layer_path<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<usize>, D::Error> {
    let v = Vec::<usize>::deserialize(d)?;
    let depth = MAX_DEPTH + 1;
    let most = MAX_LAYERS;
    if v.len() > depth || v.iter().any(|&i| i >= most) {
        return Err(D::Error::custom(format!(
            "a layer path has at most {depth} indices, each under {most}"
        )));
    }
    Ok(v)
}

/// An optional name ([`name`]).
pub fn optional_name<'de, D: Deserializer<'de>>(d: D) -> Result<Option<String>, D::Error> {
    let v = Option::<String>::deserialize(d)?;
    if let Some(text) = &v {
        name("name", text).map_err(D::Error::custom)?;
    }
    Ok(v)
}

/// An optional field written without `Some(...)`: present, it is the value.
pub fn some<'de, D: Deserializer<'de>, T: Deserialize<'de>>(d: D) -> Result<Option<T>, D::Error> {
    T::deserialize(d).map(Some)
}

/// One: the default of a field read as an opacity or a scale.
pub fn one() -> f32 {
    1.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_refuse_nan_infinity_and_the_outside() {
        for bad in [f32::NAN, f32::INFINITY, -1.0, 2.0, 1e30] {
            let err = in_range("opacity", bad, 0.0, 1.0).unwrap_err();
            assert!(err.starts_with("opacity must be"), "{err}");
        }
        assert_eq!(in_range("x", 0.0, 0.0, 1.0), Ok(0.0));
        assert_eq!(in_range("x", 1.0, 0.0, 1.0), Ok(1.0));
        assert!(all_in_range("kd", [0.5, f32::NAN, 0.0], 0.0, 1.0).is_err());
        assert!(int_in_range("bits", 17_u8, 1, 16).is_err());
    }

    #[test]
    fn names_are_bounded() {
        assert!(name("name", "").is_err());
        assert!(name("name", "   ").is_err());
        assert!(name("name", &"a".repeat(MAX_NAME_BYTES + 1)).is_err());
        assert!(name("name", "a\nb").is_err());
        assert!(name("name", "Brass (polished)").is_ok());
    }

    #[test]
    fn fitted_names_are_always_names() {
        let long = "é".repeat(MAX_NAME_BYTES);
        for (text, suffix) in [
            (long.as_str(), ""),
            (long.as_str(), " copy"),
            ("a\u{7}b", ""),
            ("   ", ""),
            ("", " copy"),
        ] {
            let fitted = fit_name(text, suffix, "Layer");
            assert!(name("name", &fitted).is_ok(), "{fitted:?}");
            assert!(fitted.ends_with(suffix));
        }
        assert_eq!(fit_name("Layer 1", " copy", "Layer"), "Layer 1 copy");
    }
}
