//! Tests of footprints, the `n` tables and the energy guard.

use glam::Vec2;

use super::*;
use crate::brush::BrushSettings;
use crate::maps::MaterialMaps;
use crate::texel::MaterialValue;
use crate::tile::TILE_SIZE;

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
    // The painted channel gives way to the other.
    let (mut kd, mut ks) = ([0.9; 3], [0.8; 3]);
    guard_energy(&mut kd, &mut ks, true, false);
    assert!(kd.iter().zip(&ks).all(|(d, s)| d + s <= 1.0 + 1e-6));
    assert_eq!(ks, [0.8; 3], "k_s untouched");
    let (mut kd, mut ks) = ([0.9; 3], [0.8; 3]);
    guard_energy(&mut kd, &mut ks, false, true);
    assert_eq!(kd, [0.9; 3], "k_d untouched");
    // Both painted: both scale down together, keeping their ratio.
    let (mut kd, mut ks) = ([0.9, 0.2, 0.6], [0.6, 0.3, 0.6]);
    guard_energy(&mut kd, &mut ks, true, true);
    assert!((kd[0] + ks[0] - 1.0).abs() < 1e-6 && (kd[0] / ks[0] - 1.5).abs() < 1e-5);
    assert_eq!((kd[1], ks[1]), (0.2, 0.3), "a sum under one stays");
}
