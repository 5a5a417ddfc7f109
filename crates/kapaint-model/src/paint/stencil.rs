//! A stencil: an image the brush, the eraser and clone paint through. Its luminance times its
//! alpha caps what a stroke can cover at each texel (the brush's opacity times the stencil's
//! weight there), so a mid-grey stencil lets half the paint through however many dabs pass.
//!
//! On the canvas the stencil lies in texel space: its centre and width in texels, the image's
//! pixel `(0, 0)` at its top-left corner and rows growing downward as the canvas's texel rows
//! do, turned by its rotation (degrees, clockwise on the canvas, whose rows grow downward).
//!
//! In the 3D viewport the stencil lies on the screen instead: with a [`ScreenView`] its centre
//! and width are in that view's pixels (`(0, 0)` the top-left corner, rows growing downward),
//! and a stroke on the mesh reads the weight where each texel's surface point projects through
//! the view.

use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3, Vec4};
use serde::Deserialize;

use crate::paint_image::Pixels;

/// A stencil placed on the canvas.
#[derive(Clone, Debug, PartialEq)]
pub struct Stencil {
    /// The image.
    pub image: Arc<Pixels>,
    /// Its centre, in texels.
    pub center: Vec2,
    /// Its width, in texels (its height follows the image's aspect).
    pub size: f32,
    /// Its rotation, in degrees.
    pub rotation: f32,
    /// How much it holds the paint back: 1 paints only through its light parts, 0 ignores it.
    pub opacity: f32,
    /// Whether the image repeats beyond its edges (else nothing paints there).
    pub tiled: bool,
    /// The view it lies in, for a stencil on the screen (none: on the canvas).
    pub view: Option<ScreenView>,
    /// The image's luminance times alpha per pixel, what a dab reads.
    plane: Arc<[f32]>,
}

impl Stencil {
    /// A stencil of `image` placed on the canvas.
    pub fn new(image: Arc<Pixels>, center: Vec2, size: f32, rotation: f32) -> Self {
        let plane = image.covered_gray().into();
        Self {
            image,
            center,
            size,
            rotation,
            opacity: 1.0,
            tiled: false,
            view: None,
            plane,
        }
    }

    /// This stencil moved, scaled or turned (its image's weights kept, not read again).
    #[must_use]
    pub fn placed(&self, center: Vec2, size: f32, rotation: f32) -> Self {
        Self {
            center,
            size,
            rotation,
            ..self.clone()
        }
    }

    /// Checks a stencil's numbers.
    ///
    /// # Errors
    /// A size that is not positive and finite, a centre or rotation that is not finite, an
    /// opacity outside `[0, 1]`.
    pub fn check(&self) -> Result<(), String> {
        if !(self.size.is_finite() && self.size > 0.0) {
            return Err(format!(
                "a stencil's size must be a positive number of texels, not {}",
                self.size
            ));
        }
        if !self.center.is_finite() || !self.rotation.is_finite() {
            return Err("a stencil's centre and rotation must be finite numbers".into());
        }
        if let Some(view) = &self.view {
            view.check()?;
        }
        if !(0.0..=1.0).contains(&self.opacity) {
            return Err(format!(
                "a stencil's opacity must be in [0, 1], not {}",
                self.opacity
            ));
        }
        Ok(())
    }

    /// The image's coordinates (`(0, 0)` top-left, `(1, 1)` bottom-right) at canvas point `p`
    /// (texels).
    pub fn uv(&self, p: Vec2) -> Vec2 {
        let (sin, cos) = (-self.rotation.to_radians()).sin_cos();
        let d = p - self.center;
        let local = Vec2::new(d.x * cos - d.y * sin, d.x * sin + d.y * cos);
        local / Vec2::new(self.size, self.size * self.image.aspect()) + 0.5
    }

    /// The weight the stencil gives a texel whose centre is at `p`.
    pub fn weight(&self, p: Vec2) -> f32 {
        let mut w = [0.0];
        self.weights(p, &mut w);
        w[0]
    }

