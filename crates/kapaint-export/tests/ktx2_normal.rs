//! Normal maps in KTX2 sets: x and y alone (BC5 in `ktx2`, two-component ASTC in `ktx2-astc`,
//! RG8 in `ktx2-raw`) with a full mip chain, z rebuilt by the consumer, and the angular error
//! reported. Checked independently of kapaint's own code: the files are parsed with the
//! `ktx2` crate's reader, decoded with `bcdec_rs` and `texture2ddecoder`, and the error is
//! recomputed here from the project's own map.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::path::{Path, PathBuf};
use std::sync::Arc;

#[path = "common/inflate.rs"]
mod inflate;

use glam::{DVec3, Vec2, Vec3};
use kapaint_export::preset;
use kapaint_export::set::{self, Compression, Manifest, NormalFile};
use kapaint_model::brush::StrokePoint;
use kapaint_model::normal::NormalMap;
use kapaint_model::texel::MaterialValue;
use kapaint_model::{Document, DocumentSettings, SettingsCommand, StrokeCommand, StrokeTool};

fn temp(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("kapaint-normal-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// A bumpy normal map of `w x h` from a height field: smooth waves, and the sharp rims of
/// raised discs (the hard case for blocks: a crease inside a 4x4 block).
fn bumps(w: u32, h: u32) -> NormalMap {
    let height = |x: f32, y: f32| {
        let waves = 0.8 * (x * 0.21).sin() * (y * 0.17).cos();
        let (cx, cy) = ((x / 24.0).fract() - 0.5, (y / 24.0).fract() - 0.5);
        let disc = if cx * cx + cy * cy < 0.09 { 2.5 } else { 0.0 };
        waves + disc
    };
    NormalMap::new(image::RgbImage::from_fn(w, h, |x, y| {
        let (x, y) = (x as f32, y as f32);
        let dx = height(x + 1.0, y) - height(x - 1.0, y);
        let dy = height(x, y + 1.0) - height(x, y - 1.0);
        let n = Vec3::new(-dx * 0.5, -dy * 0.5, 1.0).normalize();
        image::Rgb(n.to_array().map(|v| ((v + 1.0) * 127.5).round() as u8))
    }))
    .expect("normal map")
}

/// A painted project (so the set holds images) with the normal map `normal`.
fn project(normal: &NormalMap) -> Document {
    let mut doc = Document::new(
        96,
        64,
        DocumentSettings {
            base: MaterialValue::new(Vec3::new(0.6, 0.5, 0.4), Vec3::splat(0.3), 20.0),
            ..DocumentSettings::default()
        },
    )
    .expect("doc");
    doc.apply(SettingsCommand::SetPrimary(MaterialValue::new(
        Vec3::new(0.9, 0.1, 0.05),
        Vec3::splat(0.3),
        900.0,
    )))
    .expect("primary");
    doc.apply(StrokeCommand::Stroke {
        tool: StrokeTool::Brush,
        points: [10.0, 80.0]
            .map(|x| StrokePoint {
                pos: Vec2::new(x, 30.0),
                pressure: 1.0,
            })
            .to_vec(),
    })
    .expect("stroke");
    doc.with_normal(Some(Arc::new(normal.clone())))
}

/// The source's unit normal at texel `i`, in `f64`: `2 c - 1`, made unit.
fn source_normal(map: &NormalMap, i: usize) -> DVec3 {
    let w = map.width() as usize;
    let c = map.image().get_pixel((i % w) as u32, (i / w) as u32).0;
    DVec3::from_array(c.map(|c| f64::from(c) / 127.5 - 1.0)).normalize()
}

/// The normal a consumer rebuilds from bytes `x`, `y`: z = sqrt(1 - x^2 - y^2).
fn rebuilt(x: u8, y: u8) -> DVec3 {
    let (x, y) = (f64::from(x) / 127.5 - 1.0, f64::from(y) / 127.5 - 1.0);
    let zz = 1.0 - x * x - y * y;
    if zz >= 0.0 {
        DVec3::new(x, y, zz.sqrt())
    } else {
        DVec3::new(x, y, 0.0).normalize()
    }
}

fn degrees(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b)).to_degrees()
}

