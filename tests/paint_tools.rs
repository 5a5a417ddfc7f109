//! Issue 56 through `kapaint paint`: a stencil's image named from the script's folder, clone
//! and smudge strokes, and bad images refused with one line, exit 2 and the project as it was.
#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn kapaint(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_kapaint"))
        .args(args)
        .output()
        .expect("kapaint runs")
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

fn dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("kapaint-tools-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("dir");
    d
}

/// A 64 x 64 checker of 8-texel squares (white at the top-left).
fn checker(path: &Path) {
    let img = image::GrayImage::from_fn(64, 64, |x, y| {
        image::Luma([if (x / 8 + y / 8) % 2 == 0 { 255 } else { 0 }])
    });
    img.save(path).expect("checker");
}

fn project(d: &Path) -> PathBuf {
    let p = d.join("a.kapaint");
    let o = kapaint(&["new", "--size", "256", "--out", s(&p)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    p
}

const STROKES: &str = r#"(commands: [
    SetPrimary((kd: (0.8, 0.1, 0.1), ks: (0.1, 0.1, 0.1), n: 500)),
    SetStencil(image: "IMAGE", center: (128, 128), size: 128),
    SetBrush((radius_px: 24, hardness: 1, pressure_size: false)),
    Stroke(tool: Brush, points: [(pos: (70, 128), pressure: 1), (pos: (186, 128), pressure: 1)]),
    ClearStencil,
    SetCloneSource((100, 128)),
    Stroke(tool: Clone, points: [(pos: (100, 220), pressure: 1), (pos: (110, 220), pressure: 1)]),
    Stroke(tool: Smudge, points: [(pos: (160, 128), pressure: 1), (pos: (160, 60), pressure: 1)]),
])"#;

