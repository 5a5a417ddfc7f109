//! What a `kill -9` loses, measured: a child process paints a 4096^2 layered document (a
//! project of about 430 MB) stroke after stroke and autosaves after each (interval 0, so the
//! loss is the record being written); the parent kills it at a random moment, recovers the
//! copy and reports how much work since the last stroke the copy holds was lost, and how long
//! the record in flight took to write (whole or a delta).
//!
//! `cargo run --release --example autosave_bound [TRIALS]` (default 6). Numbers go to
//! docs/performance.md.

#![expect(clippy::expect_used, reason = "a measurement: a failure ends it")]

use std::io::{BufRead as _, Write as _};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use glam::{Vec2, Vec3};
use kapaint::model::brush::{BrushSettings, StrokePoint};
use kapaint::model::recovery::{self, Autosaver};
use kapaint::model::texel::{MaterialValue, Texel};
use kapaint::model::{Document, DocumentSettings, LayerKind, StrokeTool};
use kapaint::model::{
    ImportCommand, LayerCommand, MaskCommand, PaintCommand, SettingsCommand, StrokeCommand,
};

const SIDE: u32 = 4096;

/// Two noisy paint layers, one masked: every tile stored.
fn document() -> Document {
    let mut doc = Document::new(SIDE, SIDE, DocumentSettings::default()).expect("doc");
    let noise = |seed: u32| {
        let mut maps =
            kapaint::model::MaterialMaps::new(SIDE, SIDE, MaterialValue::default()).expect("maps");
        for id in 0..maps.tile_count() {
            let tile = maps.tile_mut(id);
            for i in 0..64 * 64 {
                let h = ((id * 4096 + i) as u32 ^ seed).wrapping_mul(2_654_435_761);
                let f = |k: u32| (h.rotate_left(k) % 1000) as f32 / 1000.0;
                tile.set_texel(
                    i,
                    Texel::encode(MaterialValue::new(
                        Vec3::new(f(1), f(5), f(9)),
                        Vec3::splat(f(13)),
                        f(17) * 2000.0,
                    )),
                );
            }
        }
        kapaint::model::document::ImportedMaterial {
            maps: std::sync::Arc::new(maps),
            normal: None,
            report: None,
        }
    };
    doc.apply(ImportCommand::ImportMaterial(noise(1)))
        .expect("layer 1");
    doc.apply(LayerCommand::AddLayer {
        kind: LayerKind::Paint,
        name: "Scratches".into(),
    })
    .expect("layer 2");
    doc.apply(ImportCommand::ImportMaterial(noise(7)))
        .expect("layer 2");
    doc.apply(MaskCommand::AddMask).expect("mask");
    doc
}

fn stroke(doc: &mut Document, k: u32) {
    let y = 200.0 + (k * 97 % 3700) as f32;
    // The stroke's number rides along in the primary's exponent: what recovery got back.
    doc.apply(SettingsCommand::SetPrimary(MaterialValue::new(
        Vec3::new(0.8, 0.2, 0.1),
        Vec3::splat(0.5),
        k as f32 + 1.0,
    )))
    .expect("primary");
    doc.apply(StrokeCommand::Stroke {
        tool: StrokeTool::Brush,
        points: vec![
            StrokePoint {
                pos: Vec2::new(300.0, y),
                pressure: 1.0,
            },
            StrokePoint {
                pos: Vec2::new(3800.0, y + 60.0),
                pressure: 1.0,
            },
        ],
    })
    .expect("stroke");
}

/// The child: paints and autosaves, printing when each stroke started and each record ended.
fn child(dir: &Path) {
    let start = Instant::now();
    let ms = || start.elapsed().as_millis();
    let mut doc = document();
    doc.apply(SettingsCommand::SetBrush(BrushSettings {
        radius_px: 96.0,
        ..BrushSettings::default()
    }))
    .expect("brush");
    let project = dir.join("P.kapaint");
    let mut saver = Autosaver::new(Duration::ZERO, Some(&project), &doc);
    let mut out = std::io::stdout().lock();
    writeln!(out, "session {}", saver.session().display()).expect("out");
    for k in 0.. {
        stroke(&mut doc, k);
        writeln!(out, "stroke {k} {}", ms()).expect("out");
        out.flush().expect("flush");
        let journals_before = journals(&saver.session());
        let t = Instant::now();
        saver.save_now(&doc).expect("autosave");
        let whole = journals(&saver.session()) != journals_before || k == 0;
        writeln!(
            out,
            "record {k} {} {} {}",
            ms(),
            t.elapsed().as_millis(),
            if whole { "whole" } else { "delta" }
        )
        .expect("out");
        out.flush().expect("flush");
        if k % 4 == 3 {
            // A layer painted all over: a record as large as the layer, so the journal
            // outgrows its first record and a new generation (a whole record) follows.
            doc.apply(LayerCommand::SelectLayer(kapaint::model::LayerRef::Index(
                0,
            )))
            .expect("select");
            doc.apply(PaintCommand::Gradient {
                shape: kapaint::model::paint::GradientShape::Linear,
                start: Vec2::ZERO,
                end: Vec2::splat(SIDE as f32),
            })
            .expect("gradient");
            doc.apply(LayerCommand::SelectLayer(kapaint::model::LayerRef::Index(
                1,
            )))
            .expect("select");
        }
    }
}

