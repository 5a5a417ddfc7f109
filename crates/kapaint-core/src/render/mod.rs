//! What a preview shows, independent of the GPU: the camera, the view modes, the lighting, and
//! the shading equation itself ([`shade`]), which the WGSL preview shader evaluates per
//! fragment and the CPU reference renderer ([`self::reference`]) per pixel.

pub mod reference;
pub mod traced;
mod views;

pub use views::{N_RAMP, VIEW_ERROR_TOP, ViewMode, heat_ramp, n_false_colour, relative_error};

use glam::{Mat4, Vec3, Vec4};
use serde::{Deserialize, Serialize};

use kapaint_reflectance::{self as reflectance, AmbientApprox, ShadingModel};

/// How a frame compares the two shading models (or two sides with their own model and
/// approximation, in the editor).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compare {
    /// One model alone.
    Single,
    /// One picture wiped by a divider: the left side's model left of it, the right side's
    /// right of it.
    Split,
    /// Two whole pictures side by side, one camera.
    SideBySide,
    /// `|left - right|` as a heatmap with a scale bar.
    Difference,
    /// Phong, Blinn-Phong and Cook-Torrance side by side, one camera.
    ThreeWay,
}

impl Compare {
    /// Every mode with its label, in the order the compare controls show them.
    pub const ALL: [(Self, &'static str); 5] = [
        (Self::Single, "Single"),
        (Self::Split, "Split"),
        (Self::SideBySide, "Side by side"),
        (Self::Difference, "Difference"),
        (Self::ThreeWay, "All three"),
    ];

    /// How many whole pictures the mode shows next to each other (the camera frames for a
    /// narrower picture when more than one).
    pub fn columns(self) -> usize {
        match self {
            Self::SideBySide => 2,
            Self::ThreeWay => 3,
            Self::Single | Self::Split | Self::Difference => 1,
        }
    }
}

/// The paper's lighting: a uniform sky of intensity `I_a` and one directional light.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Lighting {
    /// Direction towards the light (normalised when used).
    pub light: Vec3,
    /// Ambient (sky) intensity `I_a`.
    pub ia: f32,
    /// Directional light intensity `I_l`.
    pub il: f32,
}

impl Default for Lighting {
    fn default() -> Self {
        Self {
            light: Vec3::new(0.5, 0.8, 0.6),
            ia: 0.3,
            il: 0.8,
        }
    }
}

impl Lighting {
    /// The unit light direction (straight up when the given one is zero or not finite).
    pub fn direction(&self) -> Vec3 {
        self.light
            .try_normalize()
            .filter(|d| d.is_finite())
            .unwrap_or(Vec3::Y)
    }

    /// The light's yaw (about +Y, from +Z towards +X) and pitch (above the horizon), in
    /// radians.
    pub fn angles(&self) -> (f32, f32) {
        let l = self.direction();
        (l.x.atan2(l.z), l.y.clamp(-1.0, 1.0).asin())
    }

    /// Points the light at `yaw` and `pitch` (radians, as [`Lighting::angles`] gives them).
    pub fn set_angles(&mut self, yaw: f32, pitch: f32) {
        self.light = Vec3::new(
            pitch.cos() * yaw.sin(),
            pitch.sin(),
            pitch.cos() * yaw.cos(),
        );
    }
}

/// An orbit camera around a target, Y up.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Camera {
    /// The point orbited.
    pub target: Vec3,
    /// Distance from the target.
    pub distance: f32,
    /// Angle around Y, radians (0 looks down -Z from +Z).
    pub yaw: f32,
    /// Angle above the horizon, radians.
    pub pitch: f32,
    /// Vertical field of view, radians.
    pub fov_y: f32,
}

impl Default for Camera {
    fn default() -> Self {
        Self {
            target: Vec3::ZERO,
            distance: 3.5,
            yaw: 0.0,
            pitch: 0.0,
            fov_y: 35f32.to_radians(),
        }
    }
}

impl Camera {
    /// A camera that frames `points` (a mesh's positions) from the current direction: the
    /// target is the centre of their bounds, the distance fits the sphere around it that
    /// holds them all.
    #[must_use]
    pub fn framing(mut self, points: &[Vec3]) -> Self {
        let (min, max) = points.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        if !(min.is_finite() && max.is_finite()) {
            return self;
        }
        let center = (min + max) / 2.0;
        let radius = points
            .iter()
            .map(|p| p.distance(center))
            .fold(1e-3_f32, f32::max);
        self.target = center;
        self.distance = radius / (self.fov_y / 2.0).sin() * 1.05;
        self
    }

    /// Orbits by `yaw` and `pitch` radians (pitch kept short of the poles).
    #[must_use]
    pub fn orbit(mut self, yaw: f32, pitch: f32) -> Self {
        if yaw.is_finite() && pitch.is_finite() {
            self.yaw = (self.yaw + yaw).rem_euclid(std::f32::consts::TAU);
            self.pitch = (self.pitch + pitch).clamp(-1.55, 1.55);
        }
        self
    }

