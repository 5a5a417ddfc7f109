//! Brush settings, and turning pointer input into evenly spaced dabs.
//!
//! Dabs are placed by arc length along the input polyline, every `spacing` pixels, so the
//! result does not depend on how fast or how often input arrives. Spacing is derived from the
//! brush's base radius (not the pressure-modulated one) so that dab positions depend only on
//! the path.

use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};

/// How a stroke's target combines with what is under it. Every channel blends in `[0, 1]`
/// space: `k_d`, `k_s` as they are, `n` in log space ([`super::texel::n_to_blend`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub enum BlendMode {
    /// `v (1 - a) + target a` (exactly `target` at full alpha).
    #[default]
    Normal,
    /// `v + target a`.
    Add,
    /// `v - target a`.
    Subtract,
    /// `v (1 + (target - 1) a)`.
    Multiply,
}

impl BlendMode {
    /// All modes, for menus.
    pub const ALL: [Self; 4] = [Self::Normal, Self::Add, Self::Subtract, Self::Multiply];

    /// Applies the mode to one channel value at stroke alpha `a`, clamped into `[0, 1]`.
    #[inline]
    pub fn apply(self, v: f32, target: f32, a: f32) -> f32 {
        let out = match self {
            Self::Normal => v * (1.0 - a) + target * a,
            Self::Add => v + target * a,
            Self::Subtract => v - target * a,
            Self::Multiply => v * (1.0 + (target - 1.0) * a),
        };
        super::texel::unit(out)
    }
}

/// A grayscale alpha stamp that shapes each dab (sampled bilinearly over the dab's square).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Stamp {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Alpha per pixel in `[0, 1]`, row-major.
    pub alpha: Vec<f32>,
}

