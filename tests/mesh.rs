//! Mesh import against the real spot files of `../shared/testdata`, and corrupted copies.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::path::{Path, PathBuf};

use kapaint::mesh::{self, Mesh};

fn spot(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/testdata/spot")
        .join(name)
}

fn temp(name: &str, text: &[u8]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("kapaint-mesh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write");
    path
}

#[test]
fn spot_loads_with_uvs_and_computed_normals() {
    let tri = mesh::load(&spot("spot_triangulated.obj")).expect("loads");
    let quad = mesh::load(&spot("spot_quadrangulated.obj")).expect("loads");
    for m in [&tri, &quad] {
        assert_eq!(m.triangles.len(), 5856);
        assert!(m.uvs.is_some());
        assert!(!m.had_normals);
        m.validate().expect("valid");
        assert!(m.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-4));
        assert!(m.paintable().is_ok());
    }
    assert_eq!(tri.bounds(), quad.bounds());
    assert_eq!(tri.uv_islands(), quad.uv_islands());
    assert!(tri.uv_islands() >= 1);
}

#[test]
fn normals_are_smooth_across_uv_seams() {
    let m = mesh::load(&spot("spot_triangulated.obj")).expect("loads");
    // Vertices split only by UV (same position) carry the same normal.
    let mut by_position = std::collections::HashMap::new();
    let mut split = 0;
    for (p, n) in m.positions.iter().zip(&m.normals) {
        let key = (p.x.to_bits(), p.y.to_bits(), p.z.to_bits());
        if let Some(first) = by_position.insert(key, *n) {
            split += 1;
            assert!((first - *n).length() < 1e-6, "seam normal differs");
        }
    }
    assert!(split > 0, "spot has UV seams");
    // They agree with the winding of the faces around them...
    let agree = m
        .triangles
        .iter()
        .filter(|t| {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            let face = (b - a).cross(c - a);
            t.iter().all(|&i| face.dot(m.normals[i as usize]) > 0.0)
        })
        .count();
    assert!(
        agree * 100 > m.triangles.len() * 98,
        "{agree} of {}",
        m.triangles.len()
    );
    // ...and the faces wind outwards: a closed surface with positive signed volume.
    let volume: f32 = m
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            a.dot(b.cross(c)) / 6.0
        })
        .sum();
    assert!(volume > 0.0, "signed volume {volume}");
}

#[test]
fn meshes_without_uvs_preview_but_refuse_painting() {
    let path = temp("nouv.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let m = mesh::load(&path).expect("loads");
    let err = m.paintable().expect_err("no UVs");
    assert!(
        err.contains("no UV coordinates") && err.contains("nouv.obj"),
        "{err}"
    );
    assert_eq!(m.uv_islands(), 0);
}

#[test]
fn corrupt_obj_files_are_clear_errors_naming_the_file() {
    let text = std::fs::read(spot("spot_triangulated.obj")).expect("read");
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("empty.obj", Vec::new(), "no triangles"),
        ("range.obj", b"v 0 0 0\nv 1 0 0\nf 1 2 9\n".to_vec(), ""),
        (
            "nan.obj",
            b"v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".to_vec(),
            "",
        ),
        (
            "garbage.obj",
            vec![0xff, 0xfe, 0x00, 0x41, 0x42, 0x0a, 0x66, 0x20, 0x31],
            "",
        ),
        ("points.obj", b"v 0 0 0\nv 1 0 0\n".to_vec(), "no triangles"),
        ("cut.obj", text[..text.len() * 2 / 3].to_vec(), ""),
    ];
    for (name, bytes, needle) in cases {
        let path = temp(name, &bytes);
        match mesh::load(&path) {
            Err(e) => {
                let e = e.to_string();
                assert!(e.contains(name), "{e}");
                assert!(e.contains(needle), "{e} should mention {needle}");
            }
            // A file cut between lines can be a smaller valid mesh; it must then be valid.
            Ok(m) => {
                assert_eq!(name, "cut.obj", "{name} should not load");
                m.validate().expect("a loaded mesh is valid");
            }
        }
    }
    let unknown = temp("model.fbx", b"whatever");
    assert!(
        mesh::load(&unknown)
            .expect_err("unsupported")
            .to_string()
            .contains("unsupported")
    );
}

