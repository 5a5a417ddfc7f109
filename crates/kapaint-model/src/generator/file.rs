//! A generator as scripts and project files spell it: the fields in the variant (`Ao(black:
//! 0.2, white: 0.9)`), read and checked into a [`Generator`], and written back the same way.

use serde::{Deserialize, Serialize};

use super::{Axis, BlendOp, Generator, Levels, Noise, NoiseKind, Space};

/// A generator as a file or script spells it (fields in the variant: `Ao(black: 0.2, white:
/// 0.9)`), before it is checked.
#[derive(Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) enum GeneratorFile {
    /// No generator (only where one may be absent: `SetMaskGenerator(None)`).
    None,
    Ao {
        black: f32,
        white: f32,
        #[serde(default = "one")]
        gamma: f32,
        #[serde(default)]
        invert: bool,
        #[serde(default, skip_serializing_if = "is_false")]
        relative: bool,
    },
    Curvature {
        black: f32,
        white: f32,
        #[serde(default = "one")]
        gamma: f32,
        #[serde(default)]
        invert: bool,
        #[serde(default, skip_serializing_if = "is_false")]
        relative: bool,
    },
    Thickness {
        black: f32,
        white: f32,
        #[serde(default = "one")]
        gamma: f32,
        #[serde(default)]
        invert: bool,
        #[serde(default, skip_serializing_if = "is_false")]
        relative: bool,
    },
    Noise {
        kind: NoiseKind,
        scale: f32,
        #[serde(default = "one_octave")]
        octaves: u32,
        #[serde(default)]
        seed: u32,
        #[serde(default)]
        space: Space,
    },
    Gradient {
        axis: Axis,
        from: f32,
        to: f32,
    },
    Facing {
        axis: Axis,
        black: f32,
        white: f32,
        #[serde(default = "one")]
        gamma: f32,
        #[serde(default)]
        invert: bool,
    },
    Remap {
        black: f32,
        white: f32,
        #[serde(default = "one")]
        gamma: f32,
        #[serde(default)]
        invert: bool,
        of: Box<Generator>,
    },
    Blend {
        op: BlendOp,
        a: Box<Generator>,
        b: Box<Generator>,
    },
}

impl TryFrom<GeneratorFile> for Generator {
    type Error = String;

    fn try_from(f: GeneratorFile) -> Result<Self, String> {
        use GeneratorFile as F;
        let levels = |black, white, gamma, invert| Levels {
            black,
            white,
            gamma,
            invert,
            relative: false,
        };
        let bake_levels = |black, white, gamma, invert, relative| Levels {
            relative,
            ..levels(black, white, gamma, invert)
        };
        let g = match f {
            F::None => return Err("None is not a generator here".into()),
            F::Ao {
                black,
                white,
                gamma,
                invert,
                relative,
            } => Self::Ao(bake_levels(black, white, gamma, invert, relative)),
            F::Curvature {
                black,
                white,
                gamma,
                invert,
                relative,
            } => Self::Curvature(bake_levels(black, white, gamma, invert, relative)),
            F::Thickness {
                black,
                white,
                gamma,
                invert,
                relative,
            } => Self::Thickness(bake_levels(black, white, gamma, invert, relative)),
            F::Noise {
                kind,
                scale,
                octaves,
                seed,
                space,
            } => Self::Noise(Noise {
                kind,
                scale,
                octaves,
                seed,
                space,
            }),
            F::Gradient { axis, from, to } => Self::Gradient { axis, from, to },
            F::Facing {
                axis,
                black,
                white,
                gamma,
                invert,
            } => Self::Facing {
                axis,
                levels: levels(black, white, gamma, invert),
            },
            F::Remap {
                black,
                white,
                gamma,
                invert,
                of,
            } => Self::Remap {
                levels: levels(black, white, gamma, invert),
                of,
            },
            F::Blend { op, a, b } => Self::Blend { op, a, b },
        };
        g.check()?;
        Ok(g)
    }
}

impl From<Generator> for GeneratorFile {
    fn from(g: Generator) -> Self {
        match g {
            Generator::Ao(l) => Self::Ao {
                black: l.black,
                white: l.white,
                gamma: l.gamma,
                invert: l.invert,
                relative: l.relative,
            },
            Generator::Curvature(l) => Self::Curvature {
                black: l.black,
                white: l.white,
                gamma: l.gamma,
                invert: l.invert,
                relative: l.relative,
            },
            Generator::Thickness(l) => Self::Thickness {
                black: l.black,
                white: l.white,
                gamma: l.gamma,
                invert: l.invert,
                relative: l.relative,
            },
            Generator::Noise(n) => Self::Noise {
                kind: n.kind,
                scale: n.scale,
                octaves: n.octaves,
                seed: n.seed,
                space: n.space,
            },
            Generator::Gradient { axis, from, to } => Self::Gradient { axis, from, to },
            Generator::Facing { axis, levels: l } => Self::Facing {
                axis,
                black: l.black,
                white: l.white,
                gamma: l.gamma,
                invert: l.invert,
            },
            Generator::Remap { levels: l, of } => Self::Remap {
                black: l.black,
                white: l.white,
                gamma: l.gamma,
                invert: l.invert,
                of,
            },
            Generator::Blend { op, a, b } => Self::Blend { op, a, b },
        }
    }
}

/// A straight levels curve, the default.
fn one() -> f32 {
    1.0
}

/// Whether a switch is off (then it is left out of what is written).
#[expect(
    clippy::trivially_copy_pass_by_ref,
    reason = "serde's skip_serializing_if"
)]
fn is_false(b: &bool) -> bool {
    !b
}

/// One octave, the default.
fn one_octave() -> u32 {
    1
}

/// A mask's generator or none, as `SetMaskGenerator(...)` spells it: `None`, or a generator
/// (`Ao(black: 0.2, white: 0.9, invert: false)`), checked as it is read.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "GeneratorFile", into = "GeneratorFile")]
pub struct MaskGenerator(pub Option<Generator>);

impl TryFrom<GeneratorFile> for MaskGenerator {
    type Error = String;

    fn try_from(f: GeneratorFile) -> Result<Self, String> {
        match f {
            GeneratorFile::None => Ok(Self(None)),
            f => Generator::try_from(f).map(|g| Self(Some(g))),
        }
    }
}

impl From<MaskGenerator> for GeneratorFile {
    fn from(g: MaskGenerator) -> Self {
        g.0.map_or(Self::None, Self::from)
    }
}
