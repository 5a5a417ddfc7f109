//! The material model driven through commands, as the editor and scripts drive it.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use glam::{Vec2, Vec3};
use kapaint_model::brush::{BlendMode, BrushSettings, StrokePoint};
use kapaint_model::paint::GradientShape;
use kapaint_model::texel::{N_MAX, Texel, srgb_to_linear};
use kapaint_model::{
    Channel, Channels, Document, DocumentSettings, FillRegion, MaterialMaps, MaterialValue,
    StrokeTool, project,
};
use kapaint_model::{Command, HistoryCommand, PaintCommand, SettingsCommand, StrokeCommand};

fn doc(w: u32, h: u32) -> Document {
    Document::new(w, h, DocumentSettings::default()).expect("valid size")
}

fn point(x: f32, y: f32) -> StrokePoint {
    StrokePoint {
        pos: Vec2::new(x, y),
        pressure: 1.0,
    }
}

fn snapshot(maps: &MaterialMaps) -> Vec<Texel> {
    let mut out = Vec::with_capacity(maps.texel_count());
    maps.for_each_texel(|_, _, t| out.push(t));
    out
}

/// Every stored texel is a valid material: finite, in range, `n` bits a storable exponent.
fn assert_valid(maps: &MaterialMaps) {
    maps.for_each_texel(|x, y, t| {
        let n = half::f16::from_bits(t.n).to_f32();
        assert!(
            n.is_finite() && (0.0..=N_MAX).contains(&n),
            "texel ({x}, {y}) has n bits {:#x}",
            t.n
        );
        let v = t.decode();
        assert!(v.kd.is_finite() && v.ks.is_finite());
    });
}

fn red() -> MaterialValue {
    MaterialValue::new(Vec3::new(1.0, 0.0, 0.0), Vec3::splat(0.1), 500.0)
}

#[test]
fn every_command_keeps_the_maps_valid_and_undo_restores_bit_exactly() {
    let mut d = doc(300, 200);
    let initial = snapshot(d.maps());
    let commands: Vec<Command> = vec![
        SettingsCommand::SetPrimary(red()).into(),
        SettingsCommand::SetBrush(BrushSettings {
            radius_px: 12.0,
            jitter: 0.5,
            ..BrushSettings::default()
        })
        .into(),
        StrokeCommand::Stroke {
            tool: StrokeTool::Brush,
            points: vec![point(5.0, 5.0), point(290.0, 190.0)],
        }
        .into(),
        SettingsCommand::SetBrush(BrushSettings {
            blend: BlendMode::Multiply,
            opacity: 0.5,
            ..BrushSettings::default()
        })
        .into(),
        StrokeCommand::Stroke {
            tool: StrokeTool::Brush,
            points: vec![point(0.0, 100.0), point(300.0, 100.0)],
        }
        .into(),
        StrokeCommand::Stroke {
            tool: StrokeTool::Blur,
            points: vec![point(50.0, 50.0), point(150.0, 150.0)],
        }
        .into(),
        StrokeCommand::Stroke {
            tool: StrokeTool::Eraser,
            points: vec![point(100.0, 0.0), point(100.0, 200.0)],
        }
        .into(),
        SettingsCommand::SetChannels(Channels {
            kd: false,
            ks: true,
            n: true,
        })
        .into(),
        PaintCommand::Fill(FillRegion::Similar {
            x: 250,
            y: 20,
            channel: Channel::Kd,
            tolerance: 0.05,
        })
        .into(),
        PaintCommand::Gradient {
            shape: GradientShape::Radial,
            start: Vec2::new(150.0, 100.0),
            end: Vec2::new(300.0, 100.0),
        }
        .into(),
        SettingsCommand::SetBrush(BrushSettings {
            blend: BlendMode::Add,
            energy_guard: true,
            ..BrushSettings::default()
        })
        .into(),
        PaintCommand::Fill(FillRegion::All).into(),
    ];
    let mut snapshots = vec![initial.clone()];
    for command in commands {
        d.apply(command).expect("command applies");
        assert_valid(d.maps());
        snapshots.push(snapshot(d.maps()));
    }
    // Undo walks back through every snapshot bit-exactly, redo forward again.
    let steps = d.history().undo_steps().count();
    assert_eq!(steps, 7);
    let changed: Vec<&Vec<Texel>> = {
        let mut v = vec![&snapshots[0]];
        for pair in snapshots.windows(2) {
            if pair[0] != pair[1] {
                v.push(&pair[1]);
            }
        }
        v
    };
    assert_eq!(changed.len(), steps + 1);
    for want in changed.iter().rev().skip(1) {
        d.apply(HistoryCommand::Undo).expect("undo");
        assert!(snapshot(d.maps()) == **want, "undo is not bit-exact");
    }
    assert_eq!(snapshot(d.maps()), initial);
    for want in changed.iter().skip(1) {
        d.apply(HistoryCommand::Redo).expect("redo");
        assert!(snapshot(d.maps()) == **want, "redo is not bit-exact");
    }
}

