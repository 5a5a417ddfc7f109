//! Generator masks through the CLI, on a real mesh: the teapot unwrapped and baked, a dirt
//! layer masked by the AO bake through levels (`kapaint paint` with `SetMaskGenerator`), the
//! mask following the bake texel by texel, and bad parameters in a script or a project file
//! refused with exit 2, the file untouched.
#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::path::{Path, PathBuf};

fn kapaint(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_kapaint"))
        .args(args)
        .output()
        .expect("kapaint runs")
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("kapaint-gen-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// A 256^2 project on the unwrapped teapot with its AO baked, in `dir`.
fn baked_teapot(dir: &Path) -> PathBuf {
    let project = dir.join("teapot.kapaint");
    let mesh = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/meshes/teapot.obj");
    let p = project.to_str().expect("path");
    let o = kapaint(&[
        "new",
        "--size",
        "256",
        "--mesh",
        mesh.to_str().expect("path"),
        "--unwrap",
        "--out",
        p,
    ]);
    assert!(o.status.success(), "{o:?}");
    let o = kapaint(&["bake", p, "--map", "ao", "--rays", "32"]);
    assert!(o.status.success(), "{o:?}");
    project
}

fn script(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write");
    path
}

#[test]
fn a_dirt_layer_follows_the_ao_bake_of_the_teapot() {
    let dir = temp_dir("dirt");
    let project = baked_teapot(&dir);
    let p = project.to_str().expect("path");
    let dirt = script(
        &dir,
        "dirt.ron",
        r#"(commands: [
            AddLayer(kind: Fill, name: "Dirt"),
            SetLayerFill((kd: (0.05, 0.04, 0.03), ks: (0.0, 0.0, 0.0), n: 2.0)),
            SetMaskGenerator(Ao(black: 0.3, white: 0.9, invert: true)),
        ])"#,
    );
    let o = kapaint(&["paint", p, "--script", dirt.to_str().expect("path")]);
    assert!(o.status.success(), "{o:?}");
    let mut doc = kapaint::model::project::load(&project).expect("loads");
    kapaint::model::project::attach_own_mesh(&mut doc).expect("its mesh");
    let ao = doc
        .bake_of(kapaint::mesh::bakes::BakeMap::Ao)
        .expect("baked")
        .clone();
    let surface = doc.surface().expect("attached").clone();
    let maps = doc.maps();
    let base = doc.stack().base;
    // Where the teapot sees the whole sky there is no dirt; where it sees little, all dirt.
    let (mut open, mut dark) = (0, 0);
    for i in 0..(256 * 256) {
        if surface.bake.triangle(i).is_none() {
            continue;
        }
        let kd = maps.value((i % 256) as u32, (i / 256) as u32).kd.x;
        let a = ao.value(i, 0);
        if a >= 0.95 {
            assert!((kd - base.kd.x).abs() < 2e-3, "texel {i}: AO {a}, k_d {kd}");
            open += 1;
        } else if a <= 0.25 {
            assert!((kd - 0.05).abs() < 2e-3, "texel {i}: AO {a}, k_d {kd}");
            dark += 1;
        }
    }
    assert!(open > 1000 && dark > 10, "open {open}, dark {dark}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_generator_parameters_exit_2_and_leave_the_file_untouched() {
    let dir = temp_dir("bad");
    let project = baked_teapot(&dir);
    let p = project.to_str().expect("path");
    let before = std::fs::read(&project).expect("read");
    for (k, bad) in [
        "SetMaskGenerator(Noise(kind: Perlin, scale: NaN, octaves: 4, seed: 1, space: Object))",
        "SetMaskGenerator(Ao(black: 0.9, white: 0.1, invert: false))",
        "SetMaskGenerator(Curvature(black: -1.0, white: 0.5, invert: false))",
        "SetMaskGenerator(Noise(kind: Perlin, scale: 8.0, octaves: 12, seed: 1, space: Object))",
    ]
    .iter()
    .enumerate()
    {
        let s = script(
            &dir,
            &format!("bad{k}.ron"),
            &format!("(commands: [{bad}])"),
        );
        let o = kapaint(&["paint", p, "--script", s.to_str().expect("path")]);
        assert_eq!(o.status.code(), Some(2), "{bad}: {o:?}");
        assert_eq!(std::fs::read(&project).expect("read"), before, "{bad}");
    }
    // A project file whose generator is out of range: refused, untouched.
    let good = script(
        &dir,
        "good.ron",
        "(commands: [AddLayer(kind: Fill, name: \"d\"), SetMaskGenerator(Ao(black: 0.2, white: 0.9, invert: false))])",
    );
    let o = kapaint(&["paint", p, "--script", good.to_str().expect("path")]);
    assert!(o.status.success(), "{o:?}");
    let bytes = std::fs::read(&project).expect("read");
    let tampered = dir.join("tampered.kapaint");
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(&bytes)).expect("zip");
    let mut out = zip::ZipWriter::new(std::fs::File::create(&tampered).expect("create"));
    for i in 0..zip.len() {
        use std::io::{Read, Write};
        let mut e = zip.by_index(i).expect("entry");
        let name = e.name().expect("name").to_string();
        let mut data = Vec::new();
        e.read_to_end(&mut data).expect("read");
        if name == "manifest.json" {
            let text = String::from_utf8(data).expect("utf-8");
            assert!(text.contains("\"black\": 0.2"), "{text}");
            data = text
                .replace("\"black\": 0.2", "\"black\": 1.5")
                .into_bytes();
        }
        out.start_file(name.as_str(), zip::write::SimpleFileOptions::default())
            .expect("start");
        out.write_all(&data).expect("write");
    }
    out.finish().expect("finish");
    let tampered_bytes = std::fs::read(&tampered).expect("read");
    let t = tampered.to_str().expect("path");
    let o = kapaint(&["paint", t, "--script", good.to_str().expect("path")]);
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("black"), "{err}");
    assert_eq!(std::fs::read(&tampered).expect("read"), tampered_bytes);
    let _ = std::fs::remove_dir_all(&dir);
}
