//! Every WGSL file in `shaders/` parses and validates with naga once its includes are
//! resolved by the library's resolver, the one the renderer uses, so a broken shader or a
//! broken include fails `cargo test` instead of the first frame.

use std::path::Path;

#[test]
fn every_wgsl_file_validates() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .expect("shaders/ is readable")
        .filter_map(Result::ok)
        .filter(|e| e.path().extension().is_some_and(|x| x == "wgsl"))
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    files.sort();
    assert!(
        files.len() >= 7,
        "shaders found in {}: {files:?}",
        dir.display()
    );
    for name in files {
        let source = kapaint::gpu::shader::resolve(&name).unwrap_or_else(|e| panic!("{name}: {e}"));
        let module = naga::front::wgsl::parse_str(&source)
            .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&source)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::default(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{name}: {e:?}"));
    }
}

/// The preview's entry file reaches its types through two levels of includes (entry ->
/// bindings -> types): resolved once each, in order.
#[test]
fn nested_includes_resolve_once_in_order() {
    let source = kapaint::gpu::shader::resolve("preview.wgsl").expect("resolves");
    assert_eq!(source.matches("struct Frame {").count(), 1);
    assert_eq!(source.matches("const MODEL_PHONG").count(), 1);
    let types = source.find("struct Frame {").expect("types");
    let bindings = source.find("var<uniform> frame: Frame").expect("bindings");
    let entry = source.find("fn fs_main").expect("entry");
    assert!(types < bindings && bindings < entry);
    assert!(!source.contains("#include"));
}