    /// Moves the target in the view plane by `(dx, dy)` fractions of the view height (a
    /// drag of the full height moves by what the view shows at the target's distance).
    #[must_use]
    pub fn pan(mut self, dx: f32, dy: f32) -> Self {
        if !(dx.is_finite() && dy.is_finite()) {
            return self;
        }
        let forward = (self.target - self.eye()).normalize_or_zero();
        let right = forward.cross(Vec3::Y).normalize_or_zero();
        let up = right.cross(forward);
        let height = 2.0 * self.distance * (self.fov_y / 2.0).tan();
        self.target += (right * -dx + up * dy) * height;
        self
    }

    /// Zooms by `factor` (above 1 moves closer), within sane distances.
    #[must_use]
    pub fn zoom(mut self, factor: f32) -> Self {
        if factor.is_finite() && factor > 0.0 {
            self.distance = (self.distance / factor).clamp(1e-4, 1e6);
        }
        self
    }

    /// The eye position.
    /// The rotation from the default view (from +Z, looking down -Z) to this one: a
    /// direction given relative to the camera, turned into the world.
    pub fn rotation(&self) -> glam::Quat {
        glam::Quat::from_rotation_y(self.yaw) * glam::Quat::from_rotation_x(-self.pitch)
    }

    /// The eye position.
    pub fn eye(&self) -> Vec3 {
        let dir = Vec3::new(
            self.pitch.cos() * self.yaw.sin(),
            self.pitch.sin(),
            self.pitch.cos() * self.yaw.cos(),
        );
        self.target + dir * self.distance
    }

    /// View-projection matrix for an image of `aspect` = width / height (depth 0..1).
    pub fn view_proj(&self, aspect: f32) -> Mat4 {
        let view = glam::camera::rh::view::look_at_mat4(self.eye(), self.target, Vec3::Y);
        let near = (self.distance * 0.01).max(1e-4);
        let far = self.distance * 10.0 + 10.0;
        // wgpu's clip space: Y up, depth in [0, 1] (the Direct3D convention).
        glam::camera::rh::proj::directx::perspective(self.fov_y, aspect.max(1e-3), near, far) * view
    }

    /// The ray through pixel centre `(px + 0.5, py + 0.5)` of a `width x height` image:
    /// origin and unit direction, in object space.
    pub fn ray(&self, px: f32, py: f32, width: u32, height: u32) -> (Vec3, Vec3) {
        let inv = self.view_proj(width as f32 / height as f32).inverse();
        let x = (px + 0.5) / width as f32 * 2.0 - 1.0;
        let y = 1.0 - (py + 0.5) / height as f32 * 2.0;
        let unproject = |z: f32| {
            let p: Vec4 = inv * Vec4::new(x, y, z, 1.0);
            p.truncate() / p.w
        };
        let (near, far) = (unproject(0.0), unproject(1.0));
        (near, (far - near).normalize_or_zero())
    }
}

/// Decides whether a frame must be drawn: only when the settings, the maps (their version)
/// or the mesh (an id the caller bumps) changed since the last frame drawn.
#[derive(Clone, Debug, Default)]
pub struct RedrawGate {
    last: Option<(FrameSettings, u64, u64, (u32, u32))>,
}

impl RedrawGate {
    /// Whether this frame differs from the last one drawn; records it if so.
    pub fn needs_redraw(
        &mut self,
        settings: &FrameSettings,
        maps_version: u64,
        mesh_id: u64,
        size: (u32, u32),
    ) -> bool {
        let now = (*settings, maps_version, mesh_id, size);
        if self.last == Some(now) {
            return false;
        }
        self.last = Some(now);
        true
    }

    /// Forces the next frame to be drawn (a lost surface, a resize the caller can't see).
    pub fn invalidate(&mut self) {
        self.last = None;
    }
}

/// Everything a frame needs besides the mesh and the maps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameSettings {
    /// Shading model.
    pub model: ShadingModel,
    /// Approximation of `chi` for `k_a`.
    pub approx: AmbientApprox,
    /// What to show.
    pub view: ViewMode,
    /// Lights.
    pub lighting: Lighting,
    /// Camera.
    pub camera: Camera,
}

/// One material sample: linear `k_d`, `k_s` and `n`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Diffuse coefficient.
    pub kd: Vec3,
    /// Specular coefficient.
    pub ks: Vec3,
    /// Phong exponent.
    pub n: f32,
}

