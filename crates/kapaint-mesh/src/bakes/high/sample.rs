//! One texel of a bake from a high mesh: its samples' rays and what each found, averaged.

use glam::{Vec2, Vec3};

use super::{HighMap, HighOptions, HighRays, IdSource, NormalSpace};
use crate::bake::UvBake;
use crate::bakes::rays::turn_of;
use crate::bakes::{Directions, RayBatch, RayKind, RayMesh, RayQuery, geometric_normal};
use crate::{Mesh, Named};

/// What a texel's rays found besides its value.
pub(super) struct TexelFound {
    /// Whether a ray met nothing.
    pub(super) missed: bool,
    /// The mean angle between its rays and the low triangle's face normal (degrees).
    pub(super) skew_degrees: f32,
}

/// The low mesh's frame at a sample: its tangents (split as MikkTSpace splits them).
struct Frames {
    tangents: Option<crate::tangents::Tangents>,
}

impl Frames {
    /// `(T, B, N)` at barycentric `w` of triangle `t`, `N` the interpolated normal.
    fn at(&self, t: u32, w: Vec3, n: Vec3) -> (Vec3, Vec3, Vec3) {
        let Some(tan) = &self.tangents else {
            let (a, b) = n.any_orthonormal_pair();
            return (a, b, n);
        };
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

/// Everything a texel's samples read.
pub(super) struct Sampler<'a> {
    low: &'a Mesh,
    uv: &'a UvBake,
    high: &'a Mesh,
    cage: Option<&'a Mesh>,
    map: HighMap,
    front: f32,
    rear: f32,
    /// How far a ray that slipped between two triangles is moved to try again.
    nudge: f32,
    rays: &'a HighRays,
    directions: Directions,
    /// How far AO and thickness rays look (object units).
    far: f32,
    frames: Frames,
    /// The high mesh's curvature per vertex (curvature bakes).
    curvature: Vec<f32>,
    /// The high mesh's piece, object or material per triangle (ID bakes but by colour).
    parts: Vec<u32>,
    /// The low mesh's bounding box (position bakes).
    bounds: (Vec3, Vec3),
    /// Samples a texel's side (1, 2 or 4).
    grid: u32,
    /// Per low triangle, its corners' UVs in texels (grids of more than one sample).
    texel_uvs: Vec<[Vec2; 3]>,
}

impl<'a> Sampler<'a> {
    /// What `options` need of the meshes, with the distances `(size, front, rear)` (the
    /// default's size first).
    pub(super) fn new(
        (low, uv, high, cage): (&'a Mesh, &'a UvBake, &'a Mesh, Option<&'a Mesh>),
        rays: &'a HighRays,
        options: HighOptions,
        (size, front, rear): (f32, f32, f32),
    ) -> Self {
        let map = options.map;
        let far = match (map, options.max_distance) {
            (_, Some(d)) => d,
            (HighMap::Thickness, None) => rays.diagonal(),
            _ => f32::INFINITY,
        };
        let grid = options.samples.isqrt().max(1);
        let texel_uvs = match (&low.uvs, grid) {
            (Some(uvs), 2..) => {
                let (w, h) = (uv.width as f32, uv.height as f32);
                let at = |v: u32| {
                    let t = uvs.get(v as usize).copied().unwrap_or(Vec2::ZERO);
                    Vec2::new(t.x * w, (1.0 - t.y) * h)
                };
                low.triangles.iter().map(|t| t.map(at)).collect()
            }
            _ => Vec::new(),
        };
        let bounds = low.positions.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        Self {
            low,
            uv,
            high,
            cage,
            map,
            front,
            rear,
            nudge: size * 1e-4,
            directions: Directions::new(if map.casts_rays() { options.rays } else { 0 }),
            far,
            frames: Frames {
                tangents: (map == HighMap::Normal(NormalSpace::Tangent))
                    .then(|| crate::tangents::generate(low))
                    .flatten(),
            },
            curvature: if map == HighMap::Curvature {
                crate::bakes::vertex_curvature(high)
            } else {
                Vec::new()
            },
            parts: match map {
                HighMap::Id(IdSource::Piece) => high.parts(),
                HighMap::Id(IdSource::Object) => labelled(&high.labels.objects, high),
                HighMap::Id(IdSource::Material) => labelled(&high.labels.materials, high),
                _ => Vec::new(),
            },
            bounds,
            grid: if texel_uvs.is_empty() { 1 } else { grid },
            texel_uvs,
            rays,
        }
    }

