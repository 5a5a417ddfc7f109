//! Parsing and checking argument values: sizes, exponents, colours, directions.

use std::io::BufRead;

use glam::DVec3;

use clap::ValueEnum;

use super::CliError;
use crate::model;
use crate::reflectance::exact::EXACT_N_MAX;
use crate::reflectance::{AmbientApprox, ShadingModel};

/// `--model` values: every shading model by its name ([`ShadingModel::name`]), the list made
/// from [`ShadingModel::ALL`] so that it cannot drift from the models.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ModelArg(pub ShadingModel);

impl ValueEnum for ModelArg {
    fn value_variants<'a>() -> &'a [Self] {
        static VARIANTS: std::sync::LazyLock<Vec<ModelArg>> =
            std::sync::LazyLock::new(|| ShadingModel::ALL.into_iter().map(ModelArg).collect());
        &VARIANTS
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        Some(clap::builder::PossibleValue::new(self.0.name()).help(model_help(self.0)))
    }
}

/// A model as `--help` describes it: "Original Phong, eq. (8)".
pub fn model_help(model: ShadingModel) -> String {
    match model.paper_equation() {
        Some(eq) => format!("{}, eq. ({eq})", model.label()),
        None => model.full_label().to_owned(),
    }
}

impl From<ModelArg> for ShadingModel {
    fn from(m: ModelArg) -> Self {
        m.0
    }
}

/// `--n-mapping` values: how PBR roughness and `F0` become Phong's `n` and `k_s`.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum NMappingArg {
    /// `n` and the lobe's height fitted together (`k_s = F0 height(r)`): every roughness its
    /// own exponent.
    HeightFitted,
    /// `k_s = F0`, `n` fitted alone (the mapping before the height fit; `n` stops falling at
    /// roughness 0.48).
    HeightFixed,
}

impl From<NMappingArg> for crate::pbr::NMapping {
    fn from(m: NMappingArg) -> Self {
        match m {
            NMappingArg::HeightFitted => Self::HeightFitted,
            NMappingArg::HeightFixed => Self::HeightFixed,
        }
    }
}

/// Refuses a `--method` the model does not have: the paper printed no form for Cook-Torrance.
pub(super) fn check_method(model: ShadingModel, method: MethodArg) -> Result<(), CliError> {
    if !model.has_paper_forms() && matches!(method, MethodArg::Paper | MethodArg::PaperCorrected) {
        return Err(CliError::usage(format!(
            "the paper printed no approximation for {}: use --method fast or --method exact",
            model.label()
        )));
    }
    Ok(())
}

/// `--method` values.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum MethodArg {
    /// The exact integral of eq. (6).
    Exact,
    /// Eq. (8) / (11) as printed.
    Paper,
    /// Eq. (8) / (11) with the Blinn exponent corrected.
    PaperCorrected,
    /// kapaint's fast approximation.
    Fast,
}

impl MethodArg {
    /// The approximation, or `None` for the exact integral.
    pub fn approx(self) -> Option<AmbientApprox> {
        match self {
            Self::Exact => None,
            Self::Paper => Some(AmbientApprox::PaperPrinted),
            Self::PaperCorrected => Some(AmbientApprox::PaperCorrected),
            Self::Fast => Some(AmbientApprox::Fast),
        }
    }
}

/// A value with 17 significant digits, enough to round-trip an `f64`.
pub fn fmt17(x: f64) -> String {
    format!("{x:.16e}")
}

/// Parses `W` or `WxH`.
pub(super) fn parse_size(text: &str) -> Result<(u32, u32), CliError> {
    let bad = || {
        CliError::usage(format!(
            "--size must be W or WxH with sides 1 to 8192, got {text:?}"
        ))
    };
    let (w, h) = text.split_once(['x', 'X']).unwrap_or((text, text));
    let (w, h): (u32, u32) = (
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    );
    if w == 0 || h == 0 || w > model::maps::MAX_SIDE || h > model::maps::MAX_SIDE {
        return Err(bad());
    }
    Ok((w, h))
}

/// Parses `--light X,Y,Z` (not all zero).
pub(super) fn parse_light(text: &str) -> Result<glam::Vec3, CliError> {
    let bad = || CliError::usage(format!("--light must be a non-zero X,Y,Z, got {text:?}"));
    let v: Vec<f32> = text
        .split(',')
        .map(|p| p.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad())?;
    match v.as_slice() {
        [x, y, z] => {
            let l = glam::Vec3::new(*x, *y, *z);
            (l.is_finite() && l.length() > 0.0)
                .then_some(l)
                .ok_or_else(bad)
        }
        _ => Err(bad()),
    }
}

pub(super) fn parse_n(text: &str, method: MethodArg) -> Result<f64, CliError> {
    let n: f64 = text
        .trim()
        .parse()
        .map_err(|_| CliError::usage(format!("n must be a number, got {text:?}")))?;
    if !n.is_finite() {
        return Err(CliError::usage(format!("n must be finite, got {text:?}")));
    }
    if n < 0.0 {
        return Err(CliError::usage(format!("n must be >= 0, got {text}")));
    }
    if matches!(method, MethodArg::Exact) && n > EXACT_N_MAX {
        return Err(CliError::usage(format!(
            "n = {text} is above the exact integrator's limit {EXACT_N_MAX:e}"
        )));
    }
    if n > f64::from(f32::MAX) {
        return Err(CliError::usage(format!("n = {text} does not fit in f32")));
    }
    Ok(n)
}

/// One exponent per line of stdin (blank lines skipped), each checked as an argument would
/// be for `method`.
pub(super) fn read_stdin_values(
    stdin: &mut dyn BufRead,
    method: MethodArg,
) -> Result<Vec<f64>, CliError> {
    let mut values = Vec::new();
    for (i, line) in stdin.lines().enumerate() {
        let line = line.map_err(|e| CliError::usage(format!("cannot read stdin: {e}")))?;
        if line.trim().is_empty() {
            continue;
        }
        let n = parse_n(&line, method)
            .map_err(|e| CliError::usage(format!("stdin line {}: {}", i + 1, e.message)))?;
        values.push(n);
    }
    if values.is_empty() {
        return Err(CliError::usage("no values on stdin"));
    }
    Ok(values)
}

/// Parses `R,G,B` (or a single value when `allow_scalar`), each finite and in `[0, 1]`.
pub(super) fn parse_rgb(flag: &str, text: &str, allow_scalar: bool) -> Result<DVec3, CliError> {
    let parts: Vec<&str> = text.split(',').collect();
    let values = parts
        .iter()
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<Vec<f64>, _>>()
        .map_err(|_| CliError::usage(format!("{flag} must be numbers, got {text:?}")))?;
    if let Some(bad) = values.iter().find(|v| !(0.0..=1.0).contains(*v)) {
        return Err(CliError::usage(format!(
            "{flag} components must be in [0, 1], got {bad}"
        )));
    }
    match values.as_slice() {
        [v] if allow_scalar => Ok(DVec3::splat(*v)),
        [r, g, b] => Ok(DVec3::new(*r, *g, *b)),
        _ if allow_scalar => Err(CliError::usage(format!(
            "{flag} must be S or R,G,B, got {text:?}"
        ))),
        _ => Err(CliError::usage(format!(
            "{flag} must be R,G,B, got {text:?}"
        ))),
    }
}
