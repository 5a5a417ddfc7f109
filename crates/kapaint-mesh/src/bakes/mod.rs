//! Maps baked from the mesh at every texel the UV bake gives a surface point: ambient
//! occlusion, thickness, curvature, object-space position and normal. They describe the mesh,
//! not the material: masks and fills are made from them, and nothing here is painted.
//!
//! Occlusion and thickness cast rays against a BVH of the mesh (`obvhs`' compressed wide
//! BVH). Directions are a Hammersley set, cosine-weighted around the texel's geometric normal
//! (AO) or its opposite (thickness), turned about the normal by a hashed angle per texel so
//! neighbouring texels do not share their errors. A bake holds 2 bytes a texel
//! per channel and nothing per ray.
//!
//! Every bake computes in the mesh's [`UnitFrame`] (centred, scaled into `[-1, 1]` by a power of
//! two), so the same shape bakes to the same map at any scale: `1e-20` and `1e30` alike, with a
//! maximum distance given in object units scaled with it.

use glam::Vec3;
use kapaint_base::task::Progress;
use rayon::prelude::*;

mod bvh_build;
mod high;
mod occlusion;
mod rays;
pub use high::{
    DEFAULT_DISTANCE, HighBake, HighMap, HighOptions, HighRays, HighSource, IdSource, Matching,
    NormalSpace, SAMPLES, bake_from_high, bake_from_high_on, bake_from_high_with, check_cage,
};
use rays::turn_of;
pub use rays::{CpuCaster, Directions, RayBatch, RayCaster, RayKind, RayMesh, RayQuery};

use crate::Mesh;
use crate::bake::{Coverage, UvBake};
use crate::frame::UnitFrame;

/// What is baked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BakeMap {
    /// Ambient occlusion: the cosine-weighted fraction of the hemisphere around the geometric
    /// normal that sees no part of the mesh (1 = open sky).
    Ao,
    /// Curvature: 0.5 flat, above convex, below concave.
    Curvature,
    /// Thickness: the mean distance to the mesh along the inward hemisphere, over the
    /// maximum distance (1 = thick or open).
    Thickness,
    /// Object-space position, normalised to the bounding box (RGB).
    Position,
    /// Object-space normal, `0.5 + 0.5 n` (RGB).
    Normal,
}

impl BakeMap {
    /// Every map, by its name.
    pub const ALL: [(&'static str, Self); 5] = [
        ("ao", Self::Ao),
        ("curvature", Self::Curvature),
        ("thickness", Self::Thickness),
        ("position", Self::Position),
        ("normal", Self::Normal),
    ];

    /// Its name (`ao`, `curvature`, ...).
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, m)| *m == self)
            .map_or("ao", |(n, _)| n)
    }

    /// Channels a texel holds: 1 (grey) or 3 (RGB).
    pub fn channels(self) -> usize {
        match self {
            Self::Position | Self::Normal => 3,
            _ => 1,
        }
    }

    /// Whether it casts rays.
    pub fn casts_rays(self) -> bool {
        matches!(self, Self::Ao | Self::Thickness)
    }
}

/// Fewest and most rays a texel may cast.
pub const RAYS: std::ops::RangeInclusive<u32> = 1..=65536;

/// How rays are cast.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BakeOptions {
    /// Rays per texel.
    pub rays: u32,
    /// How far a ray looks (object units); `None`: unbounded for AO, the bounding box's
    /// diagonal for thickness.
    pub max_distance: Option<f32>,
}

impl Default for BakeOptions {
    fn default() -> Self {
        Self {
            rays: 128,
            max_distance: None,
        }
    }
}

/// A baked map: row-major unorm16 samples, `channels` a texel; empty texels are 0 (AO 1 and
/// thickness 1 are 65535; curvature 0.5 is 32768).
#[derive(Clone, Debug, PartialEq)]
pub struct Baked {
    /// What it is.
    pub map: BakeMap,
    /// How its rays were cast.
    pub options: BakeOptions,
    /// The [`Mesh::content_hash`] of the mesh it was baked from.
    pub mesh_hash: u64,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// The samples.
    pub data: Vec<u16>,
    /// Where it came from when it was baked from a high mesh onto this one (`None`: from this
    /// mesh itself).
    pub from_high: Option<FromHigh>,
}

