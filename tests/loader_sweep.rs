//! Every loader, swept with broken input: random byte flips, every kind of truncation, and
//! field-level fuzz (each number in the file set to 0, -1, NaN, 1e30 and u32::MAX in turn,
//! each string to "" and to 10 MB). A case passes when the loader gives a clean error or a
//! valid value (a project that loads must save and load again); a panic anywhere fails the
//! sweep. The counts are printed per loader (with or without `--nocapture`).

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

#[path = "common/encode.rs"]
mod encode;

use std::io::Write as _;
use std::panic::AssertUnwindSafe;
use std::path::{Path, PathBuf};

use glam::Vec2;
use kapaint::cli::PaintScript;
use kapaint::export::{preset::ExportPreset, set};
use kapaint::model::brush::{BrushSettings, Stamp, StrokePoint};
use kapaint::model::{Channel, Document, DocumentSettings, StrokeTool, project};
use kapaint::model::{SettingsCommand, StrokeCommand};

/// A deterministic xorshift generator: the same cases on every run.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// `count` copies of `bytes`, each with one to four random bytes changed.
fn flips(bytes: &[u8], count: usize, seed: u64) -> Vec<Vec<u8>> {
    let mut rng = Rng(seed | 1);
    (0..count)
        .map(|_| {
            let mut b = bytes.to_vec();
            for _ in 0..=rng.below(4) {
                let at = rng.below(b.len());
                b[at] ^= (rng.below(255) + 1) as u8;
            }
            b
        })
        .collect()
}

/// Prefixes of `bytes`: `count` lengths spread over the whole file, the empty one included.
fn truncations(bytes: &[u8], count: usize) -> Vec<Vec<u8>> {
    let count = count.min(bytes.len()).max(1);
    (0..count)
        .map(|k| bytes[..k * bytes.len() / count].to_vec())
        .collect()
}

/// The spans of the number literals and the string literals of a JSON or RON text (JSON
/// object keys left out).
/// Byte ranges `(start, end)` of a text.
type Spans = Vec<(usize, usize)>;

fn literals(text: &str) -> (Spans, Spans) {
    let b = text.as_bytes();
    let (mut numbers, mut strings) = (Vec::new(), Vec::new());
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'"' => {
                let start = i;
                i += 1;
                while i < b.len() && b[i] != b'"' {
                    i += if b[i] == b'\\' { 2 } else { 1 };
                }
                i += 1;
                let end = i.min(b.len());
                let after = text[end..].trim_start();
                if !after.starts_with(':') {
                    strings.push((start, end));
                }
            }
            c if c.is_ascii_digit()
                || (c == b'-' && b.get(i + 1).is_some_and(u8::is_ascii_digit)) =>
            {
                let prev = if i == 0 { b' ' } else { b[i - 1] };
                let start = i;
                i += 1;
                while i < b.len()
                    && (b[i].is_ascii_digit()
                        || b[i] == b'.'
                        || b[i] == b'e'
                        || b[i] == b'E'
                        || ((b[i] == b'-' || b[i] == b'+') && matches!(b[i - 1], b'e' | b'E')))
                {
                    i += 1;
                }
                if !(prev.is_ascii_alphanumeric() || prev == b'_') {
                    numbers.push((start, i));
                }
            }
            _ => i += 1,
        }
    }
    (numbers, strings)
}

/// Field-level fuzz of a JSON (`json`) or RON text: each number as 0, -1, NaN (`null` in
/// JSON, which cannot hold NaN), 1e30 and u32::MAX; each string as "" and as 10 MB.
fn field_cases(text: &str, json: bool) -> Vec<String> {
    let (numbers, strings) = literals(text);
    let nan = if json { "null" } else { "NaN" };
    let big = format!("\"{}\"", "x".repeat(10 << 20));
    let mut out = Vec::new();
    for (a, b) in numbers {
        for v in ["0", "-1", nan, "1e30", "4294967295"] {
            out.push(format!("{}{v}{}", &text[..a], &text[b..]));
        }
    }
    for (a, b) in strings {
        for v in ["\"\"", big.as_str()] {
            out.push(format!("{}{v}{}", &text[..a], &text[b..]));
        }
    }
    out
}

/// Runs every case through `check`, counting panics (with their first messages).
fn sweep(name: &str, cases: &[Vec<u8>], mut check: impl FnMut(&[u8])) -> usize {
    let mut panics = Vec::new();
    let count = cases.len();
    for (k, case) in cases.iter().enumerate() {
        if std::panic::catch_unwind(AssertUnwindSafe(|| check(case))).is_err() {
            panics.push(k);
        }
    }
    let _ = writeln!(
        std::io::stderr(),
        "sweep: {name}: {count} cases, {} panics",
        panics.len()
    );
    assert!(panics.is_empty(), "{name}: cases {panics:?} panicked");
    count
}

