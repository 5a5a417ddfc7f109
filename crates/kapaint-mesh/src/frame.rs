//! The unit frame: where a mesh's geometry is computed, whatever its scale.
//!
//! A mesh may use any coordinates f32 holds, but the arithmetic on them does not: a cross
//! product or a squared length of 1e30 is infinite in f32, of 1e-25 zero, and a BVH's surface
//! areas overflow the same way. So the BVHs and the bakes work on positions moved to the
//! bounding box's centre and scaled by a power of two that puts the box inside `[-1, 1]`
//! (in f64, then rounded once to f32): the same numbers for the same shape at any scale, with
//! lengths converted back to object units where they are handed out.

use glam::{DVec3, Vec3};

/// The longest bounding-box diagonal a mesh may have, in object units: distances across the
/// mesh are handed out in f32, so its diagonal must be one (a box from `-1e38` to `1e38` on
/// every axis is longer).
pub const MAX_DIAGONAL: f64 = f32::MAX as f64;

/// A mesh's bounding-box centre and a power-of-two scale that maps the box into `[-1, 1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnitFrame {
    /// The bounding box's centre (object units).
    centre: DVec3,
    /// Local units per object unit: a power of two, so scaling is exact.
    local_per_object: f64,
    /// The bounding box's diagonal in object units.
    diagonal: f64,
}

impl UnitFrame {
    /// The frame of `positions`, or why there is none: a non-finite position, or a bounding
    /// box whose diagonal is longer than [`MAX_DIAGONAL`].
    ///
    /// # Errors
    /// The vertex with a non-finite position, or the diagonal that cannot be measured.
    pub fn checked(positions: &[Vec3]) -> Result<Self, String> {
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(format!("vertex {i} has a non-finite position"));
        }
        let frame = Self::of(positions);
        if frame.diagonal > MAX_DIAGONAL {
            return Err(format!(
                "the mesh is too large to measure: its bounding box's diagonal is {:.3e} units, \
                 more than the {MAX_DIAGONAL:.3e} an f32 holds",
                frame.diagonal
            ));
        }
        Ok(frame)
    }

    /// The frame of the finite `positions` (non-finite ones are left out; none, or all at one
    /// point, give a frame that only moves them). Lengths handed back in object units
    /// saturate at `f32::MAX` when the box is longer than [`MAX_DIAGONAL`].
    pub fn of(positions: &[Vec3]) -> Self {
        let (lo, hi) = positions
            .iter()
            .filter(|p| p.is_finite())
            .map(|p| p.as_dvec3())
            .fold(
                (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
                |(lo, hi), p| (lo.min(p), hi.max(p)),
            );
        if !(lo.is_finite() && hi.is_finite()) {
            return Self {
                centre: DVec3::ZERO,
                local_per_object: 1.0,
                diagonal: 0.0,
            };
        }
        // Sums and differences of f32 values are exact in f64, and a product of them cannot
        // overflow it.
        let centre = (lo + hi) / 2.0;
        let half = ((hi - lo) / 2.0).max_element();
        Self {
            centre,
            local_per_object: power_of_two_at_most(1.0 / half),
            diagonal: (hi - lo).length(),
        }
    }

    /// Whether the mesh's scale is far from 1 (its box more than `2^16` or less than `2^-16`
    /// units across, or away from the origin by as much): where a camera's f32 arithmetic on
    /// object units (framing radius, near and far planes, ray offsets) loses the mesh.
    pub fn is_extreme(&self) -> bool {
        let far = 65536.0;
        !(1.0 / far..=far).contains(&self.local_per_object)
            || self.centre.abs().max_element() * self.local_per_object > far
    }

    /// Local units per object unit (a power of two).
    pub fn local_per_object(&self) -> f64 {
        self.local_per_object
    }

    /// The bounding box's diagonal in object units, saturated at `f32::MAX`.
    pub fn diagonal(&self) -> f32 {
        self.diagonal.min(MAX_DIAGONAL) as f32
    }

    /// The bounding box's diagonal in local units (at most `2 sqrt 3`).
    pub fn local_diagonal(&self) -> f32 {
        (self.diagonal * self.local_per_object) as f32
    }

    /// A point in local coordinates.
    pub fn local_from_object(&self, p: Vec3) -> Vec3 {
        ((p.as_dvec3() - self.centre) * self.local_per_object).as_vec3()
    }

    /// Every point in local coordinates.
    pub fn local_positions(&self, positions: &[Vec3]) -> Vec<Vec3> {
        positions
            .iter()
            .map(|&p| self.local_from_object(p))
            .collect()
    }

    /// An object-space length in local units (infinity stays infinite).
    pub fn local_length(&self, object: f32) -> f32 {
        (f64::from(object) * self.local_per_object) as f32
    }

    /// A local length in object units, saturated at `f32::MAX`.
    pub fn object_length(&self, local: f32) -> f32 {
        let object = f64::from(local) / self.local_per_object;
        if object.is_finite() {
            object.min(MAX_DIAGONAL) as f32
        } else {
            object as f32
        }
    }
}

