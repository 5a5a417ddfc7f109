//! Meshes to paint on: built-in shapes and imported files (no GUI or GPU code).
//!
//! A [`Mesh`] is an indexed triangle list with per-vertex position, normal and (optionally)
//! UV. UVs follow the OBJ convention: `(0, 0)` is the bottom-left of the texture, `v` grows
//! upwards (texel row = `(1 - v) * height`). Vertices are split wherever an attribute differs,
//! so a UV seam is two vertices at one position.

pub mod bake;
pub mod bakes;
mod builtin;
mod fans;
pub mod frame;
pub mod gltf_import;
mod labels;
mod obj;
pub mod pick;
mod polygon;
pub mod tangents;
pub mod unwrap;

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};

pub use builtin::{cube, plane, torus, uv_sphere};
pub use gltf_import::load_gltf;
pub use labels::{Labels, Named, Run};
pub use obj::{load_obj, parse_obj, write_obj};

/// Largest mesh file accepted (bytes).
pub const MAX_FILE_BYTES: u64 = 2 << 30;

/// Largest triangle count accepted.
pub const MAX_TRIANGLES: usize = 50_000_000;

/// Why a mesh could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file is malformed, truncated or absurd.
    #[error("{path}: {reason}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
}

/// An indexed triangle mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// Name for display.
    pub name: String,
    /// Object-space positions.
    pub positions: Vec<Vec3>,
    /// Unit normals, one per vertex.
    pub normals: Vec<Vec3>,
    /// UVs, one per vertex, if the mesh has them.
    pub uvs: Option<Vec<Vec2>>,
    /// Triangles as vertex indices, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
    /// Whether the source provided normals (else they were computed).
    pub had_normals: bool,
    /// The file's names for its objects and materials, and its vertex colours.
    pub labels: Labels,
}

impl Mesh {
    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Whether the mesh can be painted: it needs UVs to map texels onto the surface.
    pub fn paintable(&self) -> Result<(), String> {
        if self.uvs.is_none() {
            return Err(format!(
                "{} has no UV coordinates: it can be previewed, but painting needs UVs to know \
                 which texel each point of the surface uses",
                self.name
            ));
        }
        Ok(())
    }

    /// The mesh as a camera and a tracer can see it: itself, or, where its scale is extreme
    /// ([`frame::UnitFrame::is_extreme`]: coordinates of 1e30, or of 1e-20), moved into its
    /// unit frame. The same shape, so a picture framed on it is the same picture.
    #[must_use]
    pub fn viewable(self) -> Self {
        let frame = frame::UnitFrame::of(&self.positions);
        if !frame.is_extreme() {
            return self;
        }
        Self {
            positions: frame.local_positions(&self.positions),
            ..self
        }
    }

    /// Checks the invariants every consumer relies on: among them, finite positions whose
    /// bounding box has a diagonal f32 can measure ([`frame::MAX_DIAGONAL`]).
    pub fn validate(&self) -> Result<(), String> {
        if self.triangles.is_empty() {
            return Err("the mesh has no triangles".into());
        }
        if self.triangles.len() > MAX_TRIANGLES {
            return Err(format!(
                "{} triangles is more than the {MAX_TRIANGLES} supported",
                self.triangles.len()
            ));
        }
        let n = self.positions.len();
        if self.normals.len() != n || self.uvs.as_ref().is_some_and(|u| u.len() != n) {
            return Err("attribute counts differ".into());
        }
        frame::UnitFrame::checked(&self.positions)?;
        if let Some(uvs) = &self.uvs
            && let Some(i) = uvs.iter().position(|t| !t.is_finite())
        {
            return Err(format!("vertex {i} has a non-finite UV"));
        }
        if let Some(t) = self
            .triangles
            .iter()
            .position(|t| t.iter().any(|&i| i as usize >= n))
        {
            return Err(format!(
                "triangle {t} refers to a vertex that does not exist"
            ));
        }
        self.labels.validate(self.triangles.len(), n)
    }

