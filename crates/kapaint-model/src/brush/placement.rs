//! Dab placement: stroke positions and input points, the spacing resampler and the lazy mouse.

use glam::{Vec2, Vec3};
use serde::{Deserialize, Deserializer, Serialize};

use crate::check;

/// A position strokes move through: texel coordinates ([`Vec2`]) on the UV canvas, or a
/// point on a mesh with its normal ([`SurfacePos`]).
pub trait StrokePos: Copy {
    /// The point a fraction `t` of the way to `other` (computed in `f64`, so a point far
    /// along a long segment is exact).
    #[must_use]
    fn lerp_to(self, other: Self, t: f64) -> Self;
    /// Distance to `other` (texels, or object units on a mesh), in `f64`: two finite `f32`
    /// points are never an infinite distance apart (in `f32` the square of a 2e19 step is).
    fn distance_to(self, other: Self) -> f64;
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
    fn distance_to(self, other: Self) -> f64 {
        self.as_dvec2().distance(other.as_dvec2())
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
#[serde(deny_unknown_fields)]
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
    fn distance_to(self, other: Self) -> f64 {
        self.point.as_dvec3().distance(other.point.as_dvec3())
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
#[serde(deny_unknown_fields)]
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
        let length = last.pos.distance_to(point.pos);
        if length <= 0.0 {
            return Ok(());
        }
        // Distance along this segment to its first dab, then one dab per whole step.
        let first = self.spacing - self.travelled;
        self.last = Some(point);
        if first > length {
            self.travelled += length;
            return Ok(());
        }
        // Capped past the limit: a segment of 1e30 texels has more steps than u64 counts.
        let steps = ((length - first) / self.spacing)
            .floor()
            .min(MAX_STROKE_DABS as f64) as u64
            + 1;
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
        let radius = f64::from(self.radius);
        if distance <= radius {
            return (self.radius == 0.0 && distance > 0.0).then_some(pointer);
        }
        let moved = brush.lerp_to(pointer, 1.0 - radius / distance);
        self.brush = Some(moved);
        Some(moved)
    }
}
