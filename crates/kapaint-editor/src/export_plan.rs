//! What the export dialog says before it writes: the planned set (each file's packed layout,
//! the constants, `n`'s curve and the memory report) and, for block-compressed presets, how
//! the layout and effort will be chosen.

use kapaint_export::preset::ExportPreset;

/// The export dialog's preview: the packed layout of each file, the constants, the memory
/// report and the `k_a` error that `n`'s quantisation costs.
pub(super) fn export_plan_ui(
    ui: &mut egui::Ui,
    plan: &kapaint_export::set::SetPlan,
    preset: &ExportPreset,
) {
    let mb = |b: u64| b as f64 / 1e6;
    let heading = match preset.format {
        kapaint_export::preset::Format::GltfPbr => "glTF metallic-roughness textures".into(),
        kapaint_export::preset::Format::PbrTextures => format!("{} PBR textures", preset.name),
        _ => "Packed layout".into(),
    };
    ui.label(egui::RichText::new(heading).strong());
    egui::Grid::new("export layout")
        .striped(true)
        .show(ui, |ui| {
            for f in &plan.files {
                ui.monospace(&f.path);
                ui.monospace(f.layout.join(" | "));
                ui.label(format!("{:.1} MB raw", mb(f.raw_bytes)));
                ui.end_row();
            }
        });
    let c = &plan.constants;
    let mut constants = Vec::new();
    if let Some([r, g, b]) = c.kd {
        constants.push(format!("k_d = ({r:.3}, {g:.3}, {b:.3})"));
    }
    if let Some([r, g, b]) = c.ks {
        constants.push(format!("k_s = ({r:.3}, {g:.3}, {b:.3})"));
    }
    if let Some(n) = c.n {
        constants.push(format!("n = {n:.2}"));
    }
    if let Some(n) = &plan.normal {
        ui.label(format!(
            "{}: the project's normal map ({}x{}, {}); it lights only, k_a never reads it",
            n.path, n.width, n.height, n.storage
        ));
    }
    if let Some(note) = &plan.occlusion {
        ui.label(format!("Occlusion: {note}"));
    }
    if plan.files.is_empty() && plan.normal.is_none() {
        ui.label("Every channel is constant: the set is a manifest alone.");
    }
    if !constants.is_empty() {
        ui.label(format!(
            "Constants in the manifest: {}",
            constants.join(", ")
        ));
    }
    if let Some(e) = plan.n_encoding {
        ui.label(format!(
            "n: {:?} curve over [{:.2}, {:.1}], {} bits",
            e.curve, e.lo, e.hi, e.bits
        ));
    }
    if preset.format.is_pbr() {
        ui.label(
            "Base colour, metallic and roughness are converted back from k_d, k_s and n; \
             the round-trip error is measured as the set is written (material.json).",
        );
    } else {
        ui.label(format!(
            "Estimated k_a error (n quantisation): max {:.3} %, mean {:.4} %",
            plan.ka_error.max * 100.0,
            plan.ka_error.mean * 100.0
        ));
    }
    let b = &plan.bytes;
    ui.label(format!(
        "Memory: set {:.1} MB uncompressed (files are smaller), naive k_a + k_d + k_s + n {:.1} MB, project {:.1} MB",
        mb(b.exported),
        mb(b.naive),
        mb(b.project)
    ));
}

/// For a block-compressed preset: the layout above is the search's first trial; the export
/// measures and may move `n` out and colour to BC6H (the notice says what it chose).
pub(super) fn block_search_ui(ui: &mut egui::Ui, preset: &ExportPreset) {
    let Some(max_effort) = preset.format.max_effort() else {
        return;
    };
    let astc = preset
        .format
        .astc_block()
        .map(|b| format!("ASTC {b} ({:.2} bits per texel). ", b.bits_per_texel()));
    let order = if astc.is_some() {
        "this layout and n apart (alone, or beside a grey k_s), the one with fewer bytes \
         first (n apart where k_s is grey: both cost the same)"
    } else if preset.format.half_colour() {
        "this layout first, then n apart, then n apart with colour as BC6H"
    } else {
        "this layout first, then n apart"
    };
    ui.label(format!(
        "{}Blocks: the layout and effort are chosen at export by the measured k_a error \
         (budget: {}): {order}, then more effort up to {:?}. The notice and material.json \
         say what was kept.",
        astc.unwrap_or_default(),
        preset.budget.describe(),
        max_effort
    ));
}
