//! An image painted through: a projection's, a decal's or a stencil's picture.
//!
//! A command names its image by path (`image: "logo.png"` in a script); whoever applies the
//! command loads it first ([`PaintImage::load`]: the CLI before the script runs, the editor on
//! a worker), and the document refuses an image that was not loaded. What is kept is what the
//! tools read, per pixel: the colour decoded from sRGB to linear (for `k_d`), the gray as the
//! file stores it (a stencil's value, and `n` through the mapping `kapaint import --channel
//! n` uses), and the alpha (the coverage; 1 for an image without one).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Vec2, Vec3};
use image::DynamicImage;

use crate::ModelError;
use crate::texel::{linear_to_srgb, n_from_blend, n_to_blend, srgb_to_linear};

/// Largest side of an image painted through (pixels).
pub const MAX_PAINT_IMAGE_SIDE: u32 = 8192;

/// Bytes kept per pixel.
const PIXEL_BYTES: u64 = std::mem::size_of::<Pixel>() as u64;

/// One pixel as the tools read it, each part unorm16.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Pixel {
    /// Linear RGB, premultiplied by alpha.
    rgb: [u16; 3],
    /// The gray as stored (sRGB-encoded luma for integer images), premultiplied.
    gray: u16,
    /// `n`'s blend value (see [`crate::texel::n_to_blend`]), premultiplied.
    n_blend: u16,
    /// Coverage.
    alpha: u16,
}

/// An image's pixels, decoded for painting.
#[derive(Debug, PartialEq)]
pub struct Pixels {
    width: u32,
    height: u32,
    texels: Vec<Pixel>,
}

/// What an image holds at a point (bilinear, alpha-weighted).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Linear RGB (not premultiplied).
    pub rgb: Vec3,
    /// The gray as stored, in `[0, 1]`.
    pub gray: f32,
    /// `n` through the import's mapping, in the log space layers blend it in
    /// ([`n_to_blend`]; [`Self::n`] is the exponent).
    pub n_blend: f32,
    /// Coverage in `[0, 1]`: 0 outside the image.
    pub alpha: f32,
}

impl Sample {
    /// `n` through the import's mapping.
    pub fn n(&self) -> f32 {
        n_from_blend(self.n_blend)
    }

    /// The linear luminance (`k_s` from an image).
    pub fn luminance(&self) -> f32 {
        0.2126 * self.rgb.x + 0.7152 * self.rgb.y + 0.0722 * self.rgb.z
    }
}

fn unorm(v: f32) -> u16 {
    (v.clamp(0.0, 1.0) * 65535.0 + 0.5) as u16
}

fn from_unorm(v: u16) -> f32 {
    f32::from(v) / 65535.0
}