#[test]
fn stroke_result_does_not_depend_on_input_sampling() {
    let paint = |points: Vec<StrokePoint>| {
        let mut d = doc(256, 256);
        d.apply(SettingsCommand::SetPrimary(red())).expect("set");
        d.apply(SettingsCommand::SetBrush(BrushSettings {
            radius_px: 9.0,
            flow: 0.3,
            ..BrushSettings::default()
        }))
        .expect("set");
        d.apply(StrokeCommand::Stroke {
            tool: StrokeTool::Brush,
            points,
        })
        .expect("stroke");
        snapshot(d.maps())
    };
    let worst = |a: &[Texel], b: &[Texel]| {
        a.iter()
            .zip(b)
            .flat_map(|(a, b)| (0..3).map(move |c| a.kd[c].abs_diff(b.kd[c])))
            .max()
            .unwrap_or(0)
    };
    // A straight stroke: 2 input points or 301 along the same line.
    let coarse = paint(vec![point(20.0, 30.0), point(230.0, 200.0)]);
    let fine = paint(
        (0..=300)
            .map(|i| {
                let t = i as f32 / 300.0;
                point(20.0 + 210.0 * t, 30.0 + 170.0 * t)
            })
            .collect(),
    );
    // Dab centres agree to float rounding; at most a couple of unorm16 steps differ.
    let straight = worst(&coarse, &fine);
    assert!(straight <= 4, "largest difference {straight} / 65535");
    assert!(coarse.iter().any(|t| t.kd[1] < 8000), "the stroke painted");
    // A curve (three quarters of a circle with a wave on it) sampled at 360 and at 6000
    // points: dabs go by arc length along each polyline, whose lengths differ by what the
    // coarse chords cut off the curve, so the dabs drift apart by a fraction of a texel
    // along the stroke (measured: 120 / 65535, 0.2 %, at the far end).
    let curve = |samples: usize| {
        (0..=samples)
            .map(|i| {
                let t = i as f32 / samples as f32;
                let a = t * 1.5 * std::f32::consts::PI;
                point(
                    128.0 + 90.0 * a.cos() + 6.0 * (9.0 * a).sin(),
                    128.0 + 90.0 * a.sin(),
                )
            })
            .collect::<Vec<_>>()
    };
    let (slow, fast) = (paint(curve(360)), paint(curve(6000)));
    let curved = worst(&slow, &fast);
    assert!(curved <= 160, "largest difference {curved} / 65535");
    assert!(
        slow.iter().filter(|t| t.kd[1] < 8000).count() > 2000,
        "the curve painted"
    );
}

