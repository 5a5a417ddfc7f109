//! The KTX2 effort search (issue 21), checked for what it chooses and why: the cheapest
//! encoding that meets the budget and no more, `n` and colour moving out of BC7 when packing
//! fails it, `n` apart in BC7 without BC6H, and presets' budgets read and refused.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::path::Path;

use kapaint_export::codec::Effort;
use kapaint_export::preset::{self, BlockBudget, ExportPreset, Format};
use kapaint_export::set::{self, BlockLayout};

#[path = "common/stroke_edge.rs"]
mod stroke_edge;
use stroke_edge::{export, project, relative_budget, with_budget};

#[test]
fn the_cheapest_encoding_that_meets_the_budget_is_kept_and_no_more_is_spent() {
    let doc = project(128);
    let loose = with_budget(relative_budget(10.0, 1.0, 20.0), Effort::Basic);
    let (dir, manifest) = export(&doc, &loose, "loose");
    let blocks = manifest.blocks.expect("a block choice");
    assert_eq!(blocks.trials.len(), 1, "{blocks:?}");
    assert_eq!(blocks.layout, BlockLayout::Packed);
    assert_eq!(blocks.bc7_effort, Effort::UltraFast);
    assert!(blocks.within_budget && blocks.reason.contains("within the budget"));
    assert!(
        cfg!(not(target_arch = "x86_64"))
            || blocks.encoder == kapaint_export::blocks::Encoder::Ispc
    );
    // The choice is in material.json, and a set with it imports.
    let text = std::fs::read_to_string(dir.join("material.json")).expect("manifest");
    assert!(
        text.contains("\"blocks\"") && text.contains("\"trials\""),
        "{text}"
    );
    assert!(text.contains("\"level_ka_error\""));
    set::import(&dir.join("material.json")).expect("import");
    let _ = std::fs::remove_dir_all(dir);
}

/// How many of a trial's three measures miss `budget`.
fn failing(t: &kapaint_export::set::Trial, budget: &BlockBudget) -> usize {
    let srgb = t.ka_error_srgb.expect("measured");
    usize::from(srgb.p999 > budget.ka_error_srgb_p999)
        + usize::from(srgb.mean > budget.ka_error_srgb_mean)
        + usize::from(budget.max_ka_error.is_some_and(|m| t.ka_error.max > m))
        + usize::from(budget.mean_ka_error.is_some_and(|m| t.ka_error.mean > m))
        + usize::from(
            budget
                .min_psnr
                .is_some_and(|m| t.min_psnr.is_some_and(|p| p < m)),
        )
}