impl Pixels {
    /// The pixels of a decoded image.
    ///
    /// # Errors
    /// An image over [`MAX_PAINT_IMAGE_SIDE`] a side, or one the memory cannot hold.
    pub fn of(image: &DynamicImage) -> Result<Self, String> {
        let (width, height) = (image.width(), image.height());
        if width == 0 || height == 0 {
            return Err("the image is empty".into());
        }
        if width > MAX_PAINT_IMAGE_SIDE || height > MAX_PAINT_IMAGE_SIDE {
            return Err(format!(
                "the image is {width}x{height}, more than the {MAX_PAINT_IMAGE_SIDE}x{MAX_PAINT_IMAGE_SIDE} an image painted through may be"
            ));
        }
        let count = u64::from(width) * u64::from(height);
        kapaint_base::memory::check_fits("keeping the image", count * (PIXEL_BYTES + 16))?;
        let float = matches!(
            image,
            DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_)
        );
        let pixel = |[r, g, b, a]: [f32; 4]| {
            let a = if a.is_finite() {
                a.clamp(0.0, 1.0)
            } else {
                0.0
            };
            let c = [r, g, b].map(|c| if c.is_finite() { c.max(0.0) } else { 0.0 });
            let (linear, gray, n_blend) = if float {
                // A float image holds linear values, and `n` itself (as the import reads it).
                let luma = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
                (c, linear_to_srgb(luma.min(1.0)), n_to_blend(luma.max(1.0)))
            } else {
                let luma = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
                (c.map(srgb_to_linear), luma, luma)
            };
            Pixel {
                rgb: linear.map(|c| unorm(c * a)),
                gray: unorm(gray * a),
                n_blend: unorm(n_blend * a),
                alpha: unorm(a),
            }
        };
        let texels = if float {
            image.to_rgba32f().pixels().map(|p| pixel(p.0)).collect()
        } else {
            image
                .to_rgba16()
                .pixels()
                .map(|p| pixel(p.0.map(from_unorm)))
                .collect()
        };
        Ok(Self {
            width,
            height,
            texels,
        })
    }

    /// Its pixels as kept, row-major: RGBA (linear colour premultiplied by alpha, and alpha)
    /// and gray-alpha (the gray and `n`'s blend value, both premultiplied), each part unorm16:
    /// what a project keeps of a projection fill's image.
    pub fn raw(&self) -> (Vec<u16>, Vec<u16>) {
        let rgba = self
            .texels
            .iter()
            .flat_map(|p| [p.rgb[0], p.rgb[1], p.rgb[2], p.alpha])
            .collect();
        let gray = self
            .texels
            .iter()
            .flat_map(|p| [p.gray, p.n_blend])
            .collect();
        (rgba, gray)
    }

    /// The pixels [`Self::raw`] gave.
    ///
    /// # Errors
    /// Parts of another length than `width x height` pixels, or an image over
    /// [`MAX_PAINT_IMAGE_SIDE`] a side.
    pub fn from_raw(width: u32, height: u32, rgba: &[u16], gray: &[u16]) -> Result<Self, String> {
        if width == 0
            || height == 0
            || width > MAX_PAINT_IMAGE_SIDE
            || height > MAX_PAINT_IMAGE_SIDE
        {
            return Err(format!(
                "an image of {width}x{height} pixels cannot be painted through"
            ));
        }
        let count = width as usize * height as usize;
        if rgba.len() != count * 4 || gray.len() != count * 2 {
            return Err(format!(
                "the image's parts do not hold {width}x{height} pixels"
            ));
        }
        let texels = rgba
            .chunks_exact(4)
            .zip(gray.chunks_exact(2))
            .map(|(c, g)| Pixel {
                rgb: [c[0], c[1], c[2]],
                gray: g[0],
                n_blend: g[1],
                alpha: c[3],
            })
            .collect();
        Ok(Self {
            width,
            height,
            texels,
        })
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Each pixel's gray times its alpha, row-major: what a stencil paints through.
    pub fn covered_gray(&self) -> Vec<f32> {
        self.texels.iter().map(|p| from_unorm(p.gray)).collect()
    }

    /// Height over width.
    pub fn aspect(&self) -> f32 {
        self.height as f32 / self.width as f32
    }

    /// The image at `uv` (`(0, 0)` the top-left corner, `(1, 1)` the bottom-right), bilinear
    /// between pixel centres and alpha-weighted (no dark fringe at a cut-out's edge); with
    /// `tiled` the image repeats, else it is transparent outside `[0, 1]^2`.
    pub fn sample(&self, uv: Vec2, tiled: bool) -> Sample {
        const NONE: Sample = Sample {
            rgb: Vec3::ZERO,
            gray: 0.0,
            n_blend: 0.0,
            alpha: 0.0,
        };
        if !uv.is_finite() || (!tiled && (uv.cmplt(Vec2::ZERO).any() || uv.cmpgt(Vec2::ONE).any()))
        {
            return NONE;
        }
        let (w, h) = (i64::from(self.width), i64::from(self.height));
        let p = uv * Vec2::new(self.width as f32, self.height as f32) - 0.5;
        let (x0, y0) = (p.x.floor(), p.y.floor());
        let (fx, fy) = (p.x - x0, p.y - y0);
        // The two columns (rows) the sample falls between, wrapped or clamped once each.
        let pair = |v: i64, n: i64| -> (usize, usize) {
            if tiled {
                let a = v.rem_euclid(n);
                (a as usize, if a + 1 == n { 0 } else { a as usize + 1 })
            } else {
                (v.clamp(0, n - 1) as usize, (v + 1).clamp(0, n - 1) as usize)
            }
        };
        let ((xa, xb), (ya, yb)) = (pair(x0 as i64, w), pair(y0 as i64, h));
        let row = self.width as usize;
        // Sums of the stored values (unorm16 as they are: the colour's share of the alpha does
        // not need them scaled, the alpha is scaled once).
        let mut sum = [0.0_f32; 6];
        for (at, wgt) in [
            (ya * row + xa, (1.0 - fx) * (1.0 - fy)),
            (ya * row + xb, fx * (1.0 - fy)),
            (yb * row + xa, (1.0 - fx) * fy),
            (yb * row + xb, fx * fy),
        ] {
            let px = self.texels[at];
            let parts = [
                px.rgb[0], px.rgb[1], px.rgb[2], px.gray, px.n_blend, px.alpha,
            ];
            for (s, v) in sum.iter_mut().zip(parts) {
                *s += f32::from(v) * wgt;
            }
        }
        let alpha = sum[5] / 65535.0;
        if alpha <= 1e-6 {
            return NONE;
        }
        let per_alpha = 1.0 / sum[5];
        let un = |v: f32| (v * per_alpha).clamp(0.0, 1.0);
        Sample {
            rgb: Vec3::new(un(sum[0]), un(sum[1]), un(sum[2])),
            gray: un(sum[3]),
            n_blend: un(sum[4]),
            alpha: alpha.min(1.0),
        }
    }
}