    /// Texel `i`'s value into `out` (unorm16), and what its rays found; `None` (and `out` left
    /// alone) where the low mesh has no surface.
    pub(super) fn texel(&self, i: usize, out: &mut [u16]) -> Option<TexelFound> {
        let t = self.uv.triangle(i)?;
        let mut sum = Vec3::ZERO;
        let (mut missed, mut skew) = (false, 0.0_f32);
        // An ID is not averaged: the first sample's that met the high mesh.
        let mut id = None;
        let count = self.grid * self.grid;
        for k in 0..count {
            let (tri, w) = if count == 1 {
                (t, self.uv.barycentric(i))
            } else {
                self.sample_point(i, t, k)
            };
            let (value, found) = self.sample(tri, w);
            sum += value.value;
            missed |= !found;
            skew += value.skew_degrees;
            if found && id.is_none() {
                id = Some(value.value);
            }
        }
        let mean = sum / count as f32;
        let value = match self.map {
            HighMap::Normal(_) => mean.try_normalize().unwrap_or(Vec3::Z) * 0.5 + 0.5,
            HighMap::Id(_) => id.unwrap_or(Vec3::ZERO),
            _ => mean,
        };
        let unorm = |v: f32| (v.clamp(0.0, 1.0) * 65535.0).round() as u16;
        for (o, c) in out.iter_mut().zip(value.to_array()) {
            *o = unorm(c);
        }
        Some(TexelFound {
            missed,
            skew_degrees: skew / count as f32,
        })
    }

    /// The batch the queries of `queries` make: the direction set, how far (local units),
    /// what is measured.
    pub(super) fn batch<'q>(&'q self, queries: &'q [RayQuery]) -> RayBatch<'q> {
        RayBatch {
            queries,
            directions: self.directions.as_slice(),
            far: self.rays.local_length(self.far),
            kind: if self.map == HighMap::Ao {
                RayKind::Open
            } else {
                RayKind::Depth
            },
        }
    }

    /// Samples a texel takes.
    pub(super) fn samples(&self) -> usize {
        (self.grid * self.grid) as usize
    }

    /// Texel `i`'s AO or thickness rays, a query per sample into `out` ([`Self::samples`]
    /// long), and what its projection rays found; `None` where the low mesh has no surface.
    pub(super) fn texel_queries(&self, i: usize, out: &mut [RayQuery]) -> Option<TexelFound> {
        let t = self.uv.triangle(i)?;
        let (mut missed, mut skew) = (false, 0.0_f32);
        let count = self.grid * self.grid;
        for (k, query) in (0..count).zip(out.iter_mut()) {
            let (tri, w) = if count == 1 {
                (t, self.uv.barycentric(i))
            } else {
                self.sample_point(i, t, k)
            };
            let seen = self.project(tri, w);
            missed |= seen.found.is_none();
            skew += seen.skew_degrees;
            *query = self.query(&seen, i * 16 + k as usize);
        }
        Some(TexelFound {
            missed,
            skew_degrees: skew / count as f32,
        })
    }

    /// The AO or thickness rays of a sample that saw `seen`: from the point met, on the high
    /// mesh, about the high triangle's face normal (its opposite for thickness); where nothing
    /// was met, from the low point about the low face. `seed` turns the set.
    fn query(&self, seen: &Seen<'_>, seed: usize) -> RayQuery {
        let (q, g) = seen.found.map_or((seen.p, seen.face), |(q, tri, _)| {
            let c = self.high.triangles[tri as usize].map(|v| self.high.positions[v as usize]);
            (q, geometric_normal(c, high_normal(self.high, tri, q)))
        });
        let normal = if self.map == HighMap::Ao { g } else { -g };
        match seen.rays {
            Some((rays, group)) => rays.query(q, normal, turn_of(seed), group),
            None => RayQuery {
                group: RayQuery::NONE,
                ..RayQuery::default()
            },
        }
    }

