//! Image > Resize: the maps of the open project resampled to another size on a worker, as one
//! undo step, with what it costs in memory shown before it starts.

use std::sync::Arc;

use super::EditorState;
use super::dialogs::{NEW_SIZES, centred};
use kapaint_base::memory::human;
use kapaint_model::resize::{ResizedMaps, peak_bytes, resized_stack};
use kapaint_model::surface::Surface;

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

impl EditorState {
    /// Opens Image > Resize at the current size.
    pub fn open_resize(&mut self) {
        self.dialogs.resize = Some(ResizeDialog {
            width: self.doc.maps().width(),
            height: self.doc.maps().height(),
        });
    }

    /// The Resize dialog's choices, while it is open.
    pub fn resize_dialog(&self) -> Option<ResizeDialog> {
        self.dialogs.resize
    }

    /// Sets the Resize dialog's choices (opening it).
    pub fn set_resize_dialog(&mut self, dialog: ResizeDialog) {
        self.dialogs.resize = Some(dialog);
    }

    /// Resamples the maps to `width x height` on a worker (the mesh baked again at that
    /// size); the editor waits behind a window, then installs them as one undo step.
    pub fn resize_maps(&mut self, width: u32, height: u32) {
        let stack = self.doc.stack().clone();
        let mesh = self.doc.surface().map(|s| s.mesh.clone());
        self.start_job_modal(
            "Resize",
            format!("Resizing the maps to {width}x{height}…"),
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
            Self::resize_done,
        );
    }

    /// The Resize dialog: width and height, the memory before and after, Resize.
    pub(super) fn resize_window(&mut self, ctx: &egui::Context) {
        let Some(mut dialog) = self.dialogs.resize else {
            return;
        };
        let (mut open, mut go) = (true, false);
        let now = (self.doc.maps().width(), self.doc.maps().height());
        centred(egui::Window::new("Resize maps"), ctx)
            .open(&mut open)
            .collapsible(false)
            .resizable(false)
            .show(ctx, |ui| {
                ui.label(format!("Now {}x{}", now.0, now.1));
                for (name, value) in [("Width", &mut dialog.width), ("Height", &mut dialog.height)]
                {
                    egui::ComboBox::from_label(name)
                        .selected_text(value.to_string())
                        .show_ui(ui, |ui| {
                            for size in SIZES {
                                ui.selectable_value(value, size, size.to_string());
                            }
                        });
                }
                let maps_now = human(self.doc.maps().heap_bytes() as u64);
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
        if go {
            self.dialogs.resize = None;
            self.resize_maps(dialog.width, dialog.height);
        } else if open {
            self.dialogs.resize = Some(dialog);
        } else {
            self.dialogs.resize = None;
        }
    }
}