/// The value a view shows at a surface point with unit `normal`, seen along unit `to_eye`:
/// the equation of `shaders/preview.wgsl`, in linear light (not yet sRGB-encoded).
pub fn shade(s: &FrameSettings, m: Sample, normal: Vec3, to_eye: Vec3, uv: glam::Vec2) -> Vec3 {
    let view = s.view.untraced();
    let kd = m.kd.map(reflectance::sanitize_coefficient);
    let ks = m.ks.map(reflectance::sanitize_coefficient);
    let n = reflectance::sanitize_n_f32(m.n);
    let finite = |c: Vec3| c.map(|v| if v.is_finite() { v } else { 0.0 });
    match view {
        ViewMode::Kd => return kd,
        ViewMode::Ks => return ks,
        ViewMode::N => return Vec3::splat(n),
        ViewMode::NFalseColour => return n_false_colour(n),
        ViewMode::Checker => {
            let cell = (uv * 16.0).floor();
            let odd = (cell.x as i32 + cell.y as i32) & 1;
            return Vec3::splat(0.25 + 0.5 * odd as f32);
        }
        _ => {}
    }
    let ka = reflectance::ka(s.model, s.approx, kd, ks, n);
    if view == ViewMode::Ka {
        return finite(ka);
    }
    if matches!(view, ViewMode::KaView | ViewMode::KaViewError) {
        // The geometric normal's view angle: like k_a, never the normal map's.
        let phi = normal.dot(to_eye).clamp(0.0, 1.0).acos();
        let per_view = finite(reflectance::view::ka_view(s.model, kd, ks, n, phi));
        if view == ViewMode::KaView {
            return per_view;
        }
        return heat_ramp(relative_error(finite(ka), per_view) / VIEW_ERROR_TOP);
    }
    let ambient = s.lighting.ia * ka;
    if view == ViewMode::Ambient {
        return finite(ambient);
    }
    let l = s.lighting.direction();
    let n_dot_l = normal.dot(l);
    let diffuse = s.lighting.il * kd * n_dot_l.max(0.0);
    if view == ViewMode::Diffuse {
        return finite(diffuse);
    }
    let specular = s.lighting.il * s.model.specular(normal, l, to_eye, ks, n);
    if view == ViewMode::Specular {
        return finite(specular);
    }
    finite(ambient + diffuse + specular).clamp(Vec3::ZERO, Vec3::ONE)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camera_orbit_pan_zoom_and_framing() {
        let points = [Vec3::new(-1.0, 2.0, 0.0), Vec3::new(3.0, 4.0, 1.0)];
        let cam = Camera::default().framing(&points);
        assert_eq!(cam.target, Vec3::new(1.0, 3.0, 0.5));
        // Every point is inside the view cone.
        for p in points {
            let to = (p - cam.eye()).normalize();
            let axis = (cam.target - cam.eye()).normalize();
            assert!(to.dot(axis) >= (cam.fov_y / 2.0).cos() - 1e-6);
        }
        let orbited = cam.orbit(0.3, 10.0);
        assert!((orbited.eye().distance(orbited.target) - cam.distance).abs() < 1e-4);
        assert!(orbited.pitch <= 1.55, "pitch stops short of the pole");
        let panned = cam.pan(0.5, 0.0);
        assert!((panned.target - cam.target).length() > 0.0);
        assert!(
            ((panned.target - cam.target).y).abs() < 1e-5,
            "a sideways pan stays level"
        );
        assert!((cam.zoom(2.0).distance - cam.distance / 2.0).abs() < 1e-5);
        assert_eq!(cam.zoom(f32::NAN), cam);
        assert_eq!(cam.orbit(f32::INFINITY, 0.0), cam);
    }

    #[test]
    fn ray_through_the_centre_points_at_the_target() {
        let cam = Camera::default().orbit(0.7, 0.4);
        let (origin, dir) = cam.ray(49.5, 49.5, 100, 100);
        let to_target = (cam.target - origin).normalize();
        assert!(dir.dot(to_target) > 0.999_999, "{dir} vs {to_target}");
    }

    #[test]
    fn the_shader_holds_the_same_false_colour_scale() {
        let wgsl = include_str!("../../../../shaders/preview_functions.wgsl");
        for c in N_RAMP {
            let text = format!("vec3<f32>({:?}, {:?}, {:?})", c[0], c[1], c[2]);
            assert!(
                wgsl.contains(&text),
                "{text} missing from preview_functions.wgsl"
            );
        }
        let span = (1.0 + f64::from(kapaint_model::texel::N_MAX)).ln();
        assert!(
            wgsl.contains(&format!("const N_LOG_SPAN: f32 = {span:?}f;")),
            "{span}"
        );
        assert_eq!(n_false_colour(0.0), Vec3::from(N_RAMP[0]));
        assert!((n_false_colour(16384.0) - Vec3::from(N_RAMP[4])).length() < 1e-5);
    }

    #[test]
    fn redraw_only_when_something_changed() {
        let settings = FrameSettings {
            model: ShadingModel::Phong,
            approx: AmbientApprox::Fast,
            view: ViewMode::Shaded,
            lighting: Lighting::default(),
            camera: Camera::default(),
        };
        let mut gate = RedrawGate::default();
        assert!(gate.needs_redraw(&settings, 1, 0, (10, 10)));
        assert!(
            !gate.needs_redraw(&settings, 1, 0, (10, 10)),
            "idle: no redraw"
        );
        assert!(
            gate.needs_redraw(&settings, 2, 0, (10, 10)),
            "the maps changed"
        );
        let moved = FrameSettings {
            camera: settings.camera.orbit(0.1, 0.0),
            ..settings
        };
        assert!(
            gate.needs_redraw(&moved, 2, 0, (10, 10)),
            "the camera moved"
        );
        assert!(gate.needs_redraw(&moved, 2, 0, (12, 10)), "resized");
        gate.invalidate();
        assert!(gate.needs_redraw(&moved, 2, 0, (12, 10)));
    }
}
