//! The keymap: one table of every key binding. The input code matches keys against it and
//! the shortcut sheet (Help > Keyboard shortcuts) and the menus show it, so they cannot
//! disagree.

use egui::{Key, KeyboardShortcut, Modifiers};

use kapaint_tools::{ToolKind, Tools};

/// What a key does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    /// Undo the last step.
    Undo,
    /// Redo the last undone step.
    Redo,
    /// Save (Save As for an untitled project).
    Save,
    /// Save under another name.
    SaveAs,
    /// Open a project.
    Open,
    /// A new project.
    New,
    /// Export a texture set.
    Export,
    /// Quit (asking first about unsaved changes).
    Quit,
    /// Make a tool active.
    Tool(ToolKind),
    /// The fill tool over the UV canvas; frame the mesh over the 3D viewport.
    FillOrFrame,
    /// Fit the whole map in the UV canvas.
    FitCanvas,
    /// Swap the primary and secondary materials.
    SwapMaterials,
    /// A smaller brush.
    SmallerBrush,
    /// A larger brush.
    LargerBrush,
    /// A softer brush.
    SofterBrush,
    /// A harder brush.
    HarderBrush,
    /// Abandon the stroke or gradient under way.
    Abort,
    /// Show the keyboard shortcuts.
    Shortcuts,
    /// A new paint layer above the selected one.
    NewLayer,
    /// Duplicate the selected layer.
    DuplicateLayer,
    /// Merge the selected layer down.
    MergeDown,
}

/// One key binding.
#[derive(Clone, Copy, Debug)]
pub struct Binding {
    /// The key, with its modifiers (`COMMAND` is Ctrl, or Cmd on a Mac).
    pub shortcut: KeyboardShortcut,
    /// What it does.
    pub action: Action,
    /// What the shortcut sheet says.
    pub description: &'static str,
}

const fn bind(
    modifiers: Modifiers,
    key: Key,
    action: Action,
    description: &'static str,
) -> Binding {
    Binding {
        shortcut: KeyboardShortcut::new(modifiers, key),
        action,
        description,
    }
}

const CTRL: Modifiers = Modifiers::COMMAND;
const CTRL_SHIFT: Modifiers = Modifiers::COMMAND.plus(Modifiers::SHIFT);
const NONE: Modifiers = Modifiers::NONE;

/// Every binding: the editor's own, then each tool's key as the tool gives it.
pub fn keymap() -> &'static [Binding] {
    static MAP: std::sync::OnceLock<Vec<Binding>> = std::sync::OnceLock::new();
    MAP.get_or_init(|| {
        let tools = Tools::all().into_iter().filter_map(|tool| {
            let key = Key::from_name(&tool.key?.to_string())?;
            Some(bind(NONE, key, Action::Tool(tool.kind), tool.summary))
        });
        EDITOR_KEYS.iter().copied().chain(tools).collect()
    })
}

/// The editor's own bindings. Where two share a key, the one with more modifiers comes first
/// (egui matches modifiers loosely: Ctrl+Shift+Z would also match Ctrl+Z).
const EDITOR_KEYS: &[Binding] = &[
    bind(CTRL_SHIFT, Key::Z, Action::Redo, "redo"),
    bind(CTRL, Key::Y, Action::Redo, "redo"),
    bind(CTRL, Key::Z, Action::Undo, "undo"),
    bind(CTRL_SHIFT, Key::S, Action::SaveAs, "save as"),
    bind(CTRL, Key::S, Action::Save, "save"),
    bind(CTRL, Key::O, Action::Open, "open"),
    bind(CTRL_SHIFT, Key::N, Action::NewLayer, "new layer"),
    bind(CTRL, Key::N, Action::New, "new"),
    bind(CTRL_SHIFT, Key::E, Action::Export, "export"),
    bind(CTRL, Key::E, Action::MergeDown, "merge layer down"),
    bind(CTRL, Key::J, Action::DuplicateLayer, "duplicate layer"),
    bind(CTRL, Key::Q, Action::Quit, "quit"),
    bind(
        NONE,
        Key::F,
        Action::FillOrFrame,
        "fill (UV canvas) / frame mesh (viewport)",
    ),
    bind(
        NONE,
        Key::Home,
        Action::FitCanvas,
        "fit the map in the UV canvas",
    ),
    bind(
        NONE,
        Key::X,
        Action::SwapMaterials,
        "swap primary / secondary",
    ),
    bind(
        Modifiers::SHIFT,
        Key::OpenBracket,
        Action::SofterBrush,
        "softer brush",
    ),
    bind(
        Modifiers::SHIFT,
        Key::CloseBracket,
        Action::HarderBrush,
        "harder brush",
    ),
    bind(
        NONE,
        Key::OpenBracket,
        Action::SmallerBrush,
        "smaller brush",
    ),
    bind(NONE, Key::CloseBracket, Action::LargerBrush, "larger brush"),
    bind(
        NONE,
        Key::F1,
        Action::Shortcuts,
        "keyboard shortcuts (this sheet)",
    ),
    bind(
        NONE,
        Key::Escape,
        Action::Abort,
        "abandon the stroke or gradient under way; take back the decal being placed",
    ),
];

/// The first binding of `action`, for menus.
pub fn shortcut(action: Action) -> Option<KeyboardShortcut> {
    keymap()
        .iter()
        .find(|b| b.action == action)
        .map(|b| b.shortcut)
}