impl Stamp {
    /// Builds a stamp, validating the size and clamping the values.
    pub fn new(width: u32, height: u32, alpha: Vec<f32>) -> Option<Self> {
        (width > 0 && height > 0 && alpha.len() == (width * height) as usize).then(|| Self {
            width,
            height,
            alpha: alpha.into_iter().map(super::texel::unit).collect(),
        })
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

/// Everything that shapes a dab and a stroke.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
#[allow(clippy::struct_excessive_bools)] // Independent switches, as a brush panel shows them.
pub struct BrushSettings {
    /// Radius in texels (2D) at full pressure.
    pub radius_px: f32,
    /// Fraction of the radius painted at full strength before the soft falloff, `[0, 1]`.
    pub hardness: f32,
    /// The most a single stroke can cover, `[0, 1]`.
    pub opacity: f32,
    /// How much each dab adds towards `opacity`, `[0, 1]`.
    pub flow: f32,
    /// Distance between dabs as a percentage of the radius, `[1, 1000]`.
    pub spacing_percent: f32,
    /// Pressure scales the radius.
    pub pressure_size: bool,
    /// Pressure scales the flow.
    pub pressure_opacity: bool,
    /// Random offset of each dab as a fraction of the radius, `[0, 1]`.
    pub jitter: f32,
    /// Lazy-mouse radius in texels: the brush trails the pointer by this much (0: off).
    pub smoothing_px: f32,
    /// How the target blends.
    pub blend: BlendMode,
    /// Keep `k_d + k_s <= 1` per colour channel while painting.
    pub energy_guard: bool,
    /// Mirror dabs across the vertical centre line of UV space (`u = 0.5`).
    pub mirror_u: bool,
    /// Mirror dabs across the horizontal centre line of UV space (`v = 0.5`).
    pub mirror_v: bool,
    /// On a mesh: mirror dabs across the object's X = 0 plane.
    pub mirror_x: bool,
    /// On a mesh: mirror dabs across the object's Y = 0 plane.
    pub mirror_y: bool,
    /// On a mesh: mirror dabs across the object's Z = 0 plane.
    pub mirror_z: bool,
    /// On a mesh: paint only where the surface faces the brush (not through thin walls to
    /// the far side).
    pub front_faces_only: bool,
    /// Optional alpha stamp.
    pub stamp: Option<Stamp>,
    /// Kernel radius of the blur tool in texels.
    pub blur_radius_px: u32,
}

impl Default for BrushSettings {
    fn default() -> Self {
        Self {
            radius_px: 32.0,
            hardness: 0.5,
            opacity: 1.0,
            flow: 1.0,
            spacing_percent: 25.0,
            pressure_size: true,
            pressure_opacity: false,
            jitter: 0.0,
            smoothing_px: 0.0,
            blend: BlendMode::Normal,
            energy_guard: false,
            mirror_u: false,
            mirror_v: false,
            mirror_x: false,
            mirror_y: false,
            mirror_z: false,
            front_faces_only: true,
            stamp: None,
            blur_radius_px: 2,
        }
    }
}

impl BrushSettings {
    /// The settings with every number forced into its documented range (NaN to the default).
    #[must_use]
    pub fn sanitized(mut self) -> Self {
        let d = Self::default();
        let fix = |v: f32, lo: f32, hi: f32, default: f32| {
            if v.is_nan() { default } else { v.clamp(lo, hi) }
        };
        self.radius_px = fix(self.radius_px, 0.5, 4096.0, d.radius_px);
        self.hardness = fix(self.hardness, 0.0, 1.0, d.hardness);
        self.opacity = fix(self.opacity, 0.0, 1.0, d.opacity);
        self.flow = fix(self.flow, 0.0, 1.0, d.flow);
        self.spacing_percent = fix(self.spacing_percent, 1.0, 1000.0, d.spacing_percent);
        self.jitter = fix(self.jitter, 0.0, 1.0, d.jitter);
        self.smoothing_px = fix(self.smoothing_px, 0.0, 1000.0, d.smoothing_px);
        self.blur_radius_px = self.blur_radius_px.clamp(1, 16);
        self
    }

    /// Distance between dabs in texels.
    pub fn spacing_px(&self) -> f32 {
        (self.radius_px * self.spacing_percent / 100.0).max(0.5)
    }

    /// Dab weight at distance `r` from the centre for radius `radius` (hardness falloff).
    #[inline]
    pub fn falloff(&self, r: f32, radius: f32) -> f32 {
        self.falloff_sq(r * r, radius * radius)
    }

    /// The falloff on squared distances: 1 inside `hardness * radius`, then
    /// `smoothstep((R^2 - d^2) / (R^2 - (hR)^2))` down to 0 at the radius. Defined on `d^2` so
    /// the per-texel cost has no square root and no division.
    #[inline]
    pub fn falloff_sq(&self, d2: f32, r2: f32) -> f32 {
        let inner2 = self.hardness * self.hardness * r2;
        if d2 <= inner2 {
            return if d2 < r2 { 1.0 } else { 0.0 };
        }
        let t = ((r2 - d2) / (r2 - inner2)).max(0.0);
        t * t * (3.0 - 2.0 * t)
    }
}

/// A position strokes move through: texel coordinates ([`Vec2`]) on the UV canvas, or a
/// point on a mesh with its normal ([`SurfacePos`]).
pub trait StrokePos: Copy {
    /// The point a fraction `t` of the way to `other`.
    #[must_use]
    fn lerp_to(self, other: Self, t: f32) -> Self;
    /// Distance to `other` (texels, or object units on a mesh).
    fn distance_to(self, other: Self) -> f32;
    /// Whether every coordinate is finite.
    fn finite(self) -> bool;
    /// Where a stroke whose first input is not finite starts.
    fn origin() -> Self;
}

impl StrokePos for Vec2 {
    fn lerp_to(self, other: Self, t: f32) -> Self {
        self + (other - self) * t
    }
    fn distance_to(self, other: Self) -> f32 {
        self.distance(other)
    }
    fn finite(self) -> bool {
        self.is_finite()
    }
    fn origin() -> Self {
        Self::ZERO
    }
}

/// A point on a mesh surface in object space, with the direction the brush faces.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SurfacePos {
    /// Object-space point (on or very near the surface).
    pub point: Vec3,
    /// Surface normal there; zero (the default) means "take it from the mesh".
    #[serde(default)]
    pub normal: Vec3,
}

impl StrokePos for SurfacePos {
    fn lerp_to(self, other: Self, t: f32) -> Self {
        let normal = self.normal.lerp(other.normal, t);
        Self {
            point: self.point + (other.point - self.point) * t,
            normal: normal.try_normalize().unwrap_or(self.normal),
        }
    }
    fn distance_to(self, other: Self) -> f32 {
        self.point.distance(other.point)
    }
    fn finite(self) -> bool {
        self.point.is_finite() && self.normal.is_finite()
    }
    fn origin() -> Self {
        Self {
            point: Vec3::ZERO,
            normal: Vec3::ZERO,
        }
    }
}

/// One input sample of a stroke.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct StrokePoint<P = Vec2> {
    /// Position: in texel units on the canvas (texel `(i, j)` has its centre at
    /// `(i + 0.5, j + 0.5)`), or a [`SurfacePos`] on a mesh.
    pub pos: P,
    /// Pen pressure in `[0, 1]` (1 for a mouse).
    pub pressure: f32,
}

