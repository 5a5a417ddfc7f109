//! The ray-traced reference of the ambient term: per pixel, the same per-view integral as
//! `k_a` per view ([`kapaint_reflectance::view`]), with each light direction masked by whether a
//! ray from the surface point along it escapes the mesh. It is what backward ray tracing of the
//! scattered light would compute, and what `k_a` stands in for.
//!
//! The integral is the paper's: the mean over the box `theta in [0, pi/2]`, `gamma in [-pi,
//! pi]` (plain angle measure) of `k_d cos theta + k_s rho_s (+ Cook-Torrance's second part)`,
//! in the frame of the pixel's normal with the eye at `gamma = 0` (so the mirror direction is
//! at `gamma = pi`). It is estimated by progressive Monte Carlo: every pass adds samples to
//! every pixel, each sample one direction and one shadow ray, drawn by one of three strategies
//! combined by the balance heuristic:
//! - the diffuse part's own shape: `sin theta` uniform, `gamma` uniform (density
//!   `cos theta / 2 pi` in the box);
//! - the specular lobe: `theta` and then `gamma` from Cauchy distributions about the mirror
//!   direction, as wide as the lobe (truncated to the box);
//! - the whole box, uniformly (a tenth of the samples), so no direction has a vanishing
//!   density.
//!
//! The first two are chosen in proportion to the parts' unshadowed values (known from the
//! per-view table). Directions come from a three-dimensional Kronecker sequence shifted per
//! pixel (Cranley-Patterson), so a pixel's samples are evenly spread. Without anything in the
//! way (a convex mesh, an open plane) the estimate converges to `k_a` per view.

use glam::{Vec2, Vec3, Vec4};
use rayon::prelude::*;

use super::reference::Material;
use super::{FrameSettings, VIEW_ERROR_TOP, ViewMode, heat_ramp, relative_error};
use kapaint_mesh::Mesh;
use kapaint_mesh::bakes::RayMesh;
use kapaint_mesh::pick::Bvh;
use kapaint_reflectance::{self as reflectance, ShadingModel};

/// The most samples per pixel a traced view takes (`kapaint render --samples` refuses more).
pub const MAX_SAMPLES: u32 = 1 << 20;

/// The share of samples drawn uniformly over the box.
const UNIFORM_SHARE: f32 = 0.1;

/// Bytes a traced view holds per pixel of its image (besides the BVH).
pub const fn bytes_per_pixel() -> u64 {
    (std::mem::size_of::<Option<Point>>() + std::mem::size_of::<Sums>()) as u64
}

/// Bytes the shadow rays' BVH of a mesh of `triangles` triangles takes (its triangles, twice
/// while it is built, and its nodes): what is checked against the memory left before tracing.
pub fn ray_mesh_bytes(triangles: usize) -> u64 {
    triangles as u64 * 160
}

/// One covered pixel: its surface point, the frame the box is measured in, its material and
/// how its samples are shared between the strategies.
#[derive(Clone, Copy, Debug)]
struct Point {
    /// Where the shadow rays start: the hit, a little off the surface.
    origin: Vec3,
    /// The triangle's own normal (what the AO bake casts about).
    face: Vec3,
    normal: Vec3,
    to_eye: Vec3,
    kd: Vec3,
    ks: Vec3,
    n: f32,
    /// The shares of the diffuse and the specular strategies (the rest is uniform).
    shares: [f32; 2],
    /// Per-pixel shift of the sequence.
    shift: [f32; 3],
    /// The texture coordinate (mesh convention: v up).
    uv: Vec2,
}

/// A pixel's running sums: the estimates, the squares of their channel means, and how many.
#[derive(Clone, Copy, Debug, Default)]
struct Sums {
    sum: Vec3,
    square: f32,
    count: u32,
}

/// A traced view in progress (see the module's doc).
pub struct Traced {
    model: ShadingModel,
    width: u32,
    height: u32,
    points: Vec<Option<Point>>,
    sums: Vec<Sums>,
    far: f32,
    /// The AO bake at every pixel, once [`Traced::set_ao_bake`] has read it.
    ao: Option<Vec<Option<f32>>>,
}

impl std::fmt::Debug for Traced {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Traced")
            .field("width", &self.width)
            .field("height", &self.height)
            .field("samples", &self.samples())
            .finish_non_exhaustive()
    }
}

