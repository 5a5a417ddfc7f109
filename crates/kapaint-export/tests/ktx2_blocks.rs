//! Block-compressed export (issue 21), checked independently of kapaint's own code: every
//! KTX2 file the tests write is parsed with the `ktx2` crate's reader and held to the KTX2
//! specification's rules for its header, level index and data format descriptor, and every
//! mip level is decoded with `bcdec_rs` (not `block_compression`) and compared with the same
//! project's uncompressed levels. The effort search is checked in `ktx2_budget.rs`.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::collections::HashMap;
use std::path::Path;

use kapaint_export::codec::Effort;
use kapaint_export::preset::{self, ExportPreset, Format};
use kapaint_export::set::Manifest;
use kapaint_model::Document;

#[path = "common/grey.rs"]
mod grey;
#[path = "common/inflate.rs"]
mod inflate;
use grey::grey_project;

#[path = "common/stroke_edge.rs"]
mod stroke_edge;
use stroke_edge::{export, project, relative_budget, with_budget};

/// Bytes per block (or per texel, uncompressed), and the texel block's side.
fn block_of(format: ktx2::Format) -> (usize, u32) {
    match format {
        ktx2::Format::BC4_UNORM_BLOCK => (8, 4),
        ktx2::Format::BC5_UNORM_BLOCK
        | ktx2::Format::BC7_UNORM_BLOCK
        | ktx2::Format::BC7_SRGB_BLOCK
        | ktx2::Format::BC6H_UFLOAT_BLOCK => (16, 4),
        ktx2::Format::R8_UNORM => (1, 1),
        ktx2::Format::R8G8_UNORM => (2, 1),
        ktx2::Format::R8G8B8A8_UNORM | ktx2::Format::R8G8B8A8_SRGB => (4, 1),
        other => panic!("kapaint does not write {other:?}"),
    }
}

/// Checks a KTX2 file against the specification's rules; returns its levels as decoded by
/// `bcdec_rs` (or read as they are), finest first, four bytes per texel.
fn check_and_decode(path: &Path) -> Vec<Vec<u8>> {
    let bytes = std::fs::read(path).expect("read");
    let what = path.display();
    let reader = ktx2::Reader::new(&bytes[..]).expect("a KTX2 file");
    let header = reader.header();
    let format = header.format.expect("a vkFormat");
    let (block_bytes, block_side) = block_of(format);
    // Header (spec 3.1-3.10): a 2D texture, one face, no layers, a full mip chain.
    let (w, h) = (header.pixel_width, header.pixel_height);
    assert!(w > 0 && h > 0, "{what}");
    assert_eq!(header.pixel_depth, 0, "{what}: pixelDepth");
    assert_eq!(header.layer_count, 0, "{what}: layerCount");
    assert_eq!(header.face_count, 1, "{what}: faceCount");
    assert_eq!(
        header.level_count,
        32 - w.max(h).leading_zeros(),
        "{what}: a full chain"
    );
    // Plain, or each level supercompressed on its own by Zstandard (scheme 2).
    let zstd = header.supercompression_scheme == Some(ktx2::SupercompressionScheme::Zstandard);
    assert!(zstd || header.supercompression_scheme.is_none(), "{what}");
    // typeSize: 1 for block-compressed formats and 8-bit components.
    assert_eq!(header.type_size, 1, "{what}: typeSize");
    // Level index (spec 3.9.7): uncompressedByteLength the level's blocks, byteLength equal
    // without supercompression, offsets aligned to lcm(texel block size, 4) (to 1 when
    // supercompressed), levels stored smallest first without overlap, inside the file.
    let align = if zstd { 1 } else { block_bytes.max(4) };
    let mut end_of_previous = None;
    let index_at = 80;
    let mut levels = Vec::new();
    for (i, level) in reader.levels().enumerate() {
        let at = index_at + i * 24;
        let entry = ktx2::LevelIndex::from_bytes(bytes[at..at + 24].try_into().expect("24 bytes"));
        let (lw, lh) = ((w >> i).max(1), (h >> i).max(1));
        let blocks = lw.div_ceil(block_side) as usize * lh.div_ceil(block_side) as usize;
        assert_eq!(
            entry.uncompressed_byte_length as usize,
            blocks * block_bytes,
            "{what}: level {i}"
        );
        assert!(zstd || entry.uncompressed_byte_length == entry.byte_length);
        assert_eq!(
            entry.byte_offset as usize % align,
            0,
            "{what}: level {i} alignment"
        );
        assert!(
            (entry.byte_offset + entry.byte_length) as usize <= bytes.len(),
            "{what}: level {i} past the end"
        );
        if let Some(next_start) = end_of_previous {
            // Levels are stored coarsest first: level i ends at or before level i - 1.
            assert!(
                entry.byte_offset + entry.byte_length <= next_start,
                "{what}: level {i}"
            );
        }
        end_of_previous = Some(entry.byte_offset);
        assert_eq!(level.data.len(), entry.byte_length as usize);
        let data = inflate::level_bytes(header.supercompression_scheme, level.data);
        assert_eq!(
            data.len(),
            blocks * block_bytes,
            "{what}: level {i} inflated"
        );
        levels.push(decode_level(format, &data, (lw, lh)));
    }
    // Data format descriptor (spec 3.10, Khronos Data Format 1.3 section 5): one basic block,
    // its total size first, the colour model of the format, sRGB transfer exactly for the
    // _SRGB formats, 4x4 texel blocks for BC formats (stored as dimension - 1), and the bytes
    // of one block or texel in plane 0.
    let dfd_at = header.index.dfd_byte_offset as usize;
    let total = u32::from_le_bytes(bytes[dfd_at..dfd_at + 4].try_into().expect("4 bytes"));
    assert_eq!(total, header.index.dfd_byte_length, "{what}: dfdTotalSize");
    let blocks = reader.dfd_blocks();
    assert_eq!(blocks.len(), 1, "{what}: one descriptor block");
    let basic = reader.basic_dfd().expect("a basic descriptor block");
    let (model, samples) = model_of(format);
    assert_eq!(basic.color_model, Some(model), "{what}: colorModel");
    let srgb = matches!(
        format,
        ktx2::Format::BC7_SRGB_BLOCK | ktx2::Format::R8G8B8A8_SRGB
    );
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
        [block_side as u8, block_side as u8, 1, 1],
        "{what}: texelBlockDimension"
    );
    assert_eq!(
        basic.bytes_planes[0] as usize, block_bytes,
        "{what}: bytesPlane0"
    );
    assert!(basic.bytes_planes[1..].iter().all(|b| *b == 0), "{what}");
    assert_eq!(basic.sample_information.len(), samples, "{what}: samples");
    levels
}

