//! The command line as scripts see it: formats, ordering, exit codes, no partial output.
#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::io::Write;
use std::process::{Command, Output, Stdio};

fn kapaint(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_kapaint"))
        .args(args)
        .output()
        .expect("kapaint runs")
}

fn kapaint_stdin(args: &[&str], input: &str) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_kapaint"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("kapaint starts");
    child
        .stdin
        .take()
        .expect("stdin")
        .write_all(input.as_bytes())
        .expect("write stdin");
    child.wait_with_output().expect("kapaint ends")
}

fn stdout(o: &Output) -> String {
    String::from_utf8(o.stdout.clone()).expect("utf-8 output")
}

fn parse_csv(text: &str) -> Vec<(f64, f64)> {
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("n,chi"));
    lines
        .map(|l| {
            let (n, chi) = l.split_once(',').expect("two columns");
            (n.parse().expect("n"), chi.parse().expect("chi"))
        })
        .collect()
}

/// Asserts a clean usage failure: exit 2, one line on stderr, nothing on stdout.
fn assert_usage_error(o: &Output, mentions: &str) {
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    assert!(o.stdout.is_empty(), "partial output: {}", stdout(o));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.trim_end().lines().count(), 1, "stderr: {err}");
    assert!(
        err.contains(mentions),
        "stderr {err:?} should mention {mentions:?}"
    );
}

#[test]
fn chi_exact_matches_the_notes_check_values() {
    let o = kapaint(&[
        "chi", "--model", "phong", "--method", "exact", "1", "10", "200",
    ]);
    assert!(o.status.success());
    let rows = parse_csv(&stdout(&o));
    let want = [(1.0, 0.470_676), (10.0, 0.116_724), (200.0, 0.009_377_5)];
    assert_eq!(rows.len(), 3);
    for ((n, chi), (wn, wchi)) in rows.iter().zip(want) {
        assert_eq!(*n, wn);
        assert!((chi / wchi - 1.0).abs() < 1e-5, "chi({n}) = {chi}");
    }
}

#[test]
fn chi_prints_17_significant_digits_in_input_order() {
    let o = kapaint(&[
        "chi", "--model", "blinn", "--method", "fast", "200", "0", "3.5",
    ]);
    let text = stdout(&o);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[1].split(',').next(), Some("200"));
    assert_eq!(lines[2].split(',').next(), Some("0"));
    assert_eq!(lines[3].split(',').next(), Some("3.5"));
    for line in &lines[1..] {
        let chi = line.split(',').nth(1).expect("chi column");
        let mantissa = chi.split('e').next().expect("mantissa");
        let digits = mantissa.chars().filter(char::is_ascii_digit).count();
        assert_eq!(digits, 17, "{chi}");
    }
}

#[test]
fn chi_reads_values_from_stdin() {
    let o = kapaint_stdin(
        &["chi", "--model", "phong", "--method", "paper", "-"],
        "1\n2\n\n4\n",
    );
    assert!(o.status.success(), "{o:?}");
    let rows = parse_csv(&stdout(&o));
    assert_eq!(
        rows.iter().map(|r| r.0).collect::<Vec<_>>(),
        vec![1.0, 2.0, 4.0]
    );
    let bad = kapaint_stdin(
        &["chi", "--model", "phong", "--method", "paper", "-"],
        "1\nfoo\n",
    );
    assert_usage_error(&bad, "line 2");
}

