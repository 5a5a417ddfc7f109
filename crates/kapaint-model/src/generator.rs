//! Generators: a mask value per texel made from parameters, not pixels. A bake of the mesh
//! through levels, noise (Perlin or simplex fBm, Worley) in UV, object or triplanar space, a
//! gradient along an object-space axis, or a blend of two generators. Every parameter is
//! checked where it comes in (a script, a project file), so no generator that reaches the
//! model can make a NaN or run away.
//!
//! In scripts: `Ao(black: 0.2, white: 0.9, invert: false)`, `Curvature(black: 0.5, white:
//! 0.7, invert: false)`, `Noise(kind: Perlin, scale: 8.0, octaves: 4, seed: 1, space:
//! Object)`, `Gradient(axis: Y, from: 0.0, to: 1.0)`, `Blend(op: Multiply, a: ..., b: ...)`.

use fastnoise_lite::{CellularReturnType, FastNoiseLite, FractalType, NoiseType};
use glam::Vec3;
use kapaint_mesh::bakes::{BakeMap, Baked};
use serde::{Deserialize, Serialize};

/// Deepest nesting of blends.
pub const MAX_DEPTH: usize = 4;
/// Largest noise scale (features per unit of its space).
pub const MAX_SCALE: f32 = 4096.0;
/// Most noise octaves.
pub const MAX_OCTAVES: u32 = 8;

/// A mask value per texel, in `[0, 1]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "GeneratorFile", into = "GeneratorFile")]
pub enum Generator {
    /// The AO bake through levels.
    Ao(Levels),
    /// The curvature bake through levels.
    Curvature(Levels),
    /// The thickness bake through levels.
    Thickness(Levels),
    /// Noise.
    Noise(Noise),
    /// A ramp along an object-space axis (0 to 1 over the mesh's bounding box).
    Gradient {
        /// The axis.
        axis: Axis,
        /// Where along it (a fraction of the box) the ramp starts at 0.
        from: f32,
        /// Where it reaches 1.
        to: f32,
    },
    /// Two generators combined.
    Blend {
        /// How.
        op: BlendOp,
        /// The first.
        a: Box<Generator>,
        /// The second.
        b: Box<Generator>,
    },
}

/// A bake's value mapped: `black` and below to 0, `white` and above to 1, a power curve
/// between, optionally inverted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Levels {
    /// The value that becomes 0.
    pub black: f32,
    /// The value that becomes 1.
    pub white: f32,
    /// The curve between (1: straight).
    pub gamma: f32,
    /// 1 minus the result.
    pub invert: bool,
}

fn one() -> f32 {
    1.0
}

/// Noise parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Noise {
    /// Which noise.
    pub kind: NoiseKind,
    /// Features per unit of its space (UV: per map; object: per bounding-box diagonal).
    pub scale: f32,
    /// fBm octaves, 1 to 8 (each twice the frequency, half the weight).
    pub octaves: u32,
    /// Seed.
    pub seed: u32,
    /// Where it is laid.
    pub space: Space,
}

fn one_octave() -> u32 {
    1
}

/// Which noise.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum NoiseKind {
    /// Perlin gradient noise.
    Perlin,
    /// OpenSimplex2 noise.
    Simplex,
    /// Worley (cellular) distance noise.
    Worley,
}

/// Where noise is laid.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Space {
    /// On the UV map (seams show).
    Uv,
    /// In object space (3D noise at the surface point: no seams).
    #[default]
    Object,
    /// Three planar projections blended by the normal.
    Triplanar,
}

/// An object-space axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Axis {
    /// X.
    X,
    /// Y (up).
    Y,
    /// Z.
    Z,
}

/// How two generators combine.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum BlendOp {
    /// `a * b`.
    Multiply,
    /// The smaller.
    Min,
    /// The larger.
    Max,
    /// `min(a + b, 1)`.
    Add,
}