#[test]
fn opacity_caps_a_stroke_however_many_dabs_overlap() {
    let mut d = doc(128, 128);
    d.apply(SettingsCommand::SetPrimary(MaterialValue::new(
        Vec3::ONE,
        Vec3::ZERO,
        10.0,
    )))
    .expect("set");
    d.apply(SettingsCommand::SetBrush(BrushSettings {
        radius_px: 20.0,
        hardness: 1.0,
        opacity: 0.5,
        flow: 0.2,
        spacing_percent: 5.0,
        ..BrushSettings::default()
    }))
    .expect("set");
    let base = d.maps().value(64, 64).kd.x;
    let points = (0..40)
        .map(|i| point(60.0 + (i % 2) as f32 * 8.0, 64.0))
        .collect();
    d.apply(StrokeCommand::Stroke {
        tool: StrokeTool::Brush,
        points,
    })
    .expect("stroke");
    let v = d.maps().value(64, 64).kd.x;
    let half_way = base + (1.0 - base) * 0.5;
    assert!((v - half_way).abs() < 1e-3, "{v} vs {half_way}");
}

#[test]
fn mirror_eraser_and_picker() {
    let mut d = doc(200, 100);
    d.apply(SettingsCommand::SetPrimary(red())).expect("set");
    d.apply(SettingsCommand::SetBrush(BrushSettings {
        radius_px: 6.0,
        mirror_u: true,
        ..BrushSettings::default()
    }))
    .expect("set");
    d.apply(StrokeCommand::Stroke {
        tool: StrokeTool::Brush,
        points: vec![point(30.5, 20.5), point(30.5, 80.5)],
    })
    .expect("stroke");
    for y in 0..100 {
        for x in 0..100 {
            assert_eq!(
                d.maps().texel(x, y),
                d.maps().texel(199 - x, y),
                "mirror at ({x}, {y})"
            );
        }
    }
    d.apply(PaintCommand::Pick { x: 30, y: 50 }).expect("pick");
    assert_eq!(d.settings().primary, red().quantized());
    assert!(d.apply(PaintCommand::Pick { x: 200, y: 0 }).is_err());
    // The eraser paints the base material back.
    d.apply(SettingsCommand::SetBrush(BrushSettings {
        radius_px: 20.0,
        hardness: 1.0,
        ..BrushSettings::default()
    }))
    .expect("set");
    d.apply(StrokeCommand::Stroke {
        tool: StrokeTool::Eraser,
        points: vec![point(30.0, 0.0), point(30.0, 100.0)],
    })
    .expect("erase");
    assert_eq!(d.maps().value(30, 50), d.settings().base.quantized());
}

#[test]
fn gradient_and_fill_write_what_they_say() {
    let mut d = doc(256, 64);
    d.apply(SettingsCommand::SetPrimary(MaterialValue::new(
        Vec3::ZERO,
        Vec3::ZERO,
        0.0,
    )))
    .expect("set");
    d.apply(SettingsCommand::SetSecondary(MaterialValue::new(
        Vec3::ONE,
        Vec3::ONE,
        N_MAX,
    )))
    .expect("set");
    d.apply(PaintCommand::Gradient {
        shape: GradientShape::Linear,
        start: Vec2::new(0.0, 0.0),
        end: Vec2::new(256.0, 0.0),
    })
    .expect("gradient");
    let left = d.maps().value(0, 10);
    let mid = d.maps().value(128, 10);
    let right = d.maps().value(255, 10);
    assert!(left.kd.x < 0.01 && right.kd.x > 0.99);
    assert!((mid.kd.x - 0.5).abs() < 0.01);
    // n is blended in log space: the midpoint is sqrt(1 + N_MAX) - 1, not N_MAX / 2.
    let log_mid = (1.0 + N_MAX).sqrt() - 1.0;
    assert!(
        (mid.n / log_mid - 1.0).abs() < 0.02,
        "{} vs {log_mid}",
        mid.n
    );
    // A full-opacity fill makes every tile uniform again: no memory.
    d.apply(PaintCommand::Fill(FillRegion::All)).expect("fill");
    assert_eq!(d.maps().heap_bytes(), 0);
    assert_eq!(d.maps().value(200, 50), d.settings().primary.quantized());
}