#[test]
fn mesh_info_cli_reports_the_spot_mesh() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_kapaint"))
        .args([
            "mesh-info",
            spot("spot_quadrangulated.obj").to_str().expect("path"),
        ])
        .output()
        .expect("runs");
    assert!(out.status.success(), "{out:?}");
    let text = String::from_utf8(out.stdout).expect("utf-8");
    assert!(text.contains("triangles: 5856"), "{text}");
    assert!(
        text.contains("normals: computed") && text.contains("uvs: present"),
        "{text}"
    );
    let sphere = std::process::Command::new(env!("CARGO_BIN_EXE_kapaint"))
        .args(["mesh-info", "sphere"])
        .output()
        .expect("runs");
    assert!(String::from_utf8_lossy(&sphere.stdout).contains("uv islands: 1"));
    let _: Option<Mesh> = None;
}

/// Exact (f64) point-in-triangle test, inclusive of edges.
fn inside(p: (f64, f64), a: (f64, f64), b: (f64, f64), c: (f64, f64)) -> bool {
    let cross = |o: (f64, f64), u: (f64, f64), v: (f64, f64)| {
        (u.0 - o.0) * (v.1 - o.1) - (u.1 - o.1) * (v.0 - o.0)
    };
    let (d1, d2, d3) = (cross(a, b, p), cross(b, c, p), cross(c, a, p));
    let neg = d1 < 0.0 || d2 < 0.0 || d3 < 0.0;
    let pos = d1 > 0.0 || d2 > 0.0 || d3 > 0.0;
    !(neg && pos)
}

fn check_coverage(m: &Mesh, w: u32, h: u32) {
    use kapaint::mesh::bake::{Coverage, bake};
    let baked = bake(m, w, h, 0).expect("bakes");
    let uvs = m.uvs.as_ref().expect("uvs");
    let mut must = vec![false; (w * h) as usize];
    for t in &m.triangles {
        let [a, b, c] = t.map(|i| {
            let uv = uvs[i as usize];
            (
                f64::from(uv.x) * f64::from(w),
                (1.0 - f64::from(uv.y)) * f64::from(h),
            )
        });
        let x0 = a.0.min(b.0).min(c.0).floor().max(0.0) as u32;
        let x1 = (a.0.max(b.0).max(c.0).ceil() as u32).min(w - 1);
        let y0 = a.1.min(b.1).min(c.1).floor().max(0.0) as u32;
        let y1 = (a.1.max(b.1).max(c.1).ceil() as u32).min(h - 1);
        for y in y0..=y1 {
            for x in x0..=x1 {
                if inside((f64::from(x) + 0.5, f64::from(y) + 0.5), a, b, c) {
                    must[(y * w + x) as usize] = true;
                }
            }
        }
    }
    let missed = must
        .iter()
        .zip(&baked.coverage_grid())
        .filter(|(m, c)| **m && **c == Coverage::Empty)
        .count();
    assert_eq!(
        missed, 0,
        "{missed} texels whose centre lies in a triangle are not covered"
    );
    // Every covered texel holds a finite point of the surface and a unit normal.
    for k in 0..must.len() {
        if baked.coverage(k) != Coverage::Empty {
            assert!(baked.position(k).is_finite());
            assert!((baked.normal(k).length() - 1.0).abs() < 1e-3);
            assert!(baked.triangle(k).is_some() && baked.island(k).is_some());
        }
    }
    // Conservative, not sloppy: covered texels beyond the centre-inside set are a thin rim.
    let extra = baked
        .coverage_grid()
        .iter()
        .zip(&must)
        .filter(|(c, m)| **c != Coverage::Empty && !**m)
        .count();
    let inner = must.iter().filter(|m| **m).count();
    assert!(extra < inner, "{extra} rim texels for {inner} inside");
}

