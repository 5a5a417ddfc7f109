//! What each image of a set holds, by role: the role names its file and says which
//! components it carries.

use super::manifest::Comp;

/// An image's role in a set; its file stem is [`Role::stem`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) enum Role {
    /// `k_d` RGB with `n` in alpha (the packed layout).
    KdN,
    /// `k_d` RGB.
    Kd,
    /// `n` alone.
    N,
    /// Grey `k_s` with `n` (`k_d` constant, or `n` moved out of the colour blocks).
    KsN,
    /// `k_s`, one component when grey, else RGB.
    Ks,
    /// The baked `k_a` (RGB), where the preset includes it.
    Ka,
}

impl Role {
    /// The file stem (`kd_n` for `kd_n.png`).
    pub(super) fn stem(self) -> &'static str {
        match self {
            Self::KdN => "kd_n",
            Self::Kd => "kd",
            Self::N => "n",
            Self::KsN => "ks_n",
            Self::Ks => "ks",
            Self::Ka => "ka",
        }
    }

    /// The file name with `extension`.
    pub(super) fn file(self, extension: &str) -> String {
        format!("{}.{extension}", self.stem())
    }
}

/// A set's images: role and components, in file order.
pub(super) type Images = Vec<(Role, Vec<Comp>)>;
