//! The dock layout and where it is kept between runs.

use std::path::PathBuf;

use egui_dock::DockState;

use super::Tab;

/// The dock's first layout: the viewport left, the UV canvas right, the layers under it.
pub fn default_layout() -> DockState<Tab> {
    let mut dock = DockState::new(vec![Tab::Viewport]);
    let [_, canvas] =
        dock.main_surface_mut()
            .split_right(egui_dock::NodeIndex::root(), 0.55, vec![Tab::Canvas]);
    dock.main_surface_mut()
        .split_below(canvas, 0.5, vec![Tab::Layers]);
    dock
}

/// A layout saved before the Layers tab existed gains it, under the UV canvas.
fn with_layers(mut dock: DockState<Tab>) -> DockState<Tab> {
    if dock.find_tab(&Tab::Layers).is_none()
        && let Some(at) = dock.find_tab(&Tab::Canvas)
        && let Some(tree) = dock
            .get_surface_mut(at.surface)
            .and_then(|s| s.node_tree_mut())
    {
        tree.split_below(at.node, 0.5, vec![Tab::Layers]);
    }
    dock
}

/// Where the dock layout is kept between runs.
pub(super) fn layout_path() -> Option<PathBuf> {
    std::env::var_os("XDG_CONFIG_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".config")))
        .map(|d| d.join("kapaint").join("layout.json"))
}

/// The saved layout, if there is a readable one holding both tabs.
pub(super) fn load_layout() -> Option<DockState<Tab>> {
    parse_layout(&kapaint_base::file_check::read_limited(&layout_path()?, 1 << 20).ok()?)
}

/// A dock layout from its JSON, if it parses and holds both tabs (the `null` coordinates
/// earlier versions wrote read as 0).
pub fn parse_layout(json: &[u8]) -> Option<DockState<Tab>> {
    let mut value: serde_json::Value = serde_json::from_slice(json).ok()?;
    finite_points(&mut value);
    let dock: DockState<Tab> = serde_json::from_value(value).ok()?;
    (dock.find_tab(&Tab::Viewport).is_some() && dock.find_tab(&Tab::Canvas).is_some())
        .then(|| with_layers(dock))
}

/// Saves the layout (atomically; failures only cost the layout).
pub(super) fn save_layout(dock: &DockState<Tab>) {
    if let (Some(path), Some(json)) = (layout_path(), layout_json(dock)) {
        if let Some(dir) = path.parent() {
            let _ = std::fs::create_dir_all(dir);
        }
        let _ = kapaint_base::atomic::write_atomic(&path, &json);
    }
}

/// The layout as JSON that [`parse_layout`] reads back, or `None` if it would not (nothing
/// unreadable is ever written).
pub fn layout_json(dock: &DockState<Tab>) -> Option<Vec<u8>> {
    let mut value = serde_json::to_value(dock).ok()?;
    finite_points(&mut value);
    let json = serde_json::to_vec(&value).ok()?;
    parse_layout(&json).is_some().then_some(json)
}

/// egui_dock keeps each node's last on-screen rectangle, which is infinite before the first
/// frame: JSON writes those coordinates as `null`, which no number reads back. They are
/// recomputed every frame, so 0 stands in for them.
fn finite_points(value: &mut serde_json::Value) {
    match value {
        serde_json::Value::Object(map) => {
            for (key, v) in map.iter_mut() {
                if v.is_null() && (key == "x" || key == "y") {
                    *v = serde_json::Value::from(0.0);
                } else {
                    finite_points(v);
                }
            }
        }
        serde_json::Value::Array(items) => items.iter_mut().for_each(finite_points),
        _ => {}
    }
}