/// A generator as a file or script spells it (fields in the variant: `Ao(black: 0.2, white:
/// 0.9)`), before it is checked.
#[derive(Clone, Serialize, Deserialize)]
enum GeneratorFile {
    Ao {
        black: f32,
        white: f32,
        #[serde(default = "one")]
        gamma: f32,
        #[serde(default)]
        invert: bool,
    },
    Curvature {
        black: f32,
        white: f32,
        #[serde(default = "one")]
        gamma: f32,
        #[serde(default)]
        invert: bool,
    },
    Thickness {
        black: f32,
        white: f32,
        #[serde(default = "one")]
        gamma: f32,
        #[serde(default)]
        invert: bool,
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
        };
        let g = match f {
            F::Ao {
                black,
                white,
                gamma,
                invert,
            } => Self::Ao(levels(black, white, gamma, invert)),
            F::Curvature {
                black,
                white,
                gamma,
                invert,
            } => Self::Curvature(levels(black, white, gamma, invert)),
            F::Thickness {
                black,
                white,
                gamma,
                invert,
            } => Self::Thickness(levels(black, white, gamma, invert)),
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
            },
            Generator::Curvature(l) => Self::Curvature {
                black: l.black,
                white: l.white,
                gamma: l.gamma,
                invert: l.invert,
            },
            Generator::Thickness(l) => Self::Thickness {
                black: l.black,
                white: l.white,
                gamma: l.gamma,
                invert: l.invert,
            },
            Generator::Noise(n) => Self::Noise {
                kind: n.kind,
                scale: n.scale,
                octaves: n.octaves,
                seed: n.seed,
                space: n.space,
            },
            Generator::Gradient { axis, from, to } => Self::Gradient { axis, from, to },
            Generator::Blend { op, a, b } => Self::Blend { op, a, b },
        }
    }
}

impl Levels {
    fn check(self) -> Result<(), String> {
        let finite = [self.black, self.white, self.gamma]
            .iter()
            .all(|v| v.is_finite());
        if !finite {
            return Err("levels must be finite numbers".into());
        }
        if !(0.0..=1.0).contains(&self.black)
            || !(0.0..=1.0).contains(&self.white)
            || self.black >= self.white
        {
            return Err(format!(
                "levels need 0 <= black < white <= 1 (black {}, white {})",
                self.black, self.white
            ));
        }
        if !(0.05..=20.0).contains(&self.gamma) {
            return Err(format!("gamma {} is outside 0.05 to 20", self.gamma));
        }
        Ok(())
    }

    /// `v` through the levels.
    pub fn apply(self, v: f32) -> f32 {
        let t = ((v - self.black) / (self.white - self.black)).clamp(0.0, 1.0);
        let t = t.powf(1.0 / self.gamma);
        if self.invert { 1.0 - t } else { t }
    }
}

impl Generator {
    /// Checks every parameter: finite, in range, blends at most [`MAX_DEPTH`] deep.
    ///
    /// # Errors
    /// What is wrong, in one line.
    pub fn check(&self) -> Result<(), String> {
        self.check_at(0)
    }

    fn check_at(&self, depth: usize) -> Result<(), String> {
        match self {
            Self::Ao(l) | Self::Curvature(l) | Self::Thickness(l) => l.check(),
            Self::Noise(n) => {
                if !(n.scale.is_finite() && n.scale > 0.0 && n.scale <= MAX_SCALE) {
                    return Err(format!(
                        "noise scale {} is outside (0, {MAX_SCALE}]",
                        n.scale
                    ));
                }
                if !(1..=MAX_OCTAVES).contains(&n.octaves) {
                    return Err(format!(
                        "{} octaves is outside 1 to {MAX_OCTAVES}",
                        n.octaves
                    ));
                }
                Ok(())
            }
            Self::Gradient { from, to, .. } => {
                if !(from.is_finite() && to.is_finite()) || from == to {
                    return Err(format!(
                        "a gradient needs two different finite ends (from {from}, to {to})"
                    ));
                }
                Ok(())
            }
            Self::Blend { a, b, .. } => {
                if depth >= MAX_DEPTH {
                    return Err(format!("blends nest more than {MAX_DEPTH} deep"));
                }
                a.check_at(depth + 1)?;
                b.check_at(depth + 1)
            }
        }
    }

    /// The bakes it reads.
    pub fn bakes_needed(&self) -> Vec<BakeMap> {
        let mut out = Vec::new();
        self.collect_bakes(&mut out);
        out
    }

    fn collect_bakes(&self, out: &mut Vec<BakeMap>) {
        let map = match self {
            Self::Ao(_) => Some(BakeMap::Ao),
            Self::Curvature(_) => Some(BakeMap::Curvature),
            Self::Thickness(_) => Some(BakeMap::Thickness),
            Self::Noise(_) | Self::Gradient { .. } => None,
            Self::Blend { a, b, .. } => {
                a.collect_bakes(out);
                b.collect_bakes(out);
                None
            }
        };
        if let Some(m) = map
            && !out.contains(&m)
        {
            out.push(m);
        }
    }
}

/// Where a texel is: what generators read besides their parameters.
#[derive(Clone, Copy, Debug)]
pub struct Texel {
    /// Its UV (`v` up), `[0, 1]`.
    pub uv: glam::Vec2,
    /// Its object-space position, normalised to the bounding box (`[0, 1]` per axis).
    pub position: Vec3,
    /// Its object-space unit normal.
    pub normal: Vec3,
    /// Its index in the map (row-major), for the bakes.
    pub index: usize,
}

