//! What a mesh file says of its pieces besides their geometry: named objects, materials and
//! vertex colours. A bake from a high mesh pairs parts by these names and colours an ID map
//! by them.

use std::ops::Range;

use glam::Vec3;

/// A run of consecutive triangles with a name.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Run {
    /// The name the file gives them.
    pub name: String,
    /// Which triangles (indices into [`Mesh::triangles`](crate::Mesh::triangles)).
    pub triangles: Range<u32>,
}

/// The names and colours a mesh file gives its triangles and vertices; empty for built-in
/// shapes and for a mesh kept inside a project.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Labels {
    /// Named objects or groups (OBJ `o` and `g`, glTF nodes), in the order of the triangles.
    pub objects: Vec<Run>,
    /// Materials (OBJ `usemtl`, a glTF primitive's material), in the order of the triangles.
    pub materials: Vec<Run>,
    /// A colour per vertex (OBJ `v x y z r g b`, glTF `COLOR_0`), linear RGB.
    pub colors: Option<Vec<Vec3>>,
}

/// Names numbered in order of first appearance, and the number of each triangle's name.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Named {
    /// The distinct names.
    pub names: Vec<String>,
    /// Per triangle, the index of its name in `names`; [`Named::NONE`] where no run covers it.
    pub of_triangle: Vec<u32>,
}

impl Named {
    /// A triangle no run names.
    pub const NONE: u32 = u32::MAX;

    /// The runs' names numbered, over `triangles` triangles.
    pub fn of(runs: &[Run], triangles: usize) -> Self {
        let mut names: Vec<String> = Vec::new();
        let mut index = std::collections::HashMap::new();
        let mut of_triangle = vec![Self::NONE; triangles];
        for run in runs {
            let k = *index.entry(run.name.as_str()).or_insert_with(|| {
                names.push(run.name.clone());
                names.len() as u32 - 1
            });
            let (start, end) = (run.triangles.start as usize, run.triangles.end as usize);
            if let Some(slots) = of_triangle.get_mut(start..end.min(triangles)) {
                slots.fill(k);
            }
        }
        Self { names, of_triangle }
    }
}

impl Labels {
    /// Adds a run named `name` over `triangles` (after the runs there are), merged into the
    /// last one where it has the same name and ends where this starts; nothing where it is
    /// empty.
    pub fn push(runs: &mut Vec<Run>, name: &str, triangles: Range<u32>) {
        if triangles.is_empty() {
            return;
        }
        match runs.last_mut() {
            Some(last) if last.name == name && last.triangles.end == triangles.start => {
                last.triangles.end = triangles.end;
            }
            _ => runs.push(Run {
                name: name.to_string(),
                triangles,
            }),
        }
    }

    /// These labels followed by `other`'s, whose mesh's triangles and vertices come after
    /// `triangles` and `vertices` of this one's (colours kept only where both have them).
    #[must_use]
    pub fn followed_by(mut self, other: Self, triangles: u32, vertices: usize) -> Self {
        let shift = |runs: Vec<Run>| {
            runs.into_iter().map(move |r| Run {
                name: r.name,
                triangles: r.triangles.start + triangles..r.triangles.end + triangles,
            })
        };
        self.objects.extend(shift(other.objects));
        self.materials.extend(shift(other.materials));
        self.colors = match (self.colors, other.colors) {
            (Some(mut a), Some(b)) if a.len() == vertices => {
                a.extend(b);
                Some(a)
            }
            _ => None,
        };
        self
    }

    /// Checks that runs lie within `triangles` in order and colours are one per vertex of
    /// `vertices`, finite.
    pub fn validate(&self, triangles: usize, vertices: usize) -> Result<(), String> {
        for (what, runs) in [("object", &self.objects), ("material", &self.materials)] {
            let mut end = 0;
            for r in runs {
                if r.triangles.start < end
                    || r.triangles.end < r.triangles.start
                    || r.triangles.end as usize > triangles
                {
                    return Err(format!(
                        "the {what} {:?} names triangles {:?}, out of order or beyond the {triangles}",
                        r.name, r.triangles
                    ));
                }
                end = r.triangles.end;
            }
        }
        if let Some(c) = &self.colors {
            if c.len() != vertices {
                return Err("attribute counts differ (vertex colours)".into());
            }
            if let Some(i) = c.iter().position(|c| !c.is_finite()) {
                return Err(format!("vertex {i} has a non-finite colour"));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_merge_and_number_by_first_appearance() {
        let mut runs = Vec::new();
        Labels::push(&mut runs, "a", 0..2);
        Labels::push(&mut runs, "a", 2..4);
        Labels::push(&mut runs, "b", 4..4); // empty
        Labels::push(&mut runs, "b", 4..5);
        Labels::push(&mut runs, "a", 5..7);
        assert_eq!(runs.len(), 3);
        assert_eq!(runs[0].triangles, 0..4);
        let named = Named::of(&runs, 8);
        assert_eq!(named.names, ["a", "b"]);
        assert_eq!(named.of_triangle, [0, 0, 0, 0, 1, 0, 0, Named::NONE]);
        let labels = Labels {
            objects: runs,
            ..Labels::default()
        };
        assert!(labels.validate(7, 0).is_ok());
        assert!(labels.validate(6, 0).is_err());
        let both = labels.clone().followed_by(labels, 7, 0);
        assert_eq!(both.objects[3].triangles, 7..11);
        assert!(both.validate(14, 0).is_ok());
    }
}