#[test]
fn flood_fill_stops_at_the_tolerance() {
    let mut d = doc(100, 100);
    d.apply(SettingsCommand::SetPrimary(red())).expect("set");
    d.apply(SettingsCommand::SetBrush(BrushSettings {
        radius_px: 3.0,
        hardness: 1.0,
        ..BrushSettings::default()
    }))
    .expect("set");
    // A red wall at x = 50 splits the map.
    d.apply(StrokeCommand::Stroke {
        tool: StrokeTool::Brush,
        points: vec![point(50.0, -5.0), point(50.0, 105.0)],
    })
    .expect("stroke");
    d.apply(SettingsCommand::SetPrimary(MaterialValue::new(
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::ZERO,
        1.0,
    )))
    .expect("set");
    d.apply(PaintCommand::Fill(FillRegion::Similar {
        x: 10,
        y: 10,
        channel: Channel::Kd,
        tolerance: 0.01,
    }))
    .expect("fill");
    assert_eq!(d.maps().value(20, 90).kd, Vec3::new(0.0, 0.0, 1.0));
    assert_ne!(d.maps().value(90, 90).kd, Vec3::new(0.0, 0.0, 1.0));
    assert_eq!(d.maps().value(50, 50).kd, Vec3::new(1.0, 0.0, 0.0));
}

fn small_project() -> Document {
    let mut d = doc(96, 80);
    d.apply(SettingsCommand::SetPrimary(red())).expect("set");
    d.apply(StrokeCommand::Stroke {
        tool: StrokeTool::Brush,
        points: vec![point(3.0, 3.0), point(90.0, 70.0)],
    })
    .expect("stroke");
    d.apply(SettingsCommand::SetModel(
        kapaint_reflectance::ShadingModel::BlinnPhong,
    ))
    .expect("set");
    d
}

#[test]
fn project_round_trip_is_lossless() {
    let d = small_project();
    let bytes = project::to_bytes(&d).expect("saves");
    let back = project::from_reader(std::io::Cursor::new(bytes)).expect("loads");
    assert_eq!(snapshot(back.maps()), snapshot(d.maps()));
    assert_eq!(back.settings(), d.settings());
}

#[test]
fn every_truncation_of_a_project_is_a_clear_error() {
    let bytes = project::to_bytes(&small_project()).expect("saves");
    for len in 0..bytes.len() {
        let result = project::from_reader(std::io::Cursor::new(&bytes[..len]));
        let err = result.expect_err("a truncated project must not load");
        assert!(!err.is_empty());
    }
}

#[test]
fn random_byte_flips_never_panic_and_never_load_invalid_maps() {
    let bytes = project::to_bytes(&small_project()).expect("saves");
    let mut state = 0x1234_5678_9abc_def0_u64;
    let mut errors = 0;
    for _ in 0..3000 {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let mut corrupt = bytes.clone();
        let at = (state >> 33) as usize % corrupt.len();
        corrupt[at] ^= 1 << ((state >> 20) % 8);
        match project::from_reader(std::io::Cursor::new(corrupt)) {
            Ok(d) => assert_valid(d.maps()),
            Err(_) => errors += 1,
        }
    }
    // Checksums catch almost every flip (metadata such as timestamps may be harmless).
    assert!(errors > 2500, "only {errors} of 3000 flips were detected");
}

