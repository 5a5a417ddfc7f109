//! Generators: the script spellings, the checks, round trips and values.

use super::*;

fn parse(text: &str) -> Result<Generator, String> {
    ron::from_str(text).map_err(|e| e.to_string())
}

fn texel(p: Vec3) -> Texel {
    Texel {
        uv: glam::Vec2::new(p.x, p.z),
        position: p,
        normal: Vec3::Y,
        index: 0,
    }
}

#[test]
fn the_script_spellings_read_and_bad_values_are_refused() {
    let ao = parse("Ao(black: 0.2, white: 0.9, invert: false)").expect("ao");
    assert_eq!(ao.bakes_needed(), vec![BakeMap::Ao]);
    parse("Curvature(black: 0.5, white: 0.7, invert: true)").expect("curvature");
    parse("Noise(kind: Perlin, scale: 8.0, octaves: 4, seed: 1, space: Object)").expect("noise");
    parse("Noise(kind: Worley, scale: 3.0)").expect("defaults");
    let blend = parse(
        "Blend(op: Multiply, a: Curvature(black: 0.5, white: 0.7), \
         b: Noise(kind: Simplex, scale: 4.0, space: Triplanar))",
    )
    .expect("blend");
    assert_eq!(blend.bakes_needed(), vec![BakeMap::Curvature]);
    for bad in [
        "Ao(black: NaN, white: 0.9)",
        "Ao(black: 0.9, white: 0.2)",
        "Ao(black: 0.1, white: 1.5)",
        "Ao(black: 0.1, white: 0.5, gamma: 0.0)",
        "Noise(kind: Perlin, scale: inf)",
        "Noise(kind: Perlin, scale: -1.0)",
        "Noise(kind: Perlin, scale: 2.0, octaves: 0)",
        "Noise(kind: Perlin, scale: 2.0, octaves: 9)",
        "Gradient(axis: Y, from: 0.5, to: 0.5)",
        "Gradient(axis: Y, from: NaN, to: 0.5)",
        "Shadow(black: 0.1, white: 0.2)",
    ] {
        assert!(parse(bad).is_err(), "{bad} was accepted");
    }
    // Blends nest at most MAX_DEPTH deep.
    let mut deep = "Noise(kind: Perlin, scale: 1.0)".to_string();
    for _ in 0..=MAX_DEPTH {
        deep = format!("Blend(op: Max, a: {deep}, b: Noise(kind: Perlin, scale: 1.0))");
    }
    assert!(parse(&deep).is_err());
}

#[test]
fn a_generator_writes_as_it_reads() {
    let g = parse(
        "Blend(op: Add, a: Thickness(black: 0.1, white: 0.4, gamma: 2.0, invert: true), \
         b: Gradient(axis: Z, from: 1.0, to: 0.0))",
    )
    .expect("reads");
    let text = ron::to_string(&g).expect("writes");
    assert_eq!(parse(&text).expect("reads back"), g);
    let json = serde_json::to_string(&g).expect("json");
    assert_eq!(
        serde_json::from_str::<Generator>(&json).expect("json back"),
        g
    );
}

#[test]
fn values_stay_in_range_and_follow_their_parameters() {
    let no_bakes: Vec<std::sync::Arc<Baked>> = Vec::new();
    for kind in [NoiseKind::Perlin, NoiseKind::Simplex, NoiseKind::Worley] {
        for space in [Space::Uv, Space::Object, Space::Triplanar] {
            let g = Generator::Noise(Noise {
                kind,
                scale: 6.0,
                octaves: 3,
                seed: 7,
                space,
            });
            let e = Evaluator::new(&g, &no_bakes);
            let values: Vec<f32> = (0..400)
                .map(|i| {
                    let p = Vec3::new((i % 20) as f32 / 20.0, 0.3, (i / 20) as f32 / 20.0);
                    e.value(&texel(p))
                })
                .collect();
            assert!(values.iter().all(|v| (0.0..=1.0).contains(v)));
            let spread = values.iter().copied().fold(f32::MIN, f32::max)
                - values.iter().copied().fold(f32::MAX, f32::min);
            assert!(spread > 0.2, "{kind:?} {space:?} is flat: {spread}");
        }
    }
    let ramp = Generator::Gradient {
        axis: Axis::Y,
        from: 0.25,
        to: 0.75,
    };
    let e = Evaluator::new(&ramp, &no_bakes);
    assert_eq!(e.value(&texel(Vec3::new(0.0, 0.0, 0.0))), 0.0);
    assert_eq!(e.value(&texel(Vec3::new(0.0, 0.5, 0.0))), 0.5);
    assert_eq!(e.value(&texel(Vec3::new(0.0, 1.0, 0.0))), 1.0);
    let levels = Levels {
        black: 0.2,
        white: 0.6,
        gamma: 1.0,
        invert: true,
        relative: false,
    };
    assert_eq!(levels.apply(0.1), 1.0);
    assert!((levels.apply(0.4) - 0.5).abs() < 1e-6);
    assert_eq!(levels.apply(0.9), 0.0);
}

/// Interpolated noise against noise computed at every texel, on the builtin sphere's map:
/// the largest difference in 16-bit levels.
fn interpolation_error(g: &Generator, side: u32) -> u16 {
    use crate::generator::tiles::{Generated, Source};
    let made = Generated::new(g.clone(), Source::new(None, &[], side, side), false);
    let tiles = (side as usize / 64).pow(2);
    let mut worst = 0;
    for id in (0..tiles).step_by(23) {
        let fast = made.tile(id);
        let exact = made.tile_exact(id);
        for i in 0..64 * 64 {
            let d = fast.get(i).abs_diff(exact.get(i));
            worst = worst.max(d);
        }
    }
    worst
}

#[test]
fn interpolated_noise_stays_within_half_an_8_bit_level() {
    for (kind, space) in [
        (NoiseKind::Perlin, Space::Object),
        (NoiseKind::Simplex, Space::Object),
        (NoiseKind::Perlin, Space::Uv),
        (NoiseKind::Perlin, Space::Triplanar),
        (NoiseKind::Worley, Space::Object),
    ] {
        for (scale, octaves) in [(8.0, 4), (2.0, 8), (30.0, 1)] {
            let g = Generator::Noise(Noise {
                kind,
                scale,
                octaves,
                seed: 3,
                space,
            });
            let worst = interpolation_error(&g, 4096);
            eprintln!(
                "{kind:?} {space:?} scale {scale} octaves {octaves}: {worst} levels of 65535"
            );
            assert!(
                worst <= 128,
                "{kind:?} {space:?} {scale} {octaves}: {worst}"
            );
        }
    }
}