fn temp(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("kapaint-sweep-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// A painted 64^2 document with a stamp in its brush: every field a project can hold.
fn painted() -> Document {
    let mut doc = Document::new(64, 48, DocumentSettings::default()).expect("doc");
    doc.apply(SettingsCommand::SetBrush(BrushSettings {
        radius_px: 6.0,
        stamp: Some(Stamp::new(2, 2, vec![0.0, 0.5, 1.0, 0.25]).expect("stamp")),
        ..BrushSettings::default()
    }))
    .expect("brush");
    doc.apply(StrokeCommand::Stroke {
        tool: StrokeTool::Brush,
        points: vec![
            StrokePoint {
                pos: Vec2::new(3.0, 4.0),
                pressure: 1.0,
            },
            StrokePoint {
                pos: Vec2::new(60.0, 40.0),
                pressure: 0.5,
            },
        ],
    })
    .expect("stroke");
    doc
}

/// A project that loads must be valid: it saves, and what it saves loads again.
fn check_project(bytes: &[u8]) {
    if let Ok(doc) = project::from_reader(std::io::Cursor::new(bytes)) {
        let again = project::to_bytes(&doc).expect("a loaded project saves");
        project::from_reader(std::io::Cursor::new(again)).expect("and loads back");
    }
}

/// A project's bytes with its manifest replaced.
fn with_manifest(project: &[u8], manifest: &str) -> Vec<u8> {
    use std::io::Read as _;
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(project)).expect("zip");
    let mut out = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    for i in 0..zip.len() {
        let mut entry = zip.by_index(i).expect("entry");
        let name = entry.name().expect("name").to_string();
        let mut data = Vec::new();
        entry.read_to_end(&mut data).expect("bytes");
        if name == "manifest.json" {
            data = manifest.as_bytes().to_vec();
        }
        out.start_file(name, zip::write::SimpleFileOptions::default())
            .expect("start");
        out.write_all(&data).expect("write");
    }
    out.finish().expect("finish").into_inner()
}

fn manifest_of(project: &[u8]) -> String {
    use std::io::Read as _;
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(project)).expect("zip");
    let mut text = String::new();
    zip.by_name("manifest.json")
        .expect("manifest")
        .read_to_string(&mut text)
        .expect("text");
    text
}

#[test]
fn projects() {
    let bytes = project::to_bytes(&painted()).expect("save");
    let manifest = manifest_of(&bytes);
    let mut cases = flips(&bytes, 1500, 11);
    cases.extend(truncations(&bytes, 300));
    cases.extend(
        flips(manifest.as_bytes(), 500, 12)
            .into_iter()
            .map(|m| with_manifest(&bytes, &String::from_utf8_lossy(&m))),
    );
    cases.extend(
        field_cases(&manifest, true)
            .iter()
            .map(|m| with_manifest(&bytes, m)),
    );
    sweep("projects", &cases, check_project);
}

#[test]
fn sets() {
    let dir = temp("sets");
    let doc = painted();
    let out = dir.join("set");
    let compact = kapaint::export::preset::find("compact").expect("preset");
    set::export(&doc, &compact, &out).expect("export");
    let manifest_path = out.join("material.json");
    let manifest = std::fs::read_to_string(&manifest_path).expect("manifest");
    let image_path = out.join("kd_n.png");
    let image = std::fs::read(&image_path).expect("image");
    let mut cases: Vec<Vec<u8>> = Vec::new();
    // Each case: a tag byte (0 manifest, 1 image) and the file's bytes.
    let tagged = |tag: u8, bytes: Vec<u8>| [vec![tag], bytes].concat();
    cases.extend(
        flips(manifest.as_bytes(), 400, 21)
            .into_iter()
            .map(|b| tagged(0, b)),
    );
    cases.extend(
        truncations(manifest.as_bytes(), 100)
            .into_iter()
            .map(|b| tagged(0, b)),
    );
    cases.extend(
        field_cases(&manifest, true)
            .into_iter()
            .map(|m| tagged(0, m.into_bytes())),
    );
    cases.extend(flips(&image, 300, 22).into_iter().map(|b| tagged(1, b)));
    cases.extend(truncations(&image, 60).into_iter().map(|b| tagged(1, b)));
    sweep("sets", &cases, |case| {
        let (path, original) = if case[0] == 0 {
            (&manifest_path, manifest.as_bytes())
        } else {
            (&image_path, image.as_slice())
        };
        std::fs::write(path, &case[1..]).expect("write");
        if let Ok(doc) = set::import(&manifest_path) {
            project::to_bytes(&doc).expect("an imported set saves");
        }
        std::fs::write(path, original).expect("restore");
    });
    let _ = std::fs::remove_dir_all(&dir);
}

