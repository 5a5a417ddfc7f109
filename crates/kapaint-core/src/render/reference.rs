//! The CPU reference renderer: one ray per pixel centre through the BVH, the hit's
//! interpolated normal and UV, bilinear map samples (clamp to edge, as the GPU sampler), and
//! [`super::shade`]. Slow and simple on purpose: the GPU preview is tested against it.

use glam::{Vec2, Vec3, Vec4};
use rayon::prelude::*;

use super::{FrameSettings, Sample, shade};
use kapaint_mesh::Mesh;
use kapaint_mesh::pick::Bvh;
use kapaint_model::MaterialMaps;

/// Where material samples come from.
pub enum Material<'a> {
    /// One material everywhere.
    Uniform(Sample),
    /// Painted maps, sampled bilinearly.
    Maps(&'a MaterialMaps),
}

impl Material<'_> {
    /// The material at texture coordinate `uv` (mesh convention: v up).
    pub fn sample(&self, uv: Vec2) -> Sample {
        match self {
            Self::Uniform(s) => *s,
            Self::Maps(maps) => bilinear(maps, uv),
        }
    }
}

/// Bilinear sample of the maps at `uv`, texel centres at `(i + 0.5) / width`, clamped at the
/// edges.
pub fn bilinear(maps: &MaterialMaps, uv: Vec2) -> Sample {
    let (w, h) = (maps.width(), maps.height());
    let x = uv.x * w as f32 - 0.5;
    let y = (1.0 - uv.y) * h as f32 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let clamp = |v: f32, hi: u32| (v.max(0.0) as u32).min(hi - 1);
    let at = |dx: f32, dy: f32| maps.value(clamp(x0 + dx, w), clamp(y0 + dy, h));
    let (a, b, c, d) = (at(0.0, 0.0), at(1.0, 0.0), at(0.0, 1.0), at(1.0, 1.0));
    let mix3 = |p: Vec3, q: Vec3, r: Vec3, s: Vec3| p.lerp(q, fx).lerp(r.lerp(s, fx), fy);
    let mix1 = |p: f32, q: f32, r: f32, s: f32| {
        let top = p + (q - p) * fx;
        top + (r + (s - r) * fx - top) * fy
    };
    Sample {
        kd: mix3(a.kd, b.kd, c.kd, d.kd),
        ks: mix3(a.ks, b.ks, c.ks, d.ks),
        n: mix1(a.n, b.n, c.n, d.n),
    }
}

/// Renders `width x height` linear RGBA pixels, row-major from the top; alpha 0 where the
/// ray misses the mesh.
pub fn render(
    mesh: &Mesh,
    bvh: &Bvh,
    material: &Material<'_>,
    settings: &FrameSettings,
    width: u32,
    height: u32,
) -> Vec<Vec4> {
    let eye = settings.camera.eye();
    (0..width * height)
        .into_par_iter()
        .map(|i| {
            let (px, py) = ((i % width) as f32, (i / width) as f32);
            let (origin, dir) = settings.camera.ray(px, py, width, height);
            let Some(hit) = bvh.pick(mesh, origin, dir) else {
                return Vec4::ZERO;
            };
            let uv = hit.uv.unwrap_or(Vec2::ZERO);
            let to_eye = (eye - hit.position).normalize_or_zero();
            let texture_uv = Vec2::new(uv.x, 1.0 - uv.y);
            let c = shade(
                settings,
                material.sample(uv),
                hit.normal,
                to_eye,
                texture_uv,
            );
            c.extend(1.0)
        })
        .collect()
}
