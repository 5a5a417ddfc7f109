//! What a bake from a high mesh is given, checked once before any ray is cast: the UV bake,
//! the rays and samples, an ID map's source, the cage, the meshes' positions and the ray
//! distances (their defaults from the meshes' size).

use glam::Vec3;

use super::{DEFAULT_DISTANCE, HighMap, HighOptions, IdSource, SAMPLES};
use crate::Mesh;
use crate::bake::UvBake;
use crate::bakes::{BakeError, RAYS};
use crate::frame::UnitFrame;

/// Checks what a bake is given; returns the default distance's size and the front and rear
/// distances.
pub(super) fn checked(
    low: &Mesh,
    uv: &UvBake,
    high: &Mesh,
    cage: Option<&Mesh>,
    options: HighOptions,
) -> Result<(f32, f32, f32), BakeError> {
    if uv.triangle_count() != low.triangles.len() {
        return Err("the UV bake was made from another mesh".to_string().into());
    }
    check(options)?;
    check_id(high, options.map)?;
    if let Some(c) = cage {
        check_cage(low, c)?;
    }
    distances(low, high, options)
}

/// Checks the rays, their distance and the samples.
fn check(options: HighOptions) -> Result<(), BakeError> {
    if options.map.casts_rays() && !RAYS.contains(&options.rays) {
        return Err(format!(
            "{} rays per sample is outside {} to {}",
            options.rays,
            RAYS.start(),
            RAYS.end()
        )
        .into());
    }
    if let Some(d) = options.max_distance
        && !(d.is_finite() && d > 0.0)
    {
        return Err(format!("the maximum distance {d} is not a positive number").into());
    }
    if !SAMPLES.contains(&options.samples) {
        return Err(format!(
            "{} samples per texel: a texel takes 1, 4 or 16",
            options.samples
        )
        .into());
    }
    Ok(())
}

/// Refuses an ID map by what the high mesh does not have: vertex colours, named objects or
/// materials.
fn check_id(high: &Mesh, map: HighMap) -> Result<(), BakeError> {
    let labels = &high.labels;
    let (source, missing) = match map {
        HighMap::Id(s @ IdSource::Color) if labels.colors.is_none() => (s, "vertex colours"),
        HighMap::Id(s @ IdSource::Object) if labels.objects.is_empty() => (s, "named objects"),
        HighMap::Id(s @ IdSource::Material) if labels.materials.is_empty() => (s, "materials"),
        _ => return Ok(()),
    };
    Err(format!(
        "an ID map by {} needs the high mesh's {missing}, and {} has none",
        source.name(),
        high.name
    )
    .into())
}

/// Refuses a cage that is not the low mesh pushed out: the same vertices and triangles, finite
/// positions.
///
/// # Errors
/// What is wrong with the cage.
pub fn check_cage(low: &Mesh, cage: &Mesh) -> Result<(), BakeError> {
    if cage.positions.len() != low.positions.len() || cage.triangles != low.triangles {
        return Err(format!(
            "the cage {} ({} vertices, {} triangles) is not the low mesh's topology ({} vertices, {} triangles): a cage is the low mesh with its vertices moved",
            cage.name,
            cage.positions.len(),
            cage.triangles.len(),
            low.positions.len(),
            low.triangles.len()
        )
        .into());
    }
    UnitFrame::checked(&cage.positions)
        .map_err(|e| BakeError::Refused(format!("the cage {}: {e}", cage.name)))?;
    Ok(())
}

/// The default distance's size, and the front and rear distances (object units).
///
/// # Errors
/// A high mesh with no triangles or positions that are not finite, distances that are not
/// positive and finite.
fn distances(low: &Mesh, high: &Mesh, options: HighOptions) -> Result<(f32, f32, f32), BakeError> {
    if high.triangles.is_empty() {
        return Err(format!("the high mesh {} has no triangles", high.name).into());
    }
    UnitFrame::checked(&high.positions)
        .map_err(|e| BakeError::Refused(format!("the high mesh {}: {e}", high.name)))?;
    let both: Vec<Vec3> = low
        .positions
        .iter()
        .chain(&high.positions)
        .copied()
        .collect();
    let size = UnitFrame::checked(&both)?.diagonal() * DEFAULT_DISTANCE;
    let distance = |d: Option<f32>, what: &str| match d {
        None => Ok(size),
        Some(d) if d.is_finite() && d > 0.0 => Ok(d),
        Some(d) => Err(BakeError::Refused(format!(
            "the {what} distance {d} is not a positive number"
        ))),
    };
    let (front, rear) = (
        distance(options.front, "front")?,
        distance(options.rear, "rear")?,
    );
    Ok((size, front, rear))
}
