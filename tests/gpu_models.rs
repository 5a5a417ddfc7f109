//! Each shading model's shader code against its Rust source, on a real adapter (lavapipe in
//! CI): the lobe of every model (`shaders/lobes.wgsl`) and the per-view table's coordinates
//! (`shaders/view_coords.wgsl`), each at 10^4 points. The Rust side is the one source the CPU
//! renderers and the integrals call, so a shader that drifts from it fails here.

mod common;

use common::gpu;
use glam::Vec3;
use kapaint::gpu::check::{LobePoint, lobes_on_gpu, view_coords_on_gpu};
use kapaint::reflectance::ShadingModel;
use kapaint::reflectance::model::Cosines;

const POINTS: usize = 10_000;

/// A small deterministic generator (splitmix64), uniform in `[0, 1)`.
struct Uniform(u64);

impl Uniform {
    fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 40) as f32 / (1u64 << 24) as f32
    }

    fn unit(&mut self) -> Vec3 {
        let z = 2.0 * self.next() - 1.0;
        let a = std::f32::consts::TAU * self.next();
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * a.cos(), r * a.sin(), z)
    }

    /// An exponent from 0 to past every model's limit, log-spread, with the edge cases.
    fn exponent(&mut self, i: usize) -> f32 {
        const EDGES: [f32; 8] = [0.0, 1e-6, 0.5, 1.0, 16384.0, 1e6, 3e6, f32::MAX];
        EDGES
            .get(i % 50)
            .copied()
            .unwrap_or_else(|| (self.next() * 2e6_f32.ln_1p()).exp_m1())
    }
}

/// `POINTS` geometries: half at random, half within a few lobe widths of the mirror
/// direction, where the lobe is large and its rounding shows.
fn lobe_points() -> Vec<LobePoint> {
    let mut u = Uniform(55);
    (0..POINTS)
        .map(|i| {
            let n = u.exponent(i);
            let normal = u.unit();
            let l = u.unit();
            let v = if i % 2 == 0 {
                u.unit()
            } else {
                let mirror = 2.0 * normal.dot(l) * normal - l;
                let width = 3.0 / n.max(1.0).sqrt();
                (mirror + width * u.unit()).normalize()
            };
            LobePoint {
                normal: normal.to_array(),
                l: l.to_array(),
                v: v.to_array(),
                n,
            }
        })
        .collect()
}

/// The lowest and highest lobe (`[low, high]`, each `[rho_1, rho_0]`) over the cosines moved
/// by four ulps of 1 in the directions that lower or raise it.
fn rounding_band(model: ShadingModel, c: &Cosines<f32>, n: f32) -> [[f32; 2]; 2] {
    let eps = 4.0 * f32::EPSILON;
    let moved = |s: f32| Cosines {
        nl: c.nl + s * eps,
        nv: c.nv + s * eps,
        rv: c.rv + s * eps,
        nh: c.nh + s * eps,
        cross2: (c.cross2 - s * eps * (2.0 * c.cross2.sqrt() + eps)).max(0.0),
        vh: c.vh + s * eps,
        has_half: c.has_half,
    };
    let values = [-1.0, 0.0, 1.0].map(|s| model.lobe(&moved(s), n));
    let pick =
        |k: usize, f: fn(f32, f32) -> f32| values.iter().map(|v| v[k]).reduce(f).unwrap_or(0.0);
    [
        [pick(0, f32::min), pick(1, f32::min)],
        [pick(0, f32::max), pick(1, f32::max)],
    ]
}

#[test]
fn every_models_shader_lobe_is_its_rust_lobe_at_ten_thousand_points() {
    let Some(gpu) = gpu() else { return };
    let points = lobe_points();
    for model in ShadingModel::ALL {
        let got = lobes_on_gpu(&gpu, model, &points).expect("compute");
        assert_eq!(got.len(), points.len());
        let mut nonzero = 0;
        let mut worst = 0.0_f32;
        for (p, g) in points.iter().zip(&got) {
            let n = kapaint::reflectance::sanitize_n_f32(p.n).min(model.n_max());
            let cosines = Cosines::of(p.normal.into(), p.l.into(), p.v.into());
            let want = model.lobe(&cosines, n);
            // The cosines are rounded differently on the two sides (dot products in another
            // order, fused multiply-adds): the band of the lobe over the cosines moved by a few
            // ulps, on top of 1e-5 of each exp2 and log2 (which grows with `n |log2 c|`, i.e.
            // `-log2(lobe)`, for Phong and Blinn-Phong).
            let band = rounding_band(model, &cosines, n);
            let exponent = (-want[0].max(1e-30).log2()).max(0.0);
            for k in 0..2 {
                let slack = 1e-5 * want[k].abs() * (1.0 + exponent) + 1e-7;
                let (lo, hi) = (band[0][k] - slack, band[1][k] + slack);
                worst = worst.max((g[k] - want[k]).abs() / (want[k].abs() + 1e-7));
                assert!(
                    (lo..=hi).contains(&g[k]),
                    "{model:?} part {k} at {p:?}: gpu {} vs rust {} (allowed {lo} to {hi})",
                    g[k],
                    want[k]
                );
            }
            nonzero += usize::from(want[0] > 1e-3);
        }
        eprintln!("{model:?}: worst relative error {worst:e}, {nonzero} points with rho_1 > 1e-3");
        assert!(
            nonzero > POINTS / 5,
            "{model:?}: only {nonzero} points test the lobe's peak"
        );
    }
}

#[test]
fn the_shader_view_table_coordinates_are_the_rust_ones_at_ten_thousand_points() {
    let Some(gpu) = gpu() else { return };
    let mut u = Uniform(7);
    let points: Vec<[f32; 2]> = (0..POINTS)
        .map(|i| {
            let n = if i % 10 == 0 {
                [0.0, 1.0, 16384.0][i / 10 % 3]
            } else {
                (u.next() * 16385.0_f32.ln()).exp() - 1.0
            };
            let phi = if i % 7 == 0 {
                [0.0, std::f32::consts::FRAC_PI_2][i / 7 % 2]
            } else {
                u.next() * std::f32::consts::FRAC_PI_2
            };
            [n, phi]
        })
        .collect();
    let got = view_coords_on_gpu(&gpu, &points).expect("compute");
    for (p, g) in points.iter().zip(&got) {
        let (wu, wv) = kapaint::reflectance::view::table_coords(p[0], p[1]);
        for (k, (gk, wk)) in [(g[0], wu), (g[1], wv)].into_iter().enumerate() {
            assert!(
                (gk - wk).abs() <= 2e-6,
                "coordinate {k} at (n, phi) = {p:?}: gpu {gk} vs rust {wk}"
            );
        }
    }
}
