//! Brush stamps: grayscale alpha images that shape each dab.

use serde::{Deserialize, Serialize};

/// Largest stamp side in pixels.
pub const MAX_STAMP_SIDE: u32 = 1024;

/// A grayscale alpha stamp that shapes each dab (sampled bilinearly over the dab's square).
///
/// Built only through [`Stamp::new`] (files included), so its size always matches its values
/// and every value is in `[0, 1]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "StampFile")]
pub struct Stamp {
    width: u32,
    height: u32,
    alpha: Vec<f32>,
}

/// A stamp as a file spells it, before [`Stamp::new`] checks it.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct StampFile {
    width: u32,
    height: u32,
    alpha: Vec<f32>,
}

impl TryFrom<StampFile> for Stamp {
    type Error = String;

    fn try_from(file: StampFile) -> Result<Self, String> {
        Self::new(file.width, file.height, file.alpha)
    }
}

impl Stamp {
    /// A stamp of `width x height` pixels (each side 1 to [`MAX_STAMP_SIDE`]) with one alpha
    /// per pixel, row-major, each finite and in `[0, 1]`.
    ///
    /// # Errors
    /// A side out of range, a value count that is not `width * height`, or a value that is
    /// not a number in `[0, 1]`; the message says which.
    pub fn new(width: u32, height: u32, alpha: Vec<f32>) -> Result<Self, String> {
        for (side, v) in [("width", width), ("height", height)] {
            crate::check::int_in_range(&format!("stamp {side}"), v, 1, MAX_STAMP_SIDE)?;
        }
        let expected = u64::from(width) * u64::from(height);
        if alpha.len() as u64 != expected {
            return Err(format!(
                "a {width}x{height} stamp needs {expected} alpha values, got {}",
                alpha.len()
            ));
        }
        if let Some((i, v)) = alpha
            .iter()
            .enumerate()
            .find(|(_, v)| !(v.is_finite() && (0.0..=1.0).contains(*v)))
        {
            return Err(format!(
                "stamp alpha {i} must be a number in [0, 1], got {v}"
            ));
        }
        Ok(Self {
            width,
            height,
            alpha,
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

    /// Alpha per pixel in `[0, 1]`, row-major.
    pub fn alpha(&self) -> &[f32] {
        &self.alpha
    }

    /// A built-in grainy round stamp, `size` pixels square: a soft disc broken by value noise
    /// from a fixed hash, so it is the same on every machine.
    pub fn grain(size: u32) -> Self {
        let size = size.max(2);
        let hash = |x: u32, y: u32| {
            let mut h = x.wrapping_mul(0x9E37_79B9) ^ y.wrapping_mul(0x85EB_CA6B);
            h ^= h >> 15;
            h = h.wrapping_mul(0x2C1B_3C6D);
            h ^= h >> 12;
            (h & 0xffff) as f32 / 65535.0
        };
        let alpha = (0..size * size)
            .map(|i| {
                let (x, y) = (i % size, i / size);
                let c = (size as f32 - 1.0) * 0.5;
                let r = ((x as f32 - c).hypot(y as f32 - c) / (c + 0.5)).min(1.0);
                let disc = 1.0 - r * r;
                disc * (0.35 + 0.65 * hash(x, y))
            })
            .collect();
        Self {
            width: size,
            height: size,
            alpha,
        }
    }

    /// Alpha at dab-local coordinates `u, v` in `[-1, 1]` (0 outside).
    pub fn sample(&self, u: f32, v: f32) -> f32 {
        if !(-1.0..=1.0).contains(&u) || !(-1.0..=1.0).contains(&v) {
            return 0.0;
        }
        let fx = ((u + 1.0) * 0.5 * self.width as f32 - 0.5).max(0.0);
        let fy = ((v + 1.0) * 0.5 * self.height as f32 - 0.5).max(0.0);
        let (x0, y0) = (fx as u32, fy as u32);
        let (x1, y1) = ((x0 + 1).min(self.width - 1), (y0 + 1).min(self.height - 1));
        let (x0, y0) = (x0.min(self.width - 1), y0.min(self.height - 1));
        let (tx, ty) = (fx - x0 as f32, fy - y0 as f32);
        let at = |x: u32, y: u32| self.alpha[(y * self.width + x) as usize];
        let top = at(x0, y0) + (at(x1, y0) - at(x0, y0)) * tx;
        let bottom = at(x0, y1) + (at(x1, y1) - at(x0, y1)) * tx;
        top + (bottom - top) * ty
    }
}