fn text_cases(text: &str, seed: u64, json: bool) -> Vec<Vec<u8>> {
    let mut cases = flips(text.as_bytes(), 400, seed);
    cases.extend(truncations(text.as_bytes(), 200));
    cases.extend(field_cases(text, json).into_iter().map(String::into_bytes));
    cases
}

#[test]
fn material_presets() {
    let text = kapaint::model::preset::BUILTIN_FILES
        .iter()
        .find(|(stem, _)| *stem == "brass")
        .map(|(_, text)| *text)
        .expect("brass");
    sweep("material presets", &text_cases(text, 31, false), |case| {
        let text = String::from_utf8_lossy(case);
        if let Ok(p) = kapaint::model::preset::MaterialPreset::parse(Path::new("x.ron"), &text) {
            let v = p.value();
            assert!(v.kd.is_finite() && v.ks.is_finite() && v.n.is_finite());
        }
    });
}

#[test]
fn export_presets() {
    let text = include_str!("../presets/export/ktx2.ron");
    sweep("export presets", &text_cases(text, 41, false), |case| {
        let _ = ExportPreset::parse(Path::new("x.ron"), &String::from_utf8_lossy(case));
    });
}

/// A script that uses every command with fields.
const SCRIPT: &str = r"(commands: [
    SetBrush((radius_px: 5.0, hardness: 0.7, opacity: 0.9, flow: 0.8, spacing_percent: 20.0, jitter: 0.1, smoothing_px: 2.0, blur_radius_px: 2, stamp: Some((width: 2, height: 1, alpha: [0.5, 1.0])))),
    SetPrimary((kd: (1.0, 0.0, 0.0), ks: (0.2, 0.2, 0.2), n: 300.0)),
    SetSecondary((kd: (0.0, 0.0, 1.0), ks: (0.5, 0.5, 0.5), n: 4.0)),
    SetModel(blinn),
    SetApprox(paper),
    Stroke(tool: Brush, points: [(pos: (3.0, 4.0), pressure: 1.0), (pos: (50.0, 30.0), pressure: 0.5)]),
    BeginStroke(Blur),
    StrokeTo((pos: (10.0, 10.0), pressure: 1.0)),
    StrokeTo((pos: (20.0, 12.0), pressure: 0.7)),
    EndStroke,
    SetChannels((kd: false, ks: true, n: true)),
    Fill(Similar(x: 30, y: 5, channel: Kd, tolerance: 0.01)),
    Gradient(shape: Radial, start: (16.0, 16.0), end: (40.0, 20.0)),
    Pick(x: 7, y: 9),
    SurfaceStroke(tool: Eraser, points: [(pos: (point: (0.3, 0.6, 0.7)), pressure: 1.0), (pos: (point: (0.3, 0.6, -0.4), normal: (0.0, 1.0, 0.0)), pressure: 0.5)]),
    Fill(Island(x: 10, y: 20)),
    Undo,
    Redo,
])";

#[test]
fn paint_scripts() {
    let surface = std::sync::Arc::new(
        kapaint::model::surface::Surface::new(kapaint::mesh::uv_sphere(24, 12), 64, 48)
            .expect("sphere"),
    );
    sweep("paint scripts", &text_cases(SCRIPT, 51, false), |case| {
        let Ok(script) = ron::from_str::<PaintScript>(&String::from_utf8_lossy(case)) else {
            return;
        };
        let mut doc = Document::new(64, 48, DocumentSettings::default())
            .expect("doc")
            .with_surface(Some(std::sync::Arc::clone(&surface)))
            .expect("surface");
        for command in script.commands {
            let _ = doc.apply(command);
        }
        check_project(&project::to_bytes(&doc).expect("a painted project saves"));
    });
}

/// A small OBJ with UVs and normals: a quad in two triangles and a fan.
const OBJ: &str = "o quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\ng fan\nf 1/1/1 2/2/1 3/3/1 4/4/1\n";