/// A level of a two-component file as (x, y) bytes per texel, decoded independently:
/// `bcdec_rs` for BC5, `texture2ddecoder` for ASTC (luminance in RGB, alpha: x in R, y in A).
fn decode_xy(format: ktx2::Format, data: &[u8], (w, h): (u32, u32)) -> Vec<[u8; 2]> {
    let (w, h) = (w as usize, h as usize);
    if format == ktx2::Format::R8G8_UNORM {
        return data.chunks_exact(2).map(|c| [c[0], c[1]]).collect();
    }
    if format == ktx2::Format::BC5_UNORM_BLOCK {
        let mut out = vec![[0_u8; 2]; w * h];
        let across = w.div_ceil(4);
        for (b, block) in data.chunks_exact(16).enumerate() {
            let mut rg = [0_u8; 32];
            bcdec_rs::bc5(block, &mut rg, 8, false);
            for t in 0..16 {
                let (x, y) = ((b % across) * 4 + t % 4, (b / across) * 4 + t / 4);
                if x < w && y < h {
                    out[y * w + x] = [rg[t * 2], rg[t * 2 + 1]];
                }
            }
        }
        return out;
    }
    let (block, srgb) =
        kapaint_export::codec::AstcBlock::of_vk_format(format.value()).expect("an ASTC format");
    assert!(!srgb, "a normal map is not colour");
    let (bw, bh) = block.dims();
    let mut image = vec![0_u32; w * h];
    texture2ddecoder::decode_astc(data, w, h, bw as usize, bh as usize, &mut image)
        .expect("texture2ddecoder decodes the level");
    image
        .iter()
        .map(|p| {
            let [b, g, r, a] = p.to_le_bytes();
            assert!(r == g && g == b, "luminance in R, G and B");
            [r, a]
        })
        .collect()
}

/// Every level of a normal map's KTX2 file, decoded independently, after its header is held
/// to the specification's rules: `format`, 2D, a full mip chain.
fn read_levels(path: &Path, format: ktx2::Format) -> ((u32, u32), Vec<Vec<[u8; 2]>>) {
    let bytes = std::fs::read(path).expect("read");
    let reader = ktx2::Reader::new(&bytes[..]).expect("a KTX2 file");
    let header = reader.header();
    assert_eq!(header.format, Some(format));
    let (w, h) = (header.pixel_width, header.pixel_height);
    assert_eq!(header.level_count, 32 - w.max(h).leading_zeros());
    assert_eq!((header.pixel_depth, header.face_count), (0, 1));
    let levels = reader
        .levels()
        .enumerate()
        .map(|(k, level)| {
            let data = inflate::level_bytes(header.supercompression_scheme, level.data);
            decode_xy(format, &data, ((w >> k).max(1), (h >> k).max(1)))
        })
        .collect();
    ((w, h), levels)
}

/// Mean, p99 (exact, sorted) and max of the angle between the decoded level 0 and the source.
fn errors(map: &NormalMap, level0: &[[u8; 2]]) -> (f64, f64, f64) {
    let mut all: Vec<f64> = level0
        .iter()
        .enumerate()
        .map(|(i, xy)| degrees(source_normal(map, i), rebuilt(xy[0], xy[1])))
        .collect();
    all.sort_by(f64::total_cmp);
    let mean = all.iter().sum::<f64>() / all.len() as f64;
    let p99 = all[((all.len() as f64 * 0.99).ceil() as usize).max(1) - 1];
    (mean, p99, *all.last().expect("texels"))
}

/// The 2x2 box mean of `level` (unit normals, `size`), made unit again: the next level's
/// reference.
fn next_level(level: &[DVec3], (w, h): (u32, u32)) -> Vec<DVec3> {
    let (w, h) = (w as usize, h as usize);
    let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
    (0..nw * nh)
        .map(|j| {
            let (x, y) = (j % nw, j / nw);
            let xs = [(2 * x).min(w - 1), (2 * x + 1).min(w - 1)];
            let ys = [(2 * y).min(h - 1), (2 * y + 1).min(h - 1)];
            let sum: DVec3 = ys
                .iter()
                .flat_map(|y| xs.iter().map(move |x| level[y * w + x]))
                .sum();
            sum.normalize()
        })
        .collect()
}

