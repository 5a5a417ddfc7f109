//! Image > Resize: the maps of the open project resampled to another size on a worker, as one
//! undo step, with what it costs in memory shown before it starts.

use std::sync::Arc;

use super::dialogs::NEW_SIZES;
use super::notice;
use crate::desk::{Desk, JobStart, centred};
use kapaint_base::memory::human;
use kapaint_model::resize::{ResizedMaps, peak_bytes, resized_stack};
use kapaint_model::surface::Surface;
use kapaint_model::{Document, ImportCommand};

/// The Resize dialog's choices.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ResizeDialog {
    /// New width in texels.
    pub width: u32,
    /// New height in texels.
    pub height: u32,
}

/// Sizes the dialog offers: the New dialog's, and 256.
const SIZES: [u32; 6] = [
    256,
    NEW_SIZES[0],
    NEW_SIZES[1],
    NEW_SIZES[2],
    NEW_SIZES[3],
    NEW_SIZES[4],
];

/// Resamples `doc`'s maps to `width x height` on a worker (the mesh baked again at that
/// size); the editor waits behind a window, then installs them as one undo step.
pub(super) fn resize_maps(doc: &Document, width: u32, height: u32) -> JobStart {
    let stack = doc.stack().clone();
    let mesh = doc.surface().map(|s| s.mesh.clone());
    JobStart::new(
        "Resize",
        move |progress| {
            progress.start("resample", 1);
            let stack = match resized_stack(&stack, width, height) {
                Ok(m) => m,
                Err(e) => return Err(format!("resize: {e}")),
            };
            progress.start("bake", 1);
            let surface = match mesh.map(|m| Surface::new(m, width, height)).transpose() {
                Ok(s) => s.map(Arc::new),
                Err(e) => return Err(format!("resize: the mesh: {e}")),
            };
            Ok(ResizedMaps(Arc::new((stack, surface))))
        },
        resize_done,
    )
    .modal(format!("Resizing the maps to {width}x{height}…"))
}

/// The maps resized, with the mesh baked at their size.
fn resize_done(resized: ResizedMaps, desk: &mut Desk) {
    let (w, h) = (resized.0.0.width, resized.0.0.height);
    let said = notice(format!("Resized the maps to {w}x{h}"), false);
    desk.command_saying(ImportCommand::Resize(resized), vec![said]);
}

/// The Resize dialog, while `open`: width and height, the memory before and after, Resize.
pub(super) fn resize_window(open: &mut Option<ResizeDialog>, ctx: &egui::Context, desk: &mut Desk) {
    let Some(mut dialog) = *open else {
        return;
    };
    let doc = desk.doc;
    let (mut shown, mut go) = (true, false);
    let now = (doc.maps().width(), doc.maps().height());
    centred(egui::Window::new("Resize maps"), ctx)
        .open(&mut shown)
        .collapsible(false)
        .resizable(false)
        .show(ctx, |ui| {
            ui.label(format!("Now {}x{}", now.0, now.1));
            for (name, value) in [("Width", &mut dialog.width), ("Height", &mut dialog.height)] {
                egui::ComboBox::from_label(name)
                    .selected_text(value.to_string())
                    .show_ui(ui, |ui| {
                        for size in SIZES {
                            ui.selectable_value(value, size, size.to_string());
                        }
                    });
            }
            let maps_now = human(doc.maps().heap_bytes() as u64);
            let full_after = u64::from(dialog.width) * u64::from(dialog.height) * 14;
            ui.label(format!(
                "Maps: {maps_now} now, up to {} after",
                human(full_after)
            ));
            ui.label(format!("Undo keeps the old maps: {maps_now}"));
            let peak = peak_bytes(now, dialog.width, dialog.height);
            let available = kapaint_base::memory::available_bytes();
            let text = format!("Peak while resampling: {}", human(peak));
            let fits = available.is_none_or(|a| peak < a);
            if fits {
                ui.label(text);
            } else {
                ui.colored_label(ui.visuals().error_fg_color, text + ", more than is free");
            }
            ui.label("k_d and k_s resample linearly, n in log space.");
            let same = (dialog.width, dialog.height) == now;
            go = ui
                .add_enabled(!same && fits, egui::Button::new("Resize"))
                .clicked();
        });
    *open = shown.then_some(dialog);
    if go {
        *open = None;
        desk.job(resize_maps(doc, dialog.width, dialog.height));
    }
}