#[test]
fn meshes() {
    let dir = temp("meshes");
    let obj_path = dir.join("m.obj");
    let mut cases: Vec<Vec<u8>> = text_cases(OBJ, 61, false)
        .into_iter()
        .map(|b| [vec![0], b].concat())
        .collect();
    // A .gltf with its buffer as a data: URI (one triangle, indexed).
    let floats: [f32; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let mut bin: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
    bin.extend([0_u16, 1, 2, 0].iter().flat_map(|i| i.to_le_bytes()));
    let gltf = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0,"translation":[0,1,0]}}],"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1,"mode":4}}]}}],"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},{{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}}],"bufferViews":[{{"buffer":0,"byteLength":36,"byteOffset":0}},{{"buffer":0,"byteLength":6,"byteOffset":36}}],"buffers":[{{"uri":"data:application/octet-stream;base64,{}","byteLength":44}}]}}"#,
        encode::base64(&bin)
    );
    cases.extend(
        text_cases(&gltf, 62, true)
            .into_iter()
            .map(|b| [vec![1], b].concat()),
    );
    let gltf_path = dir.join("m.gltf");
    sweep("meshes (OBJ, glTF)", &cases, |case| {
        let path = if case[0] == 0 { &obj_path } else { &gltf_path };
        std::fs::write(path, &case[1..]).expect("write");
        if let Ok(mesh) = kapaint::mesh::load(path) {
            mesh.validate().expect("a loaded mesh is valid");
        }
    });
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn images() {
    let dir = temp("images");
    let spot = image::open(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/testdata/spot/spot_texture.png"),
    )
    .expect("spot")
    .resize_exact(48, 40, image::imageops::FilterType::Triangle);
    let mut cases = Vec::new();
    for (k, ext) in ["png", "jpg", "tga", "exr"].into_iter().enumerate() {
        let path = dir.join(format!("source.{ext}"));
        match ext {
            "exr" => image::DynamicImage::ImageRgb32F(spot.to_rgb32f()).save(&path),
            "jpg" => image::DynamicImage::ImageRgb8(spot.to_rgb8()).save(&path),
            _ => spot.save(&path),
        }
        .expect("encode");
        let bytes = std::fs::read(&path).expect("read");
        let tag = k as u8;
        cases.extend(
            flips(&bytes, 150, 70 + u64::from(tag))
                .into_iter()
                .chain(truncations(&bytes, 50))
                .map(|b| [vec![tag], b].concat()),
        );
    }
    sweep("images (PNG, JPEG, TGA, EXR)", &cases, |case| {
        let ext = ["png", "jpg", "tga", "exr"][case[0] as usize];
        let path = dir.join(format!("case.{ext}"));
        std::fs::write(&path, &case[1..]).expect("write");
        let mut doc = Document::new(32, 32, DocumentSettings::default()).expect("doc");
        for channel in Channel::ALL {
            if doc.import_file(channel, &path).is_err() {
                return;
            }
        }
        check_project(&project::to_bytes(&doc).expect("an imported image saves"));
    });
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn layout_and_recent_files() {
    let layout = String::from_utf8(
        kapaint::ui::layout_json(&kapaint::ui::default_layout()).expect("layout"),
    )
    .expect("utf-8");
    let mut layouts = text_cases(&layout, 81, true);
    let recent = serde_json::to_string(&["/a/b.kapaint", "/c/d.kapaint"]).expect("recent");
    layouts.extend(
        text_cases(&recent, 82, true)
            .into_iter()
            .map(|b| [b"R".to_vec(), b].concat()),
    );
    let mut harness = egui_kittest::Harness::builder()
        .with_size(egui::Vec2::new(900.0, 600.0))
        .build_ui_state(
            |ui, editor: &mut kapaint::ui::Editor| editor.frame(ui),
            kapaint::ui::Editor::new(None, None),
        );
    let parsed = std::cell::Cell::new(0_usize);
    sweep("layout and recent-files JSON", &layouts, |case| {
        if let Some(list) = case.strip_prefix(b"R") {
            let recent = kapaint::ui::parse_recent(list);
            assert!(recent.len() <= kapaint::ui::RECENT_MAX);
            return;
        }
        if let Some(dock) = kapaint::ui::parse_layout(case) {
            // A layout that loads must draw.
            parsed.set(parsed.get() + 1);
            harness.state_mut().set_layout(dock);
            harness.step();
        }
    });
    let _ = writeln!(
        std::io::stderr(),
        "sweep: {} altered layouts loaded and drew a frame",
        parsed.get()
    );
}

#[test]
fn the_layout_round_trips() {
    // As written before the fix: unset rectangles as null coordinates, read back as 0.
    let raw = serde_json::to_string(&kapaint::ui::default_layout()).expect("layout");
    assert!(raw.contains("null"), "the case this guards against");
    assert!(kapaint::ui::parse_layout(raw.as_bytes()).is_some(), "{raw}");
    let json = kapaint::ui::layout_json(&kapaint::ui::default_layout()).expect("written");
    assert!(kapaint::ui::parse_layout(&json).is_some());
}