/// A generator made ready to evaluate: noise set up once, bakes found.
pub struct Evaluator<'a> {
    node: Node<'a>,
}

enum Node<'a> {
    Bake(Levels, Option<&'a Baked>),
    Noise(Box<FastNoiseLite>, Noise),
    Gradient(Axis, f32, f32),
    Blend(BlendOp, Box<Node<'a>>, Box<Node<'a>>),
}

impl<'a> Evaluator<'a> {
    /// Prepares `generator` with the document's `bakes` (a missing bake reads as 0.5 through
    /// its levels, until it is baked).
    pub fn new(generator: &Generator, bakes: &'a [std::sync::Arc<Baked>]) -> Self {
        Self {
            node: Node::of(generator, bakes),
        }
    }

    /// The value at `texel`, in `[0, 1]`.
    pub fn value(&self, texel: &Texel) -> f32 {
        self.node.value(texel).clamp(0.0, 1.0)
    }
}

impl<'a> Node<'a> {
    fn of(g: &Generator, bakes: &'a [std::sync::Arc<Baked>]) -> Self {
        let bake = |map| bakes.iter().find(|b| b.map == map).map(AsRef::as_ref);
        match g {
            Generator::Ao(l) => Self::Bake(*l, bake(BakeMap::Ao)),
            Generator::Curvature(l) => Self::Bake(*l, bake(BakeMap::Curvature)),
            Generator::Thickness(l) => Self::Bake(*l, bake(BakeMap::Thickness)),
            Generator::Noise(n) => {
                let mut noise = FastNoiseLite::with_seed(n.seed as i32);
                noise.set_noise_type(Some(match n.kind {
                    NoiseKind::Perlin => NoiseType::Perlin,
                    NoiseKind::Simplex => NoiseType::OpenSimplex2,
                    NoiseKind::Worley => NoiseType::Cellular,
                }));
                if n.kind == NoiseKind::Worley {
                    noise.set_cellular_return_type(Some(CellularReturnType::Distance));
                }
                noise.set_frequency(Some(n.scale));
                if n.octaves > 1 {
                    noise.set_fractal_type(Some(FractalType::FBm));
                    noise.set_fractal_octaves(Some(n.octaves as i32));
                }
                Self::Noise(Box::new(noise), *n)
            }
            Generator::Gradient { axis, from, to } => Self::Gradient(*axis, *from, *to),
            Generator::Blend { op, a, b } => Self::Blend(
                *op,
                Box::new(Self::of(a, bakes)),
                Box::new(Self::of(b, bakes)),
            ),
        }
    }

