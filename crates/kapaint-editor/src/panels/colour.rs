//! The colour fields of the material panel: `k_d` as an artist types it, in sRGB (hex, RGB
//! 0-255 and HSV), while the model keeps linear values; the secondary material's swatch; the
//! materials used last.

use glam::Vec3;

use super::tool_panel::ToolPanel;
use crate::desk::Desk;
use kapaint_model::SettingsCommand;
use kapaint_model::texel::{MaterialValue, linear_to_srgb, linear_to_srgb8, srgb_to_linear};

/// How many recent materials the panel keeps.
pub const RECENT_MATERIALS: usize = 8;

/// `#rrggbb` of a linear colour, sRGB-encoded.
pub fn hex_of(linear: Vec3) -> String {
    let [r, g, b] = srgb8(linear);
    format!("#{r:02x}{g:02x}{b:02x}")
}

/// The linear colour of `#rrggbb`, `rrggbb` or `#rgb` (sRGB), if it is one.
pub fn parse_hex(text: &str) -> Option<Vec3> {
    let digits = text.trim().trim_start_matches('#');
    let long = match digits.len() {
        3 => digits.chars().flat_map(|c| [c, c]).collect::<String>(),
        6 => digits.to_string(),
        _ => return None,
    };
    let value = u32::from_str_radix(&long, 16).ok()?;
    let byte = |shift: u32| f32::from(((value >> shift) & 0xff) as u8) / 255.0;
    Some(Vec3::new(byte(16), byte(8), byte(0)).map(srgb_to_linear))
}

/// A linear colour's sRGB bytes.
fn srgb8(linear: Vec3) -> [u8; 3] {
    linear.to_array().map(linear_to_srgb8)
}

/// Hue in degrees `[0, 360)`, saturation and value in `[0, 1]` of an sRGB-encoded colour.
pub fn hsv_of(srgb: Vec3) -> [f32; 3] {
    let max = srgb.max_element();
    let min = srgb.min_element();
    let d = max - min;
    let hue = if d <= 0.0 {
        0.0
    } else if max == srgb.x {
        60.0 * ((srgb.y - srgb.z) / d).rem_euclid(6.0)
    } else if max == srgb.y {
        60.0 * ((srgb.z - srgb.x) / d + 2.0)
    } else {
        60.0 * ((srgb.x - srgb.y) / d + 4.0)
    };
    let sat = if max > 0.0 { d / max } else { 0.0 };
    [hue % 360.0, sat, max]
}

/// The sRGB-encoded colour of hue (degrees), saturation and value.
pub fn srgb_of_hsv([hue, sat, value]: [f32; 3]) -> Vec3 {
    let h = hue.rem_euclid(360.0) / 60.0;
    let c = value * sat;
    let x = c * (1.0 - (h % 2.0 - 1.0).abs());
    let (r, g, b) = match h as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    Vec3::new(r, g, b) + Vec3::splat(value - c)
}

/// A swatch of `linear` (sRGB on screen), `side` points square, named for screen readers and
/// tests.
fn swatch(ui: &mut egui::Ui, linear: Vec3, side: f32, name: &str) -> egui::Response {
    let [r, g, b] = srgb8(linear);
    let response = ui.add(
        egui::Button::new("")
            .fill(egui::Color32::from_rgb(r, g, b))
            .min_size(egui::vec2(side, side)),
    );
    let name = name.to_string();
    response.widget_info(move || {
        egui::WidgetInfo::labeled(egui::WidgetType::Button, true, name.clone())
    });
    response
}

/// The tooltip of a material: its values.
fn describe(v: &MaterialValue) -> String {
    format!(
        "k_d {} (sRGB), k_s {:.2} {:.2} {:.2}, n {:.0}",
        hex_of(v.kd),
        v.ks.x,
        v.ks.y,
        v.ks.z,
        v.n
    )
}