/// What a shifted symbol key arrives as: with Shift held, egui reports the symbol the layout
/// makes (`{` for Shift+`[` on US and most layouts), not the key.
fn shifted(shortcut: KeyboardShortcut) -> Option<KeyboardShortcut> {
    let key = match shortcut.logical_key {
        Key::OpenBracket => Key::OpenCurlyBracket,
        Key::CloseBracket => Key::CloseCurlyBracket,
        _ => return None,
    };
    shortcut
        .modifiers
        .shift
        .then(|| KeyboardShortcut::new(shortcut.modifiers, key))
}

/// The actions of the key presses among `events`, one per press (repeats of a held key
/// included) in the order they came, however many a frame holds; the presses are taken out.
/// A press runs the first binding in the keymap it matches (the more specific come first:
/// `Ctrl+Shift+Z` before `Ctrl+Z`).
pub fn pressed_actions(events: &mut Vec<egui::Event>) -> Vec<Action> {
    let matches = |shortcut: &KeyboardShortcut, key: Key, modifiers: egui::Modifiers| {
        key == shortcut.logical_key && modifiers.matches_logically(shortcut.modifiers)
    };
    let mut actions = Vec::new();
    events.retain(|event| {
        let egui::Event::Key {
            key,
            modifiers,
            pressed: true,
            ..
        } = event
        else {
            return true;
        };
        let found = keymap().iter().find(|b| {
            matches(&b.shortcut, *key, *modifiers)
                || shifted(b.shortcut).is_some_and(|s| matches(&s, *key, *modifiers))
        });
        match found {
            Some(b) => {
                actions.push(b.action);
                false
            }
            None => true,
        }
    });
    actions
}

/// A binding as the editor shows it (the shortcut sheet, the menus): the platform's modifier
/// names (`Ctrl+`, or `Cmd` on a Mac) and the key as it is printed on the keyboard (`[`, not
/// `OpenBracket`).
pub fn printed(ctx: &egui::Context, shortcut: &KeyboardShortcut) -> String {
    let names = egui::ModifierNames::NAMES;
    let mut out = names.format(&shortcut.modifiers, ctx.os().is_mac());
    if !out.is_empty() {
        out.push_str(names.concat);
    }
    out.push_str(shortcut.logical_key.symbol_or_name());
    out
}

/// A binding as people write it (`Ctrl+Shift+Z`, `Shift+[`, `B`), independent of the platform
/// (docs/editor.md's key table and the tests use it; the editor shows egui's own formatting).
pub fn written(shortcut: &KeyboardShortcut) -> String {
    let m = shortcut.modifiers;
    let mut out = String::new();
    if m.command || m.ctrl {
        out.push_str("Ctrl+");
    }
    if m.alt {
        out.push_str("Alt+");
    }
    if m.shift {
        out.push_str("Shift+");
    }
    out.push_str(shortcut.logical_key.symbol_or_name());
    out
}

/// The pointer's bindings (egui reads these from the pointer, not the keymap).
pub const MOUSE: &[(&str, &str)] = &[
    ("Left drag", "paint with the active tool"),
    ("Right drag, Alt + left drag", "orbit (viewport)"),
    ("Middle drag", "pan (viewport)"),
    ("Shift + right drag", "turn the light (viewport)"),
    (
        "Right drag on the stencil",
        "move it (Shift: scale, Ctrl: turn), canvas or viewport",
    ),
    ("Space + drag", "pan the UV canvas"),
    ("Wheel", "zoom"),
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_action_has_a_key_and_no_key_does_two_things() {
        let actions = [
            Action::Undo,
            Action::Redo,
            Action::Save,
            Action::SaveAs,
            Action::Open,
            Action::New,
            Action::Export,
            Action::Quit,
            Action::FillOrFrame,
            Action::FitCanvas,
            Action::SwapMaterials,
            Action::SmallerBrush,
            Action::LargerBrush,
            Action::SofterBrush,
            Action::HarderBrush,
            Action::Abort,
            Action::NewLayer,
            Action::DuplicateLayer,
            Action::MergeDown,
        ];
        for action in actions {
            assert!(shortcut(action).is_some(), "{action:?} has no key");
        }
        for tool in Tools::all() {
            let bound = shortcut(Action::Tool(tool.kind)).is_some() || tool.kind == ToolKind::FILL;
            assert!(bound, "{:?} has no key", tool.kind);
        }
        let map = keymap();
        for (k, a) in map.iter().enumerate() {
            for b in &map[k + 1..] {
                assert_ne!(
                    (a.shortcut.modifiers, a.shortcut.logical_key),
                    (b.shortcut.modifiers, b.shortcut.logical_key),
                    "{} and {} share a key",
                    a.description,
                    b.description
                );
            }
        }
    }

    #[test]
    fn the_key_table_lists_every_key() {
        // Every cell of docs/editor.md's tables, split where one cell lists several keys.
        let doc = include_str!("../../../docs/editor.md");
        let cells: Vec<&str> = doc
            .lines()
            .filter(|l| l.starts_with('|'))
            .flat_map(|l| l.split('|'))
            .flat_map(|c| c.split(", "))
            .flat_map(|c| c.split(" / "))
            .map(str::trim)
            .collect();
        for b in keymap() {
            let key = written(&b.shortcut);
            assert!(
                cells.contains(&key.as_str()),
                "docs/editor.md's key table lacks {key} ({})",
                b.description
            );
        }
    }
}
