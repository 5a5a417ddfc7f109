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

mod file;
use file::GeneratorFile;

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
mod tests;
