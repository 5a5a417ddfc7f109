//! Maps baked from a high-poly mesh onto a low one: per sample of a texel of the low mesh's UV
//! bake, a ray from `front` above its surface point back along its (smooth) normal, `front +
//! rear` long (or from the same point of a cage, towards the low surface and `rear` past it),
//! meets the nearest high triangle. A normal bake takes that triangle's normal (interpolated
//! from its vertex normals), written in the low mesh's MikkTSpace frame (tangent space, as the
//! preview and the exports read a normal map) or in object space, `0.5 + 0.5 n`; a height bake
//! takes how far the high surface lies above the low one, `(h + rear) / (front + rear)` (0 at
//! `rear` below, 1 at `front` above); AO and thickness cast their rays from the point met, on
//! the high mesh; curvature is the high mesh's, position the point met (in the low mesh's box).
//! Texels whose rays meet nothing keep the low surface (a flat normal, the height of the low
//! surface, AO and thickness from the low point against the high mesh) and are counted.
//!
//! With `samples` 4 or 16 a texel is the mean of a 2 x 2 or 4 x 4 grid of points across it,
//! each on the low triangle under it (the texel's own or a neighbour's).

use rayon::prelude::*;

use super::{BAND_ROWS, BakeError, BakeMap, BakeOptions, Baked, CpuCaster, RayCaster, RayQuery};
use crate::Mesh;
use crate::bake::{Coverage, UvBake};
use kapaint_base::task::Progress;

mod checks;
mod pairs;
mod sample;
pub use checks::check_cage;
use checks::checked;
pub use pairs::{HighRays, Matching};
use sample::Sampler;

/// The space normals are written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NormalSpace {
    /// The low mesh's MikkTSpace frame: `(T, B, N)` per texel, green up the image.
    Tangent,
    /// Object space.
    Object,
}

/// What is baked from the high mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HighMap {
    /// Its normals, in a space (RGB).
    Normal(NormalSpace),
    /// Its height over the low surface, by the ray distances (grey).
    Height,
    /// Ambient occlusion at the point met, on the high mesh (grey, 1 = open sky).
    Ao,
    /// Thickness at the point met, inwards through the high mesh (grey).
    Thickness,
    /// The high mesh's curvature at the point met (grey, 0.5 flat).
    Curvature,
    /// The point met, in the low mesh's bounding box (RGB).
    Position,
    /// What the high mesh says of the point met, a colour each (RGB; black where a ray met
    /// nothing).
    Id(IdSource),
}

/// What an ID map tells apart.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IdSource {
    /// Pieces of surface joined by shared positions (each separate object of a file is one).
    Piece,
    /// The file's objects or groups (OBJ `o` and `g`, glTF nodes).
    Object,
    /// The file's materials (OBJ `usemtl`, glTF primitives' materials).
    Material,
    /// The high mesh's vertex colours themselves.
    Color,
}

impl IdSource {
    /// Every source, by the name `kapaint bake --id-from` takes.
    pub const ALL: [(&'static str, Self); 4] = [
        ("piece", Self::Piece),
        ("object", Self::Object),
        ("material", Self::Material),
        ("color", Self::Color),
    ];

    /// Its name.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, s)| *s == self)
            .map_or("piece", |(n, _)| n)
    }

    /// What an ID map of `high` tells apart unless told: its materials where it names more
    /// than one, else its objects where it names more than one, else its pieces.
    pub fn for_mesh(high: &Mesh) -> Self {
        let distinct = |runs: &[crate::Run]| {
            runs.iter()
                .map(|r| r.name.as_str())
                .collect::<std::collections::HashSet<_>>()
                .len()
        };
        if distinct(&high.labels.materials) > 1 {
            Self::Material
        } else if distinct(&high.labels.objects) > 1 {
            Self::Object
        } else {
            Self::Piece
        }
    }
}

impl HighMap {
    /// Samples a texel holds.
    pub fn channels(self) -> usize {
        match self {
            Self::Normal(_) | Self::Position | Self::Id(_) => 3,
            _ => 1,
        }
    }

