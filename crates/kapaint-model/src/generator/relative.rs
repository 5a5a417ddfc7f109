//! Relative levels: a bake generator's black and white as places in the mesh's own spread of
//! the bake (percentiles of its surface texels), made absolute on the document's bakes before
//! anything is evaluated.

use kapaint_mesh::bakes::{BakeMap, Baked};

use super::{Generator, Levels};

impl Generator {
    /// The same generator with every relative level made absolute on `bakes` (the
    /// document's, at the map size): what is evaluated.
    #[must_use]
    pub fn resolved(&self, bakes: &[std::sync::Arc<Baked>]) -> Self {
        let bake = |map| bakes.iter().find(|b| b.map == map).map(AsRef::as_ref);
        match self {
            Self::Ao(l) => Self::Ao(l.resolved(bake(BakeMap::Ao))),
            Self::Curvature(l) => Self::Curvature(l.resolved(bake(BakeMap::Curvature))),
            Self::Thickness(l) => Self::Thickness(l.resolved(bake(BakeMap::Thickness))),
            Self::Remap { levels, of } => Self::Remap {
                levels: *levels,
                of: Box::new(of.resolved(bakes)),
            },
            Self::Blend { op, a, b } => Self::Blend {
                op: *op,
                a: Box::new(a.resolved(bakes)),
                b: Box::new(b.resolved(bakes)),
            },
            other => other.clone(),
        }
    }
}

impl Levels {
    /// Absolute levels for a bake whose values over the surface are `bake`: relative places
    /// become the values there, at least [`MIN_RELATIVE_SPAN`] apart (a mesh whose bake is
    /// nearly one value everywhere, a sphere's curvature, keeps a ramp, not a step at its
    /// noise).
    pub(super) fn resolved(self, bake: Option<&Baked>) -> Self {
        let Some(bake) = bake.filter(|_| self.relative) else {
            return self;
        };
        let [mut black, mut white] = quantiles(bake, [self.black, self.white]);
        if white - black < MIN_RELATIVE_SPAN {
            let mid = (0.5 * (black + white))
                .clamp(0.5 * MIN_RELATIVE_SPAN, 1.0 - 0.5 * MIN_RELATIVE_SPAN);
            (black, white) = (mid - 0.5 * MIN_RELATIVE_SPAN, mid + 0.5 * MIN_RELATIVE_SPAN);
        }
        Self {
            black,
            white,
            relative: false,
            ..self
        }
    }
}

/// The narrowest ramp relative levels make, in bake values.
pub const MIN_RELATIVE_SPAN: f32 = 0.02;

/// The values below which the fractions `at` of `bake`'s surface texels lie (its first
/// channel; texels off the surface, which a bake leaves 0, are not counted).
fn quantiles<const K: usize>(bake: &Baked, at: [f32; K]) -> [f32; K] {
    let channels = bake.map.channels();
    let mut counts = vec![0_u64; 1 << 16];
    for v in bake.data.iter().step_by(channels).filter(|&&v| v != 0) {
        counts[usize::from(*v)] += 1;
    }
    let total: u64 = counts.iter().sum();
    at.map(|q| {
        if total == 0 {
            return q;
        }
        let want = (f64::from(q.clamp(0.0, 1.0)) * total as f64)
            .ceil()
            .max(1.0) as u64;
        let mut seen = 0;
        let v = counts
            .iter()
            .position(|&c| {
                seen += c;
                seen >= want
            })
            .unwrap_or(u16::MAX.into());
        v as f32 / 65535.0
    })
}