/// The DFD colour model of `format`, and its sample count.
fn model_of(format: ktx2::Format) -> (ktx2::ColorModel, usize) {
    match format {
        ktx2::Format::BC4_UNORM_BLOCK => (ktx2::ColorModel::BC4, 1),
        ktx2::Format::BC5_UNORM_BLOCK => (ktx2::ColorModel::BC5, 2),
        ktx2::Format::BC7_UNORM_BLOCK | ktx2::Format::BC7_SRGB_BLOCK => (ktx2::ColorModel::BC7, 1),
        ktx2::Format::BC6H_UFLOAT_BLOCK => (ktx2::ColorModel::BC6H, 1),
        ktx2::Format::R8_UNORM => (ktx2::ColorModel::RGBSDA, 1),
        ktx2::Format::R8G8_UNORM => (ktx2::ColorModel::RGBSDA, 2),
        _ => (ktx2::ColorModel::RGBSDA, 4),
    }
}

/// One level as RGBA8, by `bcdec_rs` for blocks (BC6H's linear half floats sRGB-encoded, to
/// compare with 8-bit sRGB colour).
fn decode_level(format: ktx2::Format, data: &[u8], (w, h): (u32, u32)) -> Vec<u8> {
    let (w, h) = (w as usize, h as usize);
    let mut out = vec![255_u8; w * h * 4];
    let per = match format {
        ktx2::Format::R8_UNORM => Some(1),
        ktx2::Format::R8G8_UNORM => Some(2),
        ktx2::Format::R8G8B8A8_UNORM | ktx2::Format::R8G8B8A8_SRGB => Some(4),
        _ => None,
    };
    if let Some(per) = per {
        for (px, src) in out.chunks_exact_mut(4).zip(data.chunks_exact(per)) {
            px[..per].copy_from_slice(src);
        }
        return out;
    }
    let (bw, bh) = (w.div_ceil(4), h.div_ceil(4));
    let (block_bytes, _) = block_of(format);
    for by in 0..bh {
        for bx in 0..bw {
            let block = &data[(by * bw + bx) * block_bytes..][..block_bytes];
            let mut texels = [255_u8; 64];
            match format {
                ktx2::Format::BC4_UNORM_BLOCK => {
                    let mut r = [0_u8; 16];
                    bcdec_rs::bc4(block, &mut r, 4, false);
                    for (t, v) in r.iter().enumerate() {
                        texels[t * 4] = *v;
                    }
                }
                ktx2::Format::BC5_UNORM_BLOCK => {
                    let mut rg = [0_u8; 32];
                    bcdec_rs::bc5(block, &mut rg, 8, false);
                    for t in 0..16 {
                        texels[t * 4] = rg[t * 2];
                        texels[t * 4 + 1] = rg[t * 2 + 1];
                    }
                }
                ktx2::Format::BC6H_UFLOAT_BLOCK => {
                    let mut rgb = [0_u16; 48];
                    bcdec_rs::bc6h_half(block, &mut rgb, 12, false);
                    for t in 0..16 {
                        for c in 0..3 {
                            let v = half::f16::from_bits(rgb[t * 3 + c]).to_f32();
                            texels[t * 4 + c] = kapaint_model::texel::linear_to_srgb8(v);
                        }
                    }
                }
                _ => bcdec_rs::bc7(block, &mut texels, 16),
            }
            for y in 0..4 {
                for x in 0..4 {
                    let (tx, ty) = (bx * 4 + x, by * 4 + y);
                    if tx < w && ty < h {
                        out[(ty * w + tx) * 4..][..4]
                            .copy_from_slice(&texels[(y * 4 + x) * 4..][..4]);
                    }
                }
            }
        }
    }
    out
}

