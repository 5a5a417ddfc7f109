//! MikkTSpace tangents (the `bevy_mikktspace` crate): the tangent frame a tangent-space
//! normal map is read in, the one glTF tools and bakers use when a mesh brings none.
//!
//! They are computed in kapaint's UV convention (`v` up, the image's up), so the bitangent
//! `w (N x T)` points up the image, where a glTF normal map's green channel points. MikkTSpace
//! gives each triangle corner its own tangent; where the corners of one vertex disagree (UV
//! seams, mirrored islands) the vertex is split, so every vertex carries one tangent.

use glam::{Vec2, Vec3};

use super::Mesh;

/// A mesh with one tangent per vertex: `xyz` the unit tangent, `w` the bitangent's sign.
pub struct Tangents {
    /// The mesh, vertices split where their corners' tangents differ.
    pub mesh: Mesh,
    /// One tangent per vertex of `mesh`.
    pub tangents: Vec<[f32; 4]>,
}

/// The crate's view of a mesh, and where it writes each corner's tangent.
struct Corners<'a> {
    mesh: &'a Mesh,
    uvs: &'a [Vec2],
    out: Vec<[f32; 4]>,
}

impl bevy_mikktspace::Geometry for Corners<'_> {
    fn num_faces(&self) -> usize {
        self.mesh.triangles.len()
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.positions[self.mesh.triangles[face][vert] as usize].to_array()
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.normals[self.mesh.triangles[face][vert] as usize].to_array()
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        self.uvs[self.mesh.triangles[face][vert] as usize].to_array()
    }

    fn set_tangent(
        &mut self,
        tangent_space: Option<bevy_mikktspace::TangentSpace>,
        face: usize,
        vert: usize,
    ) {
        if let Some(t) = tangent_space {
            self.out[face * 3 + vert] = t.tangent_encoded();
        }
    }
}

/// A unit tangent perpendicular to `n`, for corners MikkTSpace leaves without one
/// (degenerate UVs).
fn any_tangent(n: Vec3) -> [f32; 4] {
    let t = n.any_orthonormal_vector();
    [t.x, t.y, t.z, 1.0]
}

/// The mesh's MikkTSpace tangents, vertices split where needed (see the module docs); `None`
/// for a mesh without UVs.
pub fn generate(mesh: &Mesh) -> Option<Tangents> {
    let uvs = mesh.uvs.as_deref()?;
    let mut corners = Corners {
        mesh,
        uvs,
        out: vec![[0.0; 4]; mesh.triangles.len() * 3],
    };
    // The crate's error type has no variants: it cannot fail.
    let _ = bevy_mikktspace::generate_tangents(&mut corners);
    let mut out = Mesh {
        name: mesh.name.clone(),
        positions: Vec::with_capacity(mesh.positions.len()),
        normals: Vec::with_capacity(mesh.positions.len()),
        uvs: Some(Vec::with_capacity(mesh.positions.len())),
        triangles: Vec::with_capacity(mesh.triangles.len()),
        had_normals: mesh.had_normals,
        labels: crate::Labels::default(),
    };
    let mut tangents: Vec<[f32; 4]> = Vec::with_capacity(mesh.positions.len());
    // Per source vertex, the new vertices made of it so far (usually one).
    let mut made: Vec<Vec<u32>> = vec![Vec::new(); mesh.positions.len()];
    for (f, tri) in mesh.triangles.iter().enumerate() {
        let mut new = [0_u32; 3];
        for (k, &v) in tri.iter().enumerate() {
            let vi = v as usize;
            let mut t = corners.out[f * 3 + k];
            if Vec3::new(t[0], t[1], t[2]).length_squared() < 0.5 {
                t = any_tangent(mesh.normals[vi]);
            }
            let same = |u: &u32| {
                let o = tangents[*u as usize];
                let (a, b) = (Vec3::new(o[0], o[1], o[2]), Vec3::new(t[0], t[1], t[2]));
                o[3] == t[3] && a.dot(b) > 0.9999
            };
            new[k] = if let Some(&u) = made[vi].iter().find(|u| same(u)) {
                u
            } else {
                let u = u32::try_from(out.positions.len()).unwrap_or(u32::MAX);
                out.positions.push(mesh.positions[vi]);
                out.normals.push(mesh.normals[vi]);
                if let Some(uv) = out.uvs.as_mut() {
                    uv.push(uvs[vi]);
                }
                tangents.push(t);
                made[vi].push(u);
                u
            };
        }
        out.triangles.push(new);
    }
    Some(Tangents {
        mesh: out,
        tangents,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plane_gets_its_u_direction_and_a_right_handed_frame() {
        let plane = crate::builtin("plane").expect("plane");
        let t = generate(&plane).expect("tangents");
        assert_eq!(t.tangents.len(), t.mesh.positions.len());
        assert_eq!(t.mesh.triangles.len(), plane.triangles.len());
        // One tangent everywhere on a flat, unmirrored plane: no vertex split.
        assert_eq!(t.mesh.positions.len(), plane.positions.len());
        for (tan, n) in t.tangents.iter().zip(&t.mesh.normals) {
            let tv = Vec3::new(tan[0], tan[1], tan[2]);
            assert!((tv.length() - 1.0).abs() < 1e-4);
            assert!(tv.dot(*n).abs() < 1e-4);
        }
        // The tangent follows +u: along the edge from a vertex to one with a larger u only.
        let uvs = t.mesh.uvs.as_deref().unwrap_or_default();
        let [a, b, c] = t.mesh.triangles[0].map(|i| i as usize);
        let (pa, pb, pc) = (
            t.mesh.positions[a],
            t.mesh.positions[b],
            t.mesh.positions[c],
        );
        let (ua, ub, uc) = (uvs[a], uvs[b], uvs[c]);
        // dP/du from the triangle's two edges.
        let (e1, e2) = (pb - pa, pc - pa);
        let (d1, d2) = (ub - ua, uc - ua);
        let det = d1.x * d2.y - d2.x * d1.y;
        let dpdu = (e1 * d2.y - e2 * d1.y) / det;
        let tan = t.tangents[a];
        assert!(Vec3::new(tan[0], tan[1], tan[2]).dot(dpdu.normalize()) > 0.999);
        assert_eq!(tan[3], 1.0, "an unmirrored mapping is right-handed");
    }

    #[test]
    fn a_mirrored_seam_splits_its_vertices_and_a_mesh_without_uvs_has_none() {
        // Two triangles sharing an edge, the second's UVs mirrored in u.
        let mesh = Mesh {
            name: "mirror".into(),
            positions: vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(-1.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
            ],
            normals: vec![Vec3::Z; 4],
            uvs: Some(vec![
                Vec2::new(0.5, 0.0),
                Vec2::new(0.5, 1.0),
                Vec2::new(0.0, 0.0),
                Vec2::new(0.0, 0.0),
            ]),
            triangles: vec![[2, 0, 1], [0, 3, 1]],
            had_normals: true,
            labels: crate::Labels::default(),
        };
        let t = generate(&mesh).expect("tangents");
        assert!(t.mesh.positions.len() > 4, "the shared edge splits");
        let signs: Vec<f32> = t.tangents.iter().map(|t| t[3]).collect();
        assert!(signs.contains(&1.0) && signs.contains(&-1.0), "{signs:?}");
        let bare = Mesh { uvs: None, ..mesh };
        assert!(generate(&bare).is_none());
    }
}
