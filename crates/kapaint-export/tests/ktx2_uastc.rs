//! The `ktx2-uastc` preset: Basis Universal's UASTC blocks in KTX2 (vkFormat UNDEFINED, the
//! data format descriptor UASTC), supercompressed by Zstandard, the level and RDO chosen
//! against the k_a budget as measured after transcoding; read back by kapaint and by
//! independent decoders (texture2ddecoder for the ASTC transcode, bcdec for the BC7 one).

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use kapaint_export::codec::{Codec, Uastc};
use kapaint_export::file_kind::Compression;
use kapaint_export::preset;
use kapaint_export::set;

#[path = "common/inflate.rs"]
mod inflate;
#[path = "common/stroke_edge.rs"]
#[expect(dead_code, reason = "each test file uses some of the helpers")]
mod stroke_edge;
use stroke_edge::{export, project};

#[test]
fn a_uastc_set_is_described_as_uastc_supercompressed_and_reads_back() {
    let doc = project(128);
    let shipped = preset::find("ktx2-uastc").expect("preset");
    assert_eq!(shipped.zstd, Some(18));
    let (dir, m) = export(&doc, &shipped, "uastc");
    assert!(!m.files.is_empty());
    for f in &m.files {
        assert_eq!(f.compression, Compression::Ktx2Uastc, "{}", f.path);
        let bytes = std::fs::read(dir.join(&f.path)).expect("file");
        let reader = ktx2::Reader::new(&bytes[..]).expect("a KTX2 file");
        let header = reader.header();
        assert_eq!(header.format, None, "vkFormat UNDEFINED");
        assert_eq!(reader.color_model(), Some(ktx2::ColorModel::UASTC));
        assert_eq!(
            header.supercompression_scheme,
            Some(ktx2::SupercompressionScheme::Zstandard)
        );
        let basic = reader.basic_dfd().expect("a basic descriptor");
        assert_eq!(basic.bytes_planes[0], 16);
        assert_eq!(basic.sample_information.len(), 1);
        assert_eq!(basic.sample_information[0].bit_length.get(), 128);
        // Every level holds whole UASTC blocks of its size.
        for (i, level) in reader.levels().enumerate() {
            let (w, h) = (
                (header.pixel_width >> i).max(1),
                (header.pixel_height >> i).max(1),
            );
            let raw = inflate::level_bytes(header.supercompression_scheme, level.data);
            assert_eq!(raw.len(), (w.div_ceil(4) * h.div_ceil(4) * 16) as usize);
        }
        // The budget measured the BC7 transcode: what the manifest says, within PSNR.
        let psnr = f.psnr.as_ref().expect("PSNR measured");
        assert!(
            psnr.iter().all(|p| p.is_none_or(|p| p > 35.0)),
            "{}: {psnr:?}",
            f.path
        );
    }
    // kapaint reads the set back (UASTC's own texels, through the ASTC transcode).
    let back = set::import(&dir.join("material.json")).expect("import");
    assert_eq!(back.maps().width(), 128);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The blocks of a gradient and the two transcodes' texels, as independent decoders read
/// them, against the texels encoded.
#[test]
fn the_bc7_transcode_is_the_worse_target_and_astc_is_uastc_exactly() {
    let (w, h) = (64_u32, 32_u32);
    let rgba: Vec<u8> = (0..w * h)
        .flat_map(|i| {
            let (x, y) = (i % w, i / w);
            [(x * 4) as u8, (y * 8) as u8, ((x * y) % 256) as u8, 255]
        })
        .collect();
    let uastc = Uastc::new(3, true);
    let mut blocks = vec![0_u8; uastc.blocks_len((w, h))];
    uastc
        .encode_strip(
            kapaint_export::codec::Cpu::Portable,
            kapaint_export::codec::Effort::Slow,
            &rgba,
            (w, h),
            &mut blocks,
        )
        .expect("encode");
    // kapaint's decode (the BC7 transcode) against bcdec's of the same BC7 blocks.
    let mut ours = vec![0_u8; rgba.len()];
    uastc
        .decode_strip(&blocks, (w, h), &mut ours)
        .expect("decode");
    let bc7 =
        kapaint_basis::transcode_uastc(&blocks, (w, h), kapaint_basis::Target::Bc7).expect("BC7");
    let mut theirs = vec![0_u8; rgba.len()];
    for (i, block) in bc7.chunks_exact(16).enumerate() {
        let (bx, by) = (i as u32 % (w / 4), i as u32 / (w / 4));
        let at = ((by * 4 * w + bx * 4) * 4) as usize;
        bcdec_rs::bc7(block, &mut theirs[at..], (w * 4) as usize);
    }
    assert!(ours == theirs, "kapaint decodes BC7 as bcdec does");
    // The ASTC transcode through texture2ddecoder is UASTC's lossless decode.
    let astc = kapaint_basis::transcode_uastc(&blocks, (w, h), kapaint_basis::Target::Astc4x4)
        .expect("ASTC");
    let mut words = vec![0_u32; (w * h) as usize];
    texture2ddecoder::decode_astc(&astc, w as usize, h as usize, 4, 4, &mut words)
        .expect("decode ASTC");
    let lossless: Vec<u8> = words
        .iter()
        .flat_map(|p| {
            let [b, g, r, a] = p.to_le_bytes();
            [r, g, b, a]
        })
        .collect();
    let mut kapaints = vec![0_u8; rgba.len()];
    uastc
        .decode_lossless(&blocks, (w, h), &mut kapaints)
        .expect("lossless decode");
    let sq = |a: &[u8]| -> u64 {
        a.iter()
            .zip(&rgba)
            .map(|(x, y)| u64::from(x.abs_diff(*y)).pow(2))
            .sum()
    };
    assert!(
        kapaints
            .iter()
            .zip(&lossless)
            .all(|(a, b)| a.abs_diff(*b) <= 1),
        "kapaint's ASTC decode is texture2ddecoder's"
    );
    assert!(
        sq(&ours) >= sq(&lossless),
        "BC7 {} vs ASTC {}",
        sq(&ours),
        sq(&lossless)
    );
}