#[test]
fn bake_covers_every_texel_inside_a_uv_triangle() {
    check_coverage(
        &mesh::load(&spot("spot_triangulated.obj")).expect("loads"),
        512,
        512,
    );
    check_coverage(&mesh::uv_sphere(48, 24), 256, 128);
    check_coverage(&mesh::cube(), 300, 200);
}

#[test]
fn bake_padding_grows_islands() {
    use kapaint::mesh::bake::{Coverage, bake};
    let cube = mesh::cube();
    let plain = bake(&cube, 256, 256, 0).expect("bakes");
    let padded = bake(&cube, 256, 256, 3).expect("bakes");
    let count = |b: &kapaint::mesh::bake::UvBake, c: Coverage| {
        b.coverage_grid().iter().filter(|x| **x == c).count()
    };
    assert_eq!(count(&plain, Coverage::Padding), 0);
    assert!(count(&padded, Coverage::Padding) > 0);
    assert_eq!(
        count(&plain, Coverage::Surface),
        count(&padded, Coverage::Surface)
    );
    // Padding copies a neighbour's surface point: its island is a real one.
    for (k, c) in padded.coverage_grid().iter().enumerate() {
        if *c == Coverage::Padding {
            assert!(padded.island(k).is_some_and(|i| i < 6));
        }
    }
    let no_uv = Mesh {
        uvs: None,
        ..mesh::plane()
    };
    assert!(bake(&no_uv, 16, 16, 0).is_err());
}

#[test]
fn picking_agrees_with_brute_force_on_random_rays() {
    use glam::Vec3;
    use kapaint::mesh::pick::{Bvh, intersect};
    for m in [
        mesh::load(&spot("spot_triangulated.obj")).expect("loads"),
        mesh::torus(1.0, 0.3, 40, 20),
    ] {
        let bvh = Bvh::build(&m);
        let (lo, hi) = m.bounds();
        let (center, size) = ((lo + hi) / 2.0, (hi - lo).length());
        let mut state = 0x9E37_79B9_u64;
        let mut next = move || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        };
        let mut hits = 0;
        for _ in 0..2000 {
            let origin =
                center + Vec3::new(next(), next(), next()).normalize_or(Vec3::X) * size * 1.5;
            let aim = center + Vec3::new(next(), next(), next()) * (hi - lo) * 0.5;
            let dir = aim - origin;
            let brute = (0..m.triangles.len() as u32)
                .filter_map(|t| intersect(&m, t, origin, dir).map(|(d, _, _)| (d, t)))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            let fast = bvh.pick(&m, origin, dir);
            match (brute, fast) {
                (None, None) => {}
                (Some((d, _)), Some(hit)) => {
                    hits += 1;
                    assert!((hit.t - d).abs() <= 1e-5 * d.max(1.0), "t {} vs {d}", hit.t);
                    assert!((origin + dir * hit.t - hit.position).length() < 1e-3 * size);
                    assert!(hit.uv.is_some() && (hit.barycentric.element_sum() - 1.0).abs() < 1e-5);
                }
                (b, f) => panic!("brute force {b:?} but BVH {f:?}"),
            }
        }
        assert!(hits > 500, "only {hits} rays hit");
    }
}

fn data_mesh(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/meshes")
        .join(name)
}