fn journals(session: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(session)
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.get(1).map(String::as_str) == Some("child") {
        child(Path::new(&args[2]));
        return;
    }
    let trials: u32 = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(6);
    let dir = std::env::temp_dir().join(format!("kapaint-autosave-bound-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    {
        let doc = document();
        let t = Instant::now();
        let project = dir.join("P.kapaint");
        kapaint::model::project::save(&doc, &project).expect("save");
        println!(
            "project: {:.0} MB, saved in {:.1} s (a whole-copy autosave cost this before)",
            std::fs::metadata(&project).expect("size").len() as f64 / 1e6,
            t.elapsed().as_secs_f64()
        );
    }
    let mut seed = 0x9E37_79B9_u32;
    for k in 0..trials {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        println!("trial {k}: {}", trial(&dir, seed));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// One trial: a child painting and autosaving, killed after a while picked by `seed`; what
/// was lost, in a line.
fn trial(dir: &Path, seed: u32) -> String {
    let exe = std::env::current_exe().expect("exe");
    let mut child = std::process::Command::new(exe)
        .args(["child", dir.to_str().expect("utf-8")])
        .stdout(std::process::Stdio::piped())
        .spawn()
        .expect("child");
    let lines = std::io::BufReader::new(child.stdout.take().expect("stdout"));
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::Builder::new()
        .name("reader".into())
        .spawn(move || {
            for line in lines.lines().map_while(Result::ok) {
                let _ = tx.send((Instant::now(), line));
            }
        })
        .expect("reader");
    // Wait for the first whole record, then kill at a random moment 5 to 35 s later.
    let mut log: Vec<(Instant, String)> = Vec::new();
    let mut session = PathBuf::new();
    while let Ok((at, line)) = rx.recv() {
        if let Some(s) = line.strip_prefix("session ") {
            session = PathBuf::from(s);
        }
        let first = line.starts_with("record 0 ");
        log.push((at, line));
        if first {
            break;
        }
    }
    let wait = Duration::from_millis(5000 + u64::from(seed % 30_000));
    let until = Instant::now() + wait;
    while let Ok((at, line)) = rx.recv_timeout(until.saturating_duration_since(Instant::now())) {
        log.push((at, line));
    }
    let killed = Instant::now();
    child.kill().expect("kill");
    let _ = child.wait();
    let doc = recovery::load(&session).expect("a copy to recover");
    let recovered = doc.settings().primary.n.round() as u32 - 1;
    // The loss: from the moment the stroke after the recovered one started to the kill
    // (all of that stroke and anything after it).
    let next_started = log.iter().find_map(|(at, l)| {
        let mut w = l.split(' ');
        (w.next() == Some("stroke") && w.next() == Some(&(recovered + 1).to_string()))
            .then_some(*at)
    });
    let lost = next_started.map_or(Duration::ZERO, |t| killed.duration_since(t));
    let in_flight = log
        .iter()
        .rev()
        .find(|(_, l)| l.starts_with("record "))
        .map(|(_, l)| l.clone())
        .unwrap_or_default();
    let writes: Vec<(u64, String)> = log
        .iter()
        .filter_map(|(_, l)| {
            let w: Vec<&str> = l.split(' ').collect();
            (w[0] == "record").then(|| (w[3].parse().unwrap_or(0), w[4].to_string()))
        })
        .collect();
    let longest = |kind: &str| {
        writes
            .iter()
            .filter(|(_, k)| k == kind)
            .map(|(ms, _)| *ms)
            .max()
            .unwrap_or(0)
    };
    let text = format!(
        "killed {:.1} s in, recovered stroke {recovered}, lost {:.2} s of work; \
         records: whole up to {} ms, delta up to {} ms (last finished: {in_flight})",
        wait.as_secs_f64(),
        lost.as_secs_f64(),
        longest("whole"),
        longest("delta")
    );
    let _ = std::fs::remove_dir_all(session.parent().unwrap_or(&session));
    text
}
