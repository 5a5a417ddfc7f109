//! Maps baked from the mesh at every texel the UV bake gives a surface point: ambient
//! occlusion, thickness, curvature, object-space position and normal. They describe the mesh,
//! not the material: masks and fills are made from them, and nothing here is painted.
//!
//! Occlusion and thickness cast rays against a BVH of the mesh (`obvhs`' compressed wide
//! BVH). Directions are a Hammersley set, cosine-weighted around the texel's geometric normal
//! (AO) or its opposite (thickness), turned about the normal by a hashed angle per texel so
//! neighbouring texels do not share their errors. A bake holds 2 bytes a texel
//! per channel and nothing per ray.

use glam::{Vec3, Vec3A};
use kapaint_base::task::Progress;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::Ray;
use obvhs::triangle::Triangle;
use rayon::prelude::*;

use crate::Mesh;
use crate::bake::{Coverage, UvBake};

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

/// A BVH of the mesh for occlusion and distance rays.
pub struct RayMesh {
    bvh: CwBvh,
    /// The triangles in the BVH's order (no lookup through its primitive indices per test).
    triangles: Vec<Triangle>,
    /// The bounding box's diagonal.
    pub diagonal: f32,
}

impl RayMesh {
    /// Builds the BVH of `mesh`'s triangles.
    pub fn new(mesh: &Mesh) -> Self {
        let triangles: Vec<Triangle> = mesh
            .triangles
            .iter()
            .map(|t| {
                let [v0, v1, v2] = t.map(|i| Vec3A::from(mesh.positions[i as usize]));
                Triangle { v0, v1, v2 }
            })
            .collect();
        // A slower build for fewer node visits: a mesh is built once and cast millions of
        // rays at.
        let bvh = obvhs::cwbvh::builder::build_cwbvh_from_tris(
            &triangles,
            obvhs::BvhBuildParams::slow_build(),
            &mut std::time::Duration::default(),
        );
        let triangles = bvh
            .primitive_indices
            .iter()
            .map(|&i| triangles[i as usize])
            .collect();
        let (lo, hi) = mesh.bounds();
        Self {
            bvh,
            triangles,
            diagonal: (hi - lo).length(),
        }
    }

    /// Whether a ray from `origin` along unit `dir` meets the mesh before `far`.
    pub fn occluded(&self, origin: Vec3, dir: Vec3, far: f32) -> bool {
        let ray = Ray::new(origin.into(), dir.into(), 0.0, far);
        !self
            .bvh
            .ray_traverse_miss(ray, |ray, id| self.triangles[id].intersect(ray))
    }

    /// The distance along a ray from `origin` along unit `dir` to the mesh, if it meets it
    /// before `far`.
    pub fn distance(&self, origin: Vec3, dir: Vec3, far: f32) -> Option<f32> {
        let ray = Ray::new(origin.into(), dir.into(), 0.0, far);
        let mut hit = obvhs::ray::RayHit::none();
        self.bvh
            .ray_traverse(ray, &mut hit, |ray, id| self.triangles[id].intersect(ray))
            .then_some(hit.t)
    }

    /// The cosine-weighted fraction of the `set`'s directions around unit `normal` from
    /// `point` that meet nothing before `far`; the set is turned by `turn` about the normal.
    pub fn open_fraction(
        &self,
        point: Vec3,
        normal: Vec3,
        set: &Directions,
        far: f32,
        turn: f32,
    ) -> f32 {
        let origin = point + normal * self.offset();
        let open = set
            .around(normal, turn)
            .filter(|&dir| !self.occluded(origin, dir, far))
            .count();
        open as f32 / set.len() as f32
    }

    /// The mean of `min(distance, far) / far` over the `set`'s directions around unit
    /// `normal` from `point`, turned by `turn`.
    pub fn mean_distance(
        &self,
        point: Vec3,
        normal: Vec3,
        set: &Directions,
        far: f32,
        turn: f32,
    ) -> f32 {
        let origin = point + normal * self.offset();
        let sum: f32 = set
            .around(normal, turn)
            .map(|dir| self.distance(origin, dir, far).map_or(1.0, |t| t / far))
            .sum();
        sum / set.len() as f32
    }