fn kapaint(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_kapaint"))
        .args(args)
        .output()
        .expect("kapaint runs")
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("kapaint-unwrap-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// The percentage of the map covered, from `kapaint unwrap`'s first line.
fn covered(line: &str) -> f64 {
    let (before, _) = line.split_once(" % of a").expect("coverage in the line");
    before
        .rsplit(' ')
        .next()
        .and_then(|t| t.parse().ok())
        .expect("a number")
}

/// Teapot and suzanne have no UVs: each unwraps into an atlas that covers at least 60 % of
/// the map with no texel claimed twice, written as OBJ and as GLB, and read back with UVs.
#[test]
fn meshes_without_uvs_unwrap_into_a_clean_atlas() {
    let dir = temp_dir("atlas");
    for (name, triangles) in [("teapot.obj", 6320), ("suzanne.obj", 968)] {
        let source = mesh::load(&data_mesh(name)).expect("loads");
        assert!(source.uvs.is_none(), "{name} comes without UVs");
        assert_eq!(source.triangles.len(), triangles);
        for ext in ["obj", "glb"] {
            let out = dir.join(format!("{name}.{ext}"));
            let o = kapaint(&[
                "unwrap",
                data_mesh(name).to_str().expect("path"),
                "--out",
                out.to_str().expect("path"),
            ]);
            assert!(o.status.success(), "{o:?}");
            let text = String::from_utf8(o.stdout).expect("utf-8");
            let first = text.lines().next().expect("a line");
            assert!(first.starts_with("unwrapped "), "{text}");
            assert!(covered(first) >= 60.0, "{first}");
            let back = mesh::load(&out).expect("the unwrapped mesh loads");
            assert_eq!(back.triangles.len(), triangles);
            assert!(back.paintable().is_ok());
            assert_eq!(mesh::unwrap::uv_overlap(&back, 2048), 0.0, "{name}.{ext}");
            assert!(mesh::unwrap::uv_area(&back) >= 0.6, "{name}.{ext}");
            // Every triangle keeps its corners where they were.
            for (a, b) in back.triangles.iter().zip(&source.triangles) {
                for k in 0..3 {
                    let (p, q) = (
                        back.positions[a[k] as usize],
                        source.positions[b[k] as usize],
                    );
                    assert!((p - q).length() < 1e-5, "{name}.{ext}: {p} vs {q}");
                }
            }
        }
    }
}

/// What cannot be unwrapped, or written, is one line and exit 2, and nothing is written.
#[test]
fn unwrap_refuses_what_it_cannot_do() {
    let dir = temp_dir("refused");
    let degenerate = dir.join("line.obj");
    std::fs::write(&degenerate, "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n").expect("write");
    let nan = dir.join("nan.obj");
    std::fs::write(&nan, "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n").expect("write");
    let teapot = data_mesh("teapot.obj");
    let teapot = teapot.to_str().expect("path");
    let out = dir.join("out.obj");
    let out_s = out.to_str().expect("path");
    let existing = dir.join("existing.obj");
    std::fs::write(&existing, "keep me").expect("write");
    for (args, mentions) in [
        (
            vec![degenerate.to_str().expect("path"), "--out", out_s],
            "degenerate",
        ),
        (
            vec![nan.to_str().expect("path"), "--out", out_s],
            "non-finite",
        ),
        (
            vec![teapot, "--out", out_s, "--size", "10"],
            "outside 64 to 16384",
        ),
        (
            vec![teapot, "--out", dir.join("t.png").to_str().expect("path")],
            ".obj or .glb",
        ),
        (
            vec![teapot, "--out", existing.to_str().expect("path")],
            "--force",
        ),
    ] {
        let mut all = vec!["unwrap"];
        all.extend(args);
        let o = kapaint(&all);
        assert_eq!(o.status.code(), Some(2), "{all:?}: {o:?}");
        assert!(o.stdout.is_empty());
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains(mentions), "{err} should mention {mentions}");
        assert!(!out.exists() && !dir.join("t.png").exists());
    }
    assert_eq!(std::fs::read(&existing).expect("read"), b"keep me");
    let o = kapaint(&[
        "import-pbr",
        "--base-color",
        "0.5",
        "--unwrap",
        "--out",
        out_s,
    ]);
    assert_eq!(o.status.code(), Some(2), "--unwrap needs --mesh: {o:?}");
}

/// `new --unwrap` keeps the unwrapped mesh inside the project: the project paints on it after
/// it moves away from the mesh file, and saves it again unchanged.
#[test]
fn a_project_keeps_its_unwrapped_mesh() {
    let dir = temp_dir("kept");
    let project = dir.join("teapot.kapaint");
    let project_s = project.to_str().expect("path");
    let o = kapaint(&[
        "new",
        "--size",
        "512",
        "--mesh",
        data_mesh("teapot.obj").to_str().expect("path"),
        "--unwrap",
        "--out",
        project_s,
    ]);
    assert!(o.status.success(), "{o:?}");
    let text = String::from_utf8(o.stdout).expect("utf-8");
    assert!(
        text.starts_with("unwrapped ") && text.contains("created "),
        "{text}"
    );
    let info = String::from_utf8(kapaint(&["info", project_s]).stdout).expect("utf-8");
    assert!(info.contains("teapot.obj, unwrapped"), "{info}");
    // Moved elsewhere, the project still has its mesh.
    let moved_dir = temp_dir("kept-moved");
    let moved = moved_dir.join("moved.kapaint");
    std::fs::rename(&project, &moved).expect("move");
    let moved_s = moved.to_str().expect("path");
    let (doc, failed) =
        kapaint::model::project::open_with_mesh(&moved, None).expect("the project opens");
    assert!(failed.is_none(), "{failed:?}");
    let surface = doc.surface().expect("the kept mesh is attached");
    assert_eq!(surface.mesh.triangles.len(), 6320);
    let kept = doc.embedded_mesh().expect("held").clone();
    // A stroke on the teapot's lid and a fill of one chart paint through the kept UVs.
    let script = moved_dir.join("s.ron");
    std::fs::write(
        &script,
        "(commands: [SetPrimary((kd: (0.0, 0.0, 1.0), ks: (0.1, 0.1, 0.1), n: 9.0)), \
         SetBrush((radius_px: 12.0)), \
         SurfaceStroke(tool: Brush, points: [(pos: (point: (0.0, 3.1, 0.0)), pressure: 1.0), \
         (pos: (point: (0.3, 3.0, 0.0)), pressure: 1.0)])])",
    )
    .expect("write script");
    let o = kapaint(&["paint", moved_s, "--script", script.to_str().expect("path")]);
    assert!(o.status.success(), "{o:?}");
    let info = String::from_utf8(kapaint(&["info", moved_s]).stdout).expect("utf-8");
    assert!(
        info.contains("kd.r 0.000000"),
        "the stroke painted blue: {info}"
    );
    let (again, failed) = kapaint::model::project::open_with_mesh(&moved, None).expect("opens");
    assert!(failed.is_none());
    assert!(
        **again.embedded_mesh().expect("held") == *kept,
        "saved unchanged"
    );
}

/// `kapaint bake` keeps a map of the mesh in the project (a cache, version 3), or with --out
/// writes a 16-bit PNG and leaves the project as it is; bad values are one line and exit 2.
#[test]
fn bakes_are_kept_in_the_project_or_written_out() {
    let dir = temp_dir("bake");
    let project = teapot_project(&dir);
    let p = project.to_str().expect("path");
    let o = kapaint(&["bake", p, "--map", "ao", "--rays", "16"]);
    assert!(o.status.success(), "{o:?}");
    let text = String::from_utf8(o.stdout).expect("utf-8");
    assert!(
        text.starts_with("baked ao of ") && text.contains("kept in "),
        "{text}"
    );
    let doc = kapaint::model::project::load(&project).expect("loads");
    let ao = doc
        .bake_of(kapaint::mesh::bakes::BakeMap::Ao)
        .expect("the AO bake is kept");
    assert_eq!((ao.width, ao.height, ao.options.rays), (256, 256, 16));
    let mesh = doc.embedded_mesh().expect("kept mesh");
    assert_eq!(ao.mesh_hash, mesh.content_hash());
    // Written out instead: a 16-bit grey PNG of the map's size; the project is untouched.
    let before = std::fs::read(&project).expect("read");
    let png = dir.join("curvature.png");
    let o = kapaint(&[
        "bake",
        p,
        "--map",
        "curvature",
        "--out",
        png.to_str().expect("path"),
    ]);
    assert!(o.status.success(), "{o:?}");
    let image = image::open(&png).expect("a PNG");
    assert_eq!((image.width(), image.height()), (256, 256));
    assert!(matches!(image, image::DynamicImage::ImageLuma16(_)));
    let normal = dir.join("normal.png");
    let o = kapaint(&[
        "bake",
        p,
        "--map",
        "normal",
        "--out",
        normal.to_str().expect("path"),
    ]);
    assert!(o.status.success(), "{o:?}");
    assert!(matches!(
        image::open(&normal).expect("a PNG"),
        image::DynamicImage::ImageRgb16(_)
    ));
    assert_eq!(std::fs::read(&project).expect("read"), before);
}

/// A 256^2 project on the unwrapped teapot, in `dir`.
fn teapot_project(dir: &Path) -> PathBuf {
    let project = dir.join("teapot.kapaint");
    let o = kapaint(&[
        "new",
        "--size",
        "256",
        "--mesh",
        data_mesh("teapot.obj").to_str().expect("path"),
        "--unwrap",
        "--out",
        project.to_str().expect("path"),
    ]);
    assert!(o.status.success(), "{o:?}");
    project
}

/// A bake with bad values, or of a mesh that is gone, is one line and exit 2, and the project
/// is untouched.
#[test]
fn a_bake_refuses_bad_values_and_a_missing_mesh() {
    let dir = temp_dir("bake-refused");
    let project = teapot_project(&dir);
    let p = project.to_str().expect("path");
    let png = dir.join("taken.png");
    std::fs::write(&png, b"keep").expect("write");
    let before = std::fs::read(&project).expect("read");
    // Bad values: exit 2, one line, nothing written.
    let bad = dir.join("bad.png");
    for args in [
        vec!["bake", p, "--map", "ao", "--rays", "0"],
        vec!["bake", p, "--map", "ao", "--rays", "65537"],
        vec!["bake", p, "--map", "ao", "--max-distance", "nan"],
        vec!["bake", p, "--map", "ao", "--max-distance", "-1"],
        vec!["bake", p, "--map", "shadow"],
        vec![
            "bake",
            p,
            "--map",
            "ao",
            "--out",
            dir.join("x.jpg").to_str().expect("path"),
        ],
        vec![
            "bake",
            p,
            "--map",
            "ao",
            "--out",
            png.to_str().expect("path"),
        ],
    ] {
        let o = kapaint(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {o:?}");
        assert_eq!(
            String::from_utf8_lossy(&o.stderr)
                .trim_end()
                .lines()
                .count(),
            1
        );
        assert!(o.stdout.is_empty() && !bad.exists(), "{args:?}");
    }
    assert_eq!(std::fs::read(&project).expect("read"), before);
    // A project whose mesh file is gone: one line, exit 2, untouched.
    let obj = dir.join("tri.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n",
    )
    .expect("write");
    let gone = dir.join("gone.kapaint");
    let g = gone.to_str().expect("path");
    let o = kapaint(&[
        "new",
        "--size",
        "64",
        "--mesh",
        obj.to_str().expect("path"),
        "--out",
        g,
    ]);
    assert!(o.status.success(), "{o:?}");
    std::fs::remove_file(&obj).expect("remove");
    let before = std::fs::read(&gone).expect("read");
    let o = kapaint(&["bake", g, "--map", "ao"]);
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    assert_eq!(std::fs::read(&gone).expect("read"), before);
}
