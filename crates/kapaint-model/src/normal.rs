//! The tangent-space normal map: a fourth, optional map that an imported PBR material brings
//! (glTF's `normalTexture`, or `import-pbr --normal`). It is kept with the project and passed
//! through by the `gltf-pbr` export; it is not painted.
//!
//! It never enters `k_a`: the ambient coefficient is derived from `k_d`, `k_s` and `n` alone
//! (the paper's hemispherical average does not depend on the surface normal's direction in
//! the tangent frame), and nothing that derives `k_a` takes this map.
//!
//! Texels are as glTF stores them: 8-bit RGB, `(x, y, z) = 2 c - 1` in the tangent frame
//! (+X along the tangent, +Y along the bitangent, OpenGL's convention), at the map's own size
//! (not necessarily the material maps').

use glam::Vec3;

use super::maps::MAX_SIDE;

/// A size a normal map may have.
fn check_size(w: u32, h: u32) -> Result<(), String> {
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(format!(
            "a normal map of {w}x{h} is outside 1..={MAX_SIDE} on a side"
        ));
    }
    Ok(())
}

/// A tangent-space normal map, 8-bit RGB, row-major.
#[derive(Clone, PartialEq, Eq)]
pub struct NormalMap {
    image: image::RgbImage,
}

impl std::fmt::Debug for NormalMap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NormalMap")
            .field("width", &self.image.width())
            .field("height", &self.image.height())
            .finish_non_exhaustive()
    }
}

impl NormalMap {
    /// A normal map of `image`.
    ///
    /// # Errors
    /// An empty image, or one larger than the maps may be.
    pub fn new(image: image::RgbImage) -> Result<Self, String> {
        check_size(image.width(), image.height())?;
        Ok(Self { image })
    }

    /// A normal map of `width x height` 16-bit RGB samples (a bake's), kept at 8 bits.
    ///
    /// # Errors
    /// Samples that are not the size's, an empty size, or one larger than the maps may be.
    pub fn from_rgb16(width: u32, height: u32, data: &[u16]) -> Result<Self, String> {
        if data.len() as u64 != u64::from(width) * u64::from(height) * 3 {
            return Err(format!(
                "{} samples are not a {width}x{height} RGB map",
                data.len()
            ));
        }
        let bytes = data.iter().map(|&v| (v >> 8) as u8).collect();
        let image = image::RgbImage::from_raw(width, height, bytes).ok_or("a normal map's size")?;
        Self::new(image)
    }

    /// A flat map (every normal `+Z`) of `w x h`.
    ///
    /// # Errors
    /// As [`Self::new`].
    pub fn flat(w: u32, h: u32) -> Result<Self, String> {
        check_size(w, h)?;
        Self::new(image::RgbImage::from_pixel(
            w,
            h,
            image::Rgb([128, 128, 255]),
        ))
    }

    /// Width in texels.
    pub fn width(&self) -> u32 {
        self.image.width()
    }

    /// Height in texels.
    pub fn height(&self) -> u32 {
        self.image.height()
    }

    /// The texels as stored.
    pub fn image(&self) -> &image::RgbImage {
        &self.image
    }

    /// The unit normal at a texel (`+Z` where the stored vector is zero).
    pub fn normal(&self, x: u32, y: u32) -> Vec3 {
        let c = self.image.get_pixel(x, y).0;
        let v = Vec3::from_array(c.map(|c| f32::from(c) / 127.5 - 1.0));
        v.try_normalize().unwrap_or(Vec3::Z)
    }

    /// An 8-bit RGB PNG of the map.
    ///
    /// # Errors
    /// The encoder's.
    pub fn to_png(&self) -> Result<Vec<u8>, String> {
        super::import::encode_png(
            self.image.as_raw(),
            (self.width(), self.height()),
            image::ExtendedColorType::Rgb8,
        )
    }

    /// Decodes an 8-bit RGB PNG of at most `MAX_SIDE` texels a side (what [`Self::to_png`]
    /// writes; other colour types are refused).
    ///
    /// # Errors
    /// Not a PNG, a decode error, another colour type, or too large.
    pub fn from_png(bytes: &[u8]) -> Result<Self, String> {
        let mut reader =
            image::ImageReader::with_format(std::io::Cursor::new(bytes), image::ImageFormat::Png);
        let mut limits = image::Limits::default();
        limits.max_image_width = Some(MAX_SIDE);
        limits.max_image_height = Some(MAX_SIDE);
        limits.max_alloc = Some(u64::from(MAX_SIDE) * u64::from(MAX_SIDE) * 3 + (1 << 20));
        reader.limits(limits);
        match reader.decode().map_err(|e| e.to_string())? {
            image::DynamicImage::ImageRgb8(image) => Self::new(image),
            other => Err(format!(
                "colour type {:?}, expected 8-bit RGB",
                other.color()
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_normal_map_round_trips_through_png_and_decodes_unit_normals() {
        let image = image::RgbImage::from_fn(5, 3, |x, y| {
            image::Rgb([(x * 60) as u8, (y * 100) as u8, 200])
        });
        let map = NormalMap::new(image).expect("map");
        let back = NormalMap::from_png(&map.to_png().expect("png")).expect("decode");
        assert_eq!(back, map);
        let n = map.normal(4, 2);
        assert!((n.length() - 1.0).abs() < 1e-5);
        assert!(NormalMap::flat(2, 2).expect("flat").normal(1, 1).z > 0.99);
        assert!(NormalMap::flat(0, 2).is_err());
        let gray = image::GrayImage::new(2, 2);
        let mut png = std::io::Cursor::new(Vec::new());
        gray.write_to(&mut png, image::ImageFormat::Png)
            .expect("png");
        assert!(NormalMap::from_png(png.get_ref()).is_err());
    }
}