impl Traced {
    /// A traced view of `settings`' camera and model over a `width x height` image: one
    /// primary ray per pixel centre through `bvh`, the material sampled as the reference
    /// renderer samples it; no samples yet. `rays` is `mesh`'s shadow-ray BVH.
    pub fn new(
        (mesh, bvh, rays): (&Mesh, &Bvh, &RayMesh),
        material: &Material<'_>,
        settings: &FrameSettings,
        width: u32,
        height: u32,
    ) -> Self {
        let eye = settings.camera.eye();
        let offset = rays.diagonal * 1e-5;
        let model = settings.model;
        let points = (0..width * height)
            .into_par_iter()
            .map(|i| {
                let (px, py) = ((i % width) as f32, (i / width) as f32);
                let (origin, dir) = settings.camera.ray(px, py, width, height);
                let hit = bvh.pick(mesh, origin, dir)?;
                let [a, b, c] =
                    mesh.triangles[hit.triangle as usize].map(|v| mesh.positions[v as usize]);
                let face = (b - a).cross(c - a).try_normalize().unwrap_or(hit.normal);
                let face = if face.dot(hit.normal) < 0.0 {
                    -face
                } else {
                    face
                };
                let m = material.sample(hit.uv.unwrap_or(Vec2::ZERO));
                let kd = m.kd.map(reflectance::sanitize_coefficient);
                let ks = m.ks.map(reflectance::sanitize_coefficient);
                let n = reflectance::sanitize_n_f32(m.n);
                let to_eye = (eye - hit.position).normalize_or_zero();
                let phi = hit.normal.dot(to_eye).clamp(0.0, 1.0).acos();
                let [c1, c0] = reflectance::view::chi_view_fast(
                    model,
                    n.min(reflectance::view::VIEW_N_MAX),
                    phi,
                )
                .unwrap_or([0.0; 2]);
                let diffuse = reflectance::TWO_OVER_PI as f32 * kd.element_sum() / 3.0;
                let specular = ks.element_sum() / 3.0 * c1 + c0;
                let lobes = 1.0 - UNIFORM_SHARE;
                let shares = if diffuse + specular > 0.0 {
                    let d = lobes * diffuse / (diffuse + specular);
                    [d, lobes - d]
                } else {
                    [0.0, 0.0]
                };
                Some(Point {
                    origin: hit.position + face * offset,
                    face,
                    normal: hit.normal,
                    to_eye,
                    kd,
                    ks,
                    n,
                    shares,
                    shift: shift(i),
                    uv: hit.uv.unwrap_or(Vec2::ZERO),
                })
            })
            .collect::<Vec<_>>();
        let sums = vec![Sums::default(); points.len()];
        Self {
            model,
            width,
            height,
            points,
            sums,
            far: rays.diagonal * 2.0,
            ao: None,
        }
    }

    /// Reads the AO bake at every pixel's texture coordinate (its nearest texel), for the AO
    /// stand-in's error view ([`ViewMode::KaAoTracedError`]).
    pub fn set_ao_bake(&mut self, bake: &kapaint_mesh::bakes::Baked) {
        let (w, h) = (bake.width, bake.height);
        self.ao = Some(
            self.points
                .iter()
                .map(|p| {
                    let p = p.as_ref()?;
                    let x = ((p.uv.x.clamp(0.0, 1.0) * w as f32) as u32).min(w.max(1) - 1);
                    let y = (((1.0 - p.uv.y).clamp(0.0, 1.0) * h as f32) as u32).min(h.max(1) - 1);
                    let i = (y * w + x) as usize;
                    (i * bake.map.channels() < bake.data.len()).then(|| bake.value(i, 0))
                })
                .collect(),
        );
    }

    /// The image size.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Samples every covered pixel holds (the fewest, after a stopped pass).
    pub fn samples(&self) -> u32 {
        self.points
            .iter()
            .zip(&self.sums)
            .filter(|(p, _)| p.is_some())
            .map(|(_, s)| s.count)
            .min()
            .unwrap_or(0)
    }

    /// Adds `samples` samples to every covered pixel, in parallel, tracing against `rays`.
    /// `stop` is asked between blocks of pixels; a pass it stops leaves some pixels with
    /// fewer samples (each pixel's mean stays its own). Returns whether the pass finished.
    pub fn pass(&mut self, rays: &RayMesh, samples: u32, stop: &(dyn Fn() -> bool + Sync)) -> bool {
        const BLOCK: usize = 256;
        let (model, far) = (self.model, self.far);
        let stopped = std::sync::atomic::AtomicBool::new(false);
        self.points
            .par_chunks(BLOCK)
            .zip(self.sums.par_chunks_mut(BLOCK))
            .for_each(|(points, sums)| {
                if stopped.load(std::sync::atomic::Ordering::Relaxed) || stop() {
                    stopped.store(true, std::sync::atomic::Ordering::Relaxed);
                    return;
                }
                for (point, sum) in points.iter().zip(sums) {
                    let Some(p) = point else { continue };
                    for _ in 0..samples {
                        let e = estimate(model, p, sum.count, rays, far);
                        sum.sum += e;
                        let m = e.element_sum() / 3.0;
                        sum.square += m * m;
                        sum.count += 1;
                    }
                }
            });
        !stopped.into_inner()
    }