/// An input sample on a mesh surface.
pub type SurfacePoint = StrokePoint<SurfacePos>;

/// Where one dab goes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DabPoint<P = Vec2> {
    /// Centre.
    pub pos: P,
    /// Interpolated pressure.
    pub pressure: f32,
}

/// Places dabs every `spacing` along the polyline of input points.
#[derive(Clone, Debug)]
pub struct Resampler<P = Vec2> {
    spacing: f32,
    last: Option<StrokePoint<P>>,
    /// Arc length since the last dab.
    travelled: f32,
}

impl<P: StrokePos> Resampler<P> {
    /// A resampler for dabs `spacing` apart (texels, or object units on a mesh).
    pub fn new(spacing: f32) -> Self {
        Self {
            spacing: if spacing > 0.0 { spacing } else { 1e-6 },
            last: None,
            travelled: 0.0,
        }
    }

    /// Adds an input point and appends the dabs it completes.
    pub fn push(&mut self, point: StrokePoint<P>, out: &mut Vec<DabPoint<P>>) {
        let point = StrokePoint {
            pos: if point.pos.finite() {
                point.pos
            } else {
                self.last.map_or_else(P::origin, |l| l.pos)
            },
            pressure: if point.pressure.is_nan() {
                1.0
            } else {
                point.pressure.clamp(0.0, 1.0)
            },
        };
        let Some(last) = self.last else {
            out.push(DabPoint {
                pos: point.pos,
                pressure: point.pressure,
            });
            self.last = Some(point);
            return;
        };
        let length = last.pos.distance_to(point.pos);
        if length <= 0.0 || !length.is_finite() {
            return;
        }
        // Distance along this segment to the next dab.
        let mut at = self.spacing - self.travelled;
        while at <= length {
            let t = at / length;
            out.push(DabPoint {
                pos: last.pos.lerp_to(point.pos, t),
                pressure: last.pressure + (point.pressure - last.pressure) * t,
            });
            at += self.spacing;
        }
        self.travelled = length - (at - self.spacing);
        self.last = Some(point);
    }
}

/// Lazy mouse: the brush follows the pointer on a string of length `radius`.
#[derive(Clone, Debug)]
pub struct Smoother<P = Vec2> {
    radius: f32,
    brush: Option<P>,
}

impl<P: StrokePos> Smoother<P> {
    /// A smoother with the given string length (texels, or object units; 0: pass-through).
    pub fn new(radius: f32) -> Self {
        Self {
            radius: radius.max(0.0),
            brush: None,
        }
    }