/// Each level past 0 of `levels` decodes, on average, within `limit` degrees of the
/// source's normals box-filtered level by level and made unit again.
fn check_mips(name: &str, map: &NormalMap, levels: &[Vec<[u8; 2]>], limit: f64) {
    let mut at = (map.width(), map.height());
    let mut reference: Vec<DVec3> = (0..(at.0 * at.1) as usize)
        .map(|i| source_normal(map, i))
        .collect();
    for (k, level) in levels.iter().enumerate().skip(1) {
        reference = next_level(&reference, at);
        at = ((at.0 / 2).max(1), (at.1 / 2).max(1));
        assert_eq!(level.len(), reference.len(), "{name}: level {k}");
        let mean = level
            .iter()
            .zip(&reference)
            .map(|(xy, r)| degrees(*r, rebuilt(xy[0], xy[1])))
            .sum::<f64>()
            / level.len() as f64;
        assert!(mean < limit, "{name}: level {k}: {mean}");
    }
}

#[test]
fn ktx2_sets_hold_the_normal_maps_x_and_y_with_its_angular_error() {
    // Regression: every KTX2 set carried the normal map as an RGB PNG beside its KTX2 files.
    // 70 x 50: neither side a multiple of 4.
    let map = bumps(70, 50);
    let doc = project(&map);
    for (name, compression, format) in [
        ("ktx2", Compression::Ktx2Bc5, ktx2::Format::BC5_UNORM_BLOCK),
        (
            "ktx2-astc",
            Compression::Ktx2Astc,
            ktx2::Format::ASTC_4x4_UNORM_BLOCK,
        ),
        ("ktx2-raw", Compression::Ktx2, ktx2::Format::R8G8_UNORM),
    ] {
        let out = temp(name);
        let p = preset::find(name).expect("preset");
        let m = set::export(&doc, &p, &out).expect("export");
        let n = m.normal.as_deref().expect("the normal map is in the set");
        assert_eq!(n.path, "normal.ktx2", "{name}");
        assert_eq!(n.encoding, set::NORMAL_XY_ENCODING);
        assert_eq!(n.compression, Some(compression), "{name}");
        assert_eq!(n.z.as_deref(), Some(set::NORMAL_Z));
        let xy = if compression == Compression::Ktx2Astc {
            "ra"
        } else {
            "rg"
        };
        assert_eq!(n.xy.as_deref(), Some(xy), "{name}");
        assert_eq!((n.width, n.height, n.mip_levels), (70, 50, Some(7)));
        assert!(!out.join("normal.png").exists(), "{name}: no PNG beside it");
        assert_eq!(
            n.bytes,
            std::fs::metadata(out.join("normal.ktx2"))
                .expect("file")
                .len()
        );
        // The error the manifest reports is what an independent decoder gives.
        let (size, levels) = read_levels(&out.join("normal.ktx2"), format);
        assert_eq!(size, (70, 50));
        // kapaint's own decode (its measure, its import) reads the same bytes: exactly for
        // BC5 and RG8, within a level for ASTC (as `tests/ktx2_astc.rs` finds for colour).
        let bytes = std::fs::read(out.join("normal.ktx2")).expect("read");
        let ours = kapaint_export::ktx::decode(&bytes).expect("decode");
        let second = if xy == "ra" { 3 } else { 1 };
        let off = levels[0]
            .iter()
            .enumerate()
            .map(|(i, xy)| {
                let at = |c: usize| (ours.rgba[i * 4 + c] * 255.0).round() as u8;
                xy[0].abs_diff(at(0)).max(xy[1].abs_diff(at(second)))
            })
            .max()
            .expect("texels");
        let tolerance = u8::from(compression == Compression::Ktx2Astc);
        assert!(off <= tolerance, "{name}: kapaint's decode is {off} off");
        let (mean, p99, max) = errors(&map, &levels[0]);
        let e = n.angular_error.expect("measured");
        eprintln!("{name}: manifest {e:?}");
        // `texture2ddecoder` reads some ASTC texels a level off astcenc (ARM's reference,
        // which the export measures with): a few hundredths of a degree on the mean.
        let (mean_off, off) = if compression == Compression::Ktx2Astc {
            (0.02, 1.0)
        } else {
            (1e-3, 1e-3)
        };
        assert!((e.mean - mean).abs() < mean_off, "{name}: {e:?} vs {mean}");
        assert!((e.max - max).abs() < off, "{name}: {e:?} vs {max}");
        assert!(
            e.p99 >= p99 - off && e.p99 <= p99 + 0.011 + off,
            "{name}: {e:?} vs {p99}"
        );
        eprintln!("{name}: angular error mean {mean:.3}, p99 {p99:.3}, max {max:.3} degrees");
        // 8 bits of x and y cost well under a degree; blocks a little more.
        let (mean_limit, p99_limit) = if compression == Compression::Ktx2 {
            (0.3, 0.6)
        } else {
            (100.0, 100.0)
        };
        assert!(mean < mean_limit && p99 < p99_limit, "{name}: {e:?}");
        check_mips(name, &map, &levels, mean_limit * 2.0);
        // The notices say it, and the set reads back with z rebuilt.
        let line = n.summary().expect("a line for the notices");
        assert!(
            line.contains("normal.ktx2") && line.contains("angular error mean"),
            "{line}"
        );
        let back = set::import(&out.join("material.json")).expect("import");
        let back = back.normal().expect("the normal map reads back");
        assert_eq!((back.width(), back.height()), (70, 50));
        // As kapaint decodes the file, then stored as the project stores normals (8-bit RGB).
        for i in 0..70 * 50 {
            let got = back.normal((i % 70) as u32, (i / 70) as u32).as_dvec3();
            let at = |c: usize| (ours.rgba[i * 4 + c] * 255.0).round() as u8;
            let want = rebuilt(at(0), at(second));
            assert!(degrees(got, want) < 1.0, "{name}: texel {i}");
        }
        // The manifest reads back, checked.
        let text = std::fs::read(out.join("material.json")).expect("manifest");
        let read: Manifest = serde_json::from_slice(&text).expect("reads");
        assert_eq!(read.normal.as_deref(), Some(n));
        let _ = std::fs::remove_dir_all(&out);
    }
}