    /// Sample `k` of texel `i` (whose triangle is `t`) on a grid across it: the triangle under
    /// the point among the texel's and its four neighbours' (the nearest where none is), and
    /// the barycentric weights there.
    fn sample_point(&self, i: usize, t: u32, k: u32) -> (u32, Vec3) {
        let w = self.uv.width as usize;
        let (x, y) = ((i % w) as f32, (i / w) as f32);
        let g = self.grid as f32;
        let p = Vec2::new(
            x + ((k % self.grid) as f32 + 0.5) / g,
            y + ((k / self.grid) as f32 + 0.5) / g,
        );
        let neighbours = [i.checked_sub(1), Some(i + 1), i.checked_sub(w), Some(i + w)];
        let mut best = (t, Vec3::new(1.0, 0.0, 0.0), f32::INFINITY);
        for tri in std::iter::once(Some(t))
            .chain(neighbours.map(|n| {
                n.filter(|&n| n < self.uv.len())
                    .and_then(|n| self.uv.triangle(n))
            }))
            .flatten()
        {
            let [a, b, c] = self.texel_uvs[tri as usize];
            let (bary, d2) = crate::bake::nearest_barycentric(p, a, b, c);
            if d2 < best.2 {
                best = (tri, bary, d2);
            }
            if d2 == 0.0 {
                break;
            }
        }
        (best.0, best.1)
    }

    /// What a sample at barycentric `w` of low triangle `t` sees: its ray (from the cage's
    /// point towards the low one, or from `front` above along the normal) and the high
    /// triangle it met.
    fn project(&self, t: u32, w: Vec3) -> Seen<'a> {
        let tri = self.low.triangles[t as usize].map(|v| v as usize);
        let corners = tri.map(|v| self.low.positions[v]);
        let p = corners[0] * w.x + corners[1] * w.y + corners[2] * w.z;
        let normals = self.uv.corner_normals(t);
        let n = (normals[0] * w.x + normals[1] * w.y + normals[2] * w.z)
            .try_normalize()
            .unwrap_or(normals[0]);
        // `to_low` is how far along the ray the low surface lies.
        let (origin, dir, to_low) = self
            .cage
            .and_then(|cage| {
                let c = tri.map(|v| cage.positions[v]);
                let from = c[0] * w.x + c[1] * w.y + c[2] * w.z;
                let d = p - from;
                let len = d.length();
                (len > self.nudge).then(|| (from, d / len, len))
            })
            .unwrap_or((p + n * self.front, -n, self.front));
        let rays = self.rays.for_low(t);
        let found = rays.and_then(|(r, _)| cast(r, origin, dir, to_low + self.rear, self.nudge));
        let face = geometric_normal(corners, n);
        Seen {
            t,
            w,
            p,
            n,
            face,
            to_low,
            found,
            rays,
            skew_degrees: (-dir).dot(face).clamp(-1.0, 1.0).acos().to_degrees(),
        }
    }

    /// One sample at barycentric `w` of low triangle `t`: its value (a vector, or a scalar
    /// in `x`) and whether its ray met the high mesh. AO and thickness are cast in batches
    /// instead ([`Self::texel_queries`]).
    fn sample(&self, t: u32, w: Vec3) -> (SampleValue, bool) {
        let seen = self.project(t, w);
        let (p, n, found) = (seen.p, seen.n, seen.found);
        let value = match self.map {
            HighMap::Height => {
                let above = found.map_or(0.0, |(_, _, d)| seen.to_low - d);
                Vec3::splat((above + self.rear) / (self.front + self.rear))
            }
            HighMap::Normal(space) => {
                let normal = found.map_or(n, |(q, tri, _)| high_normal(self.high, tri, q));
                match space {
                    NormalSpace::Object => normal,
                    NormalSpace::Tangent => {
                        let (ta, bi, no) = self.frames.at(seen.t, seen.w, n);
                        Vec3::new(normal.dot(ta), normal.dot(bi), normal.dot(no))
                    }
                }
            }
            // Cast in batches (`texel_queries`): never asked here.
            HighMap::Ao | HighMap::Thickness => Vec3::ONE,
            HighMap::Curvature => {
                let k = found.map_or(0.0, |(q, tri, _)| {
                    let b = barycentric_on(self.high, tri, q);
                    let [ka, kb, kc] =
                        self.high.triangles[tri as usize].map(|v| self.curvature[v as usize]);
                    ka * b.x + kb * b.y + kc * b.z
                });
                Vec3::splat(0.5 + 0.5 * k)
            }
            HighMap::Id(IdSource::Color) => found.map_or(Vec3::ZERO, |(q, tri, _)| {
                let colors = self.high.labels.colors.as_deref().unwrap_or(&[]);
                let b = barycentric_on(self.high, tri, q);
                let [ca, cb, cc] = self.high.triangles[tri as usize]
                    .map(|v| colors.get(v as usize).copied().unwrap_or(Vec3::ONE));
                ca * b.x + cb * b.y + cc * b.z
            }),
            HighMap::Id(_) => found.map_or(Vec3::ZERO, |(_, tri, _)| {
                part_colour(self.parts.get(tri as usize).copied().unwrap_or(0))
            }),
            HighMap::Position => {
                let q = found.map_or(p, |(q, _, _)| q);
                let (lo, hi) = self.bounds;
                (q - lo) / (hi - lo).max(Vec3::splat(f32::MIN_POSITIVE))
            }
        };
        (
            SampleValue {
                value,
                skew_degrees: seen.skew_degrees,
            },
            found.is_some(),
        )
    }
}

