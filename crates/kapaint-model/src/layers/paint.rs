//! Painting into a paint layer's tile: what a dab does to a layer texel (its values and its
//! coverage), given the texel before the stroke and the stroke's coverage there. The dab
//! engine's per-stroke coverage (the most a stroke lays, capped by its opacity) carries over:
//! a texel's result depends only on the pre-stroke texel and that coverage, so overlapping dabs
//! in one stroke never build up past the stroke's opacity.
//!
//! - The brush lays the target over the layer by source-over with its mode's blend `B` (W3C
//!   compositing, as Krita paints): coverage `a + a0 (1 - a)`, and value
//!   `t + a0 (a (B(v0, t) - t) + (1 - a) (v0 - t)) / coverage`, which is
//!   `(a (1 - a0) t + a a0 B(v0, t) + (1 - a) a0 v0) / coverage` written so that a transparent
//!   texel takes exactly the target (at coverage `a`, whatever the mode). In normal mode
//!   (`B = t`) the composite is then exactly what painting at `a` on the flattened maps would
//!   give; where the layer is opaque, add, subtract and multiply change its values as they
//!   change the flat maps.
//! - The eraser lowers the coverage: `a0 (1 - a)`.
//!
//! `n` works in log space, as everywhere.

use crate::brush::BlendMode;

/// What a stroke does to a layer texel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LayerStroke {
    /// Lays the target with a blend mode.
    Brush(BlendMode),
    /// Takes coverage away.
    Erase,
}

/// One channel component of a layer texel: its value (in `[0, 1]`, `n` in log space) and the
/// channel's coverage.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LayerValue {
    /// The value where covered.
    pub value: f32,
    /// The coverage.
    pub alpha: f32,
}

impl LayerStroke {
    /// `pre` after a stroke of `target` at stroke coverage `a`.
    #[inline]
    pub fn apply(self, pre: LayerValue, target: f32, a: f32) -> LayerValue {
        let a = a.clamp(0.0, 1.0);
        match self {
            Self::Brush(mode) => {
                let (alpha, w) = Self::cover(pre.alpha, a);
                let over = LayerValue {
                    value: Self::value(mode, (w, a), pre.value, target),
                    alpha: alpha.min(1.0),
                };
                // Chosen without a branch, so loops over texels vectorise.
                if alpha > 0.0 { over } else { pre }
            }
            Self::Erase => LayerValue {
                value: pre.value,
                alpha: pre.alpha * (1.0 - a),
            },
        }
    }

    /// A brush's coverage over pre-stroke coverage `a0` at stroke coverage `a` (in `[0, 1]`),
    /// and the weight `a0 / coverage` of the pre-stroke value in [`Self::value`]: the same
    /// for every component of a channel.
    #[inline]
    pub fn cover(a0: f32, a: f32) -> (f32, f32) {
        let alpha = a + a0 * (1.0 - a);
        (alpha, a0 / alpha)
    }

    /// A brush's value over pre-stroke value `v0` of weight `w` ([`Self::cover`]) at stroke
    /// coverage `a`, towards target `t`.
    #[inline]
    pub fn value(mode: BlendMode, (w, a): (f32, f32), v0: f32, t: f32) -> f32 {
        let change = match mode {
            BlendMode::Normal => (1.0 - a) * (v0 - t),
            mode => a * (mode.mix(v0, t) - t) + (1.0 - a) * (v0 - t),
        };
        (t + w * change).clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layers::{Covered, LayerBlend};

    #[test]
    fn a_normal_stroke_on_an_empty_layer_composites_as_painting_on_the_maps_below() {
        for (below, target, a) in [
            (0.2_f32, 0.9_f32, 0.35_f32),
            (0.8, 0.1, 1.0),
            (0.5, 0.5, 0.0),
        ] {
            let layer = LayerStroke::Brush(BlendMode::Normal).apply(
                LayerValue {
                    value: 0.0,
                    alpha: 0.0,
                },
                target,
                a,
            );
            let composite = Covered::opaque(below)
                .under(
                    Covered {
                        value: layer.value,
                        alpha: layer.alpha,
                    },
                    LayerBlend::Normal,
                )
                .value;
            let direct = BlendMode::Normal.apply(below, target, a);
            assert!((composite - direct).abs() < 1e-6, "{composite} vs {direct}");
        }
    }

    #[test]
    fn strokes_build_coverage_and_the_eraser_takes_it_away() {
        let half = LayerStroke::Brush(BlendMode::Normal);
        let once = half.apply(
            LayerValue {
                value: 0.0,
                alpha: 0.0,
            },
            1.0,
            0.5,
        );
        let twice = half.apply(once, 0.0, 0.5);
        assert!((twice.alpha - 0.75).abs() < 1e-6);
        // Two half strokes, white then black: a third white, two thirds black in value.
        assert!((twice.value - 1.0 / 3.0).abs() < 1e-6, "{twice:?}");
        let erased = LayerStroke::Erase.apply(twice, 0.0, 1.0);
        assert_eq!(erased.alpha, 0.0);
        // Add at full coverage over a texel covered at 3/4: a quarter of the target where
        // the layer was empty, three quarters of the sum where it was not.
        let add = LayerStroke::Brush(BlendMode::Add).apply(twice, 0.25, 1.0);
        assert_eq!(add.alpha, 1.0);
        let expected = 0.25 * 0.25 + 0.75 * (1.0 / 3.0 + 0.25);
        assert!((add.value - expected).abs() < 1e-6, "{add:?}");
    }

    #[test]
    fn every_mode_paints_the_target_exactly_on_a_transparent_texel() {
        let empty = LayerValue {
            value: 0.0,
            alpha: 0.0,
        };
        for mode in BlendMode::ALL {
            for (target, a) in [(0.3_f32, 0.4_f32), (0.8, 1.0), (0.123_456, 0.001)] {
                let out = LayerStroke::Brush(mode).apply(empty, target, a);
                assert_eq!(
                    out,
                    LayerValue {
                        value: target,
                        alpha: a
                    },
                    "{mode:?}"
                );
            }
            assert_eq!(LayerStroke::Brush(mode).apply(empty, 0.5, 0.0), empty);
        }
    }

    #[test]
    fn on_an_opaque_texel_the_modes_change_values_as_on_the_flat_maps() {
        let opaque = LayerValue {
            value: 0.6,
            alpha: 1.0,
        };
        for mode in BlendMode::ALL {
            for (target, a) in [(0.3_f32, 0.4_f32), (0.2, 1.0), (0.9, 0.25)] {
                let layer = LayerStroke::Brush(mode).apply(opaque, target, a);
                let flat = BlendMode::Normal.apply(opaque.value, mode.mix(opaque.value, target), a);
                assert_eq!(layer.alpha, 1.0);
                assert!(
                    (layer.value - flat).abs() < 1e-6,
                    "{mode:?} {layer:?} {flat}"
                );
            }
        }
    }
}
