//! Supercompression (issue 58): the shipped KTX2 presets write every level of every KTX2
//! file Zstandard-compressed on its own (KTX2 scheme 2). Inflated by an independent decoder
//! the levels are the plain export's byte for byte; the manifest says the level and the size
//! without; the set reads back as the plain one does; bad presets and damaged levels are
//! errors.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::path::Path;

use kapaint_export::preset::{self, ExportPreset};
use kapaint_export::set::{self, Manifest};

#[path = "common/inflate.rs"]
mod inflate;
#[path = "common/stroke_edge.rs"]
#[expect(dead_code, reason = "each test file uses some of the helpers")]
mod stroke_edge;
use stroke_edge::{export, project};

/// Every level of a KTX2 file as stored before supercompression, and its scheme.
fn levels(path: &Path) -> (Option<ktx2::SupercompressionScheme>, Vec<Vec<u8>>) {
    let bytes = std::fs::read(path).expect("read");
    let reader = ktx2::Reader::new(&bytes[..]).expect("a KTX2 file");
    let scheme = reader.header().supercompression_scheme;
    let levels = reader
        .levels()
        .map(|l| inflate::level_bytes(scheme, l.data))
        .collect();
    (scheme, levels)
}

fn plain(p: &ExportPreset) -> ExportPreset {
    let mut p = p.clone();
    p.zstd = None;
    p
}

fn total(m: &Manifest) -> u64 {
    m.files.iter().map(|f| f.bytes).sum()
}

#[test]
fn shipped_ktx2_presets_supercompress_every_level_losslessly() {
    let doc = project(256);
    for name in ["ktx2", "ktx2-raw", "ktx2-astc"] {
        let shipped = preset::find(name).expect("preset");
        assert_eq!(shipped.zstd, Some(9), "{name} ships with zstd");
        let (zdir, z) = export(&doc, &shipped, &format!("zstd-{name}"));
        let (pdir, p) = export(&doc, &plain(&shipped), &format!("plain-{name}"));
        assert_eq!(z.files.len(), p.files.len());
        for (zf, pf) in z.files.iter().zip(&p.files) {
            let (scheme, zl) = levels(&zdir.join(&zf.path));
            let (none, pl) = levels(&pdir.join(&pf.path));
            assert_eq!(scheme, Some(ktx2::SupercompressionScheme::Zstandard));
            assert_eq!(none, None);
            assert!(zl == pl, "{name} {}: the same levels inflated", zf.path);
            let sc = zf.supercompression.as_ref().expect("said in the manifest");
            assert_eq!((sc.scheme.as_str(), sc.level), ("zstd", 9));
            assert_eq!(sc.uncompressed_bytes, pf.bytes, "{}", zf.path);
            let on_disk = std::fs::metadata(zdir.join(&zf.path)).expect("file").len();
            assert_eq!(zf.bytes, on_disk);
            assert!(pf.supercompression.is_none());
        }
        assert!(
            total(&z) < total(&p),
            "{name}: {} vs {}",
            total(&z),
            total(&p)
        );
        let saved = z.supercompression_summary().expect("a summary");
        assert!(
            saved.starts_with("zstd 9: ") && saved.contains("% smaller"),
            "{saved}"
        );
        assert!(p.supercompression_summary().is_none());
        // Read back as the plain set is: the same document.
        let a = set::import(&zdir.join("material.json")).expect("imports");
        let b = set::import(&pdir.join("material.json")).expect("imports");
        let (w, h) = (a.maps().width(), a.maps().height());
        assert_eq!((w, h), (b.maps().width(), b.maps().height()));
        let differ = (0..w * h)
            .filter(|&i| a.maps().texel(i % w, i / w) != b.maps().texel(i % w, i / w))
            .count();
        assert_eq!(differ, 0, "{name}: the same maps read back");
        // kapaint's own reader takes the supercompressed file too.
        let first = &z.files[0].path;
        let ours = kapaint_export::ktx::decode(&std::fs::read(zdir.join(first)).expect("read"))
            .expect("decodes");
        let theirs = kapaint_export::ktx::decode(&std::fs::read(pdir.join(first)).expect("read"))
            .expect("decodes");
        assert_eq!(ours.rgba, theirs.rgba);
        let _ = std::fs::remove_dir_all(zdir);
        let _ = std::fs::remove_dir_all(pdir);
    }
}

#[test]
fn bad_levels_and_presets_are_errors() {
    for (text, want) in [
        ("format: Ktx2, zstd: 0", "zstd must be a level in 1..=22"),
        ("format: Ktx2, zstd: 23", "zstd must be a level in 1..=22"),
        ("format: Png8, zstd: 9", "zstd supercompresses KTX2 files"),
    ] {
        let preset = format!("(version: 2, name: \"z\", {text}, layout: Packed, n_bits: 8)");
        let e = ExportPreset::parse(Path::new("z.ron"), &preset)
            .expect_err("refused")
            .to_string();
        assert!(e.contains(want), "{text}: {e}");
    }
    // A supercompressed level damaged: an error, never a panic or a wrong image.
    let doc = project(64);
    let (dir, m) = export(&doc, &preset::find("ktx2-raw").expect("preset"), "zstd-bad");
    let path = dir.join(&m.files[0].path);
    let mut bytes = std::fs::read(&path).expect("read");
    let reader = ktx2::Reader::new(&bytes[..]).expect("KTX2");
    let level0 = bytes.len() - reader.levels().next().expect("level 0").data.len();
    for b in &mut bytes[level0 + 4..] {
        *b ^= 0x5a;
    }
    let e = kapaint_export::ktx::decode(&bytes).expect_err("damaged");
    assert!(e.contains("level 0 does not inflate"), "{e}");
    std::fs::write(&path, &bytes).expect("write");
    assert!(set::import(&dir.join("material.json")).is_err());
    let _ = std::fs::remove_dir_all(dir);
}