    /// Its name, as `kapaint bake --map` spells it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Normal(_) => "normal",
            Self::Height => "height",
            Self::Ao => "ao",
            Self::Thickness => "thickness",
            Self::Curvature => "curvature",
            Self::Position => "position",
            Self::Id(_) => "id",
        }
    }

    /// Whether it casts rays from the point met (AO, thickness).
    pub fn casts_rays(self) -> bool {
        matches!(self, Self::Ao | Self::Thickness)
    }

    /// The map of the project's own mesh it takes the place of when a project keeps it (what
    /// generator masks read): none for tangent-space normals (the project's normal map) and
    /// height.
    pub fn kept_as(self) -> Option<BakeMap> {
        match self {
            Self::Normal(NormalSpace::Object) => Some(BakeMap::Normal),
            Self::Ao => Some(BakeMap::Ao),
            Self::Thickness => Some(BakeMap::Thickness),
            Self::Curvature => Some(BakeMap::Curvature),
            Self::Position => Some(BakeMap::Position),
            Self::Normal(NormalSpace::Tangent) | Self::Height | Self::Id(_) => None,
        }
    }
}

/// The samples a texel may take: one, a 2 x 2 grid or a 4 x 4 grid.
pub const SAMPLES: [u32; 3] = [1, 4, 16];

/// How the rays are cast.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HighOptions {
    /// What is baked.
    pub map: HighMap,
    /// How far above the low surface a ray starts (object units); `None`: the default.
    pub front: Option<f32>,
    /// How far below it a ray still looks; `None`: the default.
    pub rear: Option<f32>,
    /// Rays per sample from the point met (AO, thickness).
    pub rays: u32,
    /// How far those rays look (object units); `None`: unbounded for AO, the high mesh's
    /// diagonal for thickness.
    pub max_distance: Option<f32>,
    /// Samples per texel, one of [`SAMPLES`].
    pub samples: u32,
}

impl HighOptions {
    /// `map` with the default distances, 128 rays, unbounded, one sample a texel.
    pub fn new(map: HighMap) -> Self {
        Self {
            map,
            front: None,
            rear: None,
            rays: 128,
            max_distance: None,
            samples: 1,
        }
    }
}

/// The default ray distances, front and rear: this share of the diagonal of the box both
/// meshes fill.
pub const DEFAULT_DISTANCE: f32 = 0.02;

/// A map baked from a high mesh: unorm16, row-major, and what the rays found.
#[derive(Clone, Debug, PartialEq)]
pub struct HighBake {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Per texel `0.5 + 0.5 n` (three samples) or the height (one); 0 where the low mesh has
    /// no surface.
    pub data: Vec<u16>,
    /// What it is.
    pub map: HighMap,
    /// The distances used (object units).
    pub front: f32,
    /// The distances used (object units).
    pub rear: f32,
    /// Rays per sample from the point met (AO, thickness; 0 for the others).
    pub rays: u32,
    /// How far those rays looked (object units), if bounded.
    pub max_distance: Option<f32>,
    /// Samples per texel.
    pub samples: u32,
    /// Whether the rays started on a cage.
    pub cage: bool,
    /// Texels baked (surface and padding).
    pub covered: u64,
    /// Of those, texels where a ray met nothing.
    pub missed: u64,
    /// One per texel: whether a ray met nothing (the miss map).
    pub misses: Vec<bool>,
    /// Seconds spent building the high mesh's BVH (the rest of the bake is the rays).
    pub bvh_seconds: f64,
    /// One per texel: the mean angle between its rays and the low triangle's face normal,
    /// 0 to 90 degrees as 0 to 255 (the skew view: where the low mesh's averaged normals tilt
    /// the rays).
    pub skew: Vec<u8>,
    /// Where the AO or thickness rays ran ([`RayCaster::name`]); empty for the other maps.
    pub cast_on: String,
}

/// The meshes a bake from a high mesh came from, as a project names them: taken once for
/// every map baked from them (hashing a sculpt of millions of triangles is not free).
#[derive(Clone, Debug, PartialEq)]
pub struct HighSource {
    /// The high mesh's name.
    pub mesh: String,
    /// Its [`Mesh::content_hash`].
    pub mesh_hash: u64,
    /// The cage's name, if the rays started on one.
    pub cage: Option<String>,
}

impl HighSource {
    /// What names `high` and `cage`.
    pub fn of(high: &Mesh, cage: Option<&Mesh>) -> Self {
        Self {
            mesh: high.name.clone(),
            mesh_hash: high.content_hash(),
            cage: cage.map(|c| c.name.clone()),
        }
    }
}