#[test]
fn bad_arguments_exit_2_with_one_line_and_no_table() {
    assert_usage_error(
        &kapaint(&["chi", "--model", "phong", "--method", "exact", "1", "-3"]),
        ">= 0",
    );
    assert_usage_error(
        &kapaint(&["chi", "--model", "phong", "--method", "fast", "1", "abc"]),
        "number",
    );
    assert_usage_error(
        &kapaint(&["chi", "--model", "cook", "--method", "fast", "1"]),
        "cook",
    );
    assert_usage_error(
        &kapaint(&["chi", "--model", "phong", "--method", "fast", "nan"]),
        "finite",
    );
    assert_usage_error(
        &kapaint(&["chi", "--model", "phong", "--method", "exact", "2e6"]),
        "limit",
    );
    assert_usage_error(
        &kapaint(&["chi", "--model", "phong", "--method", "fast"]),
        "required",
    );
    assert_usage_error(
        &kapaint(&[
            "ka", "--model", "phong", "--method", "fast", "--kd", "1,2", "--ks", "0.5", "--n", "3",
        ]),
        "--kd",
    );
    assert_usage_error(
        &kapaint(&[
            "ka",
            "--model",
            "phong",
            "--method",
            "fast",
            "--kd",
            "0.5,0.5,1.5",
            "--ks",
            "0.5",
            "--n",
            "3",
        ]),
        "[0, 1]",
    );
    assert_usage_error(&kapaint(&["bench", "--size", "3"]), "--size");
}

#[test]
fn ka_prints_rgb_of_the_formula() {
    let o = kapaint(&[
        "ka",
        "--model",
        "phong",
        "--method",
        "exact",
        "--kd",
        "0.5,0.25,0",
        "--ks",
        "1",
        "--n",
        "10",
    ]);
    assert!(o.status.success(), "{o:?}");
    let text = stdout(&o);
    let rgb: Vec<f64> = text
        .trim()
        .split(',')
        .map(|v| v.parse().expect("number"))
        .collect();
    let chi = 0.116_724_291_692_596_77;
    let two_over_pi = std::f64::consts::FRAC_2_PI;
    for (got, kd) in rgb.iter().zip([0.5, 0.25, 0.0]) {
        assert!((got - (two_over_pi * kd + chi)).abs() < 1e-12, "{text}");
    }
    // Scalar and RGB k_s agree.
    let scalar = kapaint(&[
        "ka",
        "--model",
        "blinn",
        "--method",
        "fast",
        "--kd",
        "0.1,0.2,0.3",
        "--ks",
        "0.4",
        "--n",
        "50",
    ]);
    let rgb = kapaint(&[
        "ka",
        "--model",
        "blinn",
        "--method",
        "fast",
        "--kd",
        "0.1,0.2,0.3",
        "--ks",
        "0.4,0.4,0.4",
        "--n",
        "50",
    ]);
    assert_eq!(stdout(&scalar), stdout(&rgb));
}

#[test]
fn accuracy_prints_a_markdown_table_for_every_model_and_method() {
    let o = kapaint(&["accuracy", "--points", "6"]);
    assert!(o.status.success(), "{o:?}");
    let text = stdout(&o);
    let rows = text
        .lines()
        .filter(|l| l.starts_with("| phong") || l.starts_with("| blinn"))
        .count();
    assert_eq!(rows, 2 * 3 * 2, "{text}");
    assert!(text.contains("| blinn | paper-corrected | [1, 200] |"));
    assert!(text.contains("minimax (our integrator)"));
    // Cook-Torrance: both parts, by kapaint's fit and Karis' two readings, on both ranges.
    let ct = text
        .lines()
        .filter(|l| l.starts_with("| chi1") || l.starts_with("| chi0"))
        .count();
    assert_eq!(ct, 2 * 3 * 2, "{text}");
    assert!(text.contains("| chi0 | karis (view-averaged) | [0, 16384] |"));
}