#[test]
fn a_script_paints_through_a_stencil_named_from_its_folder_then_clones_and_smudges() {
    let d = dir("ok");
    let a = project(&d);
    std::fs::create_dir_all(d.join("art")).expect("art");
    checker(&d.join("art/checker.png"));
    let script = d.join("art/strokes.ron");
    std::fs::write(&script, STROKES.replace("IMAGE", "checker.png")).expect("script");
    let out = d.join("b.kapaint");
    let o = kapaint(&["paint", s(&a), "--script", s(&script), "--out", s(&out)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let set = d.join("set");
    let o = kapaint(&["export", "--preset", "separate", "--out", s(&set), s(&out)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let kd = image::open(set.join("kd.png")).expect("kd").to_rgb8();
    let red = |x: u32, y: u32| kd.get_pixel(x, y).0[0] > 200 && kd.get_pixel(x, y).0[1] < 150;
    // Through the stencil: red on its white squares, the base on its black ones (the
    // checker's 8-pixel squares are 16 texels at this size, white at its top-left corner).
    assert!(red(72 + 8, 120 + 4), "white square");
    assert!(!red(72 + 24, 120 + 4), "black square");
    // The clone put the stripe's pattern at the clone stroke (the offset is (0, -92)).
    for x in (88..120).step_by(4) {
        assert_eq!(red(x, 220), red(x, 128), "clone at ({x}, 220)");
    }
    // The smudge dragged the red up past where the brush painted (above y = 104).
    assert!((70..100).any(|y| red(160, y) || red(152, y) || red(168, y)));
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_missing_huge_or_corrupt_image_is_one_line_exit_2_and_nothing_written() {
    let d = dir("bad");
    let a = project(&d);
    let before = std::fs::read(&a).expect("read");
    image::GrayImage::new(9000, 2)
        .save(d.join("wide.png"))
        .expect("wide");
    std::fs::write(d.join("corrupt.png"), b"\x89PNG\r\n\x1a\nnot really").expect("corrupt");
    for (name, want) in [
        ("missing.png", "missing.png"),
        ("wide.png", "more than the 8192x8192"),
        ("corrupt.png", "corrupt.png"),
    ] {
        let script = d.join("s.ron");
        std::fs::write(&script, STROKES.replace("IMAGE", name)).expect("script");
        let o = kapaint(&["paint", s(&a), "--script", s(&script)]);
        let e = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{name}: {e}");
        assert_eq!(e.lines().count(), 1, "{e}");
        assert!(e.contains(want) && e.contains("command 2"), "{name}: {e}");
        assert_eq!(std::fs::read(&a).expect("read"), before, "{name}");
    }
    // Bad numbers and a clone source outside the map: refused, nothing written.
    checker(&d.join("checker.png"));
    for (bad, want) in [
        ("size: 128", "size: 0"),
        ("SetCloneSource((100, 128))", "SetCloneSource((100, 999))"),
    ] {
        let script = d.join("s.ron");
        let text = STROKES.replace("IMAGE", "checker.png").replace(bad, want);
        std::fs::write(&script, text).expect("script");
        let o = kapaint(&["paint", s(&a), "--script", s(&script)]);
        let e = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{want}: {e}");
        assert_eq!(e.lines().count(), 1, "{e}");
        assert_eq!(std::fs::read(&a).expect("read"), before, "{want}");
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// `ProjectImage` through the CLI: the project's own mesh is baked for a planar projection,
/// and a degenerate one or one that reaches nothing is refused with nothing written.
#[test]
fn a_script_projects_an_image_onto_the_projects_mesh_and_refuses_bad_projections() {
    let d = dir("project");
    let a = project(&d);
    let before = std::fs::read(&a).expect("read");
    checker(&d.join("checker.png"));
    let run = |projection: &str| {
        let script = d.join("p.ron");
        let text = format!(
            r#"(commands: [ProjectImage(image: "checker.png", projection: {projection}, channels: (kd: true, ks: false, n: false), opacity: 1)])"#
        );
        std::fs::write(&script, text).expect("script");
        let out = d.join("out.kapaint");
        let _ = std::fs::remove_file(&out);
        let o = kapaint(&["paint", s(&a), "--script", s(&script), "--out", s(&out)]);
        (o, out)
    };
    let (o, out) =
        run("Planar(origin: (0, 0, 1), normal: (0, 0, 1), up: (0, 1, 0), width: 1, height: 1)");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.exists());
    for (projection, want) in [
        (
            "Planar(origin: (0, 0, 1), normal: (0, 0, 1), up: (0, 0, 2), width: 1, height: 1)",
            "parallel",
        ),
        (
            "Planar(origin: (0, 0, 9), normal: (0, 0, 1), up: (0, 1, 0), width: 0.001, height: 0.001)",
            "reaches no texel",
        ),
        ("Triplanar(scale: 0, blend: 0.5)", "scale"),
    ] {
        let (o, out) = run(projection);
        let e = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{projection}: {e}");
        assert_eq!(e.lines().count(), 1, "{e}");
        assert!(e.contains(want), "{projection}: {e}");
        assert!(!out.exists(), "{projection} wrote a result");
    }
    assert_eq!(std::fs::read(&a).expect("read"), before);
    let _ = std::fs::remove_dir_all(&d);
}

/// A projection fill through a script: the project keeps its image (the file may go), opens
/// laid on its mesh, lists as a fill and exports what the editor shows; a bad one is refused.
#[test]
fn a_script_adds_a_projection_fill_that_the_project_keeps_without_its_file() {
    let d = dir("projection-fill");
    let a = project(&d);
    checker(&d.join("checker.png"));
    let script = d.join("f.ron");
    std::fs::write(
        &script,
        r#"(commands: [AddProjectionFill(name: "Checks", image: "checker.png", projection: Spherical(origin: (0, 0, 0), up: (0, 1, 0), front: (0, 0, 1)), channels: (kd: true, ks: false, n: false))])"#,
    )
    .expect("script");
    let out = d.join("filled.kapaint");
    let o = kapaint(&["paint", s(&a), "--script", s(&script), "--out", s(&out)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = kapaint(&["layers", s(&out)]);
    let listed = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        listed.lines().any(|l| l.contains(",fill,Checks,")),
        "{listed}"
    );
    let export = |to: &str| {
        let folder = d.join(to);
        let o = kapaint(&["export", s(&out), "--preset", "16-bit", "--out", s(&folder)]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let mut files: Vec<_> = std::fs::read_dir(&folder)
            .expect("set")
            .map(|e| e.expect("entry").path())
            .filter(|p| p.extension().is_some_and(|e| e == "png"))
            .collect();
        files.sort();
        files
            .iter()
            .map(|f| std::fs::read(f).expect("read"))
            .collect::<Vec<_>>()
    };
    let first = export("set1");
    // The image is kept in the project: without its file it opens and exports the same.
    std::fs::remove_file(d.join("checker.png")).expect("remove");
    assert_eq!(export("set2"), first);
    // A fill that reaches nothing is refused, nothing written.
    let bad = d.join("bad.ron");
    checker(&d.join("checker.png"));
    std::fs::write(
        &bad,
        r#"(commands: [AddProjectionFill(name: "Off", image: "checker.png", projection: Planar(origin: (0, 0, 9), normal: (0, 0, 1), up: (0, 1, 0), width: 0.001, height: 0.001))])"#,
    )
    .expect("script");
    let before = std::fs::read(&out).expect("read");
    let o = kapaint(&["paint", s(&out), "--script", s(&bad)]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains("reaches no texel"), "{e}");
    assert_eq!(std::fs::read(&out).expect("read"), before);
    let _ = std::fs::remove_dir_all(&d);
}
