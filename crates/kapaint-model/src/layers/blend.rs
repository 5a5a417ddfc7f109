//! How a layer's channel lays over what is below it: the separable blend modes of the W3C
//! compositing specification, on values in `[0, 1]` (`k_d` and `k_s` as linear values, `n` in
//! the log space the brushes use, [`crate::texel::n_to_blend`]), and source-over
//! compositing with alpha, so that a group can be composited on its own first.

use serde::{Deserialize, Serialize};

use crate::texel::Channel;

/// A layer channel's blend mode.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum LayerBlend {
    /// The layer's value.
    #[default]
    Normal,
    /// `below x layer`.
    Multiply,
    /// `below + layer - below x layer`.
    Screen,
    /// Multiply where below is dark, screen where it is light.
    Overlay,
    /// `below + layer`, at most 1.
    Add,
    /// `below - layer`, at least 0.
    Subtract,
    /// The smaller of the two (for `n`: min).
    #[serde(alias = "Min")]
    Darken,
    /// The larger of the two (for `n`: max).
    #[serde(alias = "Max")]
    Lighten,
}

impl LayerBlend {
    /// Every mode, for menus of `k_d` and `k_s`.
    pub const ALL: [Self; 8] = [
        Self::Normal,
        Self::Multiply,
        Self::Screen,
        Self::Overlay,
        Self::Add,
        Self::Subtract,
        Self::Darken,
        Self::Lighten,
    ];

    /// The modes `n` takes (in log space): normal, multiply, add, min and max.
    pub const FOR_N: [Self; 5] = [
        Self::Normal,
        Self::Multiply,
        Self::Add,
        Self::Darken,
        Self::Lighten,
    ];

    /// Whether `channel` takes this mode.
    pub fn allowed_for(self, channel: Channel) -> bool {
        channel != Channel::N || Self::FOR_N.contains(&self)
    }

    /// The mode's name, as menus and the `layers` CSV show it (`n`'s darken and lighten as
    /// min and max).
    pub fn name(self, channel: Channel) -> &'static str {
        match (self, channel) {
            (Self::Darken, Channel::N) => "Min",
            (Self::Lighten, Channel::N) => "Max",
            (Self::Normal, _) => "Normal",
            (Self::Multiply, _) => "Multiply",
            (Self::Screen, _) => "Screen",
            (Self::Overlay, _) => "Overlay",
            (Self::Add, _) => "Add",
            (Self::Subtract, _) => "Subtract",
            (Self::Darken, _) => "Darken",
            (Self::Lighten, _) => "Lighten",
        }
    }

    /// `B(below, layer)` for values in `[0, 1]`.
    #[inline]
    pub fn mix(self, below: f32, layer: f32) -> f32 {
        match self {
            Self::Normal => layer,
            Self::Multiply => below * layer,
            Self::Screen => below + layer - below * layer,
            Self::Overlay => {
                if below <= 0.5 {
                    2.0 * below * layer
                } else {
                    1.0 - 2.0 * (1.0 - below) * (1.0 - layer)
                }
            }
            Self::Add => (below + layer).min(1.0),
            Self::Subtract => (below - layer).max(0.0),
            Self::Darken => below.min(layer),
            Self::Lighten => below.max(layer),
        }
    }
}

/// A channel value with its coverage, as compositing carries it: `value` in `[0, 1]` (not
/// premultiplied), `alpha` in `[0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Covered {
    /// The value where covered.
    pub value: f32,
    /// How much is covered.
    pub alpha: f32,
}

impl Covered {
    /// Nothing (the start of a group).
    pub const CLEAR: Self = Self {
        value: 0.0,
        alpha: 0.0,
    };

    /// A value covering everything.
    pub fn opaque(value: f32) -> Self {
        Self { value, alpha: 1.0 }
    }

    /// `source` (the layer's value at coverage `source.alpha`) laid over `self` with `mode`:
    /// W3C source-over with a separable blend, where the blend acts only where both are there.
    #[inline]
    #[must_use]
    pub fn under(self, source: Self, mode: LayerBlend) -> Self {
        self.under_with(source, |b, l| mode.mix(b, l))
    }

