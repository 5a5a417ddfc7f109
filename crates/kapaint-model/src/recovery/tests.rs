//! Tests of the journal, retries, poll timing, moves, offers and where recovery folders go.

use super::folder::{generations, journal_file};
use super::session::Owner;
use super::*;
use crate::layers::{Layer, LayerContent};
use crate::{DocumentSettings, FillRegion, MaterialValue};
use crate::{
    HistoryCommand, LayerCommand, MaskCommand, PaintCommand, SettingsCommand, StrokeCommand,
};

fn temp(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("kapaint-recovery-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn stroke(doc: &mut Document, y: f32) {
    doc.apply(StrokeCommand::Stroke {
        tool: crate::StrokeTool::Brush,
        points: vec![
            crate::brush::StrokePoint {
                pos: glam::Vec2::new(3.0, y),
                pressure: 1.0,
            },
            crate::brush::StrokePoint {
                pos: glam::Vec2::new(180.0, y + 7.0),
                pressure: 1.0,
            },
        ],
    })
    .unwrap();
}

/// Texel for texel over the map (a loaded plane may be uniform where the painted one is
/// full, and what lies past a partial tile's edge is not stored).
fn same_maps(a: &Document, b: &Document) -> bool {
    let (w, h) = (a.maps().width(), a.maps().height());
    (0..h).all(|y| (0..w).all(|x| a.maps().texel(x, y) == b.maps().texel(x, y)))
}

/// The same layers (settings, kinds, tiles and masks by content), selection, settings and
/// identity.
fn same_document(a: &Document, b: &Document) -> bool {
    fn same_layer(a: &Layer, b: &Layer) -> bool {
        let content = match (&a.content, &b.content) {
            (LayerContent::Paint(x), LayerContent::Paint(y)) => x
                .iter()
                .zip(y)
                .all(|(s, t)| s.as_ref().map(|s| s.get()) == t.as_ref().map(|t| t.get())),
            (LayerContent::Fill(x), LayerContent::Fill(y)) => x == y,
            (LayerContent::Projected(x), LayerContent::Projected(y)) => {
                let (x, y) = (x.fill(), y.fill());
                x.projection == y.projection
                    && x.channels == y.channels
                    && x.image.path() == y.image.path()
                    && x.image.pixels().ok() == y.image.pixels().ok()
            }
            (LayerContent::Group(x), LayerContent::Group(y)) => {
                x.len() == y.len() && x.iter().zip(y).all(|(s, t)| same_layer(s, t))
            }
            _ => false,
        };
        let mask = match (&a.mask, &b.mask) {
            (None, None) => true,
            (Some(x), Some(y)) => {
                x.enabled == y.enabled
                    && x.inverted == y.inverted
                    && x.generator() == y.generator()
                    && x.tiles
                        .iter()
                        .zip(&y.tiles)
                        .all(|(s, t)| s.get() == t.get())
            }
            _ => false,
        };
        a.props == b.props && content && mask
    }
    let (sa, sb) = (a.stack(), b.stack());
    sa.layers.len() == sb.layers.len()
        && sa
            .layers
            .iter()
            .zip(&sb.layers)
            .all(|(x, y)| same_layer(x, y))
        && sa.base == sb.base
        && a.selection() == b.selection()
        && a.settings() == b.settings()
        && a.id() == b.id()
        && same_maps(a, b)
}

/// A document of three layers: "Layer 1" painted all over (a gradient and a stroke), a fill
/// with a painted mask, a group.
fn layered(w: u32, h: u32) -> Document {
    let mut doc = Document::new(w, h, DocumentSettings::default()).unwrap();
    doc.apply(PaintCommand::Gradient {
        shape: crate::paint::GradientShape::Radial,
        start: glam::Vec2::ZERO,
        end: glam::Vec2::new(w as f32, h as f32),
    })
    .unwrap();
    stroke(&mut doc, 20.0);
    doc.apply(LayerCommand::AddLayer {
        kind: crate::LayerKind::Fill,
        name: "Rust".into(),
    })
    .unwrap();
    doc.apply(MaskCommand::AddMask).unwrap();
    doc.apply(MaskCommand::SelectMask).unwrap();
    stroke(&mut doc, 40.0);
    doc.apply(LayerCommand::AddLayer {
        kind: crate::LayerKind::Group,
        name: "Folder".into(),
    })
    .unwrap();
    doc.apply(LayerCommand::SelectLayer(crate::LayerRef::Name(
        "Layer 1".into(),
    )))
    .unwrap();
    doc
}

#[test]
fn every_autosave_after_the_first_appends_only_what_changed_layers_and_all() {
    let dir = temp("journal");
    let project = dir.join("p.kapaint");
    let mut doc = layered(300, 200);
    let mut saver = Autosaver::new(Duration::ZERO, Some(&project), &doc);
    let t = Instant::now();
    assert!(saver.poll(&doc, t).is_none());
    assert!(saver.wait().is_none(), "nothing changed, nothing written");
    stroke(&mut doc, 60.0);
    saver.poll(&doc, t);
    saver.wait().unwrap().unwrap();
    let session = saver.session();
    assert!(same_document(&load(&session).unwrap(), &doc));
    let first = saver.generation.as_ref().unwrap().bytes;
    // Later changes, settings and layer changes included, land in the journal as records of
    // what changed.
    for (k, y) in [100.0, 140.0].into_iter().enumerate() {
        stroke(&mut doc, y);
        doc.apply(SettingsCommand::SetModel(if k == 0 {
            kapaint_reflectance::ShadingModel::BlinnPhong
        } else {
            kapaint_reflectance::ShadingModel::Phong
        }))
        .unwrap();
        doc.apply(LayerCommand::SetLayerOpacity(0.5)).unwrap();
        let before = saver.generation.as_ref().unwrap().bytes;
        saver.poll(&doc, t);
        saver.wait().unwrap().unwrap();
        let grew = saver.generation.as_ref().unwrap().bytes - before;
        assert!(
            grew < first / 2,
            "a stroke's record is {grew} bytes, the whole {first}"
        );
        assert!(same_document(&load(&session).unwrap(), &doc));
    }
    assert_eq!(generations(&session).len(), 1);
    // Undo brings back tiles an earlier record held.
    doc.apply(HistoryCommand::Undo).unwrap();
    doc.apply(HistoryCommand::Undo).unwrap();
    saver.poll(&doc, t);
    saver.wait().unwrap().unwrap();
    assert!(same_document(&load(&session).unwrap(), &doc));
    // A record cut short (a kill mid-write) is ignored: recovery gets the one before.
    let before = load(&session).unwrap();
    stroke(&mut doc, 170.0);
    saver.poll(&doc, t);
    saver.wait().unwrap().unwrap();
    let g = saver.generation.as_ref().unwrap();
    let journal = journal_file(&session, g.stamp);
    let full = std::fs::metadata(&journal).unwrap().len();
    std::fs::OpenOptions::new()
        .write(true)
        .open(&journal)
        .unwrap()
        .set_len(full - 100)
        .unwrap();
    assert!(same_document(&load(&session).unwrap(), &before));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_normal_map_and_a_new_generation_are_kept() {
    let dir = temp("normal");
    let mut doc = layered(128, 128);
    let normal = crate::normal::NormalMap::flat(32, 16).unwrap();
    doc = doc.with_normal(Some(std::sync::Arc::new(normal)));
    let mut saver = Autosaver::new(Duration::ZERO, Some(&dir.join("n.kapaint")), &doc);
    stroke(&mut doc, 10.0);
    saver.poll(&doc, Instant::now());
    saver.wait().unwrap().unwrap();
    let back = load(&saver.session()).unwrap();
    assert_eq!(
        back.normal().unwrap().image(),
        doc.normal().unwrap().image()
    );
    // Past its size, the journal starts again whole, and the old generation goes.
    saver.generation.as_mut().unwrap().bytes = u64::MAX;
    stroke(&mut doc, 90.0);
    saver.poll(&doc, Instant::now());
    saver.wait().unwrap().unwrap();
    assert_eq!(generations(&saver.session()).len(), 1);
    let back = load(&saver.session()).unwrap();
    assert!(same_document(&back, &doc));
    assert!(back.normal().is_some());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_generator_mask_is_recovered_as_its_parameters() {
    let dir = temp("generator");
    let mut doc = layered(128, 128);
    let mut saver = Autosaver::new(Duration::ZERO, Some(&dir.join("g.kapaint")), &doc);
    doc.apply(LayerCommand::SelectLayer(crate::LayerRef::Name(
        "Rust".into(),
    )))
    .unwrap();
    let noise = crate::generator::Generator::Noise(crate::generator::Noise {
        kind: crate::generator::NoiseKind::Perlin,
        scale: 6.0,
        octaves: 3,
        seed: 4,
        space: crate::generator::Space::Object,
    });
    doc.apply(MaskCommand::SetMaskGenerator(Some(noise.clone())))
        .unwrap();
    saver.poll(&doc, Instant::now());
    saver.wait().unwrap().unwrap();
    let back = load(&saver.session()).unwrap();
    assert!(same_document(&back, &doc));
    let mask = back.stack().layers[1].mask.clone().unwrap();
    assert_eq!(mask.generator(), Some(&noise));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_projection_fill_is_recovered_and_its_image_written_once() {
    let dir = temp("projection-fill");
    let mut doc = layered(128, 128);
    let mut saver = Autosaver::new(Duration::ZERO, Some(&dir.join("p.kapaint")), &doc);
    // 256 x 256 pixels: 768 KiB kept, far more than a stroke's record.
    let picture = image::RgbaImage::from_fn(256, 256, |x, y| {
        image::Rgba([x as u8, y as u8, (x ^ y) as u8, 255])
    });
    let image = crate::paint_image::PaintImage::decoded(
        std::path::Path::new("grid.png"),
        &image::DynamicImage::ImageRgba8(picture),
    )
    .unwrap();
    doc.apply(LayerCommand::AddProjectionFill {
        name: "Grid".into(),
        image,
        projection: crate::paint::projection::Projection::Uv {
            offset: glam::Vec2::ZERO,
            scale: glam::Vec2::splat(2.0),
            rotation: 15.0,
        },
        channels: crate::Channels::ALL,
    })
    .unwrap();
    saver.poll(&doc, Instant::now());
    saver.wait().unwrap().unwrap();
    let back = load(&saver.session()).unwrap();
    assert!(same_document(&back, &doc));
    assert!(same_maps(&back, &doc));
    let journal_len = |saver: &Autosaver| {
        let stamps = generations(&saver.session());
        std::fs::metadata(journal_file(&saver.session(), stamps[0]))
            .unwrap()
            .len()
    };
    let first = journal_len(&saver);
    assert!(first > 256 * 256 * 12, "the image is in the first record");
    doc.apply(LayerCommand::SelectLayer(crate::LayerRef::Index(0)))
        .unwrap();
    stroke(&mut doc, 40.0);
    saver.poll(&doc, Instant::now());
    saver.wait().unwrap().unwrap();
    assert!(
        journal_len(&saver) - first < 256 * 256 * 12,
        "the next record refers to the image the journal holds"
    );
    let back = load(&saver.session()).unwrap();
    assert!(same_document(&back, &doc));
    assert!(same_maps(&back, &doc));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_kept_mesh_is_recovered_and_written_once() {
    let dir = temp("kept-mesh");
    // A kept mesh is one an OBJ file gives (vertices in the order the triangles use them).
    let torus = kapaint_mesh::torus(1.0, 0.35, 24, 12);
    let obj = kapaint_mesh::write_obj(&torus);
    let name = "torus, unwrapped".to_string();
    let mesh = std::sync::Arc::new(
        kapaint_mesh::parse_obj(obj.as_bytes(), name, "t.obj".as_ref()).unwrap(),
    );
    let settings = DocumentSettings {
        mesh: crate::MeshRef::Embedded(mesh.name.clone()),
        ..DocumentSettings::default()
    };
    let mut doc = Document::new(128, 128, settings)
        .unwrap()
        .with_embedded_mesh(Some(std::sync::Arc::clone(&mesh)));
    let mut saver = Autosaver::new(Duration::ZERO, Some(&dir.join("m.kapaint")), &doc);
    stroke(&mut doc, 10.0);
    saver.poll(&doc, Instant::now());
    saver.wait().unwrap().unwrap();
    let back = load(&saver.session()).unwrap();
    assert!(**back.embedded_mesh().unwrap() == *mesh);
    // The next record refers to the mesh the journal holds: it costs the stroke, not the mesh.
    stroke(&mut doc, 90.0);
    saver.poll(&doc, Instant::now());
    saver.wait().unwrap().unwrap();
    let stamps = generations(&saver.session());
    assert_eq!(stamps.len(), 1);
    let journal = std::fs::read(journal_file(&saver.session(), stamps[0])).unwrap();
    let header = b"# torus, unwrapped written by kapaint";
    let copies = journal
        .windows(header.len())
        .filter(|w| w == header)
        .count();
    assert_eq!(copies, 1, "the mesh is written once, not with every record");
    let back = load(&saver.session()).unwrap();
    assert!(same_document(&back, &doc));
    assert!(**back.embedded_mesh().unwrap() == *mesh);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_failed_autosave_is_retried_and_its_folder_made() {
    let dir = temp("retry");
    // The state folder of a fresh machine does not exist yet.
    let project = dir.join("state/kapaint/p.kapaint");
    let mut doc = Document::new(64, 64, DocumentSettings::default()).unwrap();
    let mut saver = Autosaver::new(Duration::from_secs(20), Some(&project), &doc);
    doc.apply(PaintCommand::Fill(FillRegion::All)).unwrap();
    let t = Instant::now();
    saver.poll(&doc, t + Duration::from_secs(21));
    saver.wait().unwrap().unwrap();
    assert!(saver.is_current(&doc));
    // A file where the folder should be: the autosave fails and counts nothing as saved.
    let session = saver.session();
    remove(&session);
    std::fs::create_dir_all(saver.recovery_folder()).unwrap();
    std::fs::write(&session, b"in the way").unwrap();
    doc.apply(SettingsCommand::SetPrimary(MaterialValue::new(
        glam::Vec3::X,
        glam::Vec3::ZERO,
        5.0,
    )))
    .unwrap();
    doc.apply(PaintCommand::Fill(FillRegion::All)).unwrap();
    saver.poll(&doc, t + Duration::from_secs(42));
    assert!(saver.wait().unwrap().is_err());
    assert!(!saver.is_current(&doc));
    assert!(
        saver.poll(&doc, t + Duration::from_secs(50)).is_none(),
        "not before the interval"
    );
    assert!(saver.wait().is_none());
    std::fs::remove_file(&session).unwrap();
    saver.poll(&doc, t + Duration::from_secs(63));
    saver.wait().unwrap().unwrap();
    assert!(saver.is_current(&doc));
    assert!(same_document(&load(&session).unwrap(), &doc));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_next_poll_is_when_the_copy_falls_due() {
    let dir = temp("next");
    let mut doc = Document::new(64, 64, DocumentSettings::default()).unwrap();
    let mut saver = Autosaver::new(Duration::from_secs(20), Some(&dir.join("r.kapaint")), &doc);
    let t = saver.last_time;
    assert_eq!(saver.next_poll(&doc, t), None, "nothing to save");
    doc.apply(PaintCommand::Fill(FillRegion::All)).unwrap();
    assert_eq!(
        saver.next_poll(&doc, t + Duration::from_secs(5)),
        Some(Duration::from_secs(15))
    );
    assert_eq!(
        saver.next_poll(&doc, t + Duration::from_secs(25)),
        Some(Duration::ZERO)
    );
    saver.poll(&doc, t + Duration::from_secs(25));
    assert!(
        saver.next_poll(&doc, t).is_some(),
        "a save runs: look again soon"
    );
    saver.wait().unwrap().unwrap();
    assert_eq!(saver.next_poll(&doc, t + Duration::from_secs(26)), None);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn recovery_folders_sit_beside_the_project_one_session_each() {
    let p = recovery_path(Some(Path::new("/work/art/cow.kapaint")));
    assert_eq!(p, Path::new("/work/art/.cow.kapaint-recovery"));
    assert!(recovery_path(None).ends_with("kapaint/untitled.kapaint-recovery"));
    let doc = Document::new(16, 16, DocumentSettings::default()).unwrap();
    let saver = Autosaver::new(
        Duration::ZERO,
        Some(Path::new("/work/art/cow.kapaint")),
        &doc,
    );
    assert_eq!(saver.session().parent(), Some(p.as_path()));
    assert_eq!(
        saver.session().file_name().and_then(|n| n.to_str()),
        Some(Owner::this_process().file_name().as_str())
    );
}

/// The copy of `saver` made to look like an ended editor's: its session folder renamed to a
/// process that no longer runs.
fn as_ended(saver: &Autosaver, pid: u32) -> PathBuf {
    let gone = Owner {
        pid,
        ..Owner::this_process().clone()
    };
    let to = saver.recovery_folder().join(gone.file_name());
    std::fs::rename(saver.session(), &to).unwrap();
    to
}

#[test]
fn save_as_moves_the_copy_to_the_new_project() {
    let dir = temp("move");
    let (a, b) = (dir.join("A.kapaint"), dir.join("B.kapaint"));
    let mut doc = layered(64, 64);
    crate::project::save(&doc, &a).unwrap();
    let mut saver = Autosaver::new(Duration::ZERO, Some(&a), &doc);
    stroke(&mut doc, 30.0);
    saver.poll(&doc, Instant::now());
    saver.wait().unwrap().unwrap();
    // Save As B: the copy goes with the work.
    crate::project::save(&doc, &b).unwrap();
    saver.relocate(Some(&b));
    assert!(
        !recovery_path(Some(&a)).exists(),
        "A keeps no copy of B's work"
    );
    stroke(&mut doc, 50.0);
    saver.poll(&doc, Instant::now());
    saver.wait().unwrap().unwrap();
    assert!(same_document(&load(&saver.session()).unwrap(), &doc));
    // Killed now: B's work is offered for B, nothing for A.
    let ended = as_ended(&saver, 4_194_305);
    assert_eq!(offer(Some(&a)), None);
    assert_eq!(offer(Some(&b)), Some(ended.clone()));
    // Recovered: the recovered copy stays until this editor's own copy is on disk.
    let recovered = load(&ended).unwrap();
    let mut saver =
        Autosaver::recovering(Duration::from_secs(20), Some(&b), &recovered, ended.clone());
    assert!(ended.exists());
    saver.poll(&recovered, Instant::now());
    saver.wait().unwrap().unwrap();
    assert!(!ended.exists());
    assert!(same_document(&load(&saver.session()).unwrap(), &doc));
    saver.discard();
    assert!(
        !recovery_path(Some(&b)).exists(),
        "a discarded copy leaves nothing"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn only_an_ended_editors_whole_copy_of_this_project_is_offered() {
    let dir = temp("offer");
    let (p, q) = (dir.join("P.kapaint"), dir.join("Q.kapaint"));
    let mut doc = layered(64, 64);
    crate::project::save(&doc, &p).unwrap();
    let other = layered(64, 64);
    crate::project::save(&other, &q).unwrap();
    std::thread::sleep(Duration::from_millis(20));
    let mut saver = Autosaver::new(Duration::ZERO, Some(&p), &doc);
    stroke(&mut doc, 30.0);
    saver.poll(&doc, Instant::now());
    saver.wait().unwrap().unwrap();
    assert_eq!(offer(Some(&p)), None, "a running editor's copy is its own");
    let ended = as_ended(&saver, 4_194_305);
    assert_eq!(offer(Some(&p)), Some(ended.clone()));
    // The same copy in Q's recovery folder is P's work, not Q's: refused.
    let planted = recovery_path(Some(&q)).join(ended.file_name().unwrap());
    std::fs::create_dir_all(recovery_path(Some(&q))).unwrap();
    std::fs::rename(&ended, &planted).unwrap();
    assert_eq!(offer(Some(&q)), None);
    std::fs::rename(&planted, &ended).unwrap();
    // Older than the project: saved since, nothing to offer.
    std::thread::sleep(Duration::from_millis(20));
    crate::project::save(&doc, &p).unwrap();
    assert_eq!(offer(Some(&p)), None);
    // A copy killed during its first record holds nothing: not offered, and removed.
    let mut saver = Autosaver::new(Duration::ZERO, Some(&p), &doc);
    stroke(&mut doc, 50.0);
    saver.poll(&doc, Instant::now());
    saver.wait().unwrap().unwrap();
    let g = saver.generation.as_ref().unwrap();
    let journal = journal_file(&saver.session(), g.stamp);
    let cut = JOURNAL_MAGIC_LEN + 40;
    std::fs::OpenOptions::new()
        .write(true)
        .open(&journal)
        .unwrap()
        .set_len(cut)
        .unwrap();
    let killed = as_ended(&saver, 4_194_306);
    assert_eq!(offer(Some(&p)), None);
    assert!(!killed.exists(), "nothing to recover: removed");
    assert!(load(&ended).is_ok(), "the other ended copy is left alone");
    let _ = std::fs::remove_dir_all(&dir);
}

const JOURNAL_MAGIC_LEN: u64 = 8;