    /// The brush position after the pointer moved to `pointer`; `None` while the pointer is
    /// still within the string's reach (the brush does not move).
    pub fn follow(&mut self, pointer: P) -> Option<P> {
        let Some(brush) = self.brush else {
            self.brush = Some(pointer);
            return Some(pointer);
        };
        let distance = brush.distance_to(pointer);
        if distance <= self.radius {
            return (self.radius == 0.0 && distance > 0.0).then_some(pointer);
        }
        let moved = brush.lerp_to(pointer, 1.0 - self.radius / distance);
        self.brush = Some(moved);
        Some(moved)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grain_stamp_is_a_grainy_disc_the_same_everywhere() {
        let a = Stamp::grain(64);
        assert_eq!(a, Stamp::grain(64), "deterministic");
        assert!(a.alpha.iter().all(|v| (0.0..=1.0).contains(v)));
        assert_eq!(a.sample(-1.0, -1.0), 0.0, "nothing in the corners");
        let centre: Vec<f32> = (0..16)
            .map(|i| a.sample(i as f32 * 0.01 - 0.08, 0.0))
            .collect();
        let (lo, hi) = centre
            .iter()
            .fold((f32::MAX, f32::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
        assert!(
            lo > 0.2 && hi - lo > 0.1,
            "grain near the centre: {lo}..{hi}"
        );
    }

    fn dabs(points: &[(f32, f32)], spacing: f32) -> Vec<DabPoint> {
        let mut r = Resampler::new(spacing);
        let mut out = Vec::new();
        for &(x, y) in points {
            r.push(
                StrokePoint {
                    pos: Vec2::new(x, y),
                    pressure: 1.0,
                },
                &mut out,
            );
        }
        out
    }

    #[test]
    fn dab_positions_do_not_depend_on_input_sampling() {
        let coarse = dabs(&[(0.0, 0.0), (100.0, 0.0)], 7.0);
        let fine_points: Vec<(f32, f32)> = (0..=100).map(|i| (i as f32, 0.0)).collect();
        let fine = dabs(&fine_points, 7.0);
        assert_eq!(coarse.len(), fine.len());
        assert_eq!(coarse.len(), 15); // 0, 7, ..., 98
        for (a, b) in coarse.iter().zip(&fine) {
            assert!((a.pos - b.pos).length() < 1e-3);
        }
    }

    #[test]
    fn pressure_is_interpolated() {
        let mut r = Resampler::new(5.0);
        let mut out = Vec::new();
        r.push(
            StrokePoint {
                pos: Vec2::ZERO,
                pressure: 0.0,
            },
            &mut out,
        );
        r.push(
            StrokePoint {
                pos: Vec2::new(10.0, 0.0),
                pressure: 1.0,
            },
            &mut out,
        );
        let p: Vec<f32> = out.iter().map(|d| d.pressure).collect();
        assert_eq!(p, vec![0.0, 0.5, 1.0]);
    }

    #[test]
    fn smoother_trails_the_pointer() {
        let mut s = Smoother::new(10.0);
        assert_eq!(s.follow(Vec2::ZERO), Some(Vec2::ZERO));
        assert_eq!(s.follow(Vec2::new(5.0, 0.0)), None);
        let moved = s.follow(Vec2::new(30.0, 0.0)).unwrap();
        assert!((moved - Vec2::new(20.0, 0.0)).length() < 1e-4, "{moved}");
    }

    #[test]
    fn falloff_and_blend_modes() {
        let b = BrushSettings {
            hardness: 0.5,
            ..BrushSettings::default()
        };
        assert_eq!(b.falloff(0.0, 10.0), 1.0);
        assert_eq!(b.falloff(5.0, 10.0), 1.0);
        // Half-way in d^2 between the core (25) and the rim (100).
        assert!((b.falloff(62.5_f32.sqrt(), 10.0) - 0.5).abs() < 1e-6);
        assert!(b.falloff(9.0, 10.0) < b.falloff(7.0, 10.0));
        assert_eq!(b.falloff(10.0, 10.0), 0.0);
        assert_eq!(BlendMode::Normal.apply(0.2, 0.8, 0.5), 0.5);
        assert_eq!(BlendMode::Add.apply(0.9, 0.5, 1.0), 1.0);
        assert_eq!(BlendMode::Subtract.apply(0.2, 0.5, 1.0), 0.0);
        assert!((BlendMode::Multiply.apply(0.8, 0.5, 1.0) - 0.4).abs() < 1e-6);
    }

    #[test]
    fn sanitize_fixes_hostile_settings() {
        let s = BrushSettings {
            radius_px: f32::NAN,
            opacity: 7.0,
            flow: -1.0,
            ..BrushSettings::default()
        }
        .sanitized();
        assert_eq!(s.radius_px, 32.0);
        assert_eq!(s.opacity, 1.0);
        assert_eq!(s.flow, 0.0);
    }
}