#[test]
fn save_is_atomic_and_never_clobbers_on_failure() {
    let dir = std::env::temp_dir().join(format!("kapaint-atomic-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join("p.kapaint");
    let d = small_project();
    project::save(&d, &path).expect("save");
    let before = std::fs::read(&path).expect("read");
    // Saving into a directory that does not exist fails cleanly and leaves no temp file.
    let missing = dir.join("missing/p.kapaint");
    assert!(project::save(&d, &missing).is_err());
    assert_eq!(std::fs::read(&path).expect("read"), before);
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .expect("list")
        .filter_map(Result::ok)
        .collect();
    assert_eq!(leftovers.len(), 1, "{leftovers:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

fn spot_texture() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/testdata/spot/spot_texture.png")
}

#[test]
fn importing_the_spot_texture_converts_srgb_to_linear() {
    let path = spot_texture();
    let mut d = doc(1024, 1024);
    d.import_file(Channel::Kd, &path).expect("import");
    let png = image::open(&path).expect("decodes").to_rgb8();
    for (x, y) in [(100, 100), (512, 300), (900, 950), (0, 0)] {
        let p = png.get_pixel(x, y).0;
        let want = Vec3::new(f32::from(p[0]), f32::from(p[1]), f32::from(p[2]))
            .map(|c| srgb_to_linear(c / 255.0));
        let got = d.maps().value(x, y).kd;
        assert!(
            (got - want).abs().max_element() < 2e-3,
            "({x}, {y}): {got} vs {want}"
        );
    }
    // One undo step restores the base.
    d.apply(HistoryCommand::Undo).expect("undo");
    assert_eq!(d.maps().value(512, 300), d.settings().base.quantized());
}

#[test]
fn importing_into_n_uses_the_log_scale() {
    let dir = std::env::temp_dir().join(format!("kapaint-n-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let gray = dir.join("gloss.png");
    image::GrayImage::from_fn(64, 64, |x, _| image::Luma([if x < 32 { 0 } else { 255 }]))
        .save(&gray)
        .expect("write");
    let mut d = doc(64, 64);
    d.import_file(Channel::N, &gray).expect("import");
    assert_eq!(d.maps().value(0, 0).n, 0.0);
    assert_eq!(d.maps().value(63, 0).n, N_MAX);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_images_are_clear_errors() {
    let dir = std::env::temp_dir().join(format!("kapaint-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let spot = std::fs::read(spot_texture()).expect("read");
    // Named so that the file name cannot satisfy the "truncated" check by itself.
    let truncated = dir.join("cut.png");
    std::fs::write(&truncated, &spot[..spot.len() / 2]).expect("write");
    let not_image = dir.join("notes.png");
    std::fs::write(&not_image, b"these are not pixels").expect("write");
    // A PNG header that claims 100000 x 100000 pixels: a decompression bomb.
    let mut bomb = spot[..33].to_vec();
    bomb[16..20].copy_from_slice(&100_000u32.to_be_bytes());
    bomb[20..24].copy_from_slice(&100_000u32.to_be_bytes());
    let crc = crc32(&bomb[12..29]);
    bomb[29..33].copy_from_slice(&crc.to_be_bytes());
    let bomb_path = dir.join("bomb.png");
    std::fs::write(&bomb_path, &bomb).expect("write");
    let mut d = doc(32, 32);
    let before = snapshot(d.maps());
    for (path, needle) in [
        (&truncated, "truncated"),
        (&not_image, "png"),
        (&bomb_path, "too large"),
    ] {
        let err = d
            .import_file(Channel::Kd, path)
            .expect_err("must fail")
            .to_string();
        assert!(
            err.contains(path.file_name().and_then(|n| n.to_str()).unwrap_or("?")),
            "{err}"
        );
        assert!(err.to_lowercase().contains(needle), "{err}");
    }
    assert_eq!(
        snapshot(d.maps()),
        before,
        "a failed import changes nothing"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// CRC-32 (IEEE), for building a valid PNG header in a test.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

#[test]
fn stored_n_decodes_within_a_tenth_of_a_percent() {
    for n in [0.7_f32, 1.0, 27.8974, 128.0, 999.0, 16000.0] {
        let stored = MaterialValue::new(Vec3::ZERO, Vec3::ZERO, n).quantized().n;
        assert!((stored / n - 1.0).abs() <= 0.0005, "{n} -> {stored}");
    }
}
