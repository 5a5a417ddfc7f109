//! The `ktx2-etc1s` preset: Basis Universal's ETC1S blocks in KTX2 with BasisLZ (vkFormat
//! UNDEFINED, supercompression scheme 1, the codebooks in the global data), each image encoded
//! whole with kapaint's own mips, the quality chosen against the k_a budget as measured after
//! transcoding to BC7; read back by kapaint (the `basisu` tool reads the same files in
//! `tests/peers.rs`).

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use kapaint_export::codec::Effort;
use kapaint_export::codec::etc1s::Etc1sCodec;
use kapaint_export::file_kind::Compression;
use kapaint_export::preset::{self, Format};
use kapaint_export::set;

#[path = "common/stroke_edge.rs"]
#[expect(dead_code, reason = "each test file uses some of the helpers")]
mod stroke_edge;
use stroke_edge::{export, project};

#[test]
fn an_etc1s_set_is_basislz_with_every_level_and_reads_back() {
    let doc = project(128);
    let shipped = preset::find("ktx2-etc1s").expect("preset");
    assert_eq!(
        shipped.format,
        Format::Ktx2Etc1s {
            max_effort: Effort::Slow
        }
    );
    let (dir, m) = export(&doc, &shipped, "etc1s");
    assert!(!m.files.is_empty());
    for f in &m.files {
        assert_eq!(f.compression, Compression::Ktx2Etc1s, "{}", f.path);
        // BasisLZ is the file's supercompression: zstd (the preset's, for the normal map)
        // is not stacked on it.
        assert!(f.supercompression.is_none(), "{}", f.path);
        let bytes = std::fs::read(dir.join(&f.path)).expect("file");
        let reader = ktx2::Reader::new(&bytes[..]).expect("a KTX2 file");
        let header = reader.header();
        assert_eq!(header.format, None, "vkFormat UNDEFINED");
        assert_eq!(reader.color_model(), Some(ktx2::ColorModel::ETC1S));
        assert_eq!(
            header.supercompression_scheme,
            Some(ktx2::SupercompressionScheme::BasisLZ)
        );
        // The full chain, 128 down to 1.
        assert_eq!(header.level_count, 8, "{}", f.path);
        assert_eq!(f.mip_levels, Some(8));
        let psnr = f.psnr.as_ref().expect("PSNR measured");
        assert!(
            psnr.iter().all(|p| p.is_none_or(|p| p > 25.0)),
            "{}: {psnr:?}",
            f.path
        );
    }
    // The search ran on ETC1S and says so; every level was measured.
    let blocks = m.blocks.as_ref().expect("a block choice");
    assert_eq!(blocks.basis, Some(Compression::Ktx2Etc1s));
    assert!(
        blocks.summary().starts_with("ETC1S, n "),
        "{}",
        blocks.summary()
    );
    assert_eq!(m.level_ka_error_srgb.len(), 8);
    // Effort steps are qualities ETC1S tells apart: none is skipped as the same blocks.
    let efforts: Vec<Effort> = blocks
        .trials
        .iter()
        .filter(|t| t.layout == blocks.layout)
        .map(|t| t.bc7_effort)
        .collect();
    assert!(
        efforts.windows(2).all(|w| w[1] as u8 == w[0] as u8 + 1),
        "{efforts:?}"
    );
    // kapaint reads the set back through the BC7 transcode: k_d near what was exported.
    let back = set::import(&dir.join("material.json")).expect("import");
    assert_eq!(back.maps().width(), 128);
    let (mut sum, mut count) = (0.0_f64, 0_u32);
    for y in 0..128 {
        for x in 0..128 {
            let a = doc.maps().texel(x, y).decode().kd;
            let b = back.maps().texel(x, y).decode().kd;
            sum += f64::from((a - b).abs().max_element());
            count += 1;
        }
    }
    let mean = sum / f64::from(count);
    assert!(mean < 0.03, "mean |Δk_d| {mean}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// ETC1S is the smallest Basis format: the same project's set in fewer bytes than UASTC's
/// (with its RDO and zstd).
#[test]
fn an_etc1s_set_is_smaller_than_the_uastc_set() {
    let doc = project(128);
    let etc1s = preset::find("ktx2-etc1s").expect("preset");
    let uastc = preset::find("ktx2-uastc").expect("preset");
    let bytes = |m: &set::Manifest| m.files.iter().map(|f| f.bytes).sum::<u64>();
    let (a, me) = export(&doc, &etc1s, "etc1s-size");
    let (b, mu) = export(&doc, &uastc, "uastc-size");
    assert!(bytes(&me) < bytes(&mu), "{} vs {}", bytes(&me), bytes(&mu));
    let _ = std::fs::remove_dir_all(&a);
    let _ = std::fs::remove_dir_all(&b);
}

/// ETC1S blocks of a gradient with hue changes, transcoded to both targets a runtime picks
/// and read by independent decoders: kapaint's measure (its BC7 decode) is bcdec's, and the
/// ASTC 4x4 transcode (texture2ddecoder) is no farther from the texels, so the measure judges
/// the worse target.
#[test]
fn the_bc7_transcode_of_etc1s_is_the_worse_target() {
    let (w, h) = (64_u32, 32_u32);
    let rgb: Vec<u8> = (0..w * h)
        .flat_map(|i| {
            let (x, y) = (i % w, i / w);
            [(x * 4) as u8, (y * 8) as u8, ((x * y) % 256) as u8]
        })
        .collect();
    let codec = Etc1sCodec::new(3, true);
    let out = codec
        .encode(&[((w, h), &rgb[..])], Effort::Fast)
        .expect("encode");
    let ours = &out.decoded[0];
    let bc7 = kapaint_basis::etc1s::transcode_etc1s(&out.image, true, kapaint_basis::Target::Bc7)
        .expect("BC7");
    let mut theirs = vec![0_u8; (w * h * 4) as usize];
    for (i, block) in bc7[0].chunks_exact(16).enumerate() {
        let (bx, by) = (i as u32 % (w / 4), i as u32 / (w / 4));
        let at = ((by * 4 * w + bx * 4) * 4) as usize;
        bcdec_rs::bc7(block, &mut theirs[at..], (w * 4) as usize);
    }
    let theirs: Vec<u8> = theirs
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    assert!(*ours == theirs, "kapaint decodes BC7 as bcdec does");
    let astc =
        kapaint_basis::etc1s::transcode_etc1s(&out.image, true, kapaint_basis::Target::Astc4x4)
            .expect("ASTC");
    let mut words = vec![0_u32; (w * h) as usize];
    texture2ddecoder::decode_astc(&astc[0], w as usize, h as usize, 4, 4, &mut words)
        .expect("decode ASTC");
    let astc: Vec<u8> = words
        .iter()
        .flat_map(|p| {
            let [b, g, r, _] = p.to_le_bytes();
            [r, g, b]
        })
        .collect();
    let sq = |a: &[u8]| -> u64 {
        a.iter()
            .zip(&rgb)
            .map(|(x, y)| u64::from(x.abs_diff(*y)).pow(2))
            .sum()
    };
    assert!(
        sq(ours) >= sq(&astc),
        "BC7 {} vs ASTC {}",
        sq(ours),
        sq(&astc)
    );
}