    fn value(&self, t: &Texel) -> f32 {
        match self {
            Self::Bake(l, bake) => {
                let v = bake
                    .filter(|b| t.index < b.data.len() / b.map.channels())
                    .map_or(0.5, |b| b.value(t.index, 0));
                l.apply(v)
            }
            Self::Noise(noise, n) => {
                // FastNoiseLite returns about [-1, 1].
                let raw = match n.space {
                    Space::Uv => noise.get_noise_2d(t.uv.x, t.uv.y),
                    Space::Object => {
                        let p = t.position;
                        noise.get_noise_3d(p.x, p.y, p.z)
                    }
                    Space::Triplanar => {
                        let p = t.position;
                        let w = t.normal.abs().powf(4.0);
                        let w = w / w.element_sum().max(1e-6);
                        w.x * noise.get_noise_2d(p.y, p.z)
                            + w.y * noise.get_noise_2d(p.z, p.x)
                            + w.z * noise.get_noise_2d(p.x, p.y)
                    }
                };
                0.5 + 0.5 * raw
            }
            Self::Gradient(axis, from, to) => {
                let v = match axis {
                    Axis::X => t.position.x,
                    Axis::Y => t.position.y,
                    Axis::Z => t.position.z,
                };
                (v - from) / (to - from)
            }
            Self::Blend(op, a, b) => {
                let (a, b) = (a.value(t).clamp(0.0, 1.0), b.value(t).clamp(0.0, 1.0));
                match op {
                    BlendOp::Multiply => a * b,
                    BlendOp::Min => a.min(b),
                    BlendOp::Max => a.max(b),
                    BlendOp::Add => (a + b).min(1.0),
                }
            }
        }
        .clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Generator, String> {
        ron::from_str(text).map_err(|e| e.to_string())
    }

    fn texel(p: Vec3) -> Texel {
        Texel {
            uv: glam::Vec2::new(p.x, p.z),
            position: p,
            normal: Vec3::Y,
            index: 0,
        }
    }

    #[test]
    fn the_script_spellings_read_and_bad_values_are_refused() {
        let ao = parse("Ao(black: 0.2, white: 0.9, invert: false)").expect("ao");
        assert_eq!(ao.bakes_needed(), vec![BakeMap::Ao]);
        parse("Curvature(black: 0.5, white: 0.7, invert: true)").expect("curvature");
        parse("Noise(kind: Perlin, scale: 8.0, octaves: 4, seed: 1, space: Object)")
            .expect("noise");
        parse("Noise(kind: Worley, scale: 3.0)").expect("defaults");
        let blend = parse(
            "Blend(op: Multiply, a: Curvature(black: 0.5, white: 0.7), \
             b: Noise(kind: Simplex, scale: 4.0, space: Triplanar))",
        )
        .expect("blend");
        assert_eq!(blend.bakes_needed(), vec![BakeMap::Curvature]);
        for bad in [
            "Ao(black: NaN, white: 0.9)",
            "Ao(black: 0.9, white: 0.2)",
            "Ao(black: 0.1, white: 1.5)",
            "Ao(black: 0.1, white: 0.5, gamma: 0.0)",
            "Noise(kind: Perlin, scale: inf)",
            "Noise(kind: Perlin, scale: -1.0)",
            "Noise(kind: Perlin, scale: 2.0, octaves: 0)",
            "Noise(kind: Perlin, scale: 2.0, octaves: 9)",
            "Gradient(axis: Y, from: 0.5, to: 0.5)",
            "Gradient(axis: Y, from: NaN, to: 0.5)",
            "Shadow(black: 0.1, white: 0.2)",
        ] {
            assert!(parse(bad).is_err(), "{bad} was accepted");
        }
        // Blends nest at most MAX_DEPTH deep.
        let mut deep = "Noise(kind: Perlin, scale: 1.0)".to_string();
        for _ in 0..=MAX_DEPTH {
            deep = format!("Blend(op: Max, a: {deep}, b: Noise(kind: Perlin, scale: 1.0))");
        }
        assert!(parse(&deep).is_err());
    }

    #[test]
    fn a_generator_writes_as_it_reads() {
        let g = parse(
            "Blend(op: Add, a: Thickness(black: 0.1, white: 0.4, gamma: 2.0, invert: true), \
             b: Gradient(axis: Z, from: 1.0, to: 0.0))",
        )
        .expect("reads");
        let text = ron::to_string(&g).expect("writes");
        assert_eq!(parse(&text).expect("reads back"), g);
        let json = serde_json::to_string(&g).expect("json");
        assert_eq!(
            serde_json::from_str::<Generator>(&json).expect("json back"),
            g
        );
    }

    #[test]
    fn values_stay_in_range_and_follow_their_parameters() {
        let no_bakes: Vec<std::sync::Arc<Baked>> = Vec::new();
        for kind in [NoiseKind::Perlin, NoiseKind::Simplex, NoiseKind::Worley] {
            for space in [Space::Uv, Space::Object, Space::Triplanar] {
                let g = Generator::Noise(Noise {
                    kind,
                    scale: 6.0,
                    octaves: 3,
                    seed: 7,
                    space,
                });
                let e = Evaluator::new(&g, &no_bakes);
                let values: Vec<f32> = (0..400)
                    .map(|i| {
                        let p = Vec3::new((i % 20) as f32 / 20.0, 0.3, (i / 20) as f32 / 20.0);
                        e.value(&texel(p))
                    })
                    .collect();
                assert!(values.iter().all(|v| (0.0..=1.0).contains(v)));
                let spread = values.iter().copied().fold(f32::MIN, f32::max)
                    - values.iter().copied().fold(f32::MAX, f32::min);
                assert!(spread > 0.2, "{kind:?} {space:?} is flat: {spread}");
            }
        }
        let ramp = Generator::Gradient {
            axis: Axis::Y,
            from: 0.25,
            to: 0.75,
        };
        let e = Evaluator::new(&ramp, &no_bakes);
        assert_eq!(e.value(&texel(Vec3::new(0.0, 0.0, 0.0))), 0.0);
        assert_eq!(e.value(&texel(Vec3::new(0.0, 0.5, 0.0))), 0.5);
        assert_eq!(e.value(&texel(Vec3::new(0.0, 1.0, 0.0))), 1.0);
        let levels = Levels {
            black: 0.2,
            white: 0.6,
            gamma: 1.0,
            invert: true,
        };
        assert_eq!(levels.apply(0.1), 1.0);
        assert!((levels.apply(0.4) - 0.5).abs() < 1e-6);
        assert_eq!(levels.apply(0.9), 0.0);
    }
}