impl HighBake {
    /// The bake as a project keeps it, in place of the map of the low mesh (whose
    /// [`Mesh::content_hash`] is `low_hash`) it stands for ([`HighMap::kept_as`]), saying
    /// where it came from; the bake itself back for the maps a project does not keep that way.
    ///
    /// # Errors
    /// The bake, for tangent-space normals, height and IDs.
    pub fn into_baked(self, low_hash: u64, source: &HighSource) -> Result<Baked, Box<Self>> {
        let Some(map) = self.map.kept_as() else {
            return Err(Box::new(self));
        };
        Ok(Baked {
            map,
            options: BakeOptions {
                rays: if map.casts_rays() { self.rays } else { 128 },
                max_distance: self.max_distance,
            },
            mesh_hash: low_hash,
            width: self.width,
            height: self.height,
            from_high: Some(super::FromHigh {
                mesh: source.mesh.clone(),
                mesh_hash: source.mesh_hash,
                front: self.front,
                rear: self.rear,
                samples: self.samples,
                cage: source.cage.clone(),
            }),
            data: self.data,
        })
    }
}

/// Bakes `options.map` of `high` onto `low` at every texel `uv` gives a surface point, the
/// rays from `cage` when one is given (the low mesh pushed out: the same triangles, each ray
/// from a sample's point on it towards the same point of the low mesh). `progress` counts rows
/// and cancels.
///
/// # Errors
/// A high mesh with no triangles or positions that are not finite, a low mesh the UV bake was
/// not made from, a cage whose topology differs from the low mesh's, distances that are not
/// positive and finite, rays or samples out of range, or cancelled.
pub fn bake_from_high(
    low: &Mesh,
    uv: &UvBake,
    high: &Mesh,
    cage: Option<&Mesh>,
    options: HighOptions,
    progress: Option<&Progress>,
) -> Result<HighBake, BakeError> {
    let distances = checked(low, uv, high, cage, options)?;
    let rays = HighRays::new(low, high, Matching::All)?;
    let caster = CpuCaster(rays.meshes());
    let mut baked = run(
        (low, uv, high, cage),
        &rays,
        options,
        distances,
        &caster,
        progress,
    )?;
    baked.bvh_seconds = rays.bvh_seconds;
    Ok(baked)
}

/// [`bake_from_high`] with the high mesh's BVHs built already ([`HighRays::new`], matched by
/// name or not), so that several maps of one high mesh build them once.
///
/// # Errors
/// As [`bake_from_high`]; BVHs matched for another low mesh.
pub fn bake_from_high_with(
    low: &Mesh,
    uv: &UvBake,
    (high, rays): (&Mesh, &HighRays),
    cage: Option<&Mesh>,
    options: HighOptions,
    progress: Option<&Progress>,
) -> Result<HighBake, BakeError> {
    bake_from_high_on(
        low,
        uv,
        (high, rays),
        cage,
        options,
        &CpuCaster(rays.meshes()),
        progress,
    )
}

/// [`bake_from_high_with`] with AO and thickness rays cast by `caster` (a GPU's, say, made
/// over [`HighRays::single`]; the CPU's is the reference).
///
/// # Errors
/// As [`bake_from_high_with`]; what the caster said.
pub fn bake_from_high_on(
    low: &Mesh,
    uv: &UvBake,
    (high, rays): (&Mesh, &HighRays),
    cage: Option<&Mesh>,
    options: HighOptions,
    caster: &dyn RayCaster,
    progress: Option<&Progress>,
) -> Result<HighBake, BakeError> {
    let distances = checked(low, uv, high, cage, options)?;
    if !rays.fits(low.triangles.len()) {
        return Err("the BVHs were matched for another low mesh"
            .to_string()
            .into());
    }
    run(
        (low, uv, high, cage),
        rays,
        options,
        distances,
        caster,
        progress,
    )
}

/// The bake once what it is given is checked (`distances` as [`checked`] found them).
fn run(
    (low, uv, high, cage): (&Mesh, &UvBake, &Mesh, Option<&Mesh>),
    rays: &HighRays,
    options: HighOptions,
    distances: (f32, f32, f32),
    caster: &dyn RayCaster,
    progress: Option<&Progress>,
) -> Result<HighBake, BakeError> {
    let sampler = Sampler::new((low, uv, high, cage), rays, options, distances);
    if let Some(p) = progress {
        p.start("bake from the high mesh", u64::from(uv.height));
    }
    let (texels, cast_on) = if options.map.casts_rays() {
        (bake_cast(&sampler, uv, caster, progress)?, caster.name())
    } else {
        (
            bake_texels(&sampler, uv, options.map, progress)?,
            String::new(),
        )
    };
    let (_, front, rear) = distances;
    let Texels { data, misses, skew } = texels;
    Ok(HighBake {
        width: uv.width,
        height: uv.height,
        data,
        map: options.map,
        front,
        rear,
        rays: if options.map.casts_rays() {
            options.rays
        } else {
            0
        },
        max_distance: options.max_distance,
        samples: options.samples,
        cage: cage.is_some(),
        covered: (0..uv.len())
            .filter(|&i| uv.coverage(i) != Coverage::Empty)
            .count() as u64,
        missed: misses.iter().filter(|&&m| m).count() as u64,
        misses,
        bvh_seconds: 0.0,
        skew,
        cast_on,
    })
}

