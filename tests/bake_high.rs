//! Issue 57's first step through the CLI: `kapaint bake --map normal --high HIGH` bakes a
//! high mesh's normals onto the project's mesh (spot's own mesh onto its quad version here),
//! written as a 16-bit PNG or kept as the project's normal map; bad input refused with the
//! project untouched.
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

/// Runs kapaint, which must succeed; returns what it printed.
fn ok(args: &[&str]) -> String {
    let o = kapaint(args);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// `kapaint bake PROJECT ARGS` refused: one line saying `want`, exit 2, the project still
/// `before`.
fn refused(project: &Path, args: &[&str], want: &str, before: &[u8]) {
    let mut all = vec!["bake", s(project)];
    all.extend(args);
    let o = kapaint(&all);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{all:?}: {e}");
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(e.contains(want), "{all:?}: {e}");
    assert_eq!(std::fs::read(project).expect("read"), before, "{all:?}");
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

fn spot(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/testdata/spot")
        .join(name)
}

fn dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("kapaint-bake-high-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("dir");
    d
}

fn low(d: &Path) -> PathBuf {
    let p = d.join("low.kapaint");
    let mesh = spot("spot_triangulated.obj");
    ok(&["new", "--size", "256", "--mesh", s(&mesh), "--out", s(&p)]);
    p
}

#[test]
fn spots_normals_bake_from_its_quad_mesh_flat_in_tangent_space_and_are_kept() {
    let d = dir("spot");
    let p = low(&d);
    let high = spot("spot_quadrangulated.obj");
    let png = d.join("n.png");
    let text = ok(&[
        "bake",
        s(&p),
        "--map",
        "normal",
        "--high",
        s(&high),
        "--out",
        s(&png),
    ]);
    assert!(
        text.contains("tangent space") && text.contains("front"),
        "{text}"
    );
    // The same surface (its quads split the other way): no ray misses, every normal within a
    // few degrees of flat.
    assert!(text.contains("missed 0 texels"), "{text}");
    let img = image::open(&png).expect("png").into_rgb16();
    let (mut n, mut sum) = (0_u32, 0.0_f64);
    for px in img.pixels() {
        if px.0 == [0, 0, 0] {
            continue;
        }
        let v = px.0.map(|c| f64::from(c) / 65535.0 * 2.0 - 1.0);
        let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        sum += (v[2] / len).clamp(-1.0, 1.0).acos().to_degrees();
        n += 1;
    }
    let mean = sum / f64::from(n);
    assert!(
        n > 10_000 && mean < 3.0,
        "{n} texels, mean {mean} degrees off flat"
    );
    // Height: the same surface stands at the middle of the distances (0.5), as a float EXR.
    let exr = d.join("h.exr");
    let text = ok(&[
        "bake",
        s(&p),
        "--map",
        "height",
        "--high",
        s(&high),
        "--out",
        s(&exr),
    ]);
    assert!(
        text.contains("height (0 at") && text.contains("missed 0 texels"),
        "{text}"
    );
    let heights = image::open(&exr).expect("exr").into_rgb32f();
    let surface: Vec<f32> = heights
        .pixels()
        .map(|p| p.0[0])
        .filter(|&v| v > 0.0)
        .collect();
    let mean = surface.iter().sum::<f32>() / surface.len() as f32;
    assert!(
        surface.len() > 10_000 && (mean - 0.5).abs() < 0.01,
        "{mean}"
    );
    // Without --out: the project's normal map, one step, saved.
    ok(&["bake", s(&p), "--map", "normal", "--high", s(&high)]);
    let doc = kapaint::model::project::load(&p).expect("opens");
    assert!(doc.normal().is_some(), "kept as the normal map");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_miss_map_draws_what_short_rays_missed() {
    let d = dir("misses");
    let p = low(&d);
    let high = spot("spot_quadrangulated.obj");
    let png = d.join("n.png");
    // Distances too short for where the quads split the other way: the misses are counted
    // and drawn, one white texel each.
    let misses = d.join("misses.png");
    let text = ok(&[
        "bake",
        s(&p),
        "--map",
        "normal",
        "--high",
        s(&high),
        "--front",
        "0.001",
        "--rear",
        "0.001",
        "--out",
        s(&png),
        "--force",
        "--misses",
        s(&misses),
    ]);
    let counted: u32 = text
        .split("missed ")
        .nth(1)
        .and_then(|t| t.split(' ').next())
        .and_then(|n| n.parse().ok())
        .expect("a count");
    let white = image::open(&misses)
        .expect("png")
        .into_luma8()
        .pixels()
        .filter(|p| p.0[0] == 255)
        .count();
    assert!(counted > 100, "{text}");
    assert_eq!(white, counted as usize, "{text}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn bad_high_bakes_are_refused_and_the_project_stays() {
    let d = dir("bad");
    let p = low(&d);
    let before = std::fs::read(&p).expect("read");
    let high = spot("spot_quadrangulated.obj");
    let empty = d.join("empty.obj");
    std::fs::write(&empty, "# nothing\n").expect("write");
    let kept = d.join("kept.png");
    std::fs::write(&kept, b"the user's own file").expect("write");
    let fresh = d.join("fresh.png");
    let nan = d.join("nan.obj");
    std::fs::write(&nan, "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n").expect("write");
    for (args, want) in [
        (vec!["--map", "id", "--high", s(&high)], "need --out"),
        (
            vec!["--map", "ao", "--high", s(&high), "--samples", "3"],
            "1, 4 or 16",
        ),
        (
            vec!["--map", "ao", "--high", s(&high), "--rays", "0"],
            "--rays",
        ),
        // spot's quad mesh is not its triangle mesh's topology.
        (
            vec!["--map", "ao", "--high", s(&high), "--cage", s(&high)],
            "topology",
        ),
        (vec!["--map", "ao", "--cage", s(&high)], "--high"),
        (
            vec!["--map", "ao", "--high", s(&high), "--high", s(&nan)],
            "nan.obj",
        ),
        (
            vec!["--map", "normal", "--high", s(&high), "--front=-1"],
            "not a positive number",
        ),
        (
            vec!["--map", "normal", "--high", s(&high), "--rear", "0"],
            "not a positive number",
        ),
        (vec!["--map", "height", "--high", s(&high)], "need --out"),
        (vec!["--map", "height"], "give --high"),
        // Flags of a bake from a high mesh, without one; a miss map over a file already there.
        (vec!["--map", "normal", "--front", "0.1"], "--high"),
        (vec!["--map", "ao", "--misses", s(&kept)], "--high"),
        (
            vec![
                "--map",
                "curvature",
                "--high",
                s(&high),
                "--out",
                s(&fresh),
                "--skew",
                s(&kept),
            ],
            "exists; pass --force",
        ),
        (
            vec![
                "--map",
                "normal",
                "--high",
                s(&high),
                "--out",
                s(&fresh),
                "--misses",
                s(&kept),
            ],
            "exists; pass --force",
        ),
        (
            vec!["--map", "normal", "--high", "nowhere.obj"],
            "nowhere.obj",
        ),
        (vec!["--map", "normal", "--high", s(&empty)], "empty.obj"),
        (vec!["--map", "normal", "--high", s(&nan)], "nan.obj"),
    ] {
        refused(&p, &args, want, &before);
        assert_eq!(std::fs::read(&kept).expect("read"), b"the user's own file");
        assert!(!fresh.exists(), "{args:?} wrote its output");
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// AO, curvature and position from spot's quad mesh (and a box beside it, a second --high)
/// are kept as the project's bakes, saying where they came from, and survive a save; ID and
/// the skew view are written out.
#[test]
fn maps_from_high_meshes_are_kept_as_the_projects_bakes_or_written() {
    let d = dir("maps");
    let p = low(&d);
    let high = spot("spot_quadrangulated.obj");
    let boxed = d.join("box.obj");
    std::fs::write(
        &boxed,
        "o box\nv 2 0 0\nv 3 0 0\nv 3 1 0\nv 2 1 0\nv 2 0 1\nv 3 0 1\nv 3 1 1\nv 2 1 1\n\
         f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n",
    )
    .expect("write");
    for map in ["ao", "curvature", "position"] {
        let text = ok(&[
            "bake",
            s(&p),
            "--map",
            map,
            "--high",
            s(&high),
            "--high",
            s(&boxed),
            "--rays",
            "16",
            "--samples",
            "4",
        ]);
        assert!(
            text.contains(&format!("kept as the {map} bake"))
                && text.contains("4 samples a texel")
                && text.contains(" + "),
            "{text}"
        );
    }
    let doc = kapaint::model::project::load(&p).expect("opens");
    let bakes = doc.bakes();
    assert_eq!(bakes.len(), 3);
    for b in bakes {
        let from = b.from_high.as_ref().expect("from the high mesh");
        assert_eq!(from.samples, 4);
        assert!(
            from.mesh.contains("spot") && from.mesh.contains("box"),
            "{}",
            from.mesh
        );
    }
    let ao = bakes
        .iter()
        .find(|b| b.map == kapaint::mesh::bakes::BakeMap::Ao)
        .expect("ao");
    assert_eq!(ao.options.rays, 16);
    // Saved again by another command, the bakes stay as they were.
    let before = bakes.to_vec();
    ok(&["bake", s(&p), "--map", "thickness", "--rays", "4"]);
    let doc = kapaint::model::project::load(&p).expect("opens");
    for b in &before {
        assert!(doc.bakes().iter().any(|k| **k == **b), "{:?} lost", b.map);
    }
    // ID and the skew view, written out.
    let (ids, skew) = (d.join("id.png"), d.join("skew.png"));
    ok(&[
        "bake",
        s(&p),
        "--map",
        "id",
        "--high",
        s(&high),
        "--out",
        s(&ids),
        "--skew",
        s(&skew),
    ]);
    let img = image::open(&ids).expect("png").into_rgb16();
    let mut colours: Vec<[u16; 3]> = img.pixels().map(|p| p.0).filter(|c| *c != [0; 3]).collect();
    colours.sort_unstable();
    colours.dedup();
    assert!(
        !colours.is_empty() && colours.len() <= 3,
        "{}",
        colours.len()
    );
    let skewed = image::open(&skew).expect("png").into_luma8();
    assert!(
        skewed.pixels().any(|p| p.0[0] > 0),
        "spot's smooth normals lean off its faces"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// A bumpy sphere written as the high mesh: the default sphere's surface, waved along its
/// radius, with its normals from its faces.
fn bumpy_sphere(path: &Path) {
    let mut m = kapaint::mesh::uv_sphere(256, 128);
    for p in &mut m.positions {
        let wave = (p.x * 9.0).sin() * (p.y * 9.0).sin() * (p.z * 9.0).sin();
        *p *= 1.0 + 0.02 * wave;
    }
    let mut sums = vec![glam::Vec3::ZERO; m.positions.len()];
    for t in &m.triangles {
        let [a, b, c] = t.map(|v| m.positions[v as usize]);
        for v in t {
            sums[*v as usize] += (b - a).cross(c - a);
        }
    }
    m.normals = sums
        .into_iter()
        .map(glam::Vec3::normalize_or_zero)
        .collect();
    m.uvs = None;
    std::fs::write(path, kapaint::mesh::write_obj(&m)).expect("write");
}

/// The grey levels of a render where it shows the mesh (alpha above zero).
fn grey(path: &Path) -> Vec<Option<f32>> {
    image::open(path)
        .expect("render")
        .into_rgba8()
        .pixels()
        .map(|p| (p.0[3] > 0).then(|| f32::from(p.0[0]) + f32::from(p.0[1]) + f32::from(p.0[2])))
        .collect()
}

/// The low sphere with its normal map baked from a bumpy sphere shades like the bumpy sphere
/// (the same camera and light, the silhouettes' parallax aside): at least twice as close as
/// the low sphere without it.
#[test]
fn the_low_mesh_with_its_baked_normal_map_shades_like_the_high_one() {
    let d = dir("shade");
    let (flat, mapped, high) = (
        d.join("flat.kapaint"),
        d.join("mapped.kapaint"),
        d.join("bumpy.obj"),
    );
    bumpy_sphere(&high);
    ok(&[
        "new",
        "--size",
        "512",
        "--mesh",
        "sphere",
        "--out",
        s(&flat),
    ]);
    std::fs::copy(&flat, &mapped).expect("copy");
    ok(&["bake", s(&mapped), "--map", "normal", "--high", s(&high)]);
    let render = |project: &Path, mesh: Option<&Path>, out: &Path| {
        let mut args = vec![
            "render",
            "--project",
            s(project),
            "--model",
            "phong",
            "--view",
            "shaded",
        ];
        args.extend(["--size", "256x256", "--out", s(out)]);
        if let Some(m) = mesh {
            args.extend(["--mesh", s(m)]);
        }
        kapaint(&args)
    };
    let shots = [
        (d.join("flat.png"), render(&flat, None, &d.join("flat.png"))),
        (
            d.join("mapped.png"),
            render(&mapped, None, &d.join("mapped.png")),
        ),
        (
            d.join("high.png"),
            render(&flat, Some(&high), &d.join("high.png")),
        ),
    ];
    for (_, o) in &shots {
        if !o.status.success() && std::env::var_os("KAPAINT_REQUIRE_GPU").is_none() {
            eprintln!("SKIPPED: no GPU adapter here");
            return;
        }
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let [flat, mapped, high] = [0, 1, 2].map(|k| grey(&shots[k].0));
    let off = |img: &[Option<f32>]| {
        let d: Vec<f32> = img
            .iter()
            .zip(&high)
            .filter_map(|(a, b)| Some((a.as_ref()? - b.as_ref()?).abs() / 3.0))
            .collect();
        assert!(d.len() > 20_000, "{} pixels", d.len());
        d.iter().sum::<f32>() / d.len() as f32
    };
    let (without, with) = (off(&flat), off(&mapped));
    eprintln!("off the high mesh's render: {without:.2} levels without the map, {with:.2} with");
    assert!(
        with * 2.0 < without,
        "with the map {with} levels off, without {without}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// A bake from a high mesh killed while its rays run leaves the project as it was (it is
/// saved, atomically, only when the bake is done).
#[test]
fn a_killed_bake_leaves_the_project_as_it_was() {
    let d = dir("killed");
    let p = low(&d);
    let before = std::fs::read(&p).expect("read");
    let high = spot("spot_quadrangulated.obj");
    let mut child = Command::new(env!("CARGO_BIN_EXE_kapaint"))
        .args([
            "bake",
            s(&p),
            "--map",
            "ao",
            "--high",
            s(&high),
            "--rays",
            "65536",
        ])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("starts");
    std::thread::sleep(std::time::Duration::from_millis(1500));
    assert!(child.try_wait().expect("waits").is_none(), "still baking");
    child.kill().expect("kills");
    let _ = child.wait();
    assert_eq!(std::fs::read(&p).expect("read"), before);
    let leftovers: Vec<_> = std::fs::read_dir(&d)
        .expect("dir")
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n != "low.kapaint" && !n.starts_with(".low.kapaint"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    let _ = std::fs::remove_dir_all(&d);
}

/// A unit square at height `z` named `name`, its UVs across `u0..u0 + 0.5`, its first vertex
/// `first`; `extra` lines go before its face.
fn square(name: &str, z: f32, u0: f32, first: u32, extra: &str) -> String {
    let [a, b, c, d] = [first, first + 1, first + 2, first + 3];
    format!(
        "o {name}\nv 0 0 {z}\nv 1 0 {z}\nv 1 1 {z}\nv 0 1 {z}\nvt {u0} 0\nvt {u1} 0\nvt {u1} 1\nvt {u0} 1\n{extra}f {a}/{a} {b}/{b} {c}/{c} {d}/{d}\n",
        u1 = u0 + 0.5
    )
}

/// `--match by-name`: two parts lying over each other, `A_low` and `b_low`, each bake from its
/// own high part (`a_high`, `B_high`) and not from the other's just above; the output says the
/// pairs. An ID map tells the high mesh's materials apart; `mesh-info` lists the
/// names a user matches by.
#[test]
fn parts_match_by_name_through_the_cli() {
    let d = dir("match");
    let (low_obj, high_obj) = (d.join("low.obj"), d.join("high.obj"));
    std::fs::write(
        &low_obj,
        square("A_low", 0.0, 0.0, 1, "") + &square("b_low", 0.01, 0.5, 5, ""),
    )
    .expect("write");
    std::fs::write(
        &high_obj,
        square("a_high", 0.002, 0.0, 1, "usemtl paint\n")
            + &square("B_high", 0.012, 0.5, 5, "usemtl metal\n"),
    )
    .expect("write");
    let info = ok(&["mesh-info", s(&low_obj)]);
    assert!(info.contains("objects: 2: A_low, b_low"), "{info}");
    let p = d.join("parts.kapaint");
    ok(&["new", "--size", "64", "--mesh", s(&low_obj), "--out", s(&p)]);
    let height = |matching: bool, out: &Path| {
        let mut args = vec![
            "bake",
            s(&p),
            "--map",
            "height",
            "--high",
            s(&high_obj),
            "--front",
            "0.02",
            "--rear",
            "0.02",
            "--out",
            s(out),
        ];
        if matching {
            args.extend(["--match", "by-name"]);
        }
        let text = ok(&args);
        let img = image::open(out).expect("png").into_luma16();
        // Texel (16, 32) lies on A.
        (text, f32::from(img.get_pixel(16, 32).0[0]) / 65535.0)
    };
    let (text, matched) = height(true, &d.join("matched.png"));
    assert!(text.contains("matched by name: 2 pairs (a, b)"), "{text}");
    assert!((matched - 0.55).abs() < 2e-3, "A from a_high: {matched}");
    let (_, all) = height(false, &d.join("all.png"));
    assert!(
        (all - 0.8).abs() < 2e-3,
        "A onto B_high without matching: {all}"
    );
    let ids = d.join("ids.png");
    let text = ok(&[
        "bake",
        s(&p),
        "--map",
        "id",
        "--high",
        s(&high_obj),
        "--out",
        s(&ids),
        "--match",
        "by-name",
    ]);
    assert!(text.contains("id (by material)"), "{text}");
    let img = image::open(&ids).expect("png").into_rgb16();
    // Matched, A meets a_high's paint and B B_high's metal (unmatched, both met the metal
    // above).
    assert_ne!(
        img.get_pixel(16, 32),
        img.get_pixel(48, 32),
        "two materials"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// `--match by-name` where no parts pair, `--match` without `--high`, and an ID map by vertex
/// colours the high mesh does not have: one line, exit 2, the project as it was.
#[test]
fn matching_and_id_sources_refuse_what_the_meshes_lack() {
    let d = dir("lack");
    let p = low(&d);
    let before = std::fs::read(&p).expect("read");
    let high = spot("spot_quadrangulated.obj");
    let out = d.join("ids.png");
    for (args, want) in [
        // spot's meshes name no parts.
        (
            vec!["--map", "normal", "--high", s(&high), "--match", "by-name"],
            "no pairs",
        ),
        (vec!["--map", "ao", "--match", "by-name"], "--high"),
        (
            vec![
                "--map",
                "id",
                "--high",
                s(&high),
                "--id-from",
                "color",
                "--out",
                s(&out),
            ],
            "vertex colours",
        ),
    ] {
        refused(&p, &args, want, &before);
        assert!(!out.exists());
    }
    let _ = std::fs::remove_dir_all(&d);
}
