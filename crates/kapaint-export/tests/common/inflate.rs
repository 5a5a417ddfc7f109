//! A KTX2 level's bytes as stored before supercompression, inflated by an independent
//! decoder (`ruzstd`, not the zstd library that wrote them).

/// `data`, a level of a file supercompressed by `scheme`, inflated (a copy where it is not).
pub fn level_bytes(scheme: Option<ktx2::SupercompressionScheme>, data: &[u8]) -> Vec<u8> {
    match scheme {
        None => data.to_vec(),
        Some(ktx2::SupercompressionScheme::Zstandard) => {
            let mut out = Vec::new();
            let mut decoder = ruzstd::decoding::StreamingDecoder::new(data).expect("a zstd frame");
            std::io::Read::read_to_end(&mut decoder, &mut out).expect("inflates");
            out
        }
        Some(other) => panic!("supercompression {other:?} is not one kapaint writes"),
    }
}
