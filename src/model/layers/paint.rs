//! Painting into a paint layer's tile: what a dab does to a layer texel (its values and its
//! coverage), given the texel before the stroke and the stroke's coverage there. The dab
//! engine's per-stroke coverage (the most a stroke lays, capped by its opacity) carries over:
//! a texel's result depends only on the pre-stroke texel and that coverage, so overlapping dabs
//! in one stroke never build up past the stroke's opacity.
//!
//! - The brush in normal mode lays the target over the layer by source-over: coverage
//!   `a + a0 (1 - a)`, value `(a t + (1 - a) a0 v0) / coverage`. On a transparent texel that is
//!   the target at coverage `a`, so the composite is exactly what painting at `a` on the
//!   flattened maps would give.
//! - The brush in another mode (add, subtract, multiply) changes the values the layer already
//!   has, in place, and leaves its coverage.
//! - The eraser lowers the coverage: `a0 (1 - a)`.
//!
//! `n` works in log space, as everywhere.

use crate::model::brush::BlendMode;

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
            Self::Brush(BlendMode::Normal) => {
                let alpha = a + pre.alpha * (1.0 - a);
                let over = LayerValue {
                    value: ((a * target + (1.0 - a) * pre.alpha * pre.value) / alpha)
                        .clamp(0.0, 1.0),
                    alpha: alpha.min(1.0),
                };
                // Chosen without a branch, so loops over texels vectorise.
                if alpha > 0.0 { over } else { pre }
            }
            Self::Brush(mode) => LayerValue {
                value: mode.apply(pre.value, target, a),
                alpha: pre.alpha,
            },
            Self::Erase => LayerValue {
                value: pre.value,
                alpha: pre.alpha * (1.0 - a),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::layers::{Covered, LayerBlend};

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
        let add = LayerStroke::Brush(BlendMode::Add).apply(twice, 0.25, 1.0);
        assert_eq!(add.alpha, twice.alpha);
        assert!((add.value - (1.0 / 3.0 + 0.25)).abs() < 1e-6);
    }
}
