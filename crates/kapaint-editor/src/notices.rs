//! The messages in the corner: information, warnings and errors, each in its own colour and
//! with its own mark, shown for a while; the same message again adds to its count instead of
//! stacking another (eight refused strokes are one notice, "×8").

use std::time::{Duration, Instant};

/// How much a notice matters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NoticeLevel {
    /// Done as asked (green).
    Info,
    /// Done, but short of what was asked or expected: a budget missed, a large conversion
    /// error (amber, with the number that missed).
    Warning,
    /// Not done (red).
    Error,
}

impl NoticeLevel {
    /// Its colour.
    pub fn colour(self) -> egui::Color32 {
        match self {
            Self::Info => egui::Color32::from_rgb(120, 200, 120),
            Self::Warning => egui::Color32::from_rgb(235, 175, 60),
            Self::Error => egui::Color32::from_rgb(220, 80, 80),
        }
    }

    /// Its mark, before the text.
    pub fn mark(self) -> &'static str {
        match self {
            Self::Info => "✔",
            Self::Warning => "⚠",
            Self::Error => "✖",
        }
    }

    /// How long it stays.
    fn shown_for(self) -> Duration {
        Duration::from_secs(match self {
            Self::Info => 5,
            Self::Warning => 10,
            Self::Error => 12,
        })
    }
}

/// A message for the user, shown for a while.
#[derive(Clone, Debug)]
pub struct Notice {
    /// Text.
    pub text: String,
    /// How much it matters.
    pub level: NoticeLevel,
    /// How many times it came, one after the other.
    pub count: u32,
    at: Instant,
}

impl Notice {
    /// A notice of `text` at `level`, now.
    pub fn new(text: impl Into<String>, level: NoticeLevel) -> Self {
        Self {
            text: text.into(),
            level,
            count: 1,
            at: Instant::now(),
        }
    }

    /// An error rather than information or a warning.
    pub fn is_error(&self) -> bool {
        self.level == NoticeLevel::Error
    }

    /// The text as shown: with its count when it came more than once.
    pub fn shown(&self) -> String {
        if self.count > 1 {
            format!("{} (×{})", self.text, self.count)
        } else {
            self.text.clone()
        }
    }
}

/// The notices shown, oldest first.
#[derive(Debug, Default)]
pub struct Notices(Vec<Notice>);

impl Notices {
    /// Adds `notice`, or, when the newest one says the same at the same level, counts it
    /// there and shows it anew.
    pub fn push(&mut self, notice: Notice) {
        match self.0.last_mut() {
            Some(last) if last.text == notice.text && last.level == notice.level => {
                last.count += 1;
                last.at = notice.at;
            }
            _ => self.0.push(notice),
        }
    }

    /// Drops the notices shown long enough.
    pub fn expire(&mut self) {
        self.0.retain(|n| n.at.elapsed() < n.level.shown_for());
    }

    /// How long until the next notice is due to go (none without notices).
    pub fn next_expiry(&self) -> Option<std::time::Duration> {
        self.0
            .iter()
            .map(|n| n.level.shown_for().saturating_sub(n.at.elapsed()))
            .min()
    }
}

impl std::ops::Deref for Notices {
    type Target = [Notice];

    fn deref(&self) -> &[Notice] {
        &self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_same_notice_again_is_counted_not_stacked() {
        let mut notices = Notices::default();
        let refused = "the group layer has no pixels to paint";
        for _ in 0..8 {
            notices.push(Notice::new(refused, NoticeLevel::Error));
        }
        assert_eq!(notices.len(), 1);
        assert_eq!(notices[0].shown(), format!("{refused} (×8)"));
        notices.push(Notice::new("saved p.kapaint", NoticeLevel::Info));
        notices.push(Notice::new(refused, NoticeLevel::Error));
        assert_eq!(notices.len(), 3, "only the newest collapses");
        assert_eq!(notices[2].count, 1);
    }
}