/// Where a map baked from a high mesh came from, as a project keeps it: the high mesh cannot
/// be read again, so this is what the bake says of itself.
#[derive(Clone, Debug, PartialEq)]
pub struct FromHigh {
    /// The high mesh's name.
    pub mesh: String,
    /// Its [`Mesh::content_hash`].
    pub mesh_hash: u64,
    /// The ray distances (object units).
    pub front: f32,
    /// The ray distances (object units).
    pub rear: f32,
    /// Samples per texel.
    pub samples: u32,
    /// The cage's name, if the rays started on one.
    pub cage: Option<String>,
}

/// What a bake holds, over the texels a UV bake gives a surface point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BakeStats {
    /// Texels baked (padding included).
    pub texels: u64,
    /// Rays cast in all (0 for maps that cast none).
    pub rays_cast: u64,
    /// The mean of the first channel.
    pub mean: f32,
    /// The least of the first channel.
    pub min: f32,
}

impl Baked {
    /// Sample `c` of texel `i` in `[0, 1]`.
    pub fn value(&self, i: usize, c: usize) -> f32 {
        f32::from(self.data[i * self.map.channels() + c]) / 65535.0
    }

    /// Its texels, rays, mean and least value over the texels `uv` covers.
    pub fn stats(&self, uv: &UvBake) -> BakeStats {
        let channels = self.map.channels();
        let (mut texels, mut sum, mut min) = (0_u64, 0.0_f64, f32::INFINITY);
        for i in (0..uv.len().min(self.data.len() / channels))
            .filter(|&i| uv.coverage(i) != Coverage::Empty)
        {
            let v = f32::from(self.data[i * channels]) / 65535.0;
            texels += 1;
            sum += f64::from(v);
            min = min.min(v);
        }
        let rays = if self.map.casts_rays() {
            self.options.rays
        } else {
            0
        };
        BakeStats {
            texels,
            rays_cast: texels * u64::from(rays),
            mean: if texels == 0 {
                0.0
            } else {
                (sum / texels as f64) as f32
            },
            min: if texels == 0 { 0.0 } else { min },
        }
    }
}

/// The unit geometric normal of a triangle with `corners`, turned to the side the `shading`
/// normal faces. A triangle with no area (a sphere's pole) gives the shading normal.
fn geometric_normal([a, b, c]: [Vec3; 3], shading: Vec3) -> Vec3 {
    match (b - a).cross(c - a).try_normalize() {
        Some(n) if n.dot(shading) < 0.0 => -n,
        Some(n) => n,
        None => shading.normalize_or(Vec3::Z),
    }
}

/// Rows baked between progress reports and cancel checks.
const BAND_ROWS: usize = 8;

/// What one bake needs at every texel. Positions, distances and bounds are in the mesh's
/// [`UnitFrame`].
struct Baker<'a> {
    mesh: &'a Mesh,
    uv: &'a UvBake,
    map: BakeMap,
    far: f32,
    ray_mesh: Option<RayMesh>,
    directions: Directions,
    curvature: Option<Vec<f32>>,
    local: Vec<Vec3>,
    bounds: (Vec3, Vec3),
}