    /// How far a ray starts off the surface: clear of the triangle it leaves, close enough to
    /// see a neighbour.
    fn offset(&self) -> f32 {
        self.diagonal * 1e-5
    }
}

/// A cosine-weighted Hammersley set of directions about `+z`, made once per bake; each texel
/// turns it about its own normal.
pub struct Directions(Vec<Vec3>);

impl Directions {
    /// `n` directions.
    pub fn new(n: u32) -> Self {
        Self(
            (0..n)
                .map(|k| {
                    let u = (k as f32 + 0.5) / n as f32;
                    let v = k.reverse_bits() as f32 / 4_294_967_296.0;
                    let r = u.sqrt();
                    let phi = std::f32::consts::TAU * v;
                    Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u).max(0.0).sqrt())
                })
                .collect(),
        )
    }

    /// How many.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The set about unit `normal`, turned by `turn` (a fraction of a full turn).
    fn around(&self, normal: Vec3, turn: f32) -> impl Iterator<Item = Vec3> + '_ {
        let (t, b) = normal.any_orthonormal_pair();
        let (sin, cos) = (std::f32::consts::TAU * turn).sin_cos();
        let (t, b) = (t * cos + b * sin, b * cos - t * sin);
        self.0.iter().map(move |d| t * d.x + b * d.y + normal * d.z)
    }
}

/// A per-texel turn in `[0, 1)` from a hash of its index.
fn turn_of(i: usize) -> f32 {
    let mut h = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    h ^= h >> 29;
    h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    h ^= h >> 32;
    (h & 0x00FF_FFFF) as f32 / 16_777_216.0
}

/// The unit geometric normal of texel `i`'s triangle, turned to the side its shading normal
/// faces.
/// A triangle with no area (a sphere's pole) gives the shading normal.
fn geometric_normal(uv: &UvBake, i: usize, t: u32) -> Vec3 {
    let [a, b, c] = uv.corners(t);
    let shading = uv.normal(i);
    match (b - a).cross(c - a).try_normalize() {
        Some(n) if n.dot(shading) < 0.0 => -n,
        Some(n) => n,
        None => shading.normalize_or(Vec3::Z),
    }
}

/// Rows baked between progress reports and cancel checks.
const BAND_ROWS: usize = 8;

