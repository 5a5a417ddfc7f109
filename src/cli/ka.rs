//! `kapaint ka`: k_a = (2/pi) k_d + k_s chi(n) of one texel as `r,g,b` (for Cook-Torrance,
//! `(2/pi) k_d + k_s chi1(n) + chi0(n)`).

use glam::DVec3;

use super::CliError;
use super::args::{MethodArg, ModelArg, check_method, fmt17, parse_n, parse_rgb};
use crate::reflectance::{self, ShadingModel, TWO_OVER_PI, exact::chi_parts_exact};

/// Print k_a = (2/pi) k_d + k_s chi(n) of one texel as `r,g,b`.
#[derive(Debug, clap::Args)]
pub struct KaArgs {
    /// Specular lobe.
    #[arg(long, value_enum)]
    model: ModelArg,
    /// How chi is computed.
    #[arg(long, value_enum)]
    method: MethodArg,
    /// Diffuse coefficient `R,G,B`, each in [0, 1].
    #[arg(long)]
    kd: String,
    /// Specular coefficient `S` or `R,G,B`, each in [0, 1].
    #[arg(long)]
    ks: String,
    /// Phong exponent (n >= 0).
    #[arg(long, allow_hyphen_values = true)]
    n: String,
}

impl KaArgs {
    /// Runs the command; returns what it prints.
    ///
    /// # Errors
    /// Coefficients or an exponent out of range.
    pub fn run(self) -> Result<String, CliError> {
        check_method(self.model.into(), self.method)?;
        let kd = parse_rgb("--kd", &self.kd, false)?;
        let ks = parse_rgb("--ks", &self.ks, true)?;
        let n = parse_n(&self.n, self.method)?;
        let ka = ka_value(self.model.into(), self.method, kd, ks, n);
        Ok(format!("{},{},{}\n", fmt17(ka.x), fmt17(ka.y), fmt17(ka.z)))
    }
}

fn ka_value(model: ShadingModel, method: MethodArg, kd: DVec3, ks: DVec3, n: f64) -> DVec3 {
    match method.approx() {
        None => {
            let [chi1, chi0] = chi_parts_exact(model, n);
            TWO_OVER_PI * kd + ks * chi1 + DVec3::splat(chi0)
        }
        Some(approx) => {
            reflectance::ka(model, approx, kd.as_vec3(), ks.as_vec3(), n as f32).as_dvec3()
        }
    }
}