/// What a bake's texels hold: the samples, whether a ray missed, the skew byte.
struct Texels {
    data: Vec<u16>,
    misses: Vec<bool>,
    skew: Vec<u8>,
}

impl Texels {
    /// Zeros for `texels` texels of `channels` samples.
    fn new(texels: usize, channels: usize) -> Self {
        Self {
            data: vec![0; texels * channels],
            misses: vec![false; texels],
            skew: vec![0; texels],
        }
    }
}

/// A map but AO and thickness, texel by texel on every core.
fn bake_texels(
    sampler: &Sampler<'_>,
    uv: &UvBake,
    map: HighMap,
    progress: Option<&Progress>,
) -> Result<Texels, BakeError> {
    let w = uv.width as usize;
    let channels = map.channels();
    let mut out = Texels::new(uv.len(), channels);
    let cancelled = std::sync::atomic::AtomicBool::new(false);
    out.data
        .par_chunks_mut(w * channels * BAND_ROWS)
        .zip(out.misses.par_chunks_mut(w * BAND_ROWS))
        .zip(out.skew.par_chunks_mut(w * BAND_ROWS))
        .enumerate()
        .for_each(|(band, ((rows, missed), skewed))| {
            if progress.is_some_and(Progress::is_cancelled) {
                cancelled.store(true, std::sync::atomic::Ordering::Relaxed);
                return;
            }
            let first = band * BAND_ROWS * w;
            for (k, ((out, miss), skew)) in rows
                .chunks_exact_mut(channels)
                .zip(missed.iter_mut())
                .zip(skewed.iter_mut())
                .enumerate()
            {
                if let Some(texel) = sampler.texel(first + k, out) {
                    *miss = texel.missed;
                    *skew = skew_byte(texel.skew_degrees);
                }
            }
            if let Some(p) = progress {
                p.advance((rows.len() / (w * channels)) as u64);
            }
        });
    if cancelled.into_inner() {
        return Err(BakeError::Cancelled);
    }
    Ok(out)
}

/// AO or thickness: per batch of rows, each sample's projection ray on every core, then
/// its rays cast by `caster`, then each texel the mean of its samples.
fn bake_cast(
    sampler: &Sampler<'_>,
    uv: &UvBake,
    caster: &dyn RayCaster,
    progress: Option<&Progress>,
) -> Result<Texels, BakeError> {
    let (w, h) = (uv.width as usize, uv.height as usize);
    let count = sampler.samples();
    let mut out = Texels::new(w * h, 1);
    let rows = (caster.batch_size() / (w * count)).clamp(1, h.max(1));
    for first_row in (0..h).step_by(rows) {
        if progress.is_some_and(Progress::is_cancelled) {
            return Err(BakeError::Cancelled);
        }
        let span = first_row * w..((first_row + rows).min(h)) * w;
        let texels: Vec<usize> = span.clone().filter(|&i| uv.triangle(i).is_some()).collect();
        let mut queries = vec![RayQuery::default(); texels.len() * count];
        let found: Vec<Option<(bool, u8)>> = queries
            .par_chunks_mut(count)
            .zip(&texels)
            .map(|(out, &i)| {
                sampler
                    .texel_queries(i, out)
                    .map(|f| (f.missed, skew_byte(f.skew_degrees)))
            })
            .collect();
        let values = caster.cast(&sampler.batch(&queries)).map_err(|e| {
            BakeError::Refused(format!("casting the rays on {}: {e}", caster.name()))
        })?;
        for ((&i, seen), v) in texels.iter().zip(found).zip(values.chunks(count)) {
            if let Some((missed, skewed)) = seen {
                let mean = v.iter().sum::<f32>() / count as f32;
                out.data[i] = (mean.clamp(0.0, 1.0) * 65535.0).round() as u16;
                out.misses[i] = missed;
                out.skew[i] = skewed;
            }
        }
        if let Some(p) = progress {
            p.advance(((span.end - span.start) / w) as u64);
        }
    }
    Ok(out)
}

/// A skew angle (degrees) as the skew view's byte.
fn skew_byte(degrees: f32) -> u8 {
    (degrees / 90.0 * 255.0).round().clamp(0.0, 255.0) as u8
}