/// An image a command paints through: its path, and its pixels once loaded.
#[derive(Clone)]
pub struct PaintImage {
    path: PathBuf,
    pixels: Option<Arc<Pixels>>,
}

impl PaintImage {
    /// An image already decoded (the editor's, decoded on a worker).
    ///
    /// # Errors
    /// As [`Pixels::of`], naming the file.
    pub fn decoded(path: &Path, image: &DynamicImage) -> Result<Self, ModelError> {
        let pixels = Pixels::of(image).map_err(|reason| ModelError::Image {
            path: path.to_path_buf(),
            reason,
        })?;
        Ok(Self {
            path: path.to_path_buf(),
            pixels: Some(Arc::new(pixels)),
        })
    }

    /// Pixels already made (a project's projection fill, read back), named by `path`.
    pub fn of_pixels(path: impl Into<PathBuf>, pixels: Arc<Pixels>) -> Self {
        Self {
            path: path.into(),
            pixels: Some(pixels),
        }
    }

    /// Named by path, not loaded yet.
    pub fn named(path: impl Into<PathBuf>) -> Self {
        Self {
            path: path.into(),
            pixels: None,
        }
    }

    /// The path the command names.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Reads and decodes the file (a relative path from `base`, a script's folder), with the
    /// import's limits; does nothing if it is loaded already.
    ///
    /// # Errors
    /// A missing, unreadable, corrupt or huge image: [`ModelError::Image`], naming the file.
    pub fn load(&mut self, base: &Path) -> Result<(), ModelError> {
        if self.pixels.is_some() {
            return Ok(());
        }
        let path = base.join(&self.path);
        let image = crate::import::read_image(&path).map_err(|e| match e {
            ModelError::Io { path, source } => ModelError::Image {
                path,
                reason: source.to_string(),
            },
            other => other,
        })?;
        self.pixels = Some(Arc::new(Pixels::of(&image).map_err(|reason| {
            ModelError::Image {
                path: path.clone(),
                reason,
            }
        })?));
        self.path = path;
        Ok(())
    }