impl Baker<'_> {
    /// Texel `i`'s samples into `out` (nothing where no triangle is).
    fn texel(&self, i: usize, out: &mut [u16]) {
        let Some(t) = self.uv.triangle(i) else {
            return;
        };
        let unorm = |v: f32| (v.clamp(0.0, 1.0) * 65535.0).round() as u16;
        let uv = self.uv;
        let corners = || self.mesh.triangles[t as usize].map(|v| self.local[v as usize]);
        let position = || {
            let ([a, b, c], w) = (corners(), uv.barycentric(i));
            a * w.x + b * w.y + c * w.z
        };
        match self.map {
            BakeMap::Ao | BakeMap::Thickness => {
                let value = self.ray_mesh.as_ref().map_or(1.0, |r| {
                    let n = geometric_normal(corners(), uv.normal(i));
                    let p = position();
                    let set = &self.directions;
                    if self.map == BakeMap::Ao {
                        r.open_fraction_local(p, n, set, self.far, turn_of(i))
                    } else {
                        r.mean_distance_local(p, -n, set, self.far, turn_of(i))
                    }
                });
                out[0] = unorm(value);
            }
            BakeMap::Curvature => {
                let k = self.curvature.as_ref().map_or(0.0, |k| {
                    let w = uv.barycentric(i);
                    let [a, b, c] = self.mesh.triangles[t as usize].map(|v| k[v as usize]);
                    a * w.x + b * w.y + c * w.z
                });
                out[0] = unorm(0.5 + 0.5 * k);
            }
            BakeMap::Position => {
                let (lo, hi) = self.bounds;
                let p = (position() - lo) / (hi - lo).max(Vec3::splat(f32::MIN_POSITIVE));
                out.copy_from_slice(&p.to_array().map(unorm));
            }
            BakeMap::Normal => {
                let n = uv.normal(i) * 0.5 + 0.5;
                out.copy_from_slice(&n.to_array().map(unorm));
            }
        }
    }
}

/// Checks a bake's values.
fn check(map: BakeMap, options: BakeOptions) -> Result<(), String> {
    if map.casts_rays() && !RAYS.contains(&options.rays) {
        return Err(format!(
            "{} rays per texel is outside {} to {}",
            options.rays,
            RAYS.start(),
            RAYS.end()
        ));
    }
    if let Some(d) = options.max_distance
        && !(d.is_finite() && d > 0.0)
    {
        return Err(format!("the maximum distance {d} is not a positive number"));
    }
    Ok(())
}

/// Why a bake did not finish: cancelled (the caller ends quietly), or refused (why, for the
/// user).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum BakeError {
    /// Cancelled through its progress.
    #[error("cancelled")]
    Cancelled,
    /// The options or the mesh cannot be baked, and why.
    #[error("{0}")]
    Refused(String),
}

impl From<String> for BakeError {
    fn from(reason: String) -> Self {
        Self::Refused(reason)
    }
}

/// Bakes `map` at every texel `uv` gives a surface point (padding texels included, so seams
/// are padded like the maps). `progress` counts rows and cancels.
///
/// # Errors
/// Rays out of range, a maximum distance that is not a positive number, a mesh whose positions
/// are not finite or whose bounding box is too large to measure
/// ([`MAX_DIAGONAL`](crate::frame::MAX_DIAGONAL)), or cancelled.
pub fn bake_map(
    mesh: &Mesh,
    uv: &UvBake,
    map: BakeMap,
    options: BakeOptions,
    progress: Option<&Progress>,
) -> Result<Baked, BakeError> {
    check(map, options)?;
    if uv.triangle_count() != mesh.triangles.len() {
        return Err(BakeError::Refused(
            "the UV bake was made from another mesh".into(),
        ));
    }
    let frame = UnitFrame::checked(&mesh.positions)?;
    let (w, h) = (uv.width as usize, uv.height as usize);
    let channels = map.channels();
    let ray_mesh = map.casts_rays().then(|| RayMesh::new(mesh));
    let far = match (map, options.max_distance) {
        (_, Some(d)) => frame.local_length(d),
        (BakeMap::Thickness, None) => frame.local_diagonal(),
        _ => f32::INFINITY,
    };
    let local = frame.local_positions(&mesh.positions);
    let bounds = local.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let baker = Baker {
        mesh,
        uv,
        map,
        far,
        ray_mesh,
        directions: Directions::new(if map.casts_rays() { options.rays } else { 0 }),
        curvature: (map == BakeMap::Curvature).then(|| curvature_in(mesh, &local)),
        local,
        bounds,
    };
    if let Some(p) = progress {
        p.start(&format!("bake {}", map.name()), h as u64);
    }
    let mut data = vec![0_u16; w * h * channels];
    let cancelled = std::sync::atomic::AtomicBool::new(false);
    data.par_chunks_mut(w * channels * BAND_ROWS)
        .enumerate()
        .for_each(|(band, rows)| {
            if progress.is_some_and(Progress::is_cancelled) {
                cancelled.store(true, std::sync::atomic::Ordering::Relaxed);
                return;
            }
            let first = band * BAND_ROWS * w;
            for (k, out) in rows.chunks_exact_mut(channels).enumerate() {
                baker.texel(first + k, out);
            }
            if let Some(p) = progress {
                p.advance((rows.len() / (w * channels)) as u64);
            }
        });
    if cancelled.into_inner() {
        return Err(BakeError::Cancelled);
    }
    Ok(Baked {
        map,
        options,
        mesh_hash: mesh.content_hash(),
        width: uv.width,
        height: uv.height,
        data,
        from_high: None,
    })
}