#[test]
fn cook_torrance_chi_prints_both_parts_and_refuses_the_paper_methods() {
    let o = kapaint(&[
        "chi",
        "--model",
        "cook-torrance",
        "--method",
        "exact",
        "0",
        "16384",
    ]);
    assert!(o.status.success(), "{o:?}");
    let text = stdout(&o);
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("n,chi1,chi0"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().expect("number")).collect())
        .collect();
    // chi_1(0) + chi_0(0) = 1/(4 pi), derived in reflectance::cook_torrance.
    assert_eq!(rows[0][0], 0.0);
    let sum = rows[0][1] + rows[0][2];
    assert!(
        (sum - 1.0 / (4.0 * std::f64::consts::PI)).abs() < 1e-12,
        "{text}"
    );
    assert!((rows[1][1] - 0.369_412_889_873_204).abs() < 1e-12, "{text}");
    // 17 significant digits in both columns, as for the other models.
    for line in text.lines().skip(1) {
        for value in line.split(',').skip(1) {
            let mantissa = value.split('e').next().expect("mantissa");
            assert_eq!(
                mantissa.chars().filter(char::is_ascii_digit).count(),
                17,
                "{value}"
            );
        }
    }
    let fast = stdout(&kapaint(&[
        "chi",
        "--model",
        "cook-torrance",
        "--method",
        "fast",
        "16384",
    ]));
    let fast1: f64 = fast
        .lines()
        .nth(1)
        .and_then(|l| l.split(',').nth(1))
        .and_then(|v| v.parse().ok())
        .expect("value");
    assert!((fast1 / rows[1][1] - 1.0).abs() < 2e-5, "{fast}");
    assert_usage_error(
        &kapaint(&["chi", "--model", "cook-torrance", "--method", "paper", "1"]),
        "no approximation for Cook-Torrance",
    );
    // k_a = (2/pi) k_d + k_s chi_1 + chi_0 per channel; chi_0 even where k_s = 0.
    let ka = stdout(&kapaint(&[
        "ka",
        "--model",
        "cook-torrance",
        "--method",
        "exact",
        "--kd",
        "0,0,0",
        "--ks",
        "0,0,1",
        "--n",
        "0",
    ]));
    let v: Vec<f64> = ka
        .trim()
        .split(',')
        .map(|x| x.parse().expect("number"))
        .collect();
    assert!(
        (v[2] - 1.0 / (4.0 * std::f64::consts::PI)).abs() < 1e-12,
        "{ka}"
    );
    assert!(v[0] > 5e-4 && v[0] == v[1], "{ka}");
    // accuracy and bench take one model too.
    let only = stdout(&kapaint(&[
        "accuracy",
        "--points",
        "3",
        "--model",
        "cook-torrance",
    ]));
    assert!(
        only.contains("| chi1 | fast |") && !only.contains("| phong"),
        "{only}"
    );
    let only = stdout(&kapaint(&[
        "bench",
        "--size",
        "16",
        "--repeats",
        "1",
        "--model",
        "phong",
    ]));
    assert!(
        only.contains("| phong | fast |") && !only.contains("cook-torrance"),
        "{only}"
    );
}

#[test]
fn bench_writes_csv_and_a_decodable_plot() {
    let dir = std::env::temp_dir().join(format!("kapaint-bench-{}", std::process::id()));
    let o = kapaint(&[
        "bench",
        "--size",
        "64",
        "--repeats",
        "1",
        "--out",
        dir.to_str().expect("path"),
    ]);
    assert!(o.status.success(), "{o:?}");
    assert_eq!(
        stdout(&o)
            .lines()
            .filter(|l| l.starts_with("| phong") || l.starts_with("| blinn"))
            .count(),
        6
    );
    assert!(stdout(&o).contains("| cook-torrance | fast |"));
    assert!(stdout(&o).contains("| cook-torrance | karis |"));
    let csv = std::fs::read_to_string(dir.join("bench.csv")).expect("csv written");
    assert_eq!(csv.lines().count(), 9);
    assert!(csv.starts_with("model,method,ns_per_texel_1t"));
    let png = image::open(dir.join("bench.png")).expect("plot decodes");
    assert!(png.width() > 100 && png.height() > 100);
    let _ = std::fs::remove_dir_all(&dir);
}

