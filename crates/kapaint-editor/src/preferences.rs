//! Edit > Preferences…: the editor's own settings, kept between runs in
//! `~/.config/kapaint/preferences.json` (beside the layout and the recent files), written
//! atomically whenever one changes. A file that does not read gives the defaults.

use std::path::PathBuf;
use std::time::Duration;

use serde::{Deserialize, Serialize};

use kapaint_model::recovery;

/// Shortest autosave interval offered (seconds).
pub const AUTOSAVE_MIN_SECONDS: u32 = 5;
/// Longest autosave interval offered (seconds): an hour.
pub const AUTOSAVE_MAX_SECONDS: u32 = 3600;

/// The editor's settings that outlive a run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Preferences {
    /// How often a changed document's recovery copy is written, in seconds
    /// ([`AUTOSAVE_MIN_SECONDS`] to [`AUTOSAVE_MAX_SECONDS`]).
    pub autosave_seconds: u32,
}

impl Default for Preferences {
    fn default() -> Self {
        Self {
            autosave_seconds: u32::try_from(recovery::AUTOSAVE_INTERVAL.as_secs()).unwrap_or(20),
        }
    }
}

impl Preferences {
    /// The preferences in `json`, each value in its range; `None` for a file that does not
    /// parse or holds a value out of range.
    pub fn parse(json: &[u8]) -> Option<Self> {
        let p: Self = serde_json::from_slice(json).ok()?;
        (AUTOSAVE_MIN_SECONDS..=AUTOSAVE_MAX_SECONDS)
            .contains(&p.autosave_seconds)
            .then_some(p)
    }

    /// The preferences saved, or the defaults.
    pub fn load() -> Self {
        path()
            .and_then(|p| kapaint_base::file_check::read_limited(&p, 1 << 16).ok())
            .and_then(|json| Self::parse(&json))
            .unwrap_or_default()
    }

    /// Writes them (atomically).
    ///
    /// # Errors
    /// Where the folder or the file cannot be written.
    pub fn save(&self) -> Result<(), String> {
        let path = path().ok_or("no home folder to keep preferences in")?;
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        }
        let json = serde_json::to_vec_pretty(self).map_err(|e| e.to_string())?;
        kapaint_base::atomic::write_atomic(&path, &json)
            .map_err(|e| format!("{}: {e}", path.display()))
    }

    /// How often the editor autosaves: the preference, unless `KAPAINT_AUTOSAVE_SECONDS`
    /// overrides it (tests and scripts; any positive number of seconds).
    pub fn autosave_interval(&self) -> Duration {
        std::env::var("KAPAINT_AUTOSAVE_SECONDS")
            .ok()
            .and_then(|s| s.parse::<f64>().ok())
            .filter(|s| s.is_finite() && *s > 0.0)
            .map_or_else(
                || Duration::from_secs(u64::from(self.autosave_seconds)),
                Duration::from_secs_f64,
            )
    }
}

/// Where the preferences are kept.
fn path() -> Option<PathBuf> {
    super::layout::layout_path().map(|p| p.with_file_name("preferences.json"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn preferences_read_back_and_bad_files_give_the_defaults() {
        let p = Preferences {
            autosave_seconds: 90,
        };
        let json = serde_json::to_vec(&p).unwrap_or_default();
        assert_eq!(Preferences::parse(&json), Some(p));
        for bad in [
            &b"{\"autosave_seconds\": 0}"[..],
            b"{\"autosave_seconds\": 99999}",
            b"{\"autosave_seconds\": 30, \"colour\": 1}",
            b"not json",
        ] {
            assert_eq!(
                Preferences::parse(bad),
                None,
                "{}",
                String::from_utf8_lossy(bad)
            );
        }
        assert_eq!(Preferences::parse(b"{}"), Some(Preferences::default()));
    }
}
