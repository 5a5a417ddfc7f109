//! The KTX2 writer's tests: sizes, levels, blocks, and its typed errors.

use super::*;

/// A cancel is a type the export acts on (it ends quietly), not an error line whose words
/// it would have to read; a shape that cannot be stored is another.
#[test]
fn a_cancelled_encode_and_a_bad_shape_say_so_in_their_type() {
    let spaces = [Space::Linear; 4];
    let level0 = vec![128_u8; 16 * 16 * 4];
    let value = |_: usize, _: usize| 0.5_f32;
    let source = Source {
        width: 16,
        height: 16,
        spaces: &spaces,
        level0: &level0,
        value: &value,
    };
    let bc = crate::preset::Format::Ktx2Bc {
        max_effort: Effort::Fast,
        bc6h: false,
    };
    let codec = bc.codec(&spaces).expect("BC7 for four components");
    let progress = Progress::default();
    progress.cancel();
    let blocks = Some((Coder::best_cpu(), &*codec, Effort::Fast));
    let cancelled = encode(&source, blocks, None, &progress);
    assert!(
        matches!(cancelled, Err(KtxError::Cancelled)),
        "{:?}",
        cancelled.err()
    );
    let empty = Source {
        width: 0,
        level0: &[],
        ..source
    };
    let shape = encode(&empty, None, None, &Progress::default());
    assert!(
        matches!(shape, Err(KtxError::Shape(_))),
        "{:?}",
        shape.err()
    );
}

fn gradient(w: u32, h: u32, ch: usize) -> Vec<f32> {
    (0..w * h)
        .flat_map(|i| {
            let (x, y) = (i % w, i / w);
            (0..ch).map(move |k| ((x + y * 3 + k as u32 * 17) % 64) as f32 / 63.0)
        })
        .collect()
}

/// Writes `values` (in the averaging space of `spaces`) as a KTX2 file.
fn write(
    (w, h): (u32, u32),
    spaces: &[Space],
    values: &[f32],
    compressed: Option<Effort>,
) -> Written {
    let ch = spaces.len();
    let bounds: Vec<Vec<f32>> = spaces.iter().map(|s| s.boundaries()).collect();
    let (per, offsets) = texel_layout(spaces);
    let mut level0 = vec![0_u8; values.len() / ch * per];
    for (t, v) in level0.chunks_exact_mut(per).zip(values.chunks_exact(ch)) {
        for k in 0..ch {
            spaces[k].store(&bounds[k], v[k], &mut t[offsets[k]..]);
        }
    }
    let value = |i: usize, k: usize| values[i * ch + k];
    let source = Source {
        width: w,
        height: h,
        spaces,
        level0: &level0,
        value: &value,
    };
    let bc = crate::preset::Format::Ktx2Bc {
        max_effort: Effort::Slow,
        bc6h: true,
    };
    let codec = bc.codec(spaces).unwrap();
    encode(
        &source,
        compressed.map(|q| (Coder::best_cpu(), &*codec, q)),
        None,
        &Progress::default(),
    )
    .unwrap()
}

#[test]
fn files_read_back_through_the_ktx2_crate() {
    for (ch, compressed) in [
        (1, None),
        (2, None),
        (3, None),
        (4, None),
        (1, Some(Effort::VeryFast)),
        (2, Some(Effort::VeryFast)),
        (4, Some(Effort::UltraFast)),
        (5, Some(Effort::UltraFast)),
    ] {
        // 5: three half floats, as BC6H.
        let half = ch == 5;
        let ch = ch.min(4) - usize::from(half);
        let (w, h) = (37, 20);
        let values = gradient(w, h, ch);
        let spaces = [Space::Srgb, Space::Srgb, Space::Srgb, Space::Linear];
        let spaces = if half {
            &[Space::Half; 3][..]
        } else if ch >= 3 {
            &spaces[..ch]
        } else {
            &[Space::Linear; 2][..ch]
        };
        let written = write((w, h), spaces, &values, compressed);
        assert_eq!(written.levels, 6);
        assert_eq!(written.decoded.len(), 6);
        let reader = ktx2::Reader::new(&written.bytes[..]).unwrap();
        assert_eq!(reader.header().level_count, 6);
        assert_eq!(reader.levels().count(), 6);
        let decoded = decode(&written.bytes).unwrap();
        assert_eq!((decoded.width, decoded.height), (w, h));
        // What decode reads is what encode says a consumer gets.
        let first: Vec<f32> = decoded
            .rgba
            .chunks(4)
            .flat_map(|p| p[..ch].to_vec())
            .collect();
        let said: Vec<f32> = if half {
            written.decoded[0]
                .chunks_exact(2)
                .map(|h| half::f16::from_le_bytes([h[0], h[1]]).to_f32())
                .collect()
        } else {
            written.decoded[0]
                .iter()
                .map(|b| f32::from(*b) / 255.0)
                .collect()
        };
        assert_eq!(first, said, "{ch} {compressed:?}");
        if half {
            assert_eq!(written.compression, Compression::Ktx2Bc6h);
            assert_eq!(reader.header().format, Some(KtxFormat::BC6H_UFLOAT_BLOCK));
            // Linear light, decoded close to the values written (the sawtooth's jumps
            // inside blocks cost the most).
            let mean = first
                .iter()
                .zip(&values)
                .map(|(a, b)| (a - b).abs())
                .sum::<f32>()
                / values.len() as f32;
            assert!(mean < 0.05, "{mean}");
        }
        if compressed.is_none() {
            let exact: Vec<u8> = values
                .iter()
                .enumerate()
                .map(|(j, v)| quantise(&spaces[j % ch].boundaries(), *v))
                .collect();
            assert_eq!(written.decoded[0], exact);
        } else {
            let p = written.psnr.unwrap();
            assert!(p.iter().all(|p| p.is_none_or(|p| p > 30.0)), "{p:?}");
        }
    }
}

