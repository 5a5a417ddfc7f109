//! Maps baked from a high-poly mesh onto a low one: per texel of the low mesh's UV bake, a ray
//! from `front` above its surface point back along its (smooth) normal, `front + rear` long,
//! meets the nearest high triangle. A normal bake takes that triangle's normal (interpolated
//! from its vertex normals), written in the low mesh's MikkTSpace frame (tangent space, as the
//! preview and the exports read a normal map) or in object space, `0.5 + 0.5 n`; a height bake
//! takes how far the high surface lies above the low one, `(h + rear) / (front + rear)` (0 at
//! `rear` below, 1 at `front` above). Texels whose ray meets nothing keep the low surface (a
//! flat normal, the height of the low surface) and are counted.

use glam::Vec3;
use rayon::prelude::*;

use super::{BAND_ROWS, BakeError, RayMesh};
use crate::Mesh;
use crate::bake::{Coverage, UvBake};
use crate::frame::UnitFrame;
use kapaint_base::task::Progress;

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
}

impl HighMap {
    /// Samples a texel holds.
    pub fn channels(self) -> usize {
        match self {
            Self::Normal(_) => 3,
            Self::Height => 1,
        }
    }
}

/// How the rays are cast.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HighOptions {
    /// What is baked.
    pub map: HighMap,
    /// How far above the low surface a ray starts (object units); `None`: the default.
    pub front: Option<f32>,
    /// How far below it a ray still looks; `None`: the default.
    pub rear: Option<f32>,
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
    /// Texels baked (surface and padding).
    pub covered: u64,
    /// Of those, texels whose ray met nothing.
    pub missed: u64,
    /// One per texel: whether its ray met nothing (the miss map).
    pub misses: Vec<bool>,
}

/// The low mesh's frame at a texel: its tangents (split as MikkTSpace splits them).
struct Frames {
    tangents: Option<crate::tangents::Tangents>,
}

impl Frames {
    /// `(T, B, N)` at texel `i` of triangle `t`, `N` the interpolated normal.
    fn at(&self, uv: &UvBake, t: u32, i: usize, n: Vec3) -> (Vec3, Vec3, Vec3) {
        let Some(tan) = &self.tangents else {
            let (a, b) = n.any_orthonormal_pair();
            return (a, b, n);
        };
        let w = uv.barycentric(i);
        let corners = tan.mesh.triangles[t as usize].map(|v| tan.tangents[v as usize]);
        let t3 = corners
            .iter()
            .zip([w.x, w.y, w.z])
            .fold(Vec3::ZERO, |s, (c, k)| s + Vec3::new(c[0], c[1], c[2]) * k);
        let sign = if corners[0][3] < 0.0 { -1.0 } else { 1.0 };
        let t3 = (t3 - n * n.dot(t3))
            .try_normalize()
            .unwrap_or_else(|| n.any_orthonormal_vector());
        (t3, n.cross(t3) * sign, n)
    }
}

/// Bakes `options.map` of `high` onto `low` at every texel `uv` gives a surface point.
/// `progress` counts rows and cancels.
///
/// # Errors
/// A high mesh with no triangles or positions that are not finite, a low mesh the UV bake was
/// not made from, distances that are not positive and finite, or cancelled.
pub fn bake_from_high(
    low: &Mesh,
    uv: &UvBake,
    high: &Mesh,
    options: HighOptions,
    progress: Option<&Progress>,
) -> Result<HighBake, BakeError> {
    if uv.triangle_count() != low.triangles.len() {
        return Err("the UV bake was made from another mesh".to_string().into());
    }
    let (size, front, rear) = distances(low, high, options)?;
    let rays = RayMesh::new(high);
    // How far a ray that slipped between two triangles is moved to try again.
    let nudge = size * 1e-4;
    let frames = Frames {
        tangents: (options.map == HighMap::Normal(NormalSpace::Tangent))
            .then(|| crate::tangents::generate(low))
            .flatten(),
    };
    let (w, h) = (uv.width as usize, uv.height as usize);
    if let Some(p) = progress {
        p.start("bake from the high mesh", h as u64);
    }
    let channels = options.map.channels();
    let mut data = vec![0_u16; w * h * channels];
    let mut misses = vec![false; w * h];
    let cancelled = std::sync::atomic::AtomicBool::new(false);
    data.par_chunks_mut(w * channels * BAND_ROWS)
        .zip(misses.par_chunks_mut(w * BAND_ROWS))
        .enumerate()
        .for_each(|(band, (rows, missed))| {
            if progress.is_some_and(Progress::is_cancelled) {
                cancelled.store(true, std::sync::atomic::Ordering::Relaxed);
                return;
            }
            let first = band * BAND_ROWS * w;
            for (k, (out, miss)) in rows
                .chunks_exact_mut(channels)
                .zip(missed.iter_mut())
                .enumerate()
            {
                let i = first + k;
                let Some(t) = uv.triangle(i) else {
                    continue;
                };
                let (p, n) = (uv.position(i), uv.normal(i));
                let found = cast(&rays, p + n * front, -n, front + rear, nudge);
                *miss = found.is_none();
                let unorm = |v: f32| (v.clamp(0.0, 1.0) * 65535.0).round() as u16;
                match options.map {
                    HighMap::Height => {
                        // Above the low surface: `front` less the way the ray went.
                        let above = found.map_or(0.0, |(_, _, d)| front - d);
                        out[0] = unorm((above + rear) / (front + rear));
                    }
                    HighMap::Normal(space) => {
                        let normal = found.map_or(n, |(q, tri, _)| high_normal(high, tri, q));
                        let written = match space {
                            NormalSpace::Object => normal,
                            NormalSpace::Tangent => {
                                let (ta, bi, no) = frames.at(uv, t, i, n);
                                Vec3::new(normal.dot(ta), normal.dot(bi), normal.dot(no))
                            }
                        };
                        for (o, c) in out.iter_mut().zip(written.to_array()) {
                            *o = unorm(0.5 + 0.5 * c);
                        }
                    }
                }
            }
            if let Some(p) = progress {
                p.advance((rows.len() / (w * channels)) as u64);
            }
        });
    if cancelled.into_inner() {
        return Err(BakeError::Cancelled);
    }
    let covered = (0..w * h)
        .filter(|&i| uv.coverage(i) != Coverage::Empty)
        .count() as u64;
    let missed = misses.iter().filter(|&&m| m).count() as u64;
    Ok(HighBake {
        width: uv.width,
        height: uv.height,
        data,
        map: options.map,
        front,
        rear,
        covered,
        missed,
        misses,
    })
}

