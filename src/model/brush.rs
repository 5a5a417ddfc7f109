//! Brush settings, and turning pointer input into evenly spaced dabs.
//!
//! Dabs are placed by arc length along the input polyline, every `spacing` pixels, so the
//! result does not depend on how fast or how often input arrives. Spacing is derived from the
//! brush's base radius (not the pressure-modulated one) so that dab positions depend only on
//! the path.

use glam::{Vec2, Vec3};
use serde::{Deserialize, Deserializer, Serialize};

use super::check;

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
            super::check::int_in_range(&format!("stamp {side}"), v, 1, MAX_STAMP_SIDE)?;
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

/// Everything that shapes a dab and a stroke.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
#[expect(
    clippy::struct_excessive_bools,
    reason = "independent switches, as a brush panel shows them"
)]
pub struct BrushSettings {
    /// Radius in texels (2D) at full pressure, `[0.5, 4096]`.
    #[serde(deserialize_with = "check::radius_px")]
    pub radius_px: f32,
    /// Fraction of the radius painted at full strength before the soft falloff, `[0, 1]`.
    #[serde(deserialize_with = "check::hardness")]
    pub hardness: f32,
    /// The most a single stroke can cover, `[0, 1]`.
    #[serde(deserialize_with = "check::opacity")]
    pub opacity: f32,
    /// How much each dab adds towards `opacity`, `[0, 1]`.
    #[serde(deserialize_with = "check::flow")]
    pub flow: f32,
    /// Distance between dabs as a percentage of the radius, `[1, 1000]`.
    #[serde(deserialize_with = "check::spacing_percent")]
    pub spacing_percent: f32,
    /// Pressure scales the radius.
    pub pressure_size: bool,
    /// Pressure scales the flow.
    pub pressure_opacity: bool,
    /// Random offset of each dab as a fraction of the radius, `[0, 1]`.
    #[serde(deserialize_with = "check::jitter")]
    pub jitter: f32,
    /// Lazy-mouse radius in texels: the brush trails the pointer by this much (0: off).
    #[serde(deserialize_with = "check::smoothing_px")]
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
    /// Kernel radius of the blur tool in texels, `[1, 16]`.
    #[serde(deserialize_with = "check::blur_radius_px")]
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
    /// The point a fraction `t` of the way to `other` (computed in `f64`, so a point far
    /// along a long segment is exact).
    #[must_use]
    fn lerp_to(self, other: Self, t: f64) -> Self;
    /// Distance to `other` (texels, or object units on a mesh).
    fn distance_to(self, other: Self) -> f32;
    /// Whether every coordinate is finite.
    fn finite(self) -> bool;
    /// Where a stroke whose first input is not finite starts.
    fn origin() -> Self;
}

