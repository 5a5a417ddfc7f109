//! Every WGSL file in `shaders/` parses and validates with naga, so a broken shader fails
//! `cargo test` instead of the first frame.

use std::path::Path;

#[test]
fn every_wgsl_file_validates() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .expect("shaders/ is readable")
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "wgsl"))
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no shaders found in {}", dir.display());
    for path in files {
        let mut source = std::fs::read_to_string(&path).expect("shader is readable");
        // A shader that uses another starts with `// requires: a.wgsl, b.wgsl`; they are
        // prepended, as the renderer does.
        if let Some(list) = source
            .lines()
            .next()
            .and_then(|l| l.strip_prefix("// requires:"))
        {
            let mut full = String::new();
            for name in list.split(',') {
                full += &std::fs::read_to_string(dir.join(name.trim())).expect("required shader");
            }
            source = full + &source;
        }
        let module = naga::front::wgsl::parse_str(&source)
            .unwrap_or_else(|e| panic!("{}: {}", path.display(), e.emit_to_string(&source)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::default(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{}: {e:?}", path.display()));
    }
}
