//! What the rays of a bake from a high mesh are cast against: the whole high mesh, or, matched
//! by name, one BVH per pair of parts (`X_low` with `X_high`) so parts never bake onto each
//! other.

use super::BakeError;
use crate::bakes::RayMesh;
use crate::{Mesh, Named};

/// How low parts find their high parts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Matching {
    /// Every low triangle against the whole high mesh.
    All,
    /// A low object or group named `X_low` against the high ones named `X_high` (case aside);
    /// the low triangles of no pair against the high triangles of no pair.
    ByName,
}

/// The BVHs a bake casts against, built once for every map of a job.
pub struct HighRays {
    /// Per pair (and last, the rest), its BVH; `None` where it has no high triangle.
    rays: Vec<Option<RayMesh>>,
    /// Per low triangle, its pair (`rays`' index); empty when there is one BVH for all.
    low_group: Vec<u32>,
    /// The pairs' names (`X` of `X_low` and `X_high`), in the order of `rays`.
    pub pairs: Vec<String>,
    /// Low triangles in no pair.
    pub unpaired_low: usize,
    /// High triangles in no pair.
    pub unpaired_high: usize,
    /// Seconds spent building the BVHs.
    pub bvh_seconds: f64,
}

impl HighRays {
    /// The BVHs of `high` for a bake onto `low`, matched as `matching` says.
    ///
    /// # Errors
    /// Matching by name where no low part has a high part of its name (listing the names
    /// found).
    pub fn new(low: &Mesh, high: &Mesh, matching: Matching) -> Result<Self, BakeError> {
        let built = std::time::Instant::now();
        let mut out = match matching {
            Matching::All => Self {
                rays: vec![Some(RayMesh::new(high))],
                low_group: Vec::new(),
                pairs: Vec::new(),
                unpaired_low: 0,
                unpaired_high: 0,
                bvh_seconds: 0.0,
            },
            Matching::ByName => Self::by_name(low, high)?,
        };
        out.bvh_seconds = built.elapsed().as_secs_f64();
        Ok(out)
    }

    /// One BVH for all of `high`, built already.
    pub fn whole(rays: RayMesh) -> Self {
        Self {
            rays: vec![Some(rays)],
            low_group: Vec::new(),
            pairs: Vec::new(),
            unpaired_low: 0,
            unpaired_high: 0,
            bvh_seconds: 0.0,
        }
    }

    fn by_name(low: &Mesh, high: &Mesh) -> Result<Self, BakeError> {
        let lows = Named::of(&low.labels.objects, low.triangles.len());
        let highs = Named::of(&high.labels.objects, high.triangles.len());
        let mut pairs: Vec<String> = Vec::new();
        // Per name of each side, its pair.
        let mut low_pair = vec![u32::MAX; lows.names.len()];
        let mut high_pair = vec![u32::MAX; highs.names.len()];
        for (i, name) in lows.names.iter().enumerate() {
            let Some(base) = base_name(name, "_low") else {
                continue;
            };
            let partners: Vec<usize> = (0..highs.names.len())
                .filter(|&j| base_name(&highs.names[j], "_high") == Some(base.clone()))
                .collect();
            if partners.is_empty() {
                continue;
            }
            let k = if let Some(k) = pairs.iter().position(|p| *p == base) {
                k as u32
            } else {
                pairs.push(base);
                pairs.len() as u32 - 1
            };
            low_pair[i] = k;
            for j in partners {
                high_pair[j] = k;
            }
        }
        if pairs.is_empty() {
            let list = |n: &Named| {
                if n.names.is_empty() {
                    "none".to_string()
                } else {
                    n.names.join(", ")
                }
            };
            return Err(format!(
                "matching by name found no pairs: a low part X_low pairs with a high part X_high \
                 (low parts: {}; high parts: {})",
                list(&lows),
                list(&highs)
            )
            .into());
        }
        let rest = pairs.len() as u32;
        let group = |named: &Named, pair: &[u32]| -> Vec<u32> {
            named
                .of_triangle
                .iter()
                .map(|&n| {
                    pair.get(n as usize)
                        .copied()
                        .filter(|&k| k != u32::MAX)
                        .unwrap_or(rest)
                })
                .collect()
        };
        let low_group = group(&lows, &low_pair);
        let high_group = group(&highs, &high_pair);
        Ok(Self {
            rays: RayMesh::split(high, &high_group, pairs.len() + 1),
            unpaired_low: low_group.iter().filter(|&&g| g == rest).count(),
            unpaired_high: high_group.iter().filter(|&&g| g == rest).count(),
            low_group,
            pairs,
            bvh_seconds: 0.0,
        })
    }

    /// The BVH low triangle `t`'s rays meet, if any, and its group.
    pub(super) fn for_low(&self, t: u32) -> Option<(&RayMesh, u32)> {
        let g = self.low_group.get(t as usize).copied().unwrap_or(0);
        self.rays.get(g as usize)?.as_ref().map(|r| (r, g))
    }

    /// The BVHs, by group (`None` where a group has no high triangle).
    pub fn meshes(&self) -> &[Option<RayMesh>] {
        &self.rays
    }

    /// The one BVH of a bake that matched no parts by name.
    pub fn single(&self) -> Option<&RayMesh> {
        match self.rays.as_slice() {
            [Some(one)] if self.low_group.is_empty() => Some(one),
            _ => None,
        }
    }

    /// `far` (object units) in the BVHs' frame (all share the high mesh's).
    pub(super) fn local_length(&self, far: f32) -> f32 {
        self.rays
            .iter()
            .flatten()
            .next()
            .map_or(far, |r| r.frame().local_length(far))
    }

    /// The high mesh's diagonal (object units).
    pub(super) fn diagonal(&self) -> f32 {
        self.rays
            .iter()
            .flatten()
            .map(|r| r.diagonal)
            .next()
            .unwrap_or(0.0)
    }

    /// Whether it was made for a low mesh of `triangles` triangles.
    pub(super) fn fits(&self, triangles: usize) -> bool {
        self.low_group.is_empty() || self.low_group.len() == triangles
    }
}

/// `name` without `suffix` at its end (case aside), lower-cased: the name a pair goes by.
fn base_name(name: &str, suffix: &str) -> Option<String> {
    let lower = name.trim().to_lowercase();
    let base = lower.strip_suffix(suffix)?;
    (!base.is_empty()).then(|| base.to_string())
}