    /// The weights of texels along a row from the one centred at `p` (one texel apart).
    pub fn weights(&self, p: Vec2, out: &mut [f32]) {
        let (sin, cos) = (-self.rotation.to_radians()).sin_cos();
        let scale = Vec2::new(self.size, self.size * self.image.aspect()).recip();
        let (w, h) = (
            i64::from(self.image.width()),
            i64::from(self.image.height()),
        );
        let size = Vec2::new(w as f32, h as f32);
        // Pixel coordinates of the first texel and the step to the next, in the image.
        let start = self.uv(p) * size - 0.5;
        let step = Vec2::new(cos, sin) * scale * size;
        let hold = 1.0 - self.opacity;
        let (wf, hf) = (w as f32, h as f32);
        let (iw, ih) = (1.0 / wf, 1.0 / hf);
        let (w, h) = (w as usize, h as usize);
        for (k, o) in out.iter_mut().enumerate() {
            let mut q = start + step * k as f32;
            if self.tiled {
                // Into [0, size): the four taps then wrap with a compare, not a division.
                q = Vec2::new(q.x - floor(q.x * iw) * wf, q.y - floor(q.y * ih) * hf);
            }
            let (xf, yf) = (floor(q.x), floor(q.y));
            let (fx, fy) = (q.x - xf, q.y - yf);
            // Most texels: all four taps on the image, read straight (no wrapping).
            if xf >= 0.0 && yf >= 0.0 && xf + 1.0 < wf && yf + 1.0 < hf {
                let i = yf as usize * w + xf as usize;
                let plane = &self.plane[i..i + w + 2];
                let top = plane[0] * (1.0 - fx) + plane[1] * fx;
                let bottom = plane[w] * (1.0 - fx) + plane[w + 1] * fx;
                *o = hold + self.opacity * (top * (1.0 - fy) + bottom * fy);
                continue;
            }
            let near = xf >= -1.0 && yf >= -1.0 && xf < wf && yf < hf;
            let v = if self.tiled || near {
                let (x0, y0) = (xf as i64, yf as i64);
                // Each tap's index, or none where it is off the image (untiled).
                let wrap = |v: i64, n: usize| -> Option<usize> {
                    if v >= 0 && (v as usize) < n {
                        Some(v as usize)
                    } else if self.tiled {
                        Some(v.rem_euclid(n as i64) as usize)
                    } else {
                        None
                    }
                };
                let (xa, xb, ya, yb) = (wrap(x0, w), wrap(x0 + 1, w), wrap(y0, h), wrap(y0 + 1, h));
                let at = |x: Option<usize>, y: Option<usize>| match (x, y) {
                    (Some(x), Some(y)) => self.plane[y * w + x],
                    _ => 0.0,
                };
                let top = at(xa, ya) * (1.0 - fx) + at(xb, ya) * fx;
                let bottom = at(xa, yb) * (1.0 - fx) + at(xb, yb) * fx;
                top * (1.0 - fy) + bottom * fy
            } else {
                0.0
            };
            *o = hold + self.opacity * v;
        }
    }
}

/// `v` rounded down, without a call: the baseline x86-64 target has no rounding instruction,
/// so `f32::floor` there is a libm call, four of them a texel in a dab's weights. Exact where
/// `|v| < 2^23`; larger floats are whole already.
#[inline(always)]
#[expect(
    clippy::inline_always,
    reason = "a few instructions in a per-texel loop, which a call would cost more than"
)]
fn floor(v: f32) -> f32 {
    if v.abs() < 8_388_608.0 {
        let t = v as i32 as f32;
        t - f32::from(u8::from(t > v))
    } else {
        v
    }
}

/// A view a stencil on the screen lies in: a perspective camera at `eye` looking at `target`
/// with `up` up, `fov` degrees of vertical field, onto a picture `size` pixels wide and high
/// (as the editor's viewport shows the mesh).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScreenView {
    /// Where the camera is (object space).
    pub eye: Vec3,
    /// The point it looks at.
    pub target: Vec3,
    /// Up on the screen (made perpendicular to the view); +Y by default.
    #[serde(default = "up_y")]
    pub up: Vec3,
    /// The vertical field of view, in degrees.
    pub fov: f32,
    /// The picture's width and height, in pixels.
    pub size: Vec2,
}

fn up_y() -> Vec3 {
    Vec3::Y
}

impl ScreenView {
    /// Checks a view's numbers.
    ///
    /// # Errors
    /// A non-finite number, the eye at the target, `up` along the view, a field of view
    /// outside (0, 180) degrees, a picture with no area.
    pub fn check(&self) -> Result<(), String> {
        let finite = self.eye.is_finite()
            && self.target.is_finite()
            && self.up.is_finite()
            && self.fov.is_finite()
            && self.size.is_finite();
        if !finite {
            return Err("a stencil's view must be made of finite numbers".into());
        }
        let forward = self.target - self.eye;
        if forward.length() <= 1e-6 * (1.0 + self.eye.length()) {
            return Err("a stencil's view needs its eye away from its target".into());
        }
        if forward
            .normalize()
            .cross(self.up.normalize_or_zero())
            .length()
            < 1e-4
        {
            return Err(
                "a stencil's view needs an up direction across the view, not along it".into(),
            );
        }
        if !(self.fov > 0.0 && self.fov < 180.0) {
            return Err(format!(
                "a stencil's view needs a field of view between 0 and 180 degrees, not {}",
                self.fov
            ));
        }
        if !(self.size.x >= 1.0 && self.size.y >= 1.0) {
            return Err(format!(
                "a stencil's view needs a picture at least 1 x 1 pixel, not {} x {}",
                self.size.x, self.size.y
            ));
        }
        Ok(())
    }