    /// The traced `k_a`, linear RGBA rows from the top (alpha 0 where no surface).
    pub fn ka(&self) -> Vec<Vec4> {
        self.points
            .iter()
            .zip(&self.sums)
            .map(|(p, s)| match p {
                Some(_) if s.count > 0 => (s.sum / s.count as f32).extend(1.0),
                Some(_) => Vec4::new(0.0, 0.0, 0.0, 1.0),
                None => Vec4::ZERO,
            })
            .collect()
    }

    /// The traced error: the relative difference of the live `k_a` of `settings` (its model
    /// and approximation) from the traced one, as the heatmap of the view-average error (0 to
    /// [`VIEW_ERROR_TOP`]), linear RGBA.
    pub fn error(&self, settings: &FrameSettings) -> Vec<Vec4> {
        self.error_with(settings, None)
    }

    /// [`Traced::error`] of the live `k_a` times `ao` (per pixel) where given.
    fn error_with(&self, settings: &FrameSettings, ao: Option<&[Option<f32>]>) -> Vec<Vec4> {
        self.points
            .iter()
            .zip(&self.sums)
            .enumerate()
            .map(|(i, (p, s))| match p {
                Some(p) => {
                    let live = reflectance::ka(settings.model, settings.approx, p.kd, p.ks, p.n);
                    let scale = ao.map_or(1.0, |ao| ao.get(i).copied().flatten().unwrap_or(1.0));
                    let traced = s.sum / s.count.max(1) as f32;
                    heat_ramp(relative_error(live * scale, traced) / VIEW_ERROR_TOP).extend(1.0)
                }
                None => Vec4::ZERO,
            })
            .collect()
    }

    /// The picture of `view` ([`ViewMode::KaTraced`] or [`ViewMode::TracedError`]); `None`
    /// for another view.
    pub fn image(&self, view: ViewMode, settings: &FrameSettings) -> Option<Vec<Vec4>> {
        match view {
            ViewMode::KaTraced => Some(self.ka()),
            ViewMode::TracedError => Some(self.error(settings)),
            ViewMode::KaAoTracedError => self
                .ao
                .as_ref()
                .map(|ao| self.error_with(settings, Some(ao))),
            _ => None,
        }
    }

    /// The AO stand-in at every pixel (`None` where no surface): what the AO bake holds at the
    /// pixel's surface point, the cosine-weighted fraction of `rays` directions about the
    /// triangle's normal that escape the mesh.
    pub fn ambient_occlusion(&self, mesh: &RayMesh, rays: u32) -> Vec<Option<f32>> {
        let set = kapaint_mesh::bakes::Directions::new(rays);
        let far = self.far;
        self.points
            .par_iter()
            .map(|p| {
                p.map(|p| {
                    let turn = p.shift[0] * std::f32::consts::TAU;
                    mesh.open_fraction(p.origin, p.face, &set, far, turn)
                })
            })
            .collect()
    }

    /// The relative difference of the live `k_a` of `settings` (times `ao` where given, the
    /// stand-in of [`Traced::ambient_occlusion`]) from the traced one, at every covered pixel
    /// that has samples.
    pub fn relative_errors(
        &self,
        settings: &FrameSettings,
        ao: Option<&[Option<f32>]>,
    ) -> Vec<f32> {
        self.points
            .iter()
            .zip(&self.sums)
            .enumerate()
            .filter_map(|(i, (p, s))| {
                let p = p.as_ref().filter(|_| s.count > 0)?;
                let live = reflectance::ka(settings.model, settings.approx, p.kd, p.ks, p.n);
                let scale = ao.map_or(Some(1.0), |ao| ao.get(i).copied().flatten())?;
                Some(relative_error(live * scale, s.sum / s.count as f32))
            })
            .collect()
    }

    /// The standard error of the traced `k_a` relative to its value, the mean over the covered
    /// pixels that hold two samples or more (of each pixel's channel mean); `None` before
    /// that. Low-discrepancy samples make this an upper bound.
    pub fn standard_error(&self) -> Option<f32> {
        let (sum, count) = self
            .points
            .iter()
            .zip(&self.sums)
            .filter(|(p, s)| p.is_some() && s.count >= 2)
            .filter_map(|(_, s)| {
                let n = s.count as f32;
                let mean = s.sum.element_sum() / 3.0 / n;
                let variance = ((s.square - n * mean * mean) / (n - 1.0)).max(0.0);
                (mean > 0.0).then(|| (variance / n).sqrt() / mean)
            })
            .fold((0.0_f64, 0_u64), |(s, c), e| (s + f64::from(e), c + 1));
        (count > 0).then(|| (sum / count as f64) as f32)
    }
}

