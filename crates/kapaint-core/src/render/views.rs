//! The views a preview shows ([`ViewMode`]), and the scales its false-colour and heatmap
//! views draw with.

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// What the preview shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ViewMode {
    /// The lit material (sRGB).
    Shaded,
    /// Derived `k_a` (linear data).
    Ka,
    /// `k_d` (linear data).
    Kd,
    /// `k_s` (linear data).
    Ks,
    /// `n` (raw value).
    N,
    /// Diffuse term only: `I_l k_d max(0, N.L)`.
    Diffuse,
    /// Specular term only: `I_l k_s rho_s`.
    Specular,
    /// Ambient term only: `I_a k_a`.
    Ambient,
    /// A UV checker.
    Checker,
    /// `n` in false colour on the log scale [`N_RAMP`] (a picture, not data).
    NFalseColour,
    /// `k_a` per view (linear data): the ambient coefficient with `chi_view` at the pixel's own
    /// view angle instead of its mean over the view (see [`kapaint_reflectance::view::ka_view`]).
    KaView,
    /// The view-average error: `k_a`'s relative difference from `k_a` per view
    /// ([`relative_error`]) as a heatmap, 0 to [`VIEW_ERROR_TOP`] (a picture, not data).
    KaViewError,
    /// `k_a` traced (linear data): the per-view integral with each light direction masked by
    /// a ray against the mesh, by progressive Monte Carlo on the CPU ([`super::traced`]).
    KaTraced,
    /// The traced error: the live `k_a`'s relative difference from the traced one, as a
    /// heatmap 0 to [`VIEW_ERROR_TOP`] (a picture, not data).
    TracedError,
    /// The AO stand-in's error: `k_a` times the AO bake against the traced `k_a`, on the same
    /// heat scale (a picture; needs an AO bake).
    KaAoTracedError,
}

/// The top of the view-average error's heatmap scale (relative error; 1 = 100 %).
pub const VIEW_ERROR_TOP: f32 = 1.0;

/// The relative difference of `live` from `reference`: the largest over the colour channels
/// of `|live - reference| / reference`, 0 where both are 0 and [`f32::MAX`] where only the
/// reference is (never NaN). `shaders/preview_functions.wgsl` holds the same.
pub fn relative_error(live: Vec3, reference: Vec3) -> f32 {
    let mut worst = 0.0_f32;
    for (a, b) in live.to_array().into_iter().zip(reference.to_array()) {
        let d = (a - b).abs();
        let e = if b > 0.0 {
            d / b
        } else if d > 0.0 {
            f32::MAX
        } else {
            0.0
        };
        if e > worst {
            worst = e;
        }
    }
    worst
}

/// The false-colour scale of `n`: `ln(1 + n) / ln(1 + 16384)` through these linear-RGB
/// colours (dark blue, blue, teal, green, yellow), evenly spaced. The shader holds the same.
pub const N_RAMP: [[f32; 3]; 5] = [
    [0.0331, 0.0006, 0.0622],
    [0.0482, 0.0785, 0.3712],
    [0.0123, 0.3016, 0.2756],
    [0.1946, 0.6172, 0.0284],
    [0.9473, 0.7991, 0.0091],
];

/// The difference heatmap's colour for `t` in `[0, 1]` (0 at no difference, 1 at the scale's
/// top): black, red, yellow, white, linear RGB. `shaders/difference.wgsl` has the same ramp.
pub fn heat_ramp(t: f32) -> Vec3 {
    let t = t.clamp(0.0, 1.0);
    Vec3::new(
        (t * 3.0).min(1.0),
        (t * 3.0 - 1.0).clamp(0.0, 1.0),
        (t * 3.0 - 2.0).clamp(0.0, 1.0),
    )
}

/// The false colour of `n` (linear RGB).
pub fn n_false_colour(n: f32) -> Vec3 {
    let span = (1.0 + f64::from(kapaint_model::texel::N_MAX)).ln() as f32;
    let t = ((1.0 + n).ln() / span).clamp(0.0, 1.0) * 4.0;
    let i = (t as usize).min(3);
    Vec3::from(N_RAMP[i]).lerp(Vec3::from(N_RAMP[i + 1]), t - i as f32)
}

impl ViewMode {
    /// Every view, in the order the shader numbers them (`gpu::shader::view_id`).
    pub const ALL: [Self; 15] = [
        Self::Shaded,
        Self::Ka,
        Self::Kd,
        Self::Ks,
        Self::N,
        Self::Diffuse,
        Self::Specular,
        Self::Ambient,
        Self::Checker,
        Self::NFalseColour,
        Self::KaView,
        Self::KaViewError,
        Self::KaTraced,
        Self::TracedError,
        Self::KaAoTracedError,
    ];

    /// The name the editor shows: the CLI's, with `k_a`, `k_d`, `k_s` spelt as everywhere
    /// else in the UI.
    pub fn label(self) -> &'static str {
        match self {
            Self::Shaded => "shaded",
            Self::Ka => "k_a",
            Self::Kd => "k_d",
            Self::Ks => "k_s",
            Self::N => "n",
            Self::Diffuse => "diffuse",
            Self::Specular => "specular",
            Self::Ambient => "ambient",
            Self::Checker => "checker",
            Self::NFalseColour => "n false colour",
            Self::KaView => "k_a per view",
            Self::KaViewError => "view-average error",
            Self::KaTraced => "k_a traced",
            Self::TracedError => "traced error",
            Self::KaAoTracedError => "k_a × AO error",
        }
    }

    /// The CLI name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Shaded => "shaded",
            Self::Ka => "ka",
            Self::Kd => "kd",
            Self::Ks => "ks",
            Self::N => "n",
            Self::Diffuse => "diffuse",
            Self::Specular => "specular",
            Self::Ambient => "ambient",
            Self::Checker => "checker",
            Self::NFalseColour => "n-false-colour",
            Self::KaView => "ka-view",
            Self::KaViewError => "ka-view-error",
            Self::KaTraced => "ka-traced",
            Self::TracedError => "ka-traced-error",
            Self::KaAoTracedError => "ka-ao-traced-error",
        }
    }

    /// From the CLI name.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|v| v.name() == name)
    }

    /// Whether the view is linear data (written raw) rather than a picture (sRGB).
    pub fn is_data(self) -> bool {
        !matches!(
            self,
            Self::Shaded
                | Self::Checker
                | Self::NFalseColour
                | Self::KaViewError
                | Self::TracedError
                | Self::KaAoTracedError
        )
    }

    /// Whether the view is traced on the CPU ([`super::traced`]) rather than shaded per fragment.
    pub fn is_traced(self) -> bool {
        matches!(
            self,
            Self::KaTraced | Self::TracedError | Self::KaAoTracedError
        )
    }

    /// Whether the view needs the project's AO bake.
    pub fn needs_ao_bake(self) -> bool {
        self == Self::KaAoTracedError
    }

    /// What a shader draws for the view: a traced view's untraced counterpart (`k_a` per view,
    /// which the traced `k_a` converges to where nothing is in the way, and its error), shown
    /// until the first samples are in; any other view itself.
    #[must_use]
    pub fn untraced(self) -> Self {
        match self {
            Self::KaTraced => Self::KaView,
            Self::TracedError | Self::KaAoTracedError => Self::KaViewError,
            other => other,
        }
    }

    /// Whether the view is a heatmap of a relative error on the scale 0 to
    /// [`VIEW_ERROR_TOP`].
    pub fn is_error_heatmap(self) -> bool {
        matches!(
            self,
            Self::KaViewError | Self::TracedError | Self::KaAoTracedError
        )
    }
}