/// The largest power of two not above `x` (1 for zero, an infinite or a non-finite `x`;
/// clamped to what f64 holds).
fn power_of_two_at_most(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return 1.0;
    }
    // 2^floor(log2 x), corrected for the rounding of log2 near a power of two.
    let mut p = 2.0_f64.powi((x.log2().floor() as i32).clamp(-1000, 1000));
    while p > x {
        p /= 2.0;
    }
    while p * 2.0 <= x {
        p *= 2.0;
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_box_lands_in_the_unit_cube_at_every_scale() {
        for scale in [1e-30_f32, 1e-20, 1.0, 3.0, 1e20, 1e30, 1e38] {
            let positions = [Vec3::new(-1.0, 0.5, 2.0), Vec3::new(1.0, -0.25, 1.0)]
                .map(|p| p * scale + Vec3::splat(scale));
            let frame = UnitFrame::checked(&positions).expect("a frame");
            let local = frame.local_positions(&positions);
            for p in &local {
                assert!(p.abs().max_element() <= 1.0, "{scale}: {p}");
            }
            // The longest side fills more than half the cube: the scale is the best power of
            // two.
            let side = (local[0] - local[1]).abs().max_element();
            assert!(side > 1.0, "{scale}: {side}");
            assert_eq!(
                frame.local_per_object().log2().fract(),
                0.0,
                "a power of two"
            );
            let d = frame.object_length(frame.local_diagonal());
            assert!((d / frame.diagonal() - 1.0).abs() < 1e-6, "{scale}: {d}");
        }
    }

    #[test]
    fn a_box_too_long_to_measure_and_non_finite_positions_are_errors() {
        let e = UnitFrame::checked(&[Vec3::splat(-1e38), Vec3::splat(1e38)]).expect_err("too long");
        assert!(e.contains("too large"), "{e}");
        // Long on one axis only: its diagonal is an f32.
        assert!(
            UnitFrame::checked(&[Vec3::new(-1e38, 0.0, 0.0), Vec3::new(1e38, 1.0, 1.0)]).is_ok()
        );
        let e = UnitFrame::checked(&[Vec3::ZERO, Vec3::NAN]).expect_err("NaN");
        assert_eq!(e, "vertex 1 has a non-finite position");
        // The lenient frame leaves it out.
        assert_eq!(
            UnitFrame::of(&[Vec3::ZERO, Vec3::X, Vec3::NAN]).diagonal(),
            1.0
        );
        assert_eq!(UnitFrame::of(&[]).local_per_object(), 1.0);
        assert_eq!(
            UnitFrame::of(&[Vec3::ONE; 3]).local_from_object(Vec3::ONE),
            Vec3::ZERO
        );
    }
}