/// Units of the curvature map: a mean curvature of `CURVATURE_SCALE` over the bounding box's
/// diagonal (a bump of radius 1/32 of the mesh) reaches 1 (convex) or 0 (concave).
pub const CURVATURE_SCALE: f32 = 32.0;

/// Signed mean curvature per vertex, in units of [`CURVATURE_SCALE`] over the mesh's
/// diagonal, clamped to `[-1, 1]`: positive convex, negative concave, 0 flat. Vertices at one
/// position count as one (a UV seam does not cut the surface); per edge, the normals' spread
/// along it over its length squared, averaged around the vertex. Computed in the mesh's
/// [`UnitFrame`], so it is the same at any scale.
pub fn vertex_curvature(mesh: &Mesh) -> Vec<f32> {
    curvature_in(
        mesh,
        &UnitFrame::of(&mesh.positions).local_positions(&mesh.positions),
    )
}

/// [`vertex_curvature`] with the mesh's positions in its unit frame (`local`, one a vertex).
fn curvature_in(mesh: &Mesh, local: &[Vec3]) -> Vec<f32> {
    // Weld by position, with each welded vertex's normal the mean of its copies'.
    let mut ids = std::collections::HashMap::new();
    let weld: Vec<usize> = mesh
        .positions
        .iter()
        .map(|p| {
            let next = ids.len();
            *ids.entry(p.to_array().map(f32::to_bits)).or_insert(next)
        })
        .collect();
    let mut normal = vec![Vec3::ZERO; ids.len()];
    let mut position = vec![Vec3::ZERO; ids.len()];
    for (v, &g) in weld.iter().enumerate() {
        normal[g] += mesh.normals[v];
        position[g] = local[v];
    }
    for n in &mut normal {
        *n = n.normalize_or_zero();
    }
    let mut sum = vec![0.0_f32; ids.len()];
    let mut count = vec![0_u32; ids.len()];
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (weld[t[k] as usize], weld[t[(k + 1) % 3] as usize]);
            let d = position[b] - position[a];
            let len2 = d.length_squared();
            if a == b || len2.is_nan() || len2 <= 0.0 {
                continue;
            }
            let k_edge = (normal[b] - normal[a]).dot(d) / len2;
            for v in [a, b] {
                sum[v] += k_edge;
                count[v] += 1;
            }
        }
    }
    let (lo, hi) = position.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let scale = (hi - lo).length() / CURVATURE_SCALE;
    weld.iter()
        .map(|&g| {
            let mean = if count[g] == 0 {
                0.0
            } else {
                sum[g] / count[g] as f32
            };
            (mean * scale).clamp(-1.0, 1.0)
        })
        .collect()
}

#[cfg(test)]
mod high_maps_tests;
#[cfg(test)]
mod high_pairs_tests;
#[cfg(test)]
mod high_tests;
#[cfg(test)]
mod occlusion_tests;
#[cfg(test)]
mod tests;