impl StrokePos for Vec2 {
    fn lerp_to(self, other: Self, t: f64) -> Self {
        let a = self.as_dvec2();
        (a + (other.as_dvec2() - a) * t).as_vec2()
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
    #[serde(deserialize_with = "check::finite_vec3")]
    pub point: Vec3,
    /// Surface normal there; zero (the default) means "take it from the mesh".
    #[serde(default, deserialize_with = "check::finite_vec3")]
    pub normal: Vec3,
}

impl StrokePos for SurfacePos {
    fn lerp_to(self, other: Self, t: f64) -> Self {
        let normal = self.normal.lerp(other.normal, t as f32);
        let a = self.point.as_dvec3();
        Self {
            point: (a + (other.point.as_dvec3() - a) * t).as_vec3(),
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
#[serde(bound(deserialize = "P: StrokePos + Deserialize<'de>"))]
pub struct StrokePoint<P = Vec2> {
    /// Position: in texel units on the canvas (texel `(i, j)` has its centre at
    /// `(i + 0.5, j + 0.5)`), or a [`SurfacePos`] on a mesh.
    #[serde(deserialize_with = "finite_pos")]
    pub pos: P,
    /// Pen pressure in `[0, 1]` (1 for a mouse).
    #[serde(deserialize_with = "check::pressure")]
    pub pressure: f32,
}

/// A stroke position from a file: every coordinate finite.
fn finite_pos<'de, D, P>(d: D) -> Result<P, D::Error>
where
    D: Deserializer<'de>,
    P: StrokePos + Deserialize<'de>,
{
    let pos = P::deserialize(d)?;
    if pos.finite() {
        Ok(pos)
    } else {
        Err(serde::de::Error::custom(
            "a stroke point must have finite coordinates",
        ))
    }
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

/// Most dabs one stroke places: far more than a day's longest stroke (a 1-texel brush at
/// its closest spacing crosses an 8192^2 map 180 times), and a bound on a scripted stroke
/// to a point a billion texels away.
pub const MAX_STROKE_DABS: u64 = 1 << 22;

/// A stroke reached [`MAX_STROKE_DABS`]; the dabs up to the limit were placed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("the stroke reached the limit of {MAX_STROKE_DABS} dabs; the rest of it was not painted")]
pub struct DabLimit;

/// Places dabs every `spacing` along the polyline of input points.
///
/// Positions along a segment are counted in whole steps from its first dab and computed in
/// `f64`, so a long segment neither drifts nor stalls (an `f32` position stepped by a small
/// spacing stops moving past 2^24 steps).
#[derive(Clone, Debug)]
pub struct Resampler<P = Vec2> {
    spacing: f64,
    last: Option<StrokePoint<P>>,
    /// Arc length since the last dab.
    travelled: f64,
    /// Dabs placed so far.
    dabs: u64,
}

impl<P: StrokePos> Resampler<P> {
    /// A resampler for dabs `spacing` apart (texels, or object units on a mesh).
    pub fn new(spacing: f32) -> Self {
        Self {
            spacing: if spacing > 0.0 && spacing.is_finite() {
                f64::from(spacing)
            } else {
                1e-6
            },
            last: None,
            travelled: 0.0,
            dabs: 0,
        }
    }

    /// Adds an input point and appends the dabs it completes.
    ///
    /// # Errors
    /// [`DabLimit`] when the stroke reaches [`MAX_STROKE_DABS`]: the dabs up to the limit are
    /// appended, and every later point adds none.
    pub fn push(
        &mut self,
        point: StrokePoint<P>,
        out: &mut Vec<DabPoint<P>>,
    ) -> Result<(), DabLimit> {
        if self.dabs >= MAX_STROKE_DABS {
            return Err(DabLimit);
        }
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
            self.dabs += 1;
            self.last = Some(point);
            return Ok(());
        };
        let length = f64::from(last.pos.distance_to(point.pos));
        if length <= 0.0 || !length.is_finite() {
            return Ok(());
        }
        // Distance along this segment to its first dab, then one dab per whole step.
        let first = self.spacing - self.travelled;
        self.last = Some(point);
        if first > length {
            self.travelled += length;
            return Ok(());
        }
        let steps = ((length - first) / self.spacing).floor() as u64 + 1;
        let placed = steps.min(MAX_STROKE_DABS - self.dabs);
        out.reserve(placed as usize);
        for k in 0..placed {
            let t = (first + k as f64 * self.spacing) / length;
            out.push(DabPoint {
                pos: last.pos.lerp_to(point.pos, t),
                pressure: last.pressure + (point.pressure - last.pressure) * t as f32,
            });
        }
        self.dabs += placed;
        self.travelled = length - (first + (steps - 1) as f64 * self.spacing);
        if placed < steps {
            Err(DabLimit)
        } else {
            Ok(())
        }
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
        let moved = brush.lerp_to(pointer, 1.0 - f64::from(self.radius / distance));
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
            )
            .unwrap();
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
        // On a curve (a half circle of radius 50), 90 or 9000 samples: the dabs drift only
        // by the arc length the coarse chords cut off.
        let arc = |n: usize| -> Vec<(f32, f32)> {
            (0..=n)
                .map(|i| {
                    let a = i as f32 / n as f32 * std::f32::consts::PI;
                    (50.0 * a.cos(), 50.0 * a.sin())
                })
                .collect()
        };
        let (coarse, fine) = (dabs(&arc(90), 3.0), dabs(&arc(9000), 3.0));
        assert!(coarse.len().abs_diff(fine.len()) <= 1);
        let drift = coarse
            .iter()
            .zip(&fine)
            .map(|(a, b)| (a.pos - b.pos).length())
            .fold(0.0_f32, f32::max);
        // 90 chords of a 50-texel half circle are 0.006 % shorter than the arc: 0.01 texels.
        assert!(drift < 0.02, "dabs drift {drift} texels apart");
    }

    #[test]
    fn a_segment_a_billion_texels_long_places_every_dab_and_then_stops() {
        // Past 2^24 spacings an f32 position stepped by the spacing stops moving; counted
        // steps in f64 do not, and the dab limit ends the stroke.
        let mut r = Resampler::new(8.0);
        let mut out = Vec::new();
        let at = |x: f32| StrokePoint {
            pos: Vec2::new(x, 0.0),
            pressure: 1.0,
        };
        r.push(at(0.0), &mut out).unwrap();
        r.push(at(1000.0), &mut out).unwrap();
        assert_eq!(out.len(), 126); // 0, 8, ..., 1000
        assert_eq!(r.push(at(1e9), &mut out), Err(DabLimit));
        assert_eq!(out.len() as u64, MAX_STROKE_DABS);
        let steps: Vec<f32> = out.windows(2).map(|w| w[1].pos.x - w[0].pos.x).collect();
        assert!(steps.iter().all(|d| (d - 8.0).abs() < 0.01), "even spacing");
        assert_eq!(r.push(at(2e9), &mut out), Err(DabLimit));
        assert_eq!(out.len() as u64, MAX_STROKE_DABS, "nothing after the limit");
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
        )
        .unwrap();
        r.push(
            StrokePoint {
                pos: Vec2::new(10.0, 0.0),
                pressure: 1.0,
            },
            &mut out,
        )
        .unwrap();
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
