//! Tests of footprints, the `n` tables, the energy guard and the run blends.

use glam::Vec2;

use super::dab::{PreRgb, blend_n_run, blend_rgb_run};
use super::*;
use crate::model::brush::BrushSettings;
use crate::model::texel::Channels;
use crate::model::tile::TILE_SIZE;

#[test]
fn disc_footprint_covers_the_disc_exactly() {
    let maps = MaterialMaps::new(300, 200, MaterialValue::default()).unwrap();
    let brush = BrushSettings {
        hardness: 1.0,
        ..BrushSettings::default()
    };
    let fp = DiscFootprint {
        center: Vec2::new(63.7, 64.2),
        radius: 20.3,
        brush: &brush,
    };
    let mut hits = std::collections::HashSet::new();
    for id in fp.tiles(&maps) {
        let rect = maps.tile_rect(id);
        fp.visit_tile(id, rect, |i, _| {
            hits.insert((
                rect.x0 + (i % TILE_SIZE) as u32,
                rect.y0 + (i / TILE_SIZE) as u32,
            ));
        });
    }
    for y in 0..200 {
        for x in 0..300 {
            let d = Vec2::new(x as f32 + 0.5, y as f32 + 0.5).distance(fp.center);
            assert_eq!(hits.contains(&(x, y)), d < fp.radius, "({x}, {y}) at {d}");
        }
    }
}

#[test]
fn n_blend_tables_are_accurate() {
    for n in [0.0_f32, 0.3, 1.0, 77.0, 5000.0, 16384.0] {
        let bits = super::super::texel::encode_n(n);
        assert_eq!(n_bits_from_blend(n_bits_to_blend(bits)), bits, "n = {n}");
    }
}

#[test]
fn energy_guard_keeps_the_sum_at_most_one() {
    let target = PaintTarget::new(
        MaterialValue::new(Vec3::splat(0.9), Vec3::splat(0.8), 10.0),
        Channels {
            kd: true,
            ks: false,
            n: false,
        },
        BlendMode::Normal,
        true,
    );
    let pre = Texel::encode(MaterialValue::new(Vec3::splat(0.1), Vec3::splat(0.8), 10.0));
    let out = target.blend(pre, 1.0).decode();
    assert!((out.kd.x + out.ks.x) <= 1.0 + 1e-4);
    assert!((out.ks.x - 0.8).abs() < 1e-4, "k_s untouched");
    // Untouched to the bit, every code, so a dab may mark only the enabled channels as
    // changed.
    for q in 0..=u16::MAX {
        let mut pre = Texel::encode(MaterialValue::new(Vec3::splat(0.3), Vec3::ZERO, 10.0));
        pre.ks = [q, q / 2, u16::MAX - q];
        let out = target.blend(pre, 0.7);
        assert_eq!((out.ks, out.n), (pre.ks, pre.n), "code {q}");
    }
}

#[test]
fn run_blends_agree_with_the_per_texel_reference() {
    use super::super::tile::Plane;
    let tables = n_tables();
    let alphas: Vec<f32> = (0..TILE_SIZE).map(|k| k as f32 / 63.0).collect();
    let mut alpha3 = [0.0; 3 * TILE_SIZE];
    for (a3, &a) in alpha3.chunks_exact_mut(3).zip(&alphas) {
        a3.fill(a);
    }
    let pre_data: Vec<[u16; 3]> = (0..TILE_TEXELS)
        .map(|i| {
            let h = (i as u32).wrapping_mul(2_654_435_761);
            [h as u16, (h >> 8) as u16, (h >> 16) as u16]
        })
        .collect();
    let n_data: Vec<u16> = (0..TILE_TEXELS)
        .map(|i| super::super::texel::encode_n((i % 997) as f32 * 9.7))
        .collect();
    let planes = [
        (
            Plane::Uniform([12_345, 0, 65_535]),
            Plane::Uniform(n_data[5]),
        ),
        (
            Plane::Data(pre_data.into_boxed_slice()),
            Plane::Data(n_data.into_boxed_slice()),
        ),
    ];
    for mode in [
        BlendMode::Normal,
        BlendMode::Add,
        BlendMode::Subtract,
        BlendMode::Multiply,
    ] {
        let target = PaintTarget::new(
            MaterialValue::new(Vec3::new(0.9, 0.1, 0.5), Vec3::splat(0.3), 700.0),
            Channels::ALL,
            mode,
            false,
        );
        let pattern: [f32; 3 * TILE_SIZE] =
            std::array::from_fn(|k| f32::from(super::super::texel::encode_rgb(target.kd)[k % 3]));
        for (rgb_plane, n_plane) in &planes {
            let start = 2 * TILE_SIZE;
            let pre = PreRgb::new(rgb_plane);
            let mut out = [[0_u16; 3]; TILE_SIZE];
            blend_rgb_run(
                &mut out,
                pre.run(start, TILE_SIZE),
                (&pattern, target.kd),
                (&alphas, &alpha3),
                mode,
            );
            let mut out_n = [0_u16; TILE_SIZE];
            blend_n_run(
                &mut out_n,
                n_plane,
                start,
                target.n_blend,
                &alphas,
                mode,
                tables,
            );
            for k in 0..TILE_SIZE {
                let p = Texel {
                    kd: rgb_plane.get(start + k),
                    ks: [0; 3],
                    n: n_plane.get(start + k),
                };
                let want = target.blend(p, alphas[k]);
                for (got, want) in out[k].iter().zip(want.kd) {
                    let diff = (i32::from(*got) - i32::from(want)).abs();
                    assert!(diff <= 1, "{mode:?} k_d at alpha {}", alphas[k]);
                }
                assert_eq!(out_n[k], want.n, "{mode:?} n at alpha {}", alphas[k]);
                if mode == BlendMode::Normal && (k == 0 || k == TILE_SIZE - 1) {
                    assert_eq!(out[k], want.kd, "exact at alpha 0 and 1");
                }
            }
        }
    }
}
