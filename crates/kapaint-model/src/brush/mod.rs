//! Brush settings, and turning pointer input into evenly spaced dabs.
//!
//! Dabs are placed by arc length along the input polyline, every `spacing` pixels, so the
//! result does not depend on how fast or how often input arrives. Spacing is derived from the
//! brush's base radius (not the pressure-modulated one) so that dab positions depend only on
//! the path.

mod placement;
pub mod preset;
mod stamp;
#[cfg(test)]
mod tests;

pub use placement::{
    DabLimit, DabPoint, MAX_STROKE_DABS, Resampler, Smoother, StrokePoint, StrokePos, SurfacePoint,
    SurfacePos,
};
pub use stamp::{MAX_STAMP_SIDE, Stamp};

use serde::{Deserialize, Serialize};

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

    /// The mode's blend of value `below` with `target` where the stroke fully covers it
    /// (what [`Self::apply`] moves towards), clamped into `[0, 1]`.
    #[inline]
    pub fn mix(self, below: f32, target: f32) -> f32 {
        super::texel::unit(match self {
            Self::Normal => target,
            Self::Add => below + target,
            Self::Subtract => below - target,
            Self::Multiply => below * target,
        })
    }

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

/// Everything that shapes a dab and a stroke.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
#[expect(
    clippy::struct_excessive_bools,
    reason = "independent switches, as a brush panel shows them"
)]
#[serde(deny_unknown_fields)]
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
