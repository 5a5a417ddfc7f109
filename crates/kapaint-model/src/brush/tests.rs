//! Tests of stamps, dab placement, smoothing, falloff, blend modes and sanitising.

use glam::Vec2;

use super::*;

#[test]
fn the_grain_stamp_is_a_grainy_disc_the_same_everywhere() {
    let a = Stamp::grain(64);
    assert_eq!(a, Stamp::grain(64), "deterministic");
    assert!(a.alpha().iter().all(|v| (0.0..=1.0).contains(v)));
    assert_eq!(a.sample(-1.0, -1.0), 0.0, "nothing in the corners");
    let centre: Vec<f32> = (0..16)
        .map(|i| a.sample(i as f32 * 0.01 - 0.08, 0.0))
        .collect();
    let (lo, hi) = centre
        .iter()
        .fold((f32::MAX, f32::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
    assert!(
        lo > 0.2 && hi - lo > 0.1,
        "grain near the centre: {lo}..{hi}"
    );
}

fn dabs(points: &[(f32, f32)], spacing: f32) -> Vec<DabPoint> {
    let mut r = Resampler::new(spacing);
    let mut out = Vec::new();
    for &(x, y) in points {
        r.push(
            StrokePoint {
                pos: Vec2::new(x, y),
                pressure: 1.0,
            },
            &mut out,
        )
        .unwrap();
    }
    out
}

#[test]
fn dab_positions_do_not_depend_on_input_sampling() {
    let coarse = dabs(&[(0.0, 0.0), (100.0, 0.0)], 7.0);
    let fine_points: Vec<(f32, f32)> = (0..=100).map(|i| (i as f32, 0.0)).collect();
    let fine = dabs(&fine_points, 7.0);
    assert_eq!(coarse.len(), fine.len());
    assert_eq!(coarse.len(), 15); // 0, 7, ..., 98
    for (a, b) in coarse.iter().zip(&fine) {
        assert!((a.pos - b.pos).length() < 1e-3);
    }
    // On a curve (a half circle of radius 50), 90 or 9000 samples: the dabs drift only
    // by the arc length the coarse chords cut off.
    let arc = |n: usize| -> Vec<(f32, f32)> {
        (0..=n)
            .map(|i| {
                let a = i as f32 / n as f32 * std::f32::consts::PI;
                (50.0 * a.cos(), 50.0 * a.sin())
            })
            .collect()
    };
    let (coarse, fine) = (dabs(&arc(90), 3.0), dabs(&arc(9000), 3.0));
    assert!(coarse.len().abs_diff(fine.len()) <= 1);
    let drift = coarse
        .iter()
        .zip(&fine)
        .map(|(a, b)| (a.pos - b.pos).length())
        .fold(0.0_f32, f32::max);
    // 90 chords of a 50-texel half circle are 0.006 % shorter than the arc: 0.01 texels.
    assert!(drift < 0.02, "dabs drift {drift} texels apart");
}

#[test]
fn a_segment_a_billion_texels_long_places_every_dab_and_then_stops() {
    // Past 2^24 spacings an f32 position stepped by the spacing stops moving; counted
    // steps in f64 do not, and the dab limit ends the stroke.
    let mut r = Resampler::new(8.0);
    let mut out = Vec::new();
    let at = |x: f32| StrokePoint {
        pos: Vec2::new(x, 0.0),
        pressure: 1.0,
    };
    r.push(at(0.0), &mut out).unwrap();
    r.push(at(1000.0), &mut out).unwrap();
    assert_eq!(out.len(), 126); // 0, 8, ..., 1000
    assert_eq!(r.push(at(1e9), &mut out), Err(DabLimit));
    assert_eq!(out.len() as u64, MAX_STROKE_DABS);
    let steps: Vec<f32> = out.windows(2).map(|w| w[1].pos.x - w[0].pos.x).collect();
    assert!(steps.iter().all(|d| (d - 8.0).abs() < 0.01), "even spacing");
    assert_eq!(r.push(at(2e9), &mut out), Err(DabLimit));
    assert_eq!(out.len() as u64, MAX_STROKE_DABS, "nothing after the limit");
}

#[test]
fn a_stroke_longer_than_f32_squares_reach_is_clipped_with_an_error_never_dropped() {
    // In f32, the square of a 2e19-texel step is infinite: the segment was dropped in silence.
    for far in [2e19_f32, 1e30, f32::MAX] {
        let mut r = Resampler::new(8.0);
        let mut out = Vec::new();
        let at = |x: f32| StrokePoint {
            pos: Vec2::new(x, -x),
            pressure: 1.0,
        };
        r.push(at(0.0), &mut out).unwrap();
        assert_eq!(r.push(at(far), &mut out), Err(DabLimit), "{far}");
        assert_eq!(out.len() as u64, MAX_STROKE_DABS, "{far}");
    }
}

#[test]
fn pressure_is_interpolated() {
    let mut r = Resampler::new(5.0);
    let mut out = Vec::new();
    r.push(
        StrokePoint {
            pos: Vec2::ZERO,
            pressure: 0.0,
        },
        &mut out,
    )
    .unwrap();
    r.push(
        StrokePoint {
            pos: Vec2::new(10.0, 0.0),
            pressure: 1.0,
        },
        &mut out,
    )
    .unwrap();
    let p: Vec<f32> = out.iter().map(|d| d.pressure).collect();
    assert_eq!(p, vec![0.0, 0.5, 1.0]);
}

#[test]
fn smoother_trails_the_pointer() {
    let mut s = Smoother::new(10.0);
    assert_eq!(s.follow(Vec2::ZERO), Some(Vec2::ZERO));
    assert_eq!(s.follow(Vec2::new(5.0, 0.0)), None);
    let moved = s.follow(Vec2::new(30.0, 0.0)).unwrap();
    assert!((moved - Vec2::new(20.0, 0.0)).length() < 1e-4, "{moved}");
}

#[test]
fn falloff_and_blend_modes() {
    let b = BrushSettings {
        hardness: 0.5,
        ..BrushSettings::default()
    };
    assert_eq!(b.falloff(0.0, 10.0), 1.0);
    assert_eq!(b.falloff(5.0, 10.0), 1.0);
    // Half-way in d^2 between the core (25) and the rim (100).
    assert!((b.falloff(62.5_f32.sqrt(), 10.0) - 0.5).abs() < 1e-6);
    assert!(b.falloff(9.0, 10.0) < b.falloff(7.0, 10.0));
    assert_eq!(b.falloff(10.0, 10.0), 0.0);
    assert_eq!(BlendMode::Normal.apply(0.2, 0.8, 0.5), 0.5);
    assert_eq!(BlendMode::Add.apply(0.9, 0.5, 1.0), 1.0);
    assert_eq!(BlendMode::Subtract.apply(0.2, 0.5, 1.0), 0.0);
    assert!((BlendMode::Multiply.apply(0.8, 0.5, 1.0) - 0.4).abs() < 1e-6);
}

#[test]
fn sanitize_fixes_hostile_settings() {
    let s = BrushSettings {
        radius_px: f32::NAN,
        opacity: 7.0,
        flow: -1.0,
        ..BrushSettings::default()
    }
    .sanitized();
    assert_eq!(s.radius_px, 32.0);
    assert_eq!(s.opacity, 1.0);
    assert_eq!(s.flow, 0.0);
}