/// What one bake needs at every texel.
struct Baker<'a> {
    mesh: &'a Mesh,
    uv: &'a UvBake,
    map: BakeMap,
    far: f32,
    ray_mesh: Option<RayMesh>,
    directions: Directions,
    curvature: Option<Vec<f32>>,
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
        match self.map {
            BakeMap::Ao | BakeMap::Thickness => {
                let value = self.ray_mesh.as_ref().map_or(1.0, |r| {
                    let n = geometric_normal(uv, i, t);
                    let p = uv.position(i);
                    let set = &self.directions;
                    if self.map == BakeMap::Ao {
                        r.open_fraction(p, n, set, self.far, turn_of(i))
                    } else {
                        r.mean_distance(p, -n, set, self.far, turn_of(i))
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
                let p = (uv.position(i) - lo) / (hi - lo).max(Vec3::splat(f32::MIN_POSITIVE));
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

/// Bakes `map` at every texel `uv` gives a surface point (padding texels included, so seams
/// are padded like the maps). `progress` counts rows and cancels.
///
/// # Errors
/// Rays out of range, a maximum distance that is not a positive number, or cancelled.
pub fn bake_map(
    mesh: &Mesh,
    uv: &UvBake,
    map: BakeMap,
    options: BakeOptions,
    progress: Option<&Progress>,
) -> Result<Baked, String> {
    check(map, options)?;
    let (w, h) = (uv.width as usize, uv.height as usize);
    let channels = map.channels();
    let ray_mesh = map.casts_rays().then(|| RayMesh::new(mesh));
    let far = match (map, options.max_distance) {
        (_, Some(d)) => d,
        (BakeMap::Thickness, None) => ray_mesh.as_ref().map_or(1.0, |r| r.diagonal),
        _ => f32::INFINITY,
    };
    let baker = Baker {
        mesh,
        uv,
        map,
        far,
        ray_mesh,
        directions: Directions::new(if map.casts_rays() { options.rays } else { 0 }),
        curvature: (map == BakeMap::Curvature).then(|| vertex_curvature(mesh)),
        bounds: mesh.bounds(),
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
        return Err("cancelled".into());
    }
    Ok(Baked {
        map,
        options,
        mesh_hash: mesh.content_hash(),
        width: uv.width,
        height: uv.height,
        data,
    })
}

/// Units of the curvature map: a mean curvature of `CURVATURE_SCALE` over the bounding box's
/// diagonal (a bump of radius 1/32 of the mesh) reaches 1 (convex) or 0 (concave).
pub const CURVATURE_SCALE: f32 = 32.0;

/// Signed mean curvature per vertex, in units of [`CURVATURE_SCALE`] over the mesh's
/// diagonal, clamped to `[-1, 1]`: positive convex, negative concave, 0 flat. Vertices at one
/// position count as one (a UV seam does not cut the surface); per edge, the normals' spread
/// along it over its length squared, averaged around the vertex.
pub fn vertex_curvature(mesh: &Mesh) -> Vec<f32> {
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
        position[g] = mesh.positions[v];
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
            if a == b || len2 <= 0.0 {
                continue;
            }
            let k_edge = (normal[b] - normal[a]).dot(d) / len2;
            for v in [a, b] {
                sum[v] += k_edge;
                count[v] += 1;
            }
        }
    }
    let (lo, hi) = mesh.bounds();
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
mod tests {
    use super::*;
    use crate::bake::bake;

    /// A floor (y = 0, z from 0 to 50) beside a wall (z = 0, height `h`), both 2000 long.
    fn floor_and_wall(h: f32) -> Mesh {
        let l = 1000.0;
        let positions = vec![
            Vec3::new(-l, 0.0, 0.0),
            Vec3::new(l, 0.0, 0.0),
            Vec3::new(l, 0.0, 50.0),
            Vec3::new(-l, 0.0, 50.0),
            Vec3::new(-l, 0.0, 0.0),
            Vec3::new(l, 0.0, 0.0),
            Vec3::new(l, h, 0.0),
            Vec3::new(-l, h, 0.0),
        ];
        Mesh {
            name: "floor and wall".into(),
            normals: [[Vec3::Y; 4], [Vec3::Z; 4]].concat(),
            positions,
            uvs: None,
            triangles: vec![[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7]],
            had_normals: true,
        }
    }

    #[test]
    fn a_floor_beside_a_wall_sees_what_geometry_says() {
        let h = 1.0;
        let rays = RayMesh::new(&floor_and_wall(h));
        for d in [0.25_f32, 1.0, 4.0] {
            let want = 0.5 * (1.0 + d / (d * d + h * h).sqrt());
            // Averaged over a few turns, as neighbouring texels would be.
            let set = Directions::new(256);
            let got: f32 = (0..8)
                .map(|k| {
                    rays.open_fraction(
                        Vec3::new(0.0, 0.0, d),
                        Vec3::Y,
                        &set,
                        f32::INFINITY,
                        turn_of(k),
                    )
                })
                .sum::<f32>()
                / 8.0;
            assert!((got - want).abs() < 0.02, "d {d}: {got} vs {want}");
        }
    }

    #[test]
    fn the_sphere_is_open_sky_everywhere_and_its_maps_are_what_a_sphere_is() {
        let sphere = crate::uv_sphere(64, 32);
        let uv = bake(&sphere, 128, 128, 2).expect("bakes");
        let ao_map = bake_map(
            &sphere,
            &uv,
            BakeMap::Ao,
            BakeOptions {
                rays: 256,
                max_distance: None,
            },
            None,
        )
        .expect("ao");
        assert_eq!(ao_map.mesh_hash, sphere.content_hash());
        let ao = ao_map.stats(&uv);
        assert!(ao.texels > 10_000);
        assert!(ao.min >= 0.99, "min AO {}", ao.min);
        assert_eq!(ao.rays_cast, ao.texels * 256);
        let k = bake_map(
            &sphere,
            &uv,
            BakeMap::Curvature,
            BakeOptions::default(),
            None,
        )
        .expect("curvature")
        .stats(&uv);
        assert!(k.min > 0.5, "a sphere is convex everywhere: {}", k.min);
        // Inward, the far side is 2 R cos(theta) away: a cosine-weighted mean of 4R/3 over
        // the diagonal 2 sqrt(3) R.
        let t = bake_map(
            &sphere,
            &uv,
            BakeMap::Thickness,
            BakeOptions {
                rays: 64,
                max_distance: None,
            },
            None,
        )
        .expect("thickness")
        .stats(&uv);
        let want = 2.0 / (3.0 * 3.0_f32.sqrt());
        assert!(
            (t.mean - want).abs() < 0.02,
            "thickness {} vs {want}",
            t.mean
        );
        let n =
            bake_map(&sphere, &uv, BakeMap::Normal, BakeOptions::default(), None).expect("normal");
        let p = bake_map(
            &sphere,
            &uv,
            BakeMap::Position,
            BakeOptions::default(),
            None,
        )
        .expect("position");
        for i in (0..uv.len()).filter(|&i| uv.coverage(i) == Coverage::Surface) {
            let normal = Vec3::new(n.value(i, 0), n.value(i, 1), n.value(i, 2)) * 2.0 - 1.0;
            let position = Vec3::new(p.value(i, 0), p.value(i, 1), p.value(i, 2)) * 2.0 - 1.0;
            // The unit sphere: the normal points where the point is.
            assert!(
                (normal - position).length() < 0.05,
                "{normal} vs {position}"
            );
        }
    }

    #[test]
    fn a_flat_plane_is_open_and_flat() {
        let plane = crate::plane();
        let uv = bake(&plane, 64, 64, 2).expect("bakes");
        let ao = bake_map(
            &plane,
            &uv,
            BakeMap::Ao,
            BakeOptions {
                rays: 16,
                max_distance: None,
            },
            None,
        )
        .expect("ao")
        .stats(&uv);
        assert_eq!(ao.min, 1.0);
        let k = bake_map(
            &plane,
            &uv,
            BakeMap::Curvature,
            BakeOptions::default(),
            None,
        )
        .expect("curvature")
        .stats(&uv);
        assert!((k.min - 0.5).abs() < 1e-4 && (k.mean - 0.5).abs() < 1e-4);
    }

    #[test]
    fn bad_values_and_cancel_are_errors() {
        let sphere = crate::uv_sphere(16, 8);
        let uv = bake(&sphere, 32, 32, 2).expect("bakes");
        for rays in [0, 65_537] {
            let e = bake_map(
                &sphere,
                &uv,
                BakeMap::Ao,
                BakeOptions {
                    rays,
                    max_distance: None,
                },
                None,
            )
            .expect_err("rays out of range");
            assert!(e.contains("outside 1 to 65536"), "{e}");
        }
        for d in [f32::NAN, 0.0, -1.0, f32::INFINITY] {
            assert!(
                bake_map(
                    &sphere,
                    &uv,
                    BakeMap::Ao,
                    BakeOptions {
                        rays: 4,
                        max_distance: Some(d)
                    },
                    None
                )
                .is_err()
            );
        }
        let progress = Progress::default();
        progress.cancel();
        let e = bake_map(
            &sphere,
            &uv,
            BakeMap::Ao,
            BakeOptions::default(),
            Some(&progress),
        )
        .expect_err("cancelled");
        assert_eq!(e, "cancelled");
    }
}
