//! A codec is a unit (issue 55): each block format's encoder and decoder calls live in its
//! file under `crates/kapaint-export/src/codec/`, nothing else in the product names a block
//! library or a block format's KTX2 number, the export crate keeps no process-global state
//! and has no `panic!`, and ARCHITECTURE.md's list of the files a new codec touches is every
//! file that names a block format, at most seven.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

mod product_sources;

use product_sources::{listed_files, product_sources, root};

/// Where codecs live.
const CODECS: &str = "crates/kapaint-export/src/codec/";

/// A block library of kapaint's own: Basis Universal's safe wrapper, which only the UASTC
/// codec calls (it is to that codec what `ctt_astcenc` is to ASTC's).
const LIBRARIES: &str = "crates/kapaint-basis/";

/// What only a codec's file may name: the block libraries' encoders and decoders, and the
/// block formats' KTX2 numbers.
const CODEC_ONLY: [&str; 10] = [
    "intel_tex_2",
    "ctt_astcenc",
    "kapaint_basis",
    "block_compression::encode",
    "block_compression::decode",
    "BC7Settings",
    "BC6HSettings",
    "Format::BC",
    "ASTC_4x4",
    "decode_block_bc",
];

/// The code of `line` before any comment.
fn code(line: &str) -> &str {
    line.split("//").next().unwrap_or("")
}

#[test]
fn block_libraries_and_formats_are_named_only_by_codecs() {
    let mut found = Vec::new();
    for (path, text) in product_sources() {
        if path.starts_with(CODECS) || path.starts_with(LIBRARIES) {
            continue;
        }
        for (i, line) in text.lines().enumerate() {
            if let Some(name) = CODEC_ONLY.iter().find(|n| code(line).contains(*n)) {
                found.push(format!("{path}:{}: {name}: {}", i + 1, line.trim()));
            }
        }
    }
    assert!(
        found.is_empty(),
        "a block format's code belongs in its codec (crates/kapaint-export/src/codec/):\n{}",
        found.join("\n")
    );
}

#[test]
fn the_export_crate_has_no_global_state_and_no_panic() {
    let mut found = Vec::new();
    for (path, text) in product_sources() {
        if !path.starts_with("crates/kapaint-export/") {
            continue;
        }
        for (i, line) in text.lines().enumerate() {
            let code = code(line);
            let global = code.trim_start().starts_with("static ")
                && (code.contains("Mutex") || code.contains("RwLock") || code.contains("Cell"));
            let panics = ["panic!(", "unreachable!(", "todo!(", "unimplemented!("]
                .iter()
                .any(|p| code.contains(p));
            if global || panics {
                found.push(format!("{path}:{}: {}", i + 1, line.trim()));
            }
        }
    }
    assert!(
        found.is_empty(),
        "contexts belong to the codec value, and a failure is an error:\n{}",
        found.join("\n")
    );
}

/// Whether `line` names one of the preset format's block variants (`Format::Ktx2Bc`,
/// `Ktx2Astc {`, ...).
fn names_a_block_format(line: &str) -> bool {
    let code = code(line);
    ["Ktx2Bc", "Ktx2Astc"].iter().any(|v| {
        code.match_indices(v).any(|(at, _)| {
            let after = &code[at + v.len()..];
            let before = &code[..at];
            // Not the manifest's compression names (`Ktx2Bc7`, `Compression::Ktx2Astc`).
            !after.starts_with(|c: char| c.is_alphanumeric() || c == '_')
                && !before.ends_with("Compression::")
                && (before.ends_with("Format::") || after.trim_start().starts_with('{'))
        })
    })
}

#[test]
fn the_detector_sees_block_formats_and_not_compressions() {
    for line in [
        "Format::Ktx2Bc { .. } => true,",
        "blocks @ (Format::Ktx2Bc { .. } | Format::Ktx2Astc { .. }) => {",
        "Self::Ktx2Astc { block, .. } => Some(block),",
        "if matches!(f, Format::Ktx2Astc) {",
    ] {
        assert!(names_a_block_format(line), "{line}");
    }
    for line in [
        "Compression::Ktx2Astc => 1,",
        "Self::Ktx2Bc7 => \"ktx2-bc7\",",
        "// Format::Ktx2Bc in a comment",
    ] {
        assert!(!names_a_block_format(line), "{line}");
    }
}

#[test]
fn architecture_lists_every_file_a_new_codec_touches_and_they_are_at_most_seven() {
    let listed = listed_files("codec-files");
    assert!(
        !listed.is_empty() && listed.len() <= 7,
        "a new codec touches {} files beside its own: {listed:?}",
        listed.len()
    );
    for path in &listed {
        assert!(
            root().join(path).is_file(),
            "ARCHITECTURE.md lists {path}, which does not exist"
        );
    }
    let naming: Vec<String> = product_sources()
        .into_iter()
        .filter(|(path, text)| {
            !(path.starts_with(CODECS) && path != "crates/kapaint-export/src/codec/mod.rs")
                && text.lines().any(names_a_block_format)
        })
        .map(|(path, _)| path)
        .collect();
    let missing: Vec<&String> = naming.iter().filter(|p| !listed.contains(p)).collect();
    assert!(
        missing.is_empty(),
        "these files name a block format, and ARCHITECTURE.md's codec-files list does not: \
         {missing:?}"
    );
    // Each shipped block preset names a format the list's preset.rs defines.
    let presets = root().join("presets/export");
    let mut block_presets = 0;
    for entry in std::fs::read_dir(presets).expect("presets") {
        let text = std::fs::read_to_string(entry.expect("entry").path()).expect("preset");
        if text.contains("format: Ktx2Bc(") || text.contains("format: Ktx2Astc(") {
            block_presets += 1;
            assert!(text.contains("version: 2"), "{text}");
        }
    }
    assert_eq!(block_presets, 2, "ktx2 and ktx2-astc");
}
