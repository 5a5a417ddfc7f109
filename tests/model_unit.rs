//! A shading model is a unit: no code outside the reflectance crate compares models (it asks
//! `ShadingModel` instead, whose matches are exhaustive), and ARCHITECTURE.md's list of the
//! files a new model touches is every file that matches on a model, at most ten.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

mod product_sources;

use kapaint::reflectance::ShadingModel;
use product_sources::{files, product_sources, root};

/// The variants' paths as code names them.
fn variant_paths() -> Vec<String> {
    ShadingModel::ALL
        .iter()
        .map(|m| format!("ShadingModel::{m:?}"))
        .collect()
}

/// Whether `line` compares a model with `==`, `!=` or `matches!`.
fn compares_a_model(line: &str, variants: &[String]) -> bool {
    let code = line.split("//").next().unwrap_or("");
    variants.iter().any(|v| code.contains(v.as_str()))
        && (code.contains("==") || code.contains("!=") || code.contains("matches!("))
}

/// Whether `line` is an arm of a match on a model (`ShadingModel::X =>`, `| ShadingModel::X`).
fn matches_on_a_model(line: &str, variants: &[String]) -> bool {
    let code = line.split("//").next().unwrap_or("");
    variants.iter().any(|v| {
        code.match_indices(v.as_str()).any(|(at, _)| {
            let after = code[at + v.len()..].trim_start();
            let before = code[..at].trim_end();
            let next_is_ident = after.starts_with(|c: char| c.is_alphanumeric() || c == '_');
            !next_is_ident
                && (after.starts_with("=>") || after.starts_with('|') || before.ends_with('|'))
        })
    })
}

#[test]
fn no_code_outside_the_reflectance_crate_compares_models() {
    let variants = variant_paths();
    let mut found = Vec::new();
    for (path, code) in product_sources() {
        if path.starts_with("crates/kapaint-reflectance/") {
            continue;
        }
        for (i, line) in code.lines().enumerate() {
            if compares_a_model(line, &variants) {
                found.push(format!("{path}:{}: {}", i + 1, line.trim()));
            }
        }
    }
    assert!(
        found.is_empty(),
        "ask ShadingModel (has_second_part, is_microfacet, paper_equation, lobe, ...) instead of \
         comparing models:\n{}",
        found.join("\n")
    );
}

#[test]
fn the_detectors_see_what_they_look_for() {
    let variants = variant_paths();
    for line in [
        "if model == ShadingModel::CookTorrance {",
        "let k = usize::from(target != ShadingModel::Phong);",
        "if matches!(m, ShadingModel::BlinnPhong) {",
    ] {
        assert!(compares_a_model(line, &variants), "{line}");
    }
    assert!(!compares_a_model("let m = ShadingModel::Phong;", &variants));
    for line in [
        "ShadingModel::Phong => 0,",
        "ShadingModel::Phong | ShadingModel::BlinnPhong => true,",
        "    | ShadingModel::CookTorrance => x,",
    ] {
        assert!(matches_on_a_model(line, &variants), "{line}");
    }
    assert!(!matches_on_a_model(
        "models: [ShadingModel::Phong, ShadingModel::BlinnPhong],",
        &variants
    ));
}

#[test]
fn architecture_lists_every_file_a_new_model_touches_and_they_are_at_most_ten() {
    let listed = product_sources::listed_files("model-files");
    assert!(
        !listed.is_empty() && listed.len() <= 10,
        "a new model touches {} files outside its folder: {listed:?}",
        listed.len()
    );
    for path in &listed {
        assert!(
            root().join(path).is_file(),
            "ARCHITECTURE.md lists {path}, which does not exist"
        );
    }
    let variants = variant_paths();
    // The code that chooses by model id in a shader (the shaders, and the Rust that writes
    // the generated one), but the generated shader.
    let ids: Vec<String> = ShadingModel::ALL
        .iter()
        .map(|m| kapaint::reflectance::wgsl::model_constant(*m))
        .collect();
    let mut touching = Vec::new();
    for (path, code) in product_sources() {
        let in_a_model_folder = path.starts_with("crates/kapaint-reflectance/src/model/")
            && path != "crates/kapaint-reflectance/src/model/mod.rs";
        let matches = code
            .lines()
            .any(|l| matches_on_a_model(l, &variants) || l.contains("Self::Phong =>"))
            || ids.iter().any(|id| code.contains(id.as_str()));
        if matches && !in_a_model_folder {
            touching.push(path);
        }
    }
    let mut shaders = Vec::new();
    files(&root().join("shaders"), ".wgsl", &mut shaders);
    for path in shaders {
        let name = format!(
            "shaders/{}",
            path.file_name().unwrap_or_default().to_string_lossy()
        );
        let text = std::fs::read_to_string(&path).unwrap_or_default();
        if name != "shaders/ambient.wgsl" && ids.iter().any(|id| text.contains(id.as_str())) {
            touching.push(name);
        }
    }
    touching.sort();
    let mut missing: Vec<&String> = touching.iter().filter(|p| !listed.contains(p)).collect();
    missing.dedup();
    assert!(
        missing.is_empty(),
        "these files match on a model but ARCHITECTURE.md does not list them: {missing:?}"
    );
    let stale: Vec<&String> = listed.iter().filter(|p| !touching.contains(p)).collect();
    assert!(
        stale.is_empty(),
        "ARCHITECTURE.md lists files that no longer match on a model: {stale:?}"
    );
}