/// The default distance's size, and the front and rear distances (object units).
///
/// # Errors
/// A high mesh with no triangles or positions that are not finite, distances that are not
/// positive and finite.
fn distances(low: &Mesh, high: &Mesh, options: HighOptions) -> Result<(f32, f32, f32), BakeError> {
    if high.triangles.is_empty() {
        return Err(format!("the high mesh {} has no triangles", high.name).into());
    }
    UnitFrame::checked(&high.positions)
        .map_err(|e| BakeError::Refused(format!("the high mesh {}: {e}", high.name)))?;
    let both: Vec<Vec3> = low
        .positions
        .iter()
        .chain(&high.positions)
        .copied()
        .collect();
    let size = UnitFrame::checked(&both)?.diagonal() * DEFAULT_DISTANCE;
    let distance = |d: Option<f32>, what: &str| match d {
        None => Ok(size),
        Some(d) if d.is_finite() && d > 0.0 => Ok(d),
        Some(d) => Err(BakeError::Refused(format!(
            "the {what} distance {d} is not a positive number"
        ))),
    };
    let (front, rear) = (
        distance(options.front, "front")?,
        distance(options.rear, "rear")?,
    );
    Ok((size, front, rear))
}

/// Where a ray from `origin` along `dir` first meets the mesh within `far`, the triangle
/// there and how far along it is. A ray exactly through a vertex or along an edge can slip between its triangles (the
/// triangle test is not watertight there; on a fine sphere 61 of 64,575 rays near the pole,
/// where many thin triangles meet): a miss is cast again twice, moved `nudge` across.
fn cast(rays: &RayMesh, origin: Vec3, dir: Vec3, far: f32, nudge: f32) -> Option<(Vec3, u32, f32)> {
    let (a, b) = dir.any_orthonormal_pair();
    [Vec3::ZERO, a * nudge, (b - a) * nudge]
        .into_iter()
        .find_map(|shift| {
            let o = origin + shift;
            rays.nearest(o, dir, far)
                .map(|(d, tri)| (o + dir * d, tri, d))
        })
}

/// The normal of `mesh`'s triangle `t` at point `q` on it: its vertex normals interpolated
/// (the face's normal where they cancel).
fn high_normal(mesh: &Mesh, t: u32, q: Vec3) -> Vec3 {
    let tri = mesh.triangles[t as usize].map(|v| v as usize);
    let [a, b, c] = tri.map(|v| mesh.positions[v]);
    let face = (b - a).cross(c - a);
    let area = face.length_squared();
    let w = if area > 0.0 {
        let wa = (b - q).cross(c - q).dot(face) / area;
        let wb = (c - q).cross(a - q).dot(face) / area;
        Vec3::new(wa, wb, 1.0 - wa - wb)
    } else {
        Vec3::splat(1.0 / 3.0)
    };
    let [na, nb, nc] = tri.map(|v| mesh.normals.get(v).copied().unwrap_or(Vec3::ZERO));
    (na * w.x + nb * w.y + nc * w.z)
        .try_normalize()
        .or_else(|| face.try_normalize())
        .unwrap_or(Vec3::Z)
}