#[test]
fn n_and_colour_move_out_of_bc7_when_packing_fails_the_budget() {
    // Regression: n in k_d's BC7 alpha shares endpoints with k_d, which ruins both at the
    // strokes' edges; the export kept that layout whatever it cost.
    let doc = project(256);
    // First the three layouts at the lowest effort, against a budget nothing meets: the
    // cheapest first, then n apart in BC7, then k_d as BC6H too (the grey project's budget,
    // which only BC6H meets, is in `every_level_...`). Then a relative mean between n
    // apart's and packed's.
    let none = with_budget(relative_budget(1e-6, 1e-9, 40.0), Effort::UltraFast);
    let (dir, manifest) = export(&doc, &none, "strict-first");
    let _ = std::fs::remove_dir_all(dir);
    let first = manifest.blocks.expect("a block choice").trials;
    let order: Vec<_> = first.iter().map(|t| (t.layout, t.bc7_effort)).collect();
    assert_eq!(
        order,
        [
            (BlockLayout::Packed, Effort::UltraFast),
            (BlockLayout::NApart, Effort::UltraFast),
            (BlockLayout::HalfColour, Effort::UltraFast)
        ],
        "the cheapest first, then n apart, then k_d as BC6H, at the same effort"
    );
    let (packed, apart) = (first[0].ka_error.mean, first[1].ka_error.mean);
    assert!(apart < packed, "n out of k_d's blocks: {first:?}");
    let budget = relative_budget(1e-6, (packed * apart).sqrt(), 40.0);
    let strict = with_budget(budget, Effort::Fast);
    let (dir, manifest) = export(&doc, &strict, "strict");
    let blocks = manifest.blocks.expect("a block choice");
    let tried: Vec<_> = blocks
        .trials
        .iter()
        .map(|t| (t.layout, t.bc7_effort))
        .collect();
    assert_eq!(tried[..3], order, "{blocks:?}");
    assert!(
        !blocks.within_budget && blocks.reason.contains("no trial"),
        "{}",
        blocks.reason
    );
    // The reason names the trial kept, not only the last one tried.
    let kept = format!(
        "kept the trial nearest it, {:?} at {:?}",
        blocks.layout, blocks.bc7_effort
    );
    assert!(blocks.reason.contains(&kept), "{}", blocks.reason);
    // Effort stops at the ceiling, and BC6H has no very-fast step of its own.
    assert!(
        blocks.trials.len() <= 5
            && blocks.trials.iter().all(|t| t.bc7_effort <= Effort::Fast
                && (t.layout != BlockLayout::HalfColour || t.bc7_effort != Effort::VeryFast)),
        "effort stops at the ceiling: {blocks:?}"
    );
    // The chosen trial misses the fewest measures, and the files are its layout.
    let fewest = blocks
        .trials
        .iter()
        .map(|t| failing(t, &budget))
        .min()
        .expect("trials");
    let chosen = blocks
        .trials
        .iter()
        .find(|t| t.layout == blocks.layout && t.bc7_effort == blocks.bc7_effort)
        .expect("the chosen trial");
    assert_eq!(failing(chosen, &budget), fewest, "{blocks:?}");
    assert!((manifest.ka_error.max - chosen.ka_error.max).abs() < 1e-12);
    let names: Vec<&str> = manifest.files.iter().map(|f| f.path.as_str()).collect();
    assert_eq!(blocks.layout, BlockLayout::NApart);
    assert_eq!(names, ["kd.ktx2", "n.ktx2"]);
    assert_eq!(manifest.files[0].bit_depth, 8);
    set::import(&dir.join("material.json")).expect("import");
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn without_bc6h_n_moves_apart_in_bc7() {
    let doc = project(128);
    let mut strict = with_budget(relative_budget(1e-6, 1e-7, 90.0), Effort::UltraFast);
    strict.format = Format::Ktx2Bc {
        max_effort: Effort::UltraFast,
        bc6h: false,
    };
    let (dir, manifest) = export(&doc, &strict, "no-bc6h");
    let blocks = manifest.blocks.expect("a block choice");
    let layouts: Vec<BlockLayout> = blocks.trials.iter().map(|t| t.layout).collect();
    assert_eq!(layouts, [BlockLayout::Packed, BlockLayout::NApart]);
    assert!(
        blocks.trials[1].ka_error.mean < blocks.trials[0].ka_error.mean,
        "n apart lowers the k_a error: {blocks:?}"
    );
    assert!(manifest.files.iter().all(|f| f.bit_depth == 8));
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn presets_name_their_budget_and_bad_budgets_are_refused() {
    let p = preset::find("ktx2").expect("preset");
    assert_eq!(p.budget, BlockBudget::default());
    assert_eq!(p.format.max_effort(), Some(Effort::Basic));
    // Version-1 presets named the ceiling bc7_quality, then max_bc7_effort, beside the
    // format: refused, with the spelling to write instead.
    let old = ExportPreset::parse(
        Path::new("old.ron"),
        "(name: \"old\", format: Ktx2Bc, layout: Packed, n_bits: 8, bc7_quality: Fast)",
    )
    .expect_err("a version-1 preset")
    .to_string();
    assert!(
        old.ends_with("write version: 2 and format: Ktx2Bc(max_effort: Fast, bc6h: true)"),
        "{old}"
    );
    // The relative limits stay limits, beside the perceptual ones.
    let relative = ExportPreset::parse(
        Path::new("old.ron"),
        "(version: 2, name: \"old\", format: Ktx2Bc(), layout: Packed, n_bits: 8, max_ka_error: 0.02, mean_ka_error: 0.002, min_psnr: 45.0)",
    )
    .expect("an older preset with relative limits");
    assert_eq!(relative.budget.max_ka_error, Some(0.02));
    assert_eq!(relative.budget.min_psnr, Some(45.0));
    assert_eq!(relative.budget.ka_error_srgb_p999, 2.0);
    for bad in [
        "max_ka_error: -0.1",
        "mean_ka_error: inf",
        "min_psnr: 500.0",
        "ka_error_srgb_p999: -1.0",
        "ka_error_srgb_mean: NaN",
    ] {
        let text = format!(
            "(version: 2, name: \"b\", format: Ktx2Bc(), layout: Packed, n_bits: 8, {bad})"
        );
        assert!(
            ExportPreset::parse(Path::new("b.ron"), &text).is_err(),
            "{bad}"
        );
    }
}