    /// [`Self::under`] with the blend given as a function `B(below, layer)`.
    #[inline]
    #[must_use]
    pub fn under_with(self, source: Self, mix: impl Fn(f32, f32) -> f32) -> Self {
        let (ab, as_) = (self.alpha, source.alpha);
        let blended = (1.0 - ab) * source.value + ab * mix(self.value, source.value);
        let alpha = as_ + ab * (1.0 - as_);
        let premultiplied = as_ * blended + (1.0 - as_) * ab * self.value;
        let over = Self {
            value: (premultiplied / alpha).clamp(0.0, 1.0),
            alpha: alpha.min(1.0),
        };
        // Nothing laid on leaves what is below as it is. Both sides are computed and one
        // chosen, without a branch, so loops over texels vectorise.
        if as_ > 0.0 { over } else { self }
    }

    /// [`Self::under_with`] over an opaque `below`, where the result is opaque too: its value
    /// only, without the division by the coverage (which is one).
    #[inline]
    #[must_use]
    pub fn over_opaque_with(below: f32, source: Self, mix: impl Fn(f32, f32) -> f32) -> f32 {
        let a = source.alpha;
        (a * mix(below, source.value) + (1.0 - a) * below).clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texel::{n_from_blend, n_to_blend};

    #[test]
    fn laying_over_an_opaque_value_agrees_with_the_general_case() {
        let steps = [0.0_f32, 0.1, 0.25, 0.5, 0.7, 0.9, 1.0];
        for mode in LayerBlend::ALL {
            for below in steps {
                for value in steps {
                    for alpha in steps {
                        let source = Covered { value, alpha };
                        let general = Covered::opaque(below).under(source, mode);
                        let opaque =
                            Covered::over_opaque_with(below, source, |b, l| mode.mix(b, l));
                        assert!((general.alpha - 1.0).abs() < 1e-6);
                        assert!(
                            (general.value - opaque).abs() < 1e-6,
                            "{mode:?} {below} {value} {alpha}: {} {opaque}",
                            general.value
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn n_blends_in_log_space() {
        // Half of n = 1000 over n = 10 is about 100 (their geometric middle), not 505.
        let below = Covered::opaque(n_to_blend(10.0));
        let half = Covered {
            value: n_to_blend(1000.0),
            alpha: 0.5,
        };
        let n = n_from_blend(below.under(half, LayerBlend::Normal).value);
        assert!((n - 104.0).abs() < 1.0, "{n}");
        assert!((n - 505.0).abs() > 300.0);
    }

    #[test]
    fn the_modes_do_what_their_names_say() {
        let (b, l) = (0.25_f32, 0.5_f32);
        let at = |m: LayerBlend| Covered::opaque(b).under(Covered::opaque(l), m).value;
        assert_eq!(at(LayerBlend::Normal), 0.5);
        assert_eq!(at(LayerBlend::Multiply), 0.125);
        assert_eq!(at(LayerBlend::Screen), 0.625);
        assert_eq!(at(LayerBlend::Overlay), 0.25);
        assert_eq!(at(LayerBlend::Add), 0.75);
        assert_eq!(at(LayerBlend::Subtract), 0.0);
        assert_eq!(at(LayerBlend::Darken), 0.25);
        assert_eq!(at(LayerBlend::Lighten), 0.5);
        // Half coverage is halfway between below and the blend.
        let half = Covered::opaque(b).under(
            Covered {
                value: l,
                alpha: 0.5,
            },
            LayerBlend::Multiply,
        );
        assert!(
            (half.value - 0.1875).abs() < 1e-6 && half.alpha == 1.0,
            "{half:?}"
        );
        // Over nothing, a layer is itself whatever its mode (a group's first layer).
        let alone = Covered::CLEAR.under(
            Covered {
                value: l,
                alpha: 0.4,
            },
            LayerBlend::Multiply,
        );
        assert!((alone.value - l).abs() < 1e-6 && (alone.alpha - 0.4).abs() < 1e-6);
        assert!(!LayerBlend::Screen.allowed_for(Channel::N));
        assert!(LayerBlend::Darken.allowed_for(Channel::N));
        assert_eq!(LayerBlend::Darken.name(Channel::N), "Min");
    }
}