fn temp_dir(tag: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("kapaint-cli-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

#[test]
fn new_info_paint_and_import_work_end_to_end() {
    let dir = temp_dir("project");
    let file = dir.join("a.kapaint");
    let path = file.to_str().expect("path");
    let o = kapaint(&[
        "new", "--size", "200x120", "--preset", "gold", "--out", path,
    ]);
    assert!(o.status.success(), "{o:?}");
    let info = stdout(&kapaint(&["info", path]));
    assert!(info.contains("size: 200x120"), "{info}");
    assert!(info.contains("preset: Gold"), "{info}");
    assert!(info.contains("kd.r 0.7516"), "{info}");
    // Refuses to overwrite without --force.
    assert_usage_error(&kapaint(&["new", "--size", "8", "--out", path]), "--force");

    let script = dir.join("s.ron");
    std::fs::write(
        &script,
        "(commands: [SetPrimary((kd: (0.0, 0.0, 1.0), ks: (0.1, 0.1, 0.1), n: 9.0)), \
         Stroke(tool: Brush, points: [(pos: (10.0, 60.0), pressure: 1.0), (pos: (190.0, 60.0), pressure: 1.0)])])",
    )
    .expect("write script");
    let o = kapaint(&["paint", path, "--script", script.to_str().expect("path")]);
    assert!(o.status.success(), "{o:?}");
    let info = stdout(&kapaint(&["info", path]));
    assert!(
        info.contains("kd.r 0.000000"),
        "the stroke reached pure blue somewhere: {info}"
    );

    let texture = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/testdata/spot/spot_texture.png");
    let out = dir.join("b.kapaint");
    let o = kapaint(&[
        "import",
        path,
        "--channel",
        "ks",
        "--image",
        texture.to_str().expect("path"),
        "--out",
        out.to_str().expect("path"),
    ]);
    assert!(o.status.success(), "{o:?}");
    assert!(stdout(&kapaint(&["info", out.to_str().expect("path")])).contains("size: 200x120"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn failures_leave_the_input_file_untouched() {
    let dir = temp_dir("untouched");
    let file = dir.join("a.kapaint");
    let path = file.to_str().expect("path");
    assert!(
        kapaint(&["new", "--size", "64", "--out", path])
            .status
            .success()
    );
    let before = std::fs::read(&file).expect("read");

    let bad_script = dir.join("bad.ron");
    std::fs::write(&bad_script, "(commands: [Teleport(1, 2)])").expect("write");
    assert_usage_error(
        &kapaint(&[
            "paint",
            path,
            "--script",
            bad_script.to_str().expect("path"),
        ]),
        "bad.ron",
    );

    let outside = dir.join("outside.ron");
    std::fs::write(&outside, "(commands: [Fill(All), Pick(x: 999, y: 0)])").expect("write");
    assert_usage_error(
        &kapaint(&["paint", path, "--script", outside.to_str().expect("path")]),
        "command 2",
    );

    let not_image = dir.join("x.png");
    std::fs::write(&not_image, b"nope").expect("write");
    assert_usage_error(
        &kapaint(&[
            "import",
            path,
            "--channel",
            "kd",
            "--image",
            not_image.to_str().expect("path"),
        ]),
        "x.png",
    );

    assert_usage_error(
        &kapaint(&[
            "new",
            "--size",
            "64",
            "--preset",
            "nope",
            "--out",
            dir.join("c.kapaint").to_str().expect("path"),
        ]),
        "nope",
    );
    assert_usage_error(
        &kapaint(&["info", dir.join("missing.kapaint").to_str().expect("path")]),
        "missing.kapaint",
    );
    let garbage = dir.join("garbage.kapaint");
    std::fs::write(&garbage, b"PK\x03\x04 truncated").expect("write");
    assert_usage_error(
        &kapaint(&["info", garbage.to_str().expect("path")]),
        "not a valid kapaint project",
    );

    assert_eq!(
        std::fs::read(&file).expect("read"),
        before,
        "the input file changed"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn paint_scripts_take_strokes_on_the_mesh() {
    let dir = temp_dir("surface");
    let file = dir.join("spot.kapaint");
    let path = file.to_str().expect("path");
    let spot = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/testdata/spot/spot_triangulated.obj");
    let o = kapaint(&[
        "new",
        "--size",
        "256",
        "--mesh",
        spot.to_str().expect("path"),
        "--out",
        path,
    ]);
    assert!(o.status.success(), "{o:?}");
    assert!(stdout(&kapaint(&["info", path])).contains("spot_triangulated.obj"));
    let before = std::fs::read(&file).expect("read");
    let script = dir.join("s.ron");
    // A stroke over spot's back (object-space points with pressure), mirrored in X.
    std::fs::write(
        &script,
        "(commands: [SetPrimary((kd: (0.0, 0.0, 1.0), ks: (0.1, 0.1, 0.1), n: 9.0)), \
         SetBrush((radius_px: 12.0, mirror_x: true)), \
         SurfaceStroke(tool: Brush, points: [(pos: (point: (0.3, 0.6, 0.0)), pressure: 1.0), \
         (pos: (point: (0.3, 0.6, -0.4), normal: (0.0, 1.0, 0.0)), pressure: 0.5)])])",
    )
    .expect("write script");
    let o = kapaint(&["paint", path, "--script", script.to_str().expect("path")]);
    assert!(o.status.success(), "{o:?}");
    assert_ne!(
        std::fs::read(&file).expect("read"),
        before,
        "the stroke changed the maps"
    );
    let info = stdout(&kapaint(&["info", path]));
    assert!(info.contains("kd.r 0.000000"), "{info}");

    // Strokes on the mesh with a mesh that cannot be painted: one clear line, file untouched.
    let painted = std::fs::read(&file).expect("read");
    let no_uvs = dir.join("no_uvs.obj");
    std::fs::write(&no_uvs, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").expect("write");
    let o = kapaint(&[
        "paint",
        path,
        "--script",
        script.to_str().expect("path"),
        "--mesh",
        no_uvs.to_str().expect("path"),
    ]);
    assert_usage_error(&o, "no UV coordinates");
    assert_eq!(std::fs::read(&file).expect("read"), painted);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn equivalent_n_maps_between_the_models() {
    let o = kapaint(&["equivalent-n", "--from", "phong", "0", "1", "10000"]);
    assert!(o.status.success(), "{o:?}");
    let text = stdout(&o);
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("n,equivalent"));
    let rows: Vec<(f64, f64)> = lines
        .map(|l| {
            let (a, b) = l.split_once(',').expect("two columns");
            (a.parse().expect("n"), b.parse().expect("m"))
        })
        .collect();
    assert_eq!(rows[0], (0.0, 0.0));
    // The documented figure (docs/renderer.md): n = 1 matches Blinn-Phong's 5.44.
    assert!((rows[1].1 - 5.44).abs() < 0.005, "{rows:?}");
    assert!((rows[2].1 / 10000.0 - 4.0).abs() < 0.01, "{rows:?}");
    assert_usage_error(
        &kapaint(&["equivalent-n", "--from", "blinn", "-1"]),
        "n must be >= 0",
    );
}

/// `kapaint edit` is a subcommand like the others: `--help` lists it, `help edit` and
/// `edit --help` print its usage and open no window (no display here: a window would fail).
#[test]
fn edit_is_listed_and_its_help_opens_no_window() {
    let headless = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_kapaint"))
            .args(args)
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .expect("kapaint runs")
    };
    let help = headless(&["--help"]);
    assert!(help.status.success());
    assert!(
        stdout(&help)
            .lines()
            .any(|l| l.trim_start().starts_with("edit ")),
        "{}",
        stdout(&help)
    );
    for args in [&["help", "edit"][..], &["edit", "--help"]] {
        let o = headless(args);
        assert!(
            o.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(
            stdout(&o).contains("Usage: kapaint edit [FILE]"),
            "{args:?}: {}",
            stdout(&o)
        );
    }
}

#[test]
fn a_paint_script_builds_layers_and_kapaint_layers_lists_them() {
    let dir = std::env::temp_dir().join(format!("kapaint-layers-cli-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    let project = dir.join("p.kapaint");
    let path = project.to_str().expect("path");
    let o = kapaint(&["new", "--size", "128", "--out", path]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let script = dir.join("layers.ron");
    std::fs::write(
        &script,
        r#"(commands: [
            AddLayer(kind: Paint, name: "Rust, old"),
            SetPrimary((kd: (0.35, 0.12, 0.04), ks: (0.02, 0.02, 0.02), n: 4.0)),
            Stroke(tool: Brush, points: [(pos: (10.0, 64.0), pressure: 1.0), (pos: (120.0, 64.0), pressure: 1.0)]),
            AddMask,
            InvertMask,
            AddLayer(kind: Fill, name: "Gloss"),
            SetLayerChannels((kd: false, ks: false, n: true)),
            SetLayerOpacity(0.5),
            SetLayerBlend(channel: N, mode: Max),
            SetLayerVisible(false),
        ])"#,
    )
    .expect("script");
    let o = kapaint(&["paint", path, "--script", script.to_str().expect("path")]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = kapaint(&["layers", path]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8(o.stdout).expect("utf-8");
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(
        lines[0],
        "index,kind,name,visible,opacity,kd_blend,ks_blend,n_blend,mask,bytes,id"
    );
    assert!(
        lines[1].starts_with("0,paint,Layer 1,true,1,normal,normal,normal,none,0"),
        "{text}"
    );
    assert!(
        lines[2].starts_with("1,paint,\"Rust, old\",true,1,normal,normal,normal,inverted,"),
        "{text}"
    );
    let bytes: u64 = lines[2]
        .rsplit(',')
        .nth(1)
        .and_then(|b| b.parse().ok())
        .expect("bytes");
    assert!(bytes > 0, "a painted layer holds tiles: {text}");
    assert!(
        lines[3].starts_with("2,fill,Gloss,false,0.5,off,off,max,none,0,"),
        "{text}"
    );
    // The id column comes last: one id a layer, each its own.
    let ids: std::collections::BTreeSet<u64> = lines[1..]
        .iter()
        .map(|l| {
            l.rsplit(',')
                .next()
                .and_then(|i| i.parse().ok())
                .expect("id")
        })
        .collect();
    assert_eq!(ids.len(), 3, "{text}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `kapaint import` onto a layer that cannot take the image: a locked layer, a fill layer, the
/// mask of a layer. Each is refused with exit 2 and one line, and the project is left byte for
/// byte as it was (the import's failure was once dropped and the project saved as if done).
#[test]
fn import_onto_a_locked_layer_a_fill_layer_or_a_mask_exits_2_and_changes_nothing() {
    let dir = std::env::temp_dir().join(format!("kapaint-import-refused-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    let image = dir.join("grey.png");
    image::GrayImage::from_fn(32, 32, |x, y| image::Luma([(x * 7 + y * 3) as u8]))
        .save(&image)
        .expect("image");
    let cases = [
        ("locked", "SetLayerLocked(true)", "is locked"),
        (
            "fill",
            "AddLayer(kind: Fill, name: \"Gloss\")",
            "has no pixels to paint",
        ),
        ("mask", "AddMask, SelectMask", "not a mask"),
    ];
    for (name, commands, says) in cases {
        let project = dir.join(format!("{name}.kapaint"));
        let path = project.to_str().expect("path");
        let o = kapaint(&["new", "--size", "64", "--out", path]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let script = dir.join(format!("{name}.ron"));
        std::fs::write(&script, format!("(commands: [{commands}])")).expect("script");
        let o = kapaint(&["paint", path, "--script", script.to_str().expect("path")]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let before = std::fs::read(&project).expect("read");
        for channel in ["kd", "ks", "n"] {
            let o = kapaint(&[
                "import",
                "--channel",
                channel,
                "--image",
                image.to_str().expect("path"),
                path,
            ]);
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "{name} {channel}: {err}");
            assert_eq!(err.lines().count(), 1, "{name} {channel}: {err}");
            assert!(err.contains(says), "{name} {channel}: {err}");
            assert!(o.stdout.is_empty(), "{name} {channel}");
            assert_eq!(
                std::fs::read(&project).expect("read"),
                before,
                "{name} {channel}: the project is untouched"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `kapaint render`'s model, view, method and sides are closed lists: an unknown value exits 2
/// with the valid ones, before anything is opened or drawn (none falls back to a default).
#[test]
fn render_refuses_unknown_models_views_methods_and_sides_with_the_valid_ones() {
    let out = std::env::temp_dir().join(format!("kapaint-render-args-{}.png", std::process::id()));
    let out = out.to_str().expect("path");
    let cases: [(&[&str], &str); 5] = [
        (
            &["--model", "bogus", "--view", "shaded"],
            "phong, blinn, cook-torrance, compare-split, compare-side, compare-diff, compare-three",
        ),
        (
            &["--model", "phong", "--view", "bogus"],
            "shaded, ka, kd, ks, n, diffuse, specular, ambient, checker, n-false-colour",
        ),
        (
            &["--model", "phong", "--view", "ka", "--method", "exactly"],
            "fast, paper, paper-corrected",
        ),
        (
            &[
                "--model",
                "compare-diff",
                "--view",
                "ka",
                "--sides",
                "phong,bogus",
            ],
            "phong, blinn, cook-torrance",
        ),
        (
            &[
                "--model",
                "compare-diff",
                "--view",
                "ka",
                "--sides",
                "phong,blinn,phong",
            ],
            "two models",
        ),
    ];
    for (args, says) in cases {
        let mut all = vec!["render", "--out", out];
        all.extend_from_slice(args);
        let o = kapaint(&all);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(!std::path::Path::new(out).exists(), "{args:?} drew nothing");
    }
}

/// `chi --method exact -` writes its rows as it computes them: the first arrives while the
/// run is still integrating the rest (it printed nothing until the end: 10^6 values showed
/// nothing for hours), and the whole output is the same as computed at once.
#[test]
fn chi_streams_its_rows_as_they_are_computed() {
    use std::io::{BufRead, BufReader};
    let values: String = (0..64).map(|k| (1 + 7 * k).to_string() + "\n").collect();
    let mut child = Command::new(env!("CARGO_BIN_EXE_kapaint"))
        .args(["chi", "--model", "phong", "--method", "exact", "-"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("kapaint starts");
    child
        .stdin
        .take()
        .expect("stdin")
        .write_all(values.as_bytes())
        .expect("values written");
    let mut out = BufReader::new(child.stdout.take().expect("stdout"));
    let mut header = String::new();
    out.read_line(&mut header).expect("header");
    assert_eq!(header, "n,chi\n");
    let mut first = String::new();
    out.read_line(&mut first).expect("a row");
    assert!(first.starts_with("1,"), "{first}");
    assert!(
        child.try_wait().expect("status").is_none(),
        "the first row came only when everything was done"
    );
    let rows: Vec<String> = std::iter::once(first.trim_end().to_owned())
        .chain(out.lines().map(|l| l.expect("row")))
        .collect();
    assert!(child.wait().expect("ends").success());
    assert_eq!(rows.len(), 64);
    let all_at_once = kapaint(&["chi", "--model", "phong", "--method", "exact", "1", "8"]);
    let expected: Vec<&str> = std::str::from_utf8(&all_at_once.stdout)
        .expect("utf-8")
        .lines()
        .skip(1)
        .collect();
    assert_eq!(&rows[..2], &expected[..]);
}