#[test]
fn psnr_sums_every_texel_of_every_component() {
    // A byte component and a half float one, more texels than one parallel run, and a
    // texel that differs only in the last run's tail.
    let spaces = [Space::Linear, Space::Half];
    let texels = (1 << 14) * 3 + 5;
    let texel = |i: usize, shift: u8| {
        let h = half::f16::from_f32((i % 97) as f32 / 97.0);
        let [lo, hi] = h.to_le_bytes();
        [(i % 251) as u8 ^ shift, lo, hi]
    };
    let a: Vec<u8> = (0..texels).flat_map(|i| texel(i, 0)).collect();
    let mut b: Vec<u8> = (0..texels)
        .flat_map(|i| texel(i, u8::from(i % 7 == 0)))
        .collect();
    let last = b.len() - 2;
    b[last] ^= 1;
    let to_level = |t: &[u8]| {
        let v = half::f16::from_le_bytes([t[1], t[2]])
            .to_f32()
            .clamp(0.0, 1.0);
        f64::from(kapaint_model::texel::linear_to_srgb(v) * 255.0)
    };
    let naive = |k: usize| {
        let sum: f64 = a
            .chunks_exact(3)
            .zip(b.chunks_exact(3))
            .map(|(x, y)| {
                let d = if k == 0 {
                    f64::from(x[0]) - f64::from(y[0])
                } else {
                    to_level(x) - to_level(y)
                };
                d * d
            })
            .sum();
        10.0 * (255.0_f64 * 255.0 / (sum / texels as f64)).log10()
    };
    let got = psnr(&a, &b, &spaces);
    for (k, p) in got.iter().enumerate() {
        let p = p.expect("they differ");
        assert!(
            (p - naive(k)).abs() < 1e-9,
            "component {k}: {p} vs {}",
            naive(k)
        );
    }
    assert_eq!(psnr(&a, &a, &spaces), [None, None]);
}

#[test]
fn garbage_is_an_error() {
    assert!(decode(b"not a ktx2 file at all").is_err());
    let values = gradient(8, 8, 1);
    let mut bytes = write((8, 8), &[Space::Linear], &values, None).bytes;
    bytes.truncate(bytes.len() - 10);
    assert!(decode(&bytes).is_err());
}

#[test]
fn an_etc1s_file_holds_its_codebooks_and_slices_and_reads_back() {
    let (w, h) = (32, 16);
    let rgba: Vec<u8> = (0..w * h)
        .flat_map(|i| {
            [
                (i % w * 8) as u8,
                (i / w * 16) as u8,
                90,
                (i % 7 * 30) as u8,
            ]
        })
        .collect();
    // Its mips: every other texel of the level above, down to 1x1.
    let mut levels = vec![((w, h), rgba)];
    while let Some(&((lw, lh), ref above)) = levels.last().filter(|(s, _)| *s != (1, 1)) {
        let (nw, nh) = ((lw / 2).max(1), (lh / 2).max(1));
        let next: Vec<u8> = (0..nw * nh)
            .flat_map(|i| {
                let at = (((i / nw) * 2).min(lh - 1) * lw + ((i % nw) * 2).min(lw - 1)) * 4;
                above[at as usize..at as usize + 4].to_vec()
            })
            .collect();
        levels.push(((nw, nh), next));
    }
    let given: Vec<((u32, u32), &[u8])> = levels.iter().map(|(s, t)| (*s, &t[..])).collect();
    let codec = crate::codec::etc1s::Etc1sCodec::new(4, false);
    let encoded = codec.encode(&given, Effort::Fast).unwrap();
    let file = super::etc1s_file(&encoded.image, false).unwrap();
    let reader = ktx2::Reader::new(&file[..]).unwrap();
    let header = reader.header();
    assert_eq!(header.format, None);
    assert_eq!(header.type_size, 1);
    assert_eq!(
        header.supercompression_scheme,
        Some(ktx2::SupercompressionScheme::BasisLZ)
    );
    assert_eq!(header.level_count, 6, "32x16 down to 1x1");
    assert_eq!(
        header.index.sgd_byte_offset % 8,
        0,
        "the global data aligned to 8"
    );
    assert_eq!(reader.color_model(), Some(ktx2::ColorModel::ETC1S));
    assert!(reader.levels().all(|l| l.uncompressed_byte_length == 0));
    let (image, srgb) = super::read_etc1s(&reader).unwrap();
    assert!(!srgb);
    assert_eq!(image, encoded.image, "what was written reads back");
    assert!(image.has_alpha());
    let decoded = super::decode(&file).unwrap();
    assert_eq!((decoded.width, decoded.height, decoded.channels), (w, h, 4));
    let same = decoded
        .rgba
        .iter()
        .zip(&encoded.decoded[0])
        .all(|(a, b)| (a * 255.0).round() as u8 == *b);
    assert!(same, "the file decodes as the encoder's measure read it");
}
