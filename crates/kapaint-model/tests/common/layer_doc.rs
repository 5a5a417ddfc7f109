//! A small layered document and script runner shared by the layer test files.

use glam::Vec3;
use kapaint_model::texel::Texel;
use kapaint_model::{Command, Document, DocumentSettings, MaterialValue};

/// A 192 x 128 document over a grey base (3 x 2 tiles), "Layer 1" selected.
pub fn document() -> Document {
    let settings = DocumentSettings {
        base: MaterialValue::new(Vec3::splat(0.5), Vec3::splat(0.04), 10.0),
        ..DocumentSettings::default()
    };
    Document::new(192, 128, settings).expect("document")
}

/// The composite, texel by texel.
pub fn texels(doc: &Document) -> Vec<Texel> {
    let m = doc.maps();
    (0..m.height())
        .flat_map(|y| (0..m.width()).map(move |x| (x, y)))
        .map(|(x, y)| m.texel(x, y))
        .collect()
}

/// Runs a RON paint script's commands, failing the test on the first error.
pub fn run(doc: &mut Document, script: &str) {
    #[derive(serde::Deserialize)]
    struct Script {
        commands: Vec<Command>,
    }
    let script: Script = ron::from_str(script).expect("script parses");
    for c in script.commands {
        let what = format!("{c:?}");
        doc.apply(c)
            .unwrap_or_else(|e| panic!("{}: {e}", &what[..what.len().min(80)]));
    }
}

/// The selected layer's mask at texel `(x, y)`: its stored gray (0 hides, 1 shows).
pub fn mask_gray(doc: &Document, x: u32, y: u32) -> f32 {
    let layer = doc.stack().layer(&doc.selection().path).expect("layer");
    let mask = layer.mask.as_ref().expect("a mask");
    let (id, i) = doc.maps().locate(x, y);
    f32::from(mask.tiles[id].get().get(i)) / 65535.0
}