    /// The matrix from object space to clip space (its depth is of no use here).
    pub fn to_clip(&self) -> Mat4 {
        let aspect = self.size.x / self.size.y;
        glam::camera::rh::proj::directx::perspective(self.fov.to_radians(), aspect, 1e-3, 1e3)
            * glam::camera::rh::view::look_at_mat4(self.eye, self.target, self.up)
    }

    /// Where `p` lands in the picture, in pixels, through `to_clip` (this view's
    /// [`Self::to_clip`]); none behind the eye.
    #[inline]
    pub fn to_screen(&self, to_clip: &Mat4, p: Vec3) -> Option<Vec2> {
        let c: Vec4 = *to_clip * p.extend(1.0);
        if c.w <= 1e-6 {
            return None;
        }
        let ndc = Vec2::new(c.x, c.y) / c.w;
        Some(Vec2::new(ndc.x + 1.0, 1.0 - ndc.y) * 0.5 * self.size)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 7x5 stencil of distinct greys (luminance only, alpha 1).
    fn stencil(tiled: bool) -> Stencil {
        let (w, h) = (7_u32, 5_u32);
        let grey: Vec<u16> = (0..w * h).map(|i| (i * 1871 % 65_536) as u16).collect();
        let rgba: Vec<u16> = grey.iter().flat_map(|g| [*g, *g, *g, u16::MAX]).collect();
        let gray: Vec<u16> = grey.iter().flat_map(|g| [*g, 0]).collect();
        let pixels = Pixels::from_raw(w, h, &rgba, &gray).expect("pixels");
        let mut s = Stencil::new(Arc::new(pixels), Vec2::new(20.0, 11.0), 30.0, 23.0);
        s.tiled = tiled;
        s.opacity = 0.8;
        s
    }

    /// The bilinear weight at image pixel coordinates `q`, tap by tap: wrapped where tiled,
    /// zero off the image otherwise.
    fn reference(s: &Stencil, q: Vec2) -> f32 {
        let (w, h) = (i64::from(s.image.width()), i64::from(s.image.height()));
        let tap = |x: i64, y: i64| -> f32 {
            let (x, y) = if s.tiled {
                (x.rem_euclid(w), y.rem_euclid(h))
            } else if x < 0 || y < 0 || x >= w || y >= h {
                return 0.0;
            } else {
                (x, y)
            };
            s.plane[(y * w + x) as usize]
        };
        let (x0, y0) = (q.x.floor(), q.y.floor());
        let (fx, fy) = (q.x - x0, q.y - y0);
        let (x, y) = (x0 as i64, y0 as i64);
        let top = tap(x, y) * (1.0 - fx) + tap(x + 1, y) * fx;
        let bottom = tap(x, y + 1) * (1.0 - fx) + tap(x + 1, y + 1) * fx;
        1.0 - s.opacity + s.opacity * (top * (1.0 - fy) + bottom * fy)
    }

    #[test]
    fn floor_without_a_call_is_floor() {
        for v in [
            0.0_f32,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            2.999,
            -2.001,
            1e6 + 0.5,
            -1e6 - 0.5,
            8_388_607.5,
            -8_388_607.5,
            3e9,
            -3e9,
            1e30,
        ] {
            assert_eq!(floor(v), v.floor(), "{v}");
        }
        assert!(floor(f32::NAN).is_nan());
    }

    #[test]
    fn a_row_of_weights_is_the_bilinear_image_inside_at_and_past_its_edges() {
        for tiled in [false, true] {
            let s = stencil(tiled);
            let size = Vec2::new(s.image.width() as f32, s.image.height() as f32);
            for y in 0..24 {
                let mut row = [0.0_f32; 48];
                s.weights(Vec2::new(0.5, y as f32 + 0.5), &mut row);
                for (x, got) in row.iter().enumerate() {
                    let mut q = s.uv(Vec2::new(x as f32 + 0.5, y as f32 + 0.5)) * size - 0.5;
                    if tiled {
                        q = Vec2::new(q.x.rem_euclid(size.x), q.y.rem_euclid(size.y));
                    }
                    let want = reference(&s, q);
                    assert!(
                        (got - want).abs() < 2e-4,
                        "tiled {tiled}, ({x}, {y}): {got} vs {want}"
                    );
                }
            }
        }
    }
}