    /// The pixels.
    ///
    /// # Errors
    /// When the image was not loaded: a command applied without [`Self::load`].
    pub fn pixels(&self) -> Result<&Arc<Pixels>, ModelError> {
        self.pixels.as_ref().ok_or_else(|| ModelError::Image {
            path: self.path.clone(),
            reason: "the image was not loaded before the command was applied".into(),
        })
    }
}

impl PartialEq for PaintImage {
    fn eq(&self, other: &Self) -> bool {
        self.path == other.path
            && match (&self.pixels, &other.pixels) {
                (Some(a), Some(b)) => Arc::ptr_eq(a, b),
                (a, b) => a.is_none() && b.is_none(),
            }
    }
}

impl std::fmt::Debug for PaintImage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let size = self.pixels.as_ref().map(|p| (p.width, p.height));
        f.debug_struct("PaintImage")
            .field("path", &self.path)
            .field("size", &size)
            .finish()
    }
}

impl<'de> serde::Deserialize<'de> for PaintImage {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let path = PathBuf::deserialize(d)?;
        if path.as_os_str().is_empty() {
            return Err(serde::de::Error::custom("an image's path is empty"));
        }
        Ok(Self::named(path))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checker() -> Pixels {
        let mut img = image::RgbaImage::new(2, 2);
        img.put_pixel(0, 0, image::Rgba([255, 255, 255, 255]));
        img.put_pixel(1, 0, image::Rgba([0, 0, 0, 255]));
        img.put_pixel(0, 1, image::Rgba([255, 0, 0, 0]));
        img.put_pixel(1, 1, image::Rgba([128, 128, 128, 255]));
        Pixels::of(&DynamicImage::ImageRgba8(img)).expect("pixels")
    }

    #[test]
    fn pixel_centres_read_back_and_the_outside_is_transparent() {
        let p = checker();
        let white = p.sample(Vec2::new(0.25, 0.25), false);
        assert!((white.rgb - Vec3::ONE).abs().max_element() < 1e-4 && white.alpha > 0.999);
        let grey = p.sample(Vec2::new(0.75, 0.75), false);
        assert!((grey.gray - 128.0 / 255.0).abs() < 1e-4, "{grey:?}");
        assert!((grey.rgb.x - srgb_to_linear(128.0 / 255.0)).abs() < 1e-4);
        assert!((grey.n() - n_from_blend(128.0 / 255.0)).abs() < 1e-2 * grey.n());
        assert_eq!(p.sample(Vec2::new(0.25, 0.75), false).alpha, 0.0);
        assert_eq!(p.sample(Vec2::new(1.5, 0.25), false).alpha, 0.0);
        let tiled = p.sample(Vec2::new(1.25, 0.25), true);
        assert!(tiled.alpha > 0.999 && tiled.gray > 0.999, "{tiled:?}");
        assert_eq!(p.sample(Vec2::NAN, true).alpha, 0.0);
    }

    #[test]
    fn a_transparent_neighbour_leaves_no_dark_fringe() {
        let p = checker();
        // Between the white and the transparent red pixel: white at half coverage.
        let s = p.sample(Vec2::new(0.25, 0.5), false);
        assert!((s.alpha - 0.5).abs() < 1e-3, "{s:?}");
        assert!((s.rgb - Vec3::ONE).abs().max_element() < 1e-3, "{s:?}");
    }

    #[test]
    fn an_image_not_loaded_is_refused_and_a_missing_file_names_itself() {
        let img = PaintImage::named("nowhere/logo.png");
        assert!(img.pixels().is_err());
        let mut img = img;
        let e = img.load(Path::new("/nonexistent")).expect_err("missing");
        assert!(
            matches!(&e, ModelError::Image { path, .. } if path.ends_with("nowhere/logo.png")),
            "{e}"
        );
    }
}