#[test]
fn image_sets_keep_the_normal_map_as_the_project_stores_it() {
    let map = bumps(40, 30);
    let doc = project(&map);
    let out = temp("compact");
    let m = set::export(&doc, &preset::find("compact").expect("preset"), &out).expect("export");
    let n = m.normal.as_deref().expect("normal");
    assert_eq!(n.path, "normal.png");
    assert!(n.angular_error.is_none() && n.summary().is_none());
    let written = image::open(out.join("normal.png")).expect("png").to_rgb8();
    assert_eq!(&written, map.image(), "as stored");
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn a_normal_entry_that_does_not_hold_together_is_refused() {
    let map = bumps(16, 16);
    let doc = project(&map);
    let out = temp("refused");
    set::export(&doc, &preset::find("ktx2").expect("preset"), &out).expect("export");
    let path = out.join("material.json");
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&path).expect("manifest")).expect("json");
    for (field, value) in [
        ("xy", serde_json::json!("ra")),
        ("z", serde_json::json!("1")),
        ("encoding", serde_json::json!("png-rgb8-tangent-normal")),
        ("compression", serde_json::json!("ktx2-bc7")),
        ("astc_block", serde_json::json!("4x4")),
    ] {
        let mut bad = json.clone();
        bad["normal"][field] = value;
        let text = serde_json::to_vec(&bad).expect("json");
        assert!(
            serde_json::from_slice::<Manifest>(&text).is_err(),
            "{field}: accepted"
        );
    }
    let entry: NormalFile = serde_json::from_value(json["normal"].clone()).expect("entry");
    assert_eq!(entry.path, "normal.ktx2");
    let _ = std::fs::remove_dir_all(&out);
}
