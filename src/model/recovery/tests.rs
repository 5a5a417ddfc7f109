//! Tests of the journal, retries, poll timing and where recovery folders go.

use super::folder::{generations, journal_file};
use super::*;
use crate::model::{Command, DocumentSettings, FillRegion, MaterialValue};

fn temp(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("kapaint-recovery-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn stroke(doc: &mut Document, y: f32) {
    doc.apply(Command::Stroke {
        tool: crate::model::StrokeTool::Brush,
        points: vec![
            crate::model::brush::StrokePoint {
                pos: glam::Vec2::new(3.0, y),
                pressure: 1.0,
            },
            crate::model::brush::StrokePoint {
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

#[test]
fn every_autosave_after_the_first_appends_only_what_changed() {
    let dir = temp("journal");
    let path = dir.join(".p.kapaint-recovery");
    let mut doc = Document::new(200, 130, DocumentSettings::default()).unwrap();
    let mut saver = Autosaver::new(Duration::ZERO, path.clone(), &doc);
    let t = Instant::now();
    assert!(saver.poll(&doc, t).is_none());
    assert!(saver.wait().is_none(), "nothing changed, nothing written");
    stroke(&mut doc, 20.0);
    saver.poll(&doc, t);
    saver.wait().unwrap().unwrap();
    let base_bytes = saver.generation.unwrap().base_bytes;
    assert!(same_maps(&load(&path).unwrap(), &doc));
    // Later changes, settings included, land in the journal; the base stays.
    for (k, y) in [60.0, 100.0].into_iter().enumerate() {
        stroke(&mut doc, y);
        doc.apply(Command::SetModel(if k == 0 {
            crate::reflectance::ShadingModel::BlinnPhong
        } else {
            crate::reflectance::ShadingModel::Phong
        }))
        .unwrap();
        saver.poll(&doc, t);
        saver.wait().unwrap().unwrap();
        let back = load(&path).unwrap();
        assert!(same_maps(&back, &doc));
        assert_eq!(back.settings(), doc.settings());
    }
    let g = saver.generation.unwrap();
    assert_eq!(g.base_bytes, base_bytes);
    assert_eq!(generations(&path).len(), 1);
    // A record cut short (a kill mid-write) is ignored: recovery gets the one before.
    let before = load(&path).unwrap();
    stroke(&mut doc, 120.0);
    saver.poll(&doc, t);
    saver.wait().unwrap().unwrap();
    let journal = journal_file(&path, g.stamp);
    let full = std::fs::metadata(&journal).unwrap().len();
    std::fs::OpenOptions::new()
        .write(true)
        .open(&journal)
        .unwrap()
        .set_len(full - 100)
        .unwrap();
    assert!(same_maps(&load(&path).unwrap(), &before));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_failed_autosave_is_retried_and_its_folder_made() {
    let dir = temp("retry");
    // The state folder of a fresh machine does not exist yet.
    let path = dir.join("state/kapaint/untitled.kapaint-recovery");
    let mut doc = Document::new(64, 64, DocumentSettings::default()).unwrap();
    let mut saver = Autosaver::new(Duration::from_secs(20), path.clone(), &doc);
    doc.apply(Command::Fill(FillRegion::All)).unwrap();
    let t = Instant::now();
    saver.poll(&doc, t + Duration::from_secs(21));
    saver.wait().unwrap().unwrap();
    assert!(saver.is_current(&doc));
    // A file where the folder should be: the autosave fails and counts nothing as saved.
    remove(&path);
    std::fs::write(&path, b"in the way").unwrap();
    doc.apply(Command::SetPrimary(MaterialValue::new(
        glam::Vec3::X,
        glam::Vec3::ZERO,
        5.0,
    )))
    .unwrap();
    doc.apply(Command::Fill(FillRegion::All)).unwrap();
    saver.poll(&doc, t + Duration::from_secs(42));
    assert!(saver.wait().unwrap().is_err());
    assert!(!saver.is_current(&doc));
    assert!(
        saver.poll(&doc, t + Duration::from_secs(50)).is_none(),
        "not before the interval"
    );
    assert!(saver.wait().is_none());
    std::fs::remove_file(&path).unwrap();
    saver.poll(&doc, t + Duration::from_secs(63));
    saver.wait().unwrap().unwrap();
    assert!(saver.is_current(&doc));
    assert!(same_maps(&load(&path).unwrap(), &doc));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_next_poll_is_when_the_copy_falls_due() {
    let dir = temp("next");
    let mut doc = Document::new(64, 64, DocumentSettings::default()).unwrap();
    let mut saver = Autosaver::new(Duration::from_secs(20), dir.join("r"), &doc);
    let t = saver.last_time;
    assert_eq!(saver.next_poll(&doc, t), None, "nothing to save");
    doc.apply(Command::Fill(FillRegion::All)).unwrap();
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
fn recovery_folders_sit_beside_the_project() {
    let p = recovery_path(Some(Path::new("/work/art/cow.kapaint")));
    assert_eq!(p, Path::new("/work/art/.cow.kapaint-recovery"));
    assert!(recovery_path(None).ends_with("kapaint/untitled.kapaint-recovery"));
}
