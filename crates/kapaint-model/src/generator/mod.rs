//! Generators: a mask value per texel made from parameters, not pixels. A bake of the mesh
//! through levels, noise (Perlin or simplex fBm, Worley) in UV, object or triplanar space, a
//! gradient along an object-space axis, or a blend of two generators. Every parameter is
//! checked where it comes in (a script, a project file), so no generator that reaches the
//! model can make a NaN or run away.
//!
//! In scripts: `Ao(black: 0.2, white: 0.9, invert: false)`, `Curvature(black: 0.5, white:
//! 0.7, invert: false)`, `Noise(kind: Perlin, scale: 8.0, octaves: 4, seed: 1, space:
//! Object)`, `Gradient(axis: Y, from: 0.0, to: 1.0)`, `Facing(axis: Y, black: 0.7, white:
//! 0.95)`, `Remap(black: 0.45, white: 0.55, of: ...)`, `Blend(op: Multiply, a: ..., b: ...)`.

use fastnoise_lite::{CellularReturnType, FastNoiseLite, FractalType, NoiseType};
use glam::Vec3;
use kapaint_mesh::bakes::{BakeMap, Baked};
use serde::{Deserialize, Serialize};

mod file;
pub mod preset;
mod relative;
pub use relative::MIN_RELATIVE_SPAN;
pub mod tiles;
use file::GeneratorFile;
pub use file::MaskGenerator;

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
    /// How much the surface faces along an object-space axis (`0.5 + 0.5 n.axis` of the
    /// surface normal) through levels: dust settles on what faces up.
    Facing {
        /// The axis.
        axis: Axis,
        /// The levels.
        levels: Levels,
    },
    /// Another generator through levels (noise made into patches, say).
    Remap {
        /// The levels.
        levels: Levels,
        /// The generator.
        of: Box<Generator>,
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
    /// `black` and `white` are places in the mesh's own distribution of the bake (0.9: the
    /// value 90 % of the surface lies below), not values: the same levels find the edges of
    /// a smooth teapot and of a sharp barrel. Only bakes read them so.
    pub relative: bool,
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
            Self::Facing { levels, .. } => levels.check(),
            Self::Remap { levels, of } => {
                if depth >= MAX_DEPTH {
                    return Err(format!("generators nest more than {MAX_DEPTH} deep"));
                }
                levels.check()?;
                of.check_at(depth + 1)
            }
            Self::Blend { a, b, .. } => {
                if depth >= MAX_DEPTH {
                    return Err(format!("generators nest more than {MAX_DEPTH} deep"));
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
            Self::Noise(_) | Self::Gradient { .. } | Self::Facing { .. } => None,
            Self::Remap { of, .. } => {
                of.collect_bakes(out);
                None
            }
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
    Facing(Axis, Levels),
    Remap(Levels, Box<Node<'a>>),
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

/// A tile's texels as a generator reads them: `side x side`, row-major, `None` where no
/// surface is.
pub struct Grid {
    /// Texels a side.
    pub side: usize,
    /// The texels.
    pub texels: Vec<Option<Texel>>,
}

/// Largest span, in cells of a noise's finest octave, over which a value between two exact
/// samples is interpolated instead of computed: linear interpolation of fBm over an eighth
/// of its finest cell stays within half an 8-bit level (measured in the tests: at most 87
/// of 65535 on the builtin sphere at 4096^2, one octave of Perlin at scale 30).
pub const SMOOTH_SPAN: f32 = 0.125;

impl Evaluator<'_> {
    /// The values at every texel of `grid` into `out` (0 where no surface is). With
    /// `interpolate`, noise whose finest octave is smooth over two texels is computed on
    /// every second texel and interpolated between (see [`SMOOTH_SPAN`]).
    pub fn grid_values(&self, grid: &Grid, interpolate: bool, out: &mut [f32]) {
        self.node.values(grid, interpolate, out);
        for (o, t) in out.iter_mut().zip(&grid.texels) {
            *o = if t.is_some() { o.clamp(0.0, 1.0) } else { 0.0 };
        }
    }
}

impl<'a> Node<'a> {
    /// [`Evaluator::grid_values`] of this node.
    fn values(&self, grid: &Grid, interpolate: bool, out: &mut [f32]) {
        match self {
            // Only Perlin is interpolated: Worley's distance has creases, which interpolation
            // would round off, and OpenSimplex2 bends too sharply to gain.
            Self::Noise(noise, n) if interpolate && n.kind == NoiseKind::Perlin => {
                noise_values(noise, n, grid, out);
            }
            Self::Remap(levels, of) => {
                of.values(grid, interpolate, out);
                for o in out.iter_mut() {
                    *o = levels.apply(o.clamp(0.0, 1.0));
                }
            }
            Self::Blend(op, a, b) => {
                let mut other = vec![0.0; out.len()];
                a.values(grid, interpolate, out);
                b.values(grid, interpolate, &mut other);
                for (a, b) in out.iter_mut().zip(other) {
                    let (x, y) = (a.clamp(0.0, 1.0), b.clamp(0.0, 1.0));
                    *a = match op {
                        BlendOp::Multiply => x * y,
                        BlendOp::Min => x.min(y),
                        BlendOp::Max => x.max(y),
                        BlendOp::Add => (x + y).min(1.0),
                    };
                }
            }
            _ => {
                for (o, t) in out.iter_mut().zip(&grid.texels) {
                    *o = t.as_ref().map_or(0.0, |t| self.value(t));
                }
            }
        }
    }

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
            Generator::Facing { axis, levels } => Self::Facing(*axis, *levels),
            Generator::Remap { levels, of } => Self::Remap(*levels, Box::new(Self::of(of, bakes))),
            Generator::Blend { op, a, b } => Self::Blend(
                *op,
                Box::new(Self::of(a, bakes)),
                Box::new(Self::of(b, bakes)),
            ),
        }
    }

    fn value(&self, t: &Texel) -> f32 {
        match self {
            Self::Noise(noise, n) => noise_at(noise, n, t),
            Self::Bake(l, bake) => {
                let v = bake
                    .filter(|b| t.index < b.data.len() / b.map.channels())
                    .map_or(0.5, |b| b.value(t.index, 0));
                l.apply(v)
            }
            Self::Facing(axis, levels) => {
                let n = match axis {
                    Axis::X => t.normal.x,
                    Axis::Y => t.normal.y,
                    Axis::Z => t.normal.z,
                };
                levels.apply(0.5 + 0.5 * n)
            }
            Self::Remap(levels, of) => levels.apply(of.value(t)),
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

/// Noise `n` at texel `t`, in `[0, 1]`.
fn noise_at(noise: &FastNoiseLite, n: &Noise, t: &Texel) -> f32 {
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

/// Noise over a grid: exact on even rows' even texels, then each other texel interpolated
/// between its two computed neighbours (left and right on even rows, above and below on odd
/// ones) where both have a surface and lie within [`SMOOTH_SPAN`] of the finest octave's
/// cell of each other (with normals alike, for triplanar noise), else computed.
fn noise_values(noise: &FastNoiseLite, n: &Noise, grid: &Grid, out: &mut [f32]) {
    let side = grid.side;
    let finest = n.scale * (1_u32 << (n.octaves - 1)) as f32;
    let at = |i: usize| grid.texels[i].as_ref();
    let close = |a: &Texel, b: &Texel| {
        let d = match n.space {
            Space::Uv => a.uv.distance(b.uv),
            Space::Object => a.position.distance(b.position),
            Space::Triplanar => {
                if a.normal.dot(b.normal) < 0.999 {
                    return false;
                }
                a.position.distance(b.position)
            }
        };
        d * finest <= SMOOTH_SPAN
    };
    let exact = |i: usize| at(i).map_or(0.0, |t| noise_at(noise, n, t));
    // Between `a` and `b` (indices), at `i`.
    let between = |out: &[f32], i: usize, a: usize, b: usize| match (at(i), at(a), at(b)) {
        (Some(_), Some(ta), Some(tb)) if close(ta, tb) => 0.5 * (out[a] + out[b]),
        _ => exact(i),
    };
    for y in (0..side).step_by(2) {
        for x in (0..side).step_by(2) {
            out[y * side + x] = exact(y * side + x);
        }
        for x in (1..side).step_by(2) {
            let i = y * side + x;
            out[i] = if x + 1 < side {
                between(out, i, i - 1, i + 1)
            } else {
                exact(i)
            };
        }
    }
    for y in (1..side).step_by(2) {
        for x in 0..side {
            let i = y * side + x;
            out[i] = if y + 1 < side {
                between(out, i, i - side, i + side)
            } else {
                exact(i)
            };
        }
    }
}

#[cfg(test)]
mod tests;