/// Per component name, every level's bytes of a set, and the file holding it.
fn components(dir: &Path, manifest: &Manifest) -> HashMap<String, (String, Vec<Vec<u8>>)> {
    let mut out = HashMap::new();
    for file in &manifest.files {
        let levels = check_and_decode(&dir.join(&file.path));
        for (k, name) in file.layout.iter().enumerate() {
            let per_level = levels
                .iter()
                .map(|rgba| rgba.chunks_exact(4).map(|p| p[k]).collect())
                .collect();
            out.insert(name.clone(), (file.path.clone(), per_level));
        }
    }
    out
}

fn psnr(a: &[u8], b: &[u8]) -> f64 {
    let mse = a
        .iter()
        .zip(b)
        .map(|(x, y)| (f64::from(*x) - f64::from(*y)).powi(2))
        .sum::<f64>()
        / a.len().max(1) as f64;
    if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (255.0_f64 * 255.0 / mse).log10()
    }
}

#[test]
fn every_level_of_every_file_decodes_independently_close_to_the_uncompressed_levels() {
    let raw_preset = preset::find("ktx2-raw").expect("preset");
    // The stroke-edge project at a budget the cheapest trial meets (BC7 k_d with n in its
    // alpha); the grey project at the shipped budget, whose mean only BC6H k_d meets. (This
    // once asked for a maximum nothing meets, at a ceiling that ended the search on the BC6H
    // trial; the files were that trial's while the manifest named the nearest, packed BC7:
    // `tests/ktx2_astc.rs` checks the files are the kept trial's.)
    let loose = with_budget(relative_budget(10.0, 1.0, 20.0), Effort::UltraFast);
    let mut shipped = preset::find("ktx2").expect("preset");
    shipped.format = Format::Ktx2Bc {
        max_effort: Effort::UltraFast,
        bc6h: true,
    };
    let mut half_files = Vec::new();
    for (doc, bc_preset, tag) in [
        (project(256), loose, "bc"),
        (grey_project(256), shipped, "bc6h"),
    ] {
        let (raw_dir, raw) = export(&doc, &raw_preset, &format!("raw-{tag}"));
        half_files.push(compare_with_raw(&doc, &raw_dir, &raw, &bc_preset, tag));
        let _ = std::fs::remove_dir_all(raw_dir);
    }
    assert_eq!(half_files, [0, 1], "k_d as BC6H once");
}

