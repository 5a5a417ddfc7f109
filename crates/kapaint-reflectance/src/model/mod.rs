//! The shading models, each one unit: a folder that gives its lobe once (generic in the
//! float type, so the preview's `f32` twin, the CPU renderers and the `f64` integrals are one
//! source), its exact integrals and how the traced renderer samples it, beside its fast fit
//! and tables. [`ShadingModel`] is how the rest of kapaint asks a model anything: through
//! exhaustive matches here, never by comparing models elsewhere. ARCHITECTURE.md lists the
//! files a new model touches.

pub mod blinn;
pub mod cook_torrance;
pub mod lobe;
pub mod phong;

use glam::Vec3;
use num_traits::Float;

pub use lobe::Cosines;

/// Which specular lobe the surface uses.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, Default, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum ShadingModel {
    /// Original Phong, `rho_s = max(0, R.V)^n` (eq. 4); its ambient is eq. (8).
    #[default]
    #[serde(alias = "Phong")]
    Phong,
    /// Modified (Blinn-)Phong, `rho_s = max(0, N.H)^n` (eq. 9); its ambient is eq. (11).
    /// Files say `blinn`; scripts may say `BlinnPhong` as the type does.
    #[serde(rename = "blinn", alias = "BlinnPhong", alias = "blinn-phong")]
    BlinnPhong,
    /// Cook-Torrance with GGX, height-correlated Smith and Schlick's Fresnel (`k_s` as `F0`),
    /// roughness from `n` by `alpha = sqrt(2 / (n + 2))`; its ambient is
    /// `(2/pi) k_d + k_s chi_1(n) + chi_0(n)` (see [`cook_torrance`]).
    #[serde(rename = "cook-torrance", alias = "CookTorrance")]
    CookTorrance,
}

impl ShadingModel {
    /// Every model, in a fixed order for reports (and the shader ids).
    pub const ALL: [Self; 3] = [Self::Phong, Self::BlinnPhong, Self::CookTorrance];

    /// The two models of the paper, whose ambient has the printed forms.
    pub const PAPER: [Self; 2] = [Self::Phong, Self::BlinnPhong];

    /// The model's place in [`Self::ALL`]: its column in tables kept per model, and its id in
    /// the shaders.
    pub fn index(self) -> usize {
        match self {
            Self::Phong => 0,
            Self::BlinnPhong => 1,
            Self::CookTorrance => 2,
        }
    }

    /// The name used on the command line and in files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Phong => "phong",
            Self::BlinnPhong => "blinn",
            Self::CookTorrance => "cook-torrance",
        }
    }

    /// The model [`ShadingModel::name`] names.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }

    /// The name people read in reports and the editor.
    pub fn label(self) -> &'static str {
        match self {
            Self::Phong => "Phong",
            Self::BlinnPhong => "Blinn-Phong",
            Self::CookTorrance => "Cook-Torrance",
        }
    }

    /// The name with what kind of model it is, where the short one does not say: "Cook-Torrance
    /// (GGX)".
    pub fn full_label(self) -> &'static str {
        match self {
            Self::Phong | Self::BlinnPhong => self.label(),
            Self::CookTorrance => "Cook-Torrance (GGX)",
        }
    }

    /// The number of the paper's equation that approximates this model's ambient (8 and 11),
    /// `None` where the paper printed none.
    pub fn paper_equation(self) -> Option<u8> {
        match self {
            Self::Phong => Some(8),
            Self::BlinnPhong => Some(11),
            Self::CookTorrance => None,
        }
    }

    /// Whether the paper printed an approximation of this model's ambient (eq. 8 and 11).
    pub fn has_paper_forms(self) -> bool {
        self.paper_equation().is_some()
    }

    /// Whether the lobe has a second part that does not scale with `k_s` (Cook-Torrance's
    /// Fresnel: `rho_s = k_s rho_1 + rho_0`, so its ambient is `k_s chi_1 + chi_0` and a
    /// surface with `k_s = 0` still has a specular term).
    pub fn has_second_part(self) -> bool {
        match self {
            Self::Phong | Self::BlinnPhong => false,
            Self::CookTorrance => true,
        }
    }

    /// Whether the model is a microfacet model whose roughness is the one glTF's
    /// metallic-roughness means (GGX): a PBR conversion to it maps roughness through its own
    /// `alpha` with no fit and no conversion error of the lobe.
    pub fn is_microfacet(self) -> bool {
        match self {
            Self::Phong | Self::BlinnPhong => false,
            Self::CookTorrance => true,
        }
    }

    /// The largest exponent the model distinguishes; larger `n` shade as this one.
    pub fn n_max(self) -> f32 {
        match self {
            Self::Phong | Self::BlinnPhong => f32::MAX,
            Self::CookTorrance => cook_torrance::fast::N_MAX,
        }
    }

    /// The lobe `[rho_1, rho_0]` at the cosines `c` for an `n` already sanitized and within
    /// [`Self::n_max`]: `rho_s = k_s rho_1 + rho_0` per colour channel (`rho_0 = 0` where
    /// there is no second part). Every path that shades or integrates the lobe calls this.
    #[inline]
    pub fn lobe<F: Float>(self, c: &Cosines<F>, n: F) -> [F; 2] {
        match self {
            Self::Phong => phong::lobe(c, n),
            Self::BlinnPhong => blinn::lobe(c, n),
            Self::CookTorrance => cook_torrance::lobe(c, n),
        }
    }

    /// The specular radiance factor per colour channel at unit `normal`, `l` (towards the
    /// light) and `v` (towards the eye) for any painted `n`: what the preview's shader
    /// computes, operation for operation (`shaders/lobes.wgsl`, checked against this at 10^4
    /// points by the GPU tests).
    #[inline]
    pub fn specular(self, normal: Vec3, l: Vec3, v: Vec3, ks: Vec3, n: f32) -> Vec3 {
        let n = crate::sanitize_n_f32(n).min(self.n_max());
        let [first, second] = self.lobe(&Cosines::of(normal, l, v), n);
        ks * first + Vec3::splat(second)
    }

    /// The lobe `[rho_1, rho_0]` at a point `(theta, gamma, phi)` of the paper's box, for a
    /// sanitized `n` (not capped: the integrals reach past [`Self::n_max`]).
    pub fn lobe_in_box(self, n: f64, theta: f64, gamma: f64, phi: f64) -> [f64; 2] {
        self.lobe(&Cosines::of_box(theta, gamma, phi), n)
    }

    /// The lobe's angular width in the light direction (radians, at most 8), by which the
    /// traced renderer importance-samples it.
    pub fn lobe_width(self, n: f32) -> f32 {
        let n = n.max(1e-6);
        let w = match self {
            Self::Phong => phong::width(n),
            Self::BlinnPhong => blinn::width(n),
            Self::CookTorrance => cook_torrance::width(n),
        };
        w.min(8.0)
    }

    /// The lobe's width across the mirror direction (in the light's azimuth) at the light's
    /// polar angle `theta` and the view angle `phi`, from its [`Self::lobe_width`].
    pub fn across_width(self, width: f32, theta: f32, phi: f32) -> f32 {
        match self {
            Self::Phong => phong::across(width, theta, phi),
            Self::BlinnPhong => blinn::across(width, theta, phi),
            Self::CookTorrance => cook_torrance::across(width, theta, phi),
        }
    }
}