/// What one sample's projection ray saw.
struct Seen<'r> {
    /// The low triangle and the barycentric weights on it.
    t: u32,
    w: Vec3,
    /// The low point, its smooth normal and its face's normal.
    p: Vec3,
    n: Vec3,
    face: Vec3,
    /// How far along the ray the low surface lies.
    to_low: f32,
    /// The point met, the high triangle there and how far along the ray.
    found: Option<(Vec3, u32, f32)>,
    /// The BVH the low triangle's rays meet, and its group.
    rays: Option<(&'r RayMesh, u32)>,
    /// The angle between the ray and the low face's normal (degrees).
    skew_degrees: f32,
}

/// A sample's value and the skew of its ray.
struct SampleValue {
    value: Vec3,
    skew_degrees: f32,
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

/// The barycentric weights of point `q` on `mesh`'s triangle `t` (a third each where it has
/// no area).
fn barycentric_on(mesh: &Mesh, t: u32, q: Vec3) -> Vec3 {
    let [a, b, c] = mesh.triangles[t as usize].map(|v| mesh.positions[v as usize]);
    let face = (b - a).cross(c - a);
    let area = face.length_squared();
    if area > 0.0 {
        let wa = (b - q).cross(c - q).dot(face) / area;
        let wb = (c - q).cross(a - q).dot(face) / area;
        Vec3::new(wa, wb, 1.0 - wa - wb)
    } else {
        Vec3::splat(1.0 / 3.0)
    }
}

/// The normal of `mesh`'s triangle `t` at point `q` on it: its vertex normals interpolated
/// (the face's normal where they cancel).
fn high_normal(mesh: &Mesh, t: u32, q: Vec3) -> Vec3 {
    let tri = mesh.triangles[t as usize].map(|v| v as usize);
    let w = barycentric_on(mesh, t, q);
    let [a, b, c] = tri.map(|v| mesh.positions[v]);
    let [na, nb, nc] = tri.map(|v| mesh.normals.get(v).copied().unwrap_or(Vec3::ZERO));
    (na * w.x + nb * w.y + nc * w.z)
        .try_normalize()
        .or_else(|| (b - a).cross(c - a).try_normalize())
        .unwrap_or(Vec3::Z)
}

/// Per triangle of `mesh`, the number of its run's name in order of first appearance (a
/// triangle no run names counts as one more name).
fn labelled(runs: &[crate::Run], mesh: &Mesh) -> Vec<u32> {
    let named = Named::of(runs, mesh.triangles.len());
    let none = named.names.len() as u32;
    named
        .of_triangle
        .into_iter()
        .map(|k| if k == Named::NONE { none } else { k })
        .collect()
}

/// Part `k`'s colour in an ID map: hues a golden angle apart (neighbouring parts far apart on
/// the wheel), bright and fairly saturated.
pub(super) fn part_colour(k: u32) -> Vec3 {
    let hue = (k as f32 * 0.618_034).fract() * 6.0;
    let (s, v) = (0.7, 0.95);
    let f = hue.fract();
    let (p, q, t) = (v * (1.0 - s), v * (1.0 - s * f), v * (1.0 - s * (1.0 - f)));
    match hue as u32 {
        0 => Vec3::new(v, t, p),
        1 => Vec3::new(q, v, p),
        2 => Vec3::new(p, v, t),
        3 => Vec3::new(p, q, v),
        4 => Vec3::new(t, p, v),
        _ => Vec3::new(v, p, q),
    }
}