/// Exports `doc` with `bc_preset`, checks every file and level against the `ktx2-raw` set
/// `raw` in `raw_dir`; the number of BC6H files.
fn compare_with_raw(
    doc: &Document,
    raw_dir: &Path,
    raw: &Manifest,
    bc_preset: &ExportPreset,
    tag: &str,
) -> usize {
    let (bc_dir, bc) = export(doc, bc_preset, tag);
    let reference = components(raw_dir, raw);
    let compressed = components(&bc_dir, &bc);
    assert_eq!(bc.level_ka_error.len(), 9, "a k_a error per level");
    assert_eq!(raw.level_ka_error.len(), 9);
    for (name, (file, levels)) in &compressed {
        let (_, want) = &reference[name];
        assert_eq!(levels.len(), want.len(), "{name}");
        for (l, (got, want)) in levels.iter().zip(want).enumerate() {
            // A wrong format, layout or level order decodes far below this (under 20 dB);
            // BC7's fastest effort on the finer levels of this texture, over 40 dB.
            let p = psnr(want, got);
            assert!(p >= 30.0, "{file} {name} level {l}: {p:.1} dB");
            if l == 0 {
                assert!(p >= 40.0, "{file} {name} level 0: {p:.1} dB");
            }
        }
    }
    // Level 0 as bcdec decodes it is what the manifest's PSNR measured (within the rounding
    // by which decoders may differ: BC4/BC5 interpolate at 8 bits or more). BC6H's PSNR is
    // of half floats against half floats; here both sides are rounded to 8-bit sRGB, which
    // adds error: bcdec's may only be lower, and still over 45 dB.
    let mut half_files = 0;
    for file in &bc.files {
        let bc6h = file.compression == kapaint_export::set::Compression::Ktx2Bc6h;
        half_files += usize::from(bc6h);
        let psnr_listed = file
            .psnr
            .as_ref()
            .expect("compressed files list their PSNR");
        for (k, name) in file.layout.iter().enumerate() {
            let (_, levels) = &compressed[name];
            let p = psnr(&reference[name].1[0], &levels[0]);
            match psnr_listed[k] {
                Some(listed) if bc6h => {
                    assert!(p < listed + 0.5 && p > 45.0, "{name}: {p} vs {listed}");
                }
                // Above 55 dB (an RMS error under half a level) decoders' rounding moves
                // the PSNR by more than that (the grey project's near-flat k_s: 64.1 dB
                // against 63.1).
                Some(listed) => assert!(
                    (p - listed).abs() < 0.5 || p.min(listed) > 55.0,
                    "{name}: {p} vs {listed}"
                ),
                None => {}
            }
        }
    }
    let _ = std::fs::remove_dir_all(bc_dir);
    half_files
}

/// A block of one colour decodes to that colour exactly (decoded by `bcdec_rs`), from every
/// CPU encoder at every effort, opaque or with alpha. ISPC's BC7 missed the typical project's
/// background `(255, 238, 230)` by a level in red at every effort (mode 6's p-bits), about
/// three quarters of a level on average over that project.
#[test]
fn blocks_of_one_colour_decode_exactly() {
    use kapaint_export::blocks::{Coder, encode};
    use kapaint_export::codec::Bc7;
    let colours: [[u8; 4]; 8] = [
        [255, 238, 230, 255],
        [255, 198, 167, 255],
        [64, 64, 64, 255],
        [0, 1, 2, 255],
        [128, 127, 129, 200],
        [7, 200, 99, 0],
        [254, 255, 253, 17],
        [31, 32, 33, 128],
    ];
    let (w, h) = (16_u32, 8_u32);
    // Block i (of 4 across, 2 down) holds colour i.
    let texels: Vec<u8> = (0..w * h)
        .flat_map(|t| colours[((t / w / 4) * 4 + (t % w) / 4) as usize])
        .collect();
    for coder in [Coder::best_cpu(), Coder::Portable] {
        for effort in Effort::ALL {
            for alpha in [false, true] {
                let bc7 = Bc7::new(alpha, false);
                let blocks = encode(coder, &bc7, effort, &texels, (w, h), None).expect("blocks");
                for (i, block) in blocks.chunks_exact(16).enumerate() {
                    let mut decoded = [0_u8; 64];
                    bcdec_rs::bc7(block, &mut decoded, 16);
                    let want = colours[i];
                    let keep = if alpha { 4 } else { 3 };
                    for texel in decoded.chunks_exact(4) {
                        assert_eq!(
                            texel[..keep],
                            want[..keep],
                            "{coder:?} {bc7:?} {effort:?}, block {i}"
                        );
                    }
                }
            }
        }
    }
}