impl ToolPanel {
    /// The primary and secondary swatches (a click on the secondary swaps them) and the
    /// primary's `k_d` in sRGB: hex, RGB 0-255 and HSV. Whether the swatches were swapped
    /// (`primary` is the secondary then).
    pub(super) fn colour_ui(
        &mut self,
        ui: &mut egui::Ui,
        primary: &mut MaterialValue,
        desk: &mut Desk,
    ) -> bool {
        let secondary = desk.doc.settings().secondary;
        let mut swapped = false;
        ui.horizontal(|ui| {
            swatch(ui, primary.kd, 28.0, "Primary")
                .on_hover_text(format!("Primary: {}", describe(primary)));
            if swatch(ui, secondary.kd, 18.0, "Secondary")
                .on_hover_text(format!("Secondary (X swaps): {}", describe(&secondary)))
                .clicked()
            {
                desk.command(SettingsCommand::SwapMaterials);
                *primary = secondary;
                swapped = true;
            }
            ui.label("Hex");
            let shown = hex_of(primary.kd);
            let text = self.hex_text.get_or_insert_with(|| shown.clone());
            let edit = ui.add(
                egui::TextEdit::singleline(text)
                    .desired_width(64.0)
                    .hint_text("#rrggbb"),
            );
            let edit = edit.on_hover_text("k_d in sRGB, as #rrggbb");
            if edit.changed()
                && let Some(kd) = parse_hex(text)
            {
                primary.kd = kd;
            }
            if !edit.has_focus() {
                // Follows the colour whenever the field is not being typed in.
                self.hex_text = Some(hex_of(primary.kd));
            }
        });
        let srgb = primary.kd.map(linear_to_srgb);
        let mut bytes = srgb8(primary.kd).map(i32::from);
        let mut hsv = hsv_of(srgb);
        let (mut rgb_changed, mut hsv_changed) = (false, false);
        ui.horizontal(|ui| {
            ui.label("RGB");
            for (v, name) in bytes.iter_mut().zip(["R", "G", "B"]) {
                let label = ui.label(name);
                rgb_changed |= ui
                    .add(egui::DragValue::new(v).range(0..=255))
                    .labelled_by(label.id)
                    .on_hover_text("sRGB, 0-255")
                    .changed();
            }
        });
        ui.horizontal(|ui| {
            ui.label("HSV");
            let label = ui.label("H");
            hsv_changed |= ui
                .add(
                    egui::DragValue::new(&mut hsv[0])
                        .range(0.0..=359.9)
                        .suffix("°")
                        .max_decimals(0),
                )
                .labelled_by(label.id)
                .on_hover_text("Hue")
                .changed();
            for (v, (short, name)) in hsv[1..]
                .iter_mut()
                .zip([("S", "Saturation"), ("V", "Value")])
            {
                let mut percent = *v * 100.0;
                let label = ui.label(short);
                if ui
                    .add(
                        egui::DragValue::new(&mut percent)
                            .range(0.0..=100.0)
                            .suffix("%")
                            .max_decimals(0),
                    )
                    .labelled_by(label.id)
                    .on_hover_text(name)
                    .changed()
                {
                    *v = percent / 100.0;
                    hsv_changed = true;
                }
            }
        });
        if rgb_changed {
            primary.kd = Vec3::from_array(bytes.map(|b| b as f32 / 255.0)).map(srgb_to_linear);
        } else if hsv_changed {
            primary.kd = srgb_of_hsv(hsv).map(srgb_to_linear);
        }
        swapped
    }

    /// The materials used last (a click makes one the primary).
    pub(super) fn recent_materials_ui(&self, ui: &mut egui::Ui, desk: &mut Desk) {
        if self.recent_materials.is_empty() {
            return;
        }
        let mut chosen = None;
        ui.horizontal_wrapped(|ui| {
            ui.label("Recent");
            for (i, value) in self.recent_materials.iter().enumerate() {
                if swatch(ui, value.kd, 18.0, &format!("Recent material {}", i + 1))
                    .on_hover_text(describe(value))
                    .clicked()
                {
                    chosen = Some(*value);
                }
            }
        });
        if let Some(v) = chosen {
            desk.command(SettingsCommand::SetPrimary(v));
        }
    }

    /// Puts `value` first among the recent materials (a stroke, fill or gradient has laid
    /// it).
    pub(crate) fn remember_material(&mut self, value: MaterialValue) {
        self.recent_materials.retain(|v| *v != value);
        self.recent_materials.insert(0, value);
        self.recent_materials.truncate(RECENT_MATERIALS);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hex_round_trips_through_linear() {
        for hex in ["#000000", "#ffffff", "#ff8000", "#1a2b3c", "#7f7f7f"] {
            let linear = parse_hex(hex).expect("hex");
            assert_eq!(hex_of(linear), hex);
        }
        assert_eq!(parse_hex("f80"), parse_hex("#ff8800"));
        for bad in ["", "#12345", "#gggggg", "#1234567", "red"] {
            assert_eq!(parse_hex(bad), None, "{bad}");
        }
        // sRGB 128 is about 0.216 linear.
        let grey = parse_hex("#808080").expect("grey");
        assert!((grey.x - 0.2158).abs() < 1e-3, "{grey}");
    }

    #[test]
    fn hsv_round_trips_and_names_the_primaries() {
        assert_eq!(hsv_of(Vec3::new(1.0, 0.0, 0.0)), [0.0, 1.0, 1.0]);
        assert_eq!(hsv_of(Vec3::new(0.0, 1.0, 0.0)), [120.0, 1.0, 1.0]);
        assert_eq!(hsv_of(Vec3::new(0.0, 0.0, 1.0)), [240.0, 1.0, 1.0]);
        assert_eq!(hsv_of(Vec3::splat(0.5)), [0.0, 0.0, 0.5]);
        for i in 0..200 {
            let t = i as f32 / 200.0;
            let c = Vec3::new(t, (t * 7.3).fract(), (t * 3.1 + 0.4).fract());
            let back = srgb_of_hsv(hsv_of(c));
            assert!((back - c).abs().max_element() < 1e-5, "{c} -> {back}");
        }
    }
}