    /// Axis-aligned bounds `(min, max)`.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.positions.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        )
    }

    /// One mesh of `meshes` (at least one) side by side: their vertices and triangles in
    /// order, named after them all; UVs only where every one has them.
    ///
    /// # Errors
    /// No meshes, or more vertices than a triangle indexes.
    pub fn merged(meshes: Vec<Self>) -> Result<Self, String> {
        let mut all = meshes.into_iter();
        let mut out = all.next().ok_or("no meshes to merge")?;
        for m in all {
            let base = u32::try_from(out.positions.len())
                .ok()
                .filter(|b| b.checked_add(m.positions.len() as u32).is_some())
                .ok_or("the meshes together have more vertices than a triangle indexes")?;
            out.name = format!("{} + {}", out.name, m.name);
            out.labels = std::mem::take(&mut out.labels).followed_by(
                m.labels,
                out.triangles.len() as u32,
                out.positions.len(),
            );
            out.positions.extend(m.positions);
            out.normals.extend(m.normals);
            out.uvs = match (out.uvs.take(), m.uvs) {
                (Some(mut a), Some(b)) => {
                    a.extend(b);
                    Some(a)
                }
                _ => None,
            };
            out.triangles
                .extend(m.triangles.into_iter().map(|t| t.map(|v| v + base)));
            out.had_normals &= m.had_normals;
        }
        Ok(out)
    }

    /// A hash of what the mesh is (positions, UVs, triangles), stable across runs and
    /// builds: the key its bakes are kept under, so a changed mesh is baked again.
    pub fn content_hash(&self) -> u64 {
        use std::hash::Hasher as _;
        let mut h = fnv::FnvHasher::default();
        // Little-endian whatever the machine, so a project's key is the same everywhere.
        let mut word = |w: u32| h.write(&w.to_le_bytes());
        for p in &self.positions {
            p.to_array().into_iter().for_each(|c| word(c.to_bits()));
        }
        if let Some(uvs) = &self.uvs {
            word(u32::MAX);
            for t in uvs {
                t.to_array().into_iter().for_each(|c| word(c.to_bits()));
            }
        }
        for &i in self.triangles.iter().flatten() {
            word(i);
        }
        h.finish()
    }

    /// Per-triangle part labels: pieces of surface connected through shared positions (so a
    /// UV seam does not split a part, but separate objects of a file are separate parts).
    pub fn parts(&self) -> Vec<u32> {
        connected_triangles(self, |v| {
            self.positions[v as usize].to_array().map(f32::to_bits)
        })
    }

    /// Number of UV islands: groups of triangles connected through shared UV points (0 without
    /// UVs).
    pub fn uv_islands(&self) -> usize {
        if self.uvs.is_none() {
            return 0;
        }
        // Labels are dense from 0, so the count is one more than the largest.
        bake::triangle_islands(self)
            .iter()
            .max()
            .map_or(0, |&m| m as usize + 1)
    }
}

/// Dense labels (from 0, in order of first appearance) of the groups of triangles connected
/// through vertices with equal `key(vertex)`.
fn connected_triangles(mesh: &Mesh, key: impl Fn(u32) -> [u32; 3]) -> Vec<u32> {
    let mut ids = std::collections::HashMap::new();
    let node: Vec<usize> = (0..mesh.vertex_count() as u32)
        .map(|v| {
            let next = ids.len();
            *ids.entry(key(v)).or_insert(next)
        })
        .collect();
    let mut parent: Vec<usize> = (0..ids.len()).collect();
    for t in &mesh.triangles {
        let a = root(&mut parent, node[t[0] as usize]);
        for &v in &t[1..] {
            let b = root(&mut parent, node[v as usize]);
            parent[b] = a;
        }
    }
    let mut labels = std::collections::HashMap::new();
    mesh.triangles
        .iter()
        .map(|t| {
            let r = root(&mut parent, node[t[0] as usize]);
            let next = labels.len() as u32;
            *labels.entry(r).or_insert(next)
        })
        .collect()
}

/// The root of `i` in a union-find forest, halving paths on the way.
fn root(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Area-weighted smooth normals: faces add their normal to the group of each corner, and every
/// vertex of a group gets the group's normal. `group[v]` names the geometric vertex `v` belongs
/// to (for OBJ, its position index), so normals stay smooth across UV seams while vertices the
/// file itself split stay hard edges.
pub fn smooth_normals(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    group: &[usize],
    groups: usize,
) -> Vec<Vec3> {
    // In f64: a product of two f32 coordinates always fits (1e30 squared overflows f32, 1e-20
    // squared is below its least value), so normals are the same at any scale.
    let mut sums = vec![glam::DVec3::ZERO; groups];
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize].as_dvec3());
        let face = (b - a).cross(c - a); // length = twice the area: area weighting
        for &i in t {
            sums[group[i as usize]] += face;
        }
    }
    group
        .iter()
        .map(|&g| {
            sums[g]
                .try_normalize()
                .map_or(Vec3::Y, glam::DVec3::as_vec3)
        })
        .collect()
}