/// The per-pixel shift of the sequence: a hash of the pixel index to three numbers in [0, 1).
fn shift(i: u32) -> [f32; 3] {
    let mut h = u64::from(i).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0x5851_F42D_4C95_7F2D;
    std::array::from_fn(|_| {
        h ^= h >> 33;
        h = h.wrapping_mul(0xFF51_AFD7_ED55_8CCD);
        h ^= h >> 29;
        (h >> 40) as f32 / (1u64 << 24) as f32
    })
}

/// Sample `k` of a pixel shifted by `shift`: the three-dimensional Kronecker sequence of the
/// plastic-like constant (powers of `1 / 1.2207...`).
fn sequence(k: u32, shift: [f32; 3]) -> [f32; 3] {
    const ALPHA: [f64; 3] = [
        0.819_172_513_396_164_4,
        0.671_043_606_703_789_2,
        0.549_700_477_901_970_7,
    ];
    std::array::from_fn(|d| ((f64::from(shift[d]) + f64::from(k) * ALPHA[d]).fract()) as f32)
}

/// A Cauchy distribution about `centre` of scale `scale`, truncated to `[lo, hi]`.
#[derive(Clone, Copy, Debug)]
struct Cauchy {
    centre: f32,
    scale: f32,
    a: f32,
    b: f32,
}

impl Cauchy {
    fn new(centre: f32, scale: f32, lo: f32, hi: f32) -> Self {
        let scale = scale.max(1e-6);
        Self {
            centre,
            scale,
            a: ((lo - centre) / scale).atan(),
            b: ((hi - centre) / scale).atan(),
        }
    }

    fn sample(&self, u: f32) -> f32 {
        self.centre + self.scale * (self.a + u * (self.b - self.a)).tan()
    }

    fn density(&self, x: f32) -> f32 {
        let d = (x - self.centre) / self.scale;
        1.0 / (self.scale * (self.b - self.a) * (1.0 + d * d))
    }
}

/// The box integrand at unit light direction `l`: `k_d cos theta + k_s rho_s` (+ the second
/// part for Cook-Torrance), as the preview shades it.
fn integrand(model: ShadingModel, p: &Point, l: Vec3) -> Vec3 {
    let n_dot_l = p.normal.dot(l).max(0.0);
    let specular = model.specular(p.normal, l, p.to_eye, p.ks, p.n);
    p.kd * n_dot_l + specular
}

/// One sample's estimate of a pixel's traced `k_a`.
fn estimate(model: ShadingModel, p: &Point, k: u32, rays: &RayMesh, far: f32) -> Vec3 {
    use std::f32::consts::{FRAC_PI_2, PI, TAU};
    let [pick, u1, u2] = sequence(k, p.shift);
    // The frame: the eye at gamma = 0.
    let across = p.to_eye - p.normal * p.normal.dot(p.to_eye);
    let x = across
        .try_normalize()
        .unwrap_or_else(|| p.normal.any_orthonormal_vector());
    let z = p.normal.cross(x);
    let phi = p.normal.dot(p.to_eye).clamp(0.0, 1.0).acos();
    let width = model.lobe_width(p.n);
    let theta_lobe = Cauchy::new(phi, width, 0.0, FRAC_PI_2);
    // Across the mirror direction the lobe narrows with the light's distance from the normal.
    let gamma_lobe = |theta: f32| {
        let scale = model.across_width(width, theta, phi);
        Cauchy::new(PI, scale.min(1e3), 0.0, TAU)
    };
    let [diffuse, specular] = p.shares;
    let (theta, gamma) = if pick < diffuse {
        (u1.asin(), TAU * u2)
    } else if pick < diffuse + specular {
        let theta = theta_lobe.sample(u1);
        (theta, gamma_lobe(theta).sample(u2))
    } else {
        (FRAC_PI_2 * u1, TAU * u2)
    };
    let (st, ct) = theta.sin_cos();
    let l = x * (st * gamma.cos()) + p.normal * ct + z * (st * gamma.sin());
    let f = integrand(model, p, l);
    if f == Vec3::ZERO {
        return Vec3::ZERO;
    }
    // The density of the mixture at (theta, gamma), per unit of the box's plain measure.
    let gamma = gamma.rem_euclid(TAU);
    let uniform = 1.0 - diffuse - specular;
    let density = diffuse * ct / TAU
        + specular * theta_lobe.density(theta) * gamma_lobe(theta).density(gamma)
        + uniform / (PI * PI);
    if density.is_nan() || density <= 0.0 || rays.occluded(p.origin, l, far) {
        return Vec3::ZERO;
    }
    f / (PI * PI * density)
}

#[cfg(test)]
mod tests;
