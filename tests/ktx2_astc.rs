//! Issue 43, item 3: the `ktx2-astc` preset, checked independently of kapaint's own code.
//! Every file is parsed with the `ktx2` crate's reader and held to the KTX2 specification's
//! rules for an ASTC file (vkFormat of the footprint, sRGB for colour, the DFD's ASTC colour
//! model and texel block), every level is decoded with `texture2ddecoder` (not astcenc, which
//! encoded it) and compared with the same project's uncompressed levels and with what
//! kapaint's own decode (the export's measure, the import) reads.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::path::{Path, PathBuf};

#[path = "../crates/kapaint-export/tests/common/inflate.rs"]
mod inflate;

use kapaint::export::blocks::{self, Coder};
use kapaint::export::codec::{Astc, AstcBlock, Effort};
use kapaint::export::preset::{self, ExportPreset};
use kapaint::export::set::{self, BlockLayout, ColourSpace, Compression, Manifest};
use kapaint::model::Document;
use kapaint::report::typical::typical_document;

#[path = "../crates/kapaint-export/tests/common/grey.rs"]
mod grey;
use grey::grey_project;

fn temp(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("kapaint-astc-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn project(side: u32) -> Document {
    let texture =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/testdata/spot/spot_texture.png");
    typical_document(side, texture.exists().then_some(texture.as_path()), 12).expect("project")
}

fn astc_preset(block: &str, max_effort: &str, extra: &str) -> ExportPreset {
    let text = format!(
        "(version: 2, name: \"astc-{block}\", format: Ktx2Astc(block: \"{block}\", \
         max_effort: {max_effort}), layout: Packed, n_bits: 8{extra})"
    );
    ExportPreset::parse(Path::new("astc.ron"), &text).expect("preset")
}

/// A level's texels by `texture2ddecoder`, as RGBA8.
fn decode(data: &[u8], (w, h): (u32, u32), block: AstcBlock) -> Vec<u8> {
    let (bw, bh) = block.dims();
    let mut image = vec![0_u32; w as usize * h as usize];
    texture2ddecoder::decode_astc(
        data,
        w as usize,
        h as usize,
        bw as usize,
        bh as usize,
        &mut image,
    )
    .expect("texture2ddecoder decodes the level");
    // Packed as little-endian BGRA.
    image
        .iter()
        .flat_map(|p| {
            let [b, g, r, a] = p.to_le_bytes();
            [r, g, b, a]
        })
        .collect()
}

/// Checks an ASTC KTX2 file against the specification; returns its levels decoded by
/// `texture2ddecoder`, finest first, RGBA8.
fn check_and_decode(path: &Path, block: AstcBlock, srgb: bool) -> Vec<Vec<u8>> {
    let bytes = std::fs::read(path).expect("read");
    let what = path.display();
    let reader = ktx2::Reader::new(&bytes[..]).expect("a KTX2 file");
    let header = reader.header();
    let format = header.format.expect("a vkFormat");
    // VK_FORMAT_ASTC_{w}x{h}_{UNORM,SRGB}_BLOCK.
    assert_eq!(format.value(), block.vk_format(srgb), "{what}: vkFormat");
    let (w, h) = (header.pixel_width, header.pixel_height);
    assert_eq!(header.type_size, 1, "{what}: typeSize");
    assert_eq!(header.level_count, 32 - w.max(h).leading_zeros(), "{what}");
    let (bw, bh) = block.dims();
    let mut levels = Vec::new();
    let scheme = header.supercompression_scheme;
    for (i, level) in reader.levels().enumerate() {
        let (lw, lh) = ((w >> i).max(1), (h >> i).max(1));
        let blocks = lw.div_ceil(bw) as usize * lh.div_ceil(bh) as usize;
        let data = inflate::level_bytes(scheme, level.data);
        assert_eq!(data.len(), blocks * 16, "{what}: level {i}");
        let at = 80 + i * 24;
        let entry = ktx2::LevelIndex::from_bytes(bytes[at..at + 24].try_into().expect("24"));
        // Aligned to a block, or to 1 when supercompressed.
        if scheme.is_none() {
            assert_eq!(entry.byte_offset % 16, 0, "{what}: level {i} alignment");
        }
        levels.push(decode(&data, (lw, lh), block));
    }
    let basic = reader.basic_dfd().expect("a basic descriptor block");
    assert_eq!(basic.color_model, Some(ktx2::ColorModel::ASTC), "{what}");
    assert_eq!(
        basic.transfer_function,
        Some(if srgb {
            ktx2::TransferFunction::SRGB
        } else {
            ktx2::TransferFunction::Linear
        }),
        "{what}: transferFunction"
    );
    let dims: Vec<u8> = basic
        .texel_block_dimensions
        .iter()
        .map(|d| d.get())
        .collect();
    assert_eq!(
        dims,
        [bw as u8, bh as u8, 1, 1],
        "{what}: texelBlockDimension"
    );
    assert_eq!(basic.bytes_planes[0], 16, "{what}: bytesPlane0");
    levels
}

/// Where component `k` of an image of `count` components sits in a decoded RGBA texel: in
/// order, but the second of two in alpha (luminance + alpha).
fn channel(count: usize, k: usize) -> usize {
    if count == 2 && k == 1 { 3 } else { k }
}

/// PSNR of two byte sequences.
fn psnr(a: &[u8], b: &[u8]) -> f64 {
    let mse = a
        .iter()
        .zip(b)
        .map(|(x, y)| (f64::from(*x) - f64::from(*y)).powi(2))
        .sum::<f64>()
        / a.len() as f64;
    10.0 * (255.0 * 255.0 / mse.max(1e-12)).log10()
}

/// Every component of every file of an ASTC set against the same project's `ktx2-raw` set,
/// level by level, decoded independently; and level 0 as kapaint's import decodes it.
fn compare_with_raw(doc: &Document, dir: &Path, m: &Manifest, block: AstcBlock, tag: &str) {
    // 8 bits per texel at 4x4 keeps every level within 36 dB of the project; 3.56 at 6x6
    // loses more on the small levels, where one block spans much of the texture's detail.
    let floor = if block == AstcBlock::DEFAULT {
        36.0
    } else {
        25.0
    };
    let raw_dir = temp(&format!("{tag}-raw"));
    let raw = set::export(doc, &preset::find("ktx2-raw").expect("raw"), &raw_dir).expect("raw");
    for file in &m.files {
        assert_eq!(file.compression, Compression::Ktx2Astc, "{}", file.path);
        assert_eq!(file.astc_block, Some(block), "{}", file.path);
        let srgb = file.colour_space == ColourSpace::Srgb;
        let levels = check_and_decode(&dir.join(&file.path), block, srgb);
        let ours =
            kapaint::export::ktx::decode(&std::fs::read(dir.join(&file.path)).expect("read"))
                .expect("kapaint decodes");
        // kapaint's decode (the export's measure and the import) and an independent decoder
        // agree to within a level.
        let worst = ours
            .rgba
            .iter()
            .zip(&levels[0])
            .map(|(a, b)| ((a * 255.0).round() - f32::from(*b)).abs())
            .fold(0.0_f32, f32::max);
        assert!(worst <= 1.0, "{}: decoders differ by {worst}", file.path);
        for (k, comp) in file.layout.iter().enumerate() {
            let (raw_file, at) = raw
                .files
                .iter()
                .find_map(|f| f.layout.iter().position(|c| c == comp).map(|i| (f, i)))
                .expect("the raw set holds every component");
            let raw_levels = check_raw(&raw_dir.join(&raw_file.path));
            for (i, (got, want)) in levels.iter().zip(&raw_levels).enumerate().take(4) {
                let c = channel(file.layout.len(), k);
                // Uncompressed files hold components in order.
                let rc = at;
                let a: Vec<u8> = got.chunks_exact(4).map(|t| t[c]).collect();
                let b: Vec<u8> = want.chunks_exact(4).map(|t| t[rc]).collect();
                let p = psnr(&a, &b);
                eprintln!("{tag} {}: {comp} level {i}: {p:.1} dB", file.path);
                assert!(
                    p > floor,
                    "{tag} {}: {comp} level {i}: {p:.1} dB",
                    file.path
                );
            }
        }
    }
    let _ = std::fs::remove_dir_all(&raw_dir);
}

/// An uncompressed KTX2 file's levels, RGBA8 (components in order).
fn check_raw(path: &Path) -> Vec<Vec<u8>> {
    let bytes = std::fs::read(path).expect("read");
    let reader = ktx2::Reader::new(&bytes[..]).expect("KTX2");
    let per = match reader.header().format {
        Some(ktx2::Format::R8_UNORM) => 1,
        Some(ktx2::Format::R8G8_UNORM) => 2,
        _ => 4,
    };
    let scheme = reader.header().supercompression_scheme;
    reader
        .levels()
        .map(|l| {
            inflate::level_bytes(scheme, l.data)
                .chunks_exact(per)
                .flat_map(|t| {
                    let mut px = [255_u8; 4];
                    px[..per].copy_from_slice(t);
                    px
                })
                .collect()
        })
        .collect()
}

#[test]
fn astc_sets_are_valid_ktx2_that_an_independent_decoder_reads_close_to_the_project() {
    let doc = project(128);
    let p = preset::find("ktx2-astc").expect("the built-in preset");
    assert_eq!(p.format.astc_block(), Some(AstcBlock::DEFAULT));
    let out = temp("4x4");
    let m = set::export(&doc, &p, &out).expect("export");
    let blocks = m.blocks.as_ref().expect("the search's record");
    assert_eq!(blocks.astc_block, Some(AstcBlock::DEFAULT));
    assert_eq!(blocks.encoder, kapaint::export::blocks::Encoder::Astcenc);
    let text = std::fs::read_to_string(out.join("material.json")).expect("manifest");
    assert!(text.contains("\"astc_block\": \"4x4\""), "{text}");
    assert!(text.contains("\"ktx2-astc\""), "{text}");
    compare_with_raw(&doc, &out, &m, AstcBlock::DEFAULT, "4x4");
    // The set imports (the blocks decoded as a consumer does).
    let back = set::import(&out.join("material.json")).expect("import");
    assert_eq!((back.maps().width(), back.maps().height()), (128, 128));
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn a_larger_footprint_is_a_preset_field_and_pads_partial_blocks() {
    // 6x6 on a 128^2 project: 22 blocks across, the last one two texels past the edge.
    let doc = project(128);
    let block = AstcBlock::parse("6x6").expect("6x6");
    let p = astc_preset("6x6", "Basic", "");
    assert_eq!(p.format.astc_block(), Some(block));
    let out = temp("6x6");
    let m = set::export(&doc, &p, &out).expect("export");
    assert_eq!(m.blocks.as_ref().and_then(|b| b.astc_block), Some(block));
    compare_with_raw(&doc, &out, &m, block, "6x6");
    // Fewer bytes than 4x4: 16 bytes per 36 texels against per 16.
    let kd = m.files.iter().find(|f| f.layout[0] == "kd.r").expect("kd");
    assert!(kd.bytes < 128 * 128 * 16 / 36 * 2, "{}", kd.bytes);
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn footprints_astc_does_not_define_are_refused_by_the_preset_loader() {
    for bad in ["7x7", "4x5", "16x16", "4x4x4", "big"] {
        let text = format!(
            "(version: 2, name: \"a\", format: Ktx2Astc(block: \"{bad}\"), layout: Packed, n_bits: 8)"
        );
        let err = ExportPreset::parse(Path::new("bad.ron"), &text)
            .expect_err(bad)
            .to_string();
        assert!(
            err.starts_with("bad.ron: ") && err.contains("12x12"),
            "{bad}: {err}"
        );
    }
    // A footprint belongs to ASTC presets only.
    let text =
        "(version: 2, name: \"a\", format: Ktx2Bc(block: \"4x4\"), layout: Packed, n_bits: 8)";
    assert!(ExportPreset::parse(Path::new("x.ron"), text).is_err());
    for good in AstcBlock::ALL {
        let p = astc_preset(&good.name(), "Basic", "");
        assert_eq!(p.format.astc_block(), Some(good));
    }
}

#[test]
fn two_components_are_luminance_and_alpha() {
    // A grey k_s beside n, as the n-apart layout stores them: one in RGB, the other in alpha.
    let (w, h) = (64_u32, 32_u32);
    let src: Vec<u8> = (0..w * h)
        .flat_map(|i| {
            let (x, y) = (i % w, i / w);
            [(x * 4) as u8, (255 - y * 6) as u8]
        })
        .collect();
    let astc = Astc::new(AstcBlock::DEFAULT, 2, false);
    let encoded = blocks::encode_stored(
        Coder::best_cpu(),
        &astc,
        Effort::Fast,
        &src,
        2,
        (w, h),
        None,
    )
    .expect("blocks");
    let theirs = decode(&encoded, (w, h), AstcBlock::DEFAULT);
    let ours = blocks::decode_stored(&astc, &encoded, (w, h), 2).expect("decoded");
    for (i, (t, s)) in theirs.chunks_exact(4).zip(src.chunks_exact(2)).enumerate() {
        assert!(t[0] == t[1] && t[1] == t[2], "texel {i}: luminance {t:?}");
        assert!(
            t[0].abs_diff(s[0]) <= 2 && t[3].abs_diff(s[1]) <= 2,
            "texel {i}: {t:?} {s:?}"
        );
        // The two decoders round unorm8 differently by at most one level.
        let mine = &ours[2 * i..2 * i + 2];
        assert!(
            mine[0].abs_diff(t[0]) <= 1 && mine[1].abs_diff(t[3]) <= 1,
            "texel {i}: {mine:?} against {t:?}"
        );
    }
}

#[test]
fn the_search_tries_both_layouts_then_more_effort_against_the_perceptual_budget() {
    // A budget no encoding meets: every layout is tried, then more effort while it pays.
    let doc = project(64);
    let p = astc_preset(
        "4x4",
        "Fast",
        ", ka_error_srgb_p999: 0.0, ka_error_srgb_mean: 0.0",
    );
    let out = temp("search");
    let m = set::export(&doc, &p, &out).expect("export");
    let b = m.blocks.as_ref().expect("blocks");
    let tried: Vec<(BlockLayout, Effort)> =
        b.trials.iter().map(|t| (t.layout, t.bc7_effort)).collect();
    // The project's k_s is grey: packed (kd_n + ks) and n apart (kd + ks_n) are two images of
    // 16-byte blocks each, the same bytes, and n apart goes first.
    assert_eq!(m.files.len(), 2, "{:?}", m.files);
    assert!(m.files.iter().any(|f| f.layout.contains(&"ks".to_string())));
    assert_eq!(
        tried[0],
        (BlockLayout::NApart, Effort::UltraFast),
        "{tried:?}"
    );
    assert_eq!(
        tried[1],
        (BlockLayout::Packed, Effort::UltraFast),
        "{tried:?}"
    );
    assert!(
        !b.within_budget && b.reason.contains("no trial"),
        "{}",
        b.reason
    );
    assert!(
        tried.iter().all(|(l, _)| *l != BlockLayout::HalfColour),
        "ASTC has no BC6H: {tried:?}"
    );
    // What was kept is on disk, and imports.
    set::import(&out.join("material.json")).expect("import");
    let _ = std::fs::remove_dir_all(&out);
}

/// Whether a set's files are the packed layout's: `n` beside `k_d` in one image.
fn packed_files(m: &Manifest) -> bool {
    m.files
        .iter()
        .any(|f| f.layout.first().is_some_and(|c| c == "kd.r") && f.layout.contains(&"n".into()))
}

#[test]
fn the_files_written_are_the_kept_trials_when_the_search_ends_on_another() {
    // A ceiling of the cheapest effort and a budget nothing meets: both layouts are tried at
    // it, and the nearest is kept. Where that is not the last one tried, its level 0 must be
    // encoded again: the files once held the last trial's layout under the kept one's name.
    let doc = project(64);
    for (preset, tag) in [
        (
            astc_preset(
                "4x4",
                "UltraFast",
                ", ka_error_srgb_p999: 0.0, ka_error_srgb_mean: 0.0",
            ),
            "kept-astc",
        ),
        (
            ExportPreset::parse(
                Path::new("bc.ron"),
                "(version: 2, name: \"bc\", format: Ktx2Bc(max_effort: UltraFast, bc6h: false), \
                 layout: Packed, n_bits: 8, ka_error_srgb_p999: 0.0, ka_error_srgb_mean: 0.0)",
            )
            .expect("preset"),
            "kept-bc",
        ),
    ] {
        let out = temp(tag);
        let m = set::export(&doc, &preset, &out).expect("export");
        let b = m.blocks.as_ref().expect("blocks");
        assert_eq!(b.trials.len(), 2, "{tag}: {:?}", b.trials);
        assert_eq!(
            packed_files(&m),
            b.layout == BlockLayout::Packed,
            "{tag}: kept {:?}, files {:?}",
            b.layout,
            m.files.iter().map(|f| &f.layout).collect::<Vec<_>>()
        );
        let _ = std::fs::remove_dir_all(&out);
    }
}

#[test]
fn a_budget_that_8_bit_storage_misses_is_said_and_costs_no_more_effort() {
    // A mid-grey k_d (0.5 linear) is 187.5 in 8-bit sRGB: stored in 8 bits it is half a level
    // off everywhere, and k_a with it, so no 8-bit file meets a mean of 0.3 levels, however
    // its blocks are encoded. The search says so and stops after the layouts.
    let doc = grey_project(256);
    let p = preset::find("ktx2-astc").expect("preset");
    let out = temp("floor");
    let m = set::export(&doc, &p, &out).expect("export");
    let b = m.blocks.as_ref().expect("blocks");
    let floor = b
        .uncompressed_ka_error_srgb
        .expect("measured once a trial missed");
    assert!(floor.mean > 0.3, "{floor:?}");
    assert!(!b.within_budget);
    assert_eq!(
        b.trials.len(),
        2,
        "both layouts, no more effort: {:?}",
        b.trials
    );
    assert!(b.reason.contains("uncompressed"), "{}", b.reason);
    assert!(
        b.summary().contains("8-bit storage alone misses it"),
        "{}",
        b.summary()
    );
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn an_astc_file_of_garbage_blocks_reads_without_a_crash() {
    // A hostile or corrupt file: the header and index of a real set, level 0's blocks
    // replaced by noise (reserved modes, void extents out of range, illegal weight counts),
    // for the smallest and the largest footprints. ASTC decodes every 128-bit pattern: the
    // import reads colours (an illegal block is the error colour), never crashes; and a file
    // cut short is an error.
    let doc = project(64);
    for block in ["4x4", "12x12"] {
        let out = temp(&format!("garbage-{block}"));
        let m = set::export(&doc, &astc_preset(block, "Basic", ""), &out).expect("export");
        let path = out.join(&m.files[0].path);
        let mut bytes = std::fs::read(&path).expect("read");
        let reader = ktx2::Reader::new(&bytes[..]).expect("KTX2");
        let level0 = bytes.len() - reader.levels().next().expect("level 0").data.len();
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        for b in &mut bytes[level0..] {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            *b = state as u8;
        }
        let decoded = kapaint::export::ktx::decode(&bytes).expect("garbage blocks decode");
        assert_eq!((decoded.width, decoded.height), (64, 64));
        assert!(
            decoded
                .rgba
                .iter()
                .all(|v| v.is_finite() && (0.0..=1.0).contains(v))
        );
        bytes.truncate(bytes.len() - 7);
        assert!(
            kapaint::export::ktx::decode(&bytes).is_err(),
            "{block}: cut short"
        );
        let _ = std::fs::remove_dir_all(&out);
    }
}

#[test]
fn the_cli_report_names_the_footprint() {
    let dir = temp("cli");
    std::fs::create_dir_all(&dir).expect("dir");
    let project = dir.join("p.kapaint");
    let run = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_kapaint"))
            .args(args)
            .output()
            .expect("kapaint runs")
    };
    let s = |p: &Path| p.to_str().expect("UTF-8 path").to_owned();
    let o = run(&["new", "--size", "64", "--out", &s(&project)]);
    assert!(o.status.success(), "{o:?}");
    // A k_d that varies, so the set holds block-compressed images.
    let image = dir.join("kd.png");
    image::RgbImage::from_fn(64, 64, |x, y| {
        image::Rgb([(x * 4) as u8, (y * 4) as u8, 90])
    })
    .save(&image)
    .expect("png");
    let o = run(&[
        "import",
        &s(&project),
        "--channel",
        "kd",
        "--image",
        &s(&image),
    ]);
    assert!(o.status.success(), "{o:?}");
    let out = dir.join("set");
    let o = run(&[
        "export",
        &s(&project),
        "--preset",
        "ktx2-astc",
        "--out",
        &s(&out),
        "--report",
    ]);
    assert!(o.status.success(), "{o:?}");
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("  blocks: ASTC 4x4, "), "{text}");
    let _ = std::fs::remove_dir_all(&dir);
}