/// Reads a whole mesh file: a regular file (not a FIFO, a device or a link to one) of at most
/// [`MAX_FILE_BYTES`].
fn read_mesh_file(path: &Path) -> Result<Vec<u8>, MeshError> {
    kapaint_base::file_check::read_limited(path, MAX_FILE_BYTES).map_err(|e| match e {
        kapaint_base::file_check::FileCheck::Io(source) => MeshError::Io {
            path: path.to_path_buf(),
            source,
        },
        other => MeshError::Invalid {
            path: path.to_path_buf(),
            reason: format!("the file {other}"),
        },
    })
}

/// Names of the built-in meshes.
pub const BUILTIN_NAMES: [&str; 4] = ["sphere", "plane", "cube", "torus"];

/// The built-in mesh of that name, at the resolution the editor uses.
pub fn builtin(name: &str) -> Option<Mesh> {
    match name {
        "sphere" => Some(uv_sphere(64, 32)),
        "plane" => Some(plane()),
        "cube" => Some(cube()),
        "torus" => Some(torus(1.0, 0.35, 64, 32)),
        _ => None,
    }
}

/// A mesh by name or path: a built-in name (unless a file of that name exists), else a file.
pub fn open(spec: &Path) -> Result<Mesh, MeshError> {
    if !spec.exists()
        && let Some(m) = spec.to_str().and_then(builtin)
    {
        return Ok(m);
    }
    load(spec)
}

/// Loads a mesh file by extension (`.obj`, `.gltf`, `.glb`).
pub fn load(path: &Path) -> Result<Mesh, MeshError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("obj") => load_obj(path),
        Some("gltf" | "glb") => load_gltf(path),
        _ => Err(MeshError::Invalid {
            path: path.to_path_buf(),
            reason: "unsupported mesh format (supported: .obj, .gltf, .glb)".into(),
        }),
    }
}

/// The `kapaint mesh-info` report.
pub fn info_text(path: &Path, mesh: &Mesh) -> String {
    use std::fmt::Write as _;
    const SHOWN: usize = 12;
    let (lo, hi) = mesh.bounds();
    let names = |runs: &[Run]| {
        let named = Named::of(runs, 0).names;
        let mut list = named
            .iter()
            .take(SHOWN)
            .cloned()
            .collect::<Vec<_>>()
            .join(", ");
        if named.len() > SHOWN {
            let _ = write!(list, ", … ({} more)", named.len() - SHOWN);
        }
        format!(
            "{}{}{list}",
            named.len(),
            if named.is_empty() { "" } else { ": " }
        )
    };
    format!(
        "file: {}\nvertices: {}\ntriangles: {}\nuv islands: {}\nbounds: min ({}, {}, {}) max ({}, {}, {})\nnormals: {}\nuvs: {}\nobjects: {}\nmaterials: {}\nvertex colours: {}\n",
        path.display(),
        mesh.vertex_count(),
        mesh.triangles.len(),
        mesh.uv_islands(),
        lo.x,
        lo.y,
        lo.z,
        hi.x,
        hi.y,
        hi.z,
        if mesh.had_normals {
            "present"
        } else {
            "computed"
        },
        if mesh.uvs.is_some() {
            "present"
        } else {
            "missing"
        },
        names(&mesh.labels.objects),
        names(&mesh.labels.materials),
        if mesh.labels.colors.is_some() {
            "present"
        } else {
            "none"
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn computed_normals_are_the_same_at_every_scale() {
        let torus = torus(1.0, 0.35, 24, 12);
        let group: Vec<usize> = (0..torus.vertex_count()).collect();
        let at = |scale: f32| {
            let positions: Vec<Vec3> = torus.positions.iter().map(|&p| p * scale).collect();
            smooth_normals(&positions, &torus.triangles, &group, group.len())
        };
        let unit = at(1.0);
        for scale in [1e-20_f32, 1e30] {
            for (a, b) in unit.iter().zip(at(scale)) {
                assert!((*a - b).length() < 1e-5, "at {scale}: {a} against {b}");
            }
        }
    }
}
