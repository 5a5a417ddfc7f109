//! Built-in meshes: the UV sphere (the default preview: a real UV seam and two poles), a
//! plane, a cube and a torus. All have UVs and analytic normals, unit-ish size around the
//! origin, Y up.

use std::f32::consts::{PI, TAU};

use glam::{Vec2, Vec3};

use super::Mesh;

/// A grid of `(cols + 1) x (rows + 1)` vertices from `vertex(i, j)`, two triangles per cell,
/// wound so that `(d/di) x (d/dj)` points outwards.
fn grid(name: &str, cols: u32, rows: u32, vertex: impl Fn(u32, u32) -> (Vec3, Vec3, Vec2)) -> Mesh {
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    for j in 0..=rows {
        for i in 0..=cols {
            let (p, n, t) = vertex(i, j);
            positions.push(p);
            normals.push(n);
            uvs.push(t);
        }
    }
    let at = |i: u32, j: u32| j * (cols + 1) + i;
    let mut triangles = Vec::new();
    for j in 0..rows {
        for i in 0..cols {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1));
            for t in [[a, c, b], [b, c, d]] {
                // Skip triangles collapsed onto a pole.
                let [p, q, r] = t.map(|v| positions[v as usize]);
                if (q - p).cross(r - p).length_squared() > 1e-14 {
                    triangles.push(t);
                }
            }
        }
    }
    Mesh {
        name: name.into(),
        positions,
        normals,
        uvs: Some(uvs),
        triangles,
        had_normals: true,
        labels: crate::Labels::default(),
    }
}

/// A UV sphere of radius 1 with `segments` around and `rings` from pole to pole. The seam is
/// at `u = 0 / 1` (vertices duplicated there) and each pole is a ring of vertices.
pub fn uv_sphere(segments: u32, rings: u32) -> Mesh {
    let (segments, rings) = (segments.max(3), rings.max(2));
    grid("sphere", segments, rings, |i, j| {
        let u = i as f32 / segments as f32;
        let v = j as f32 / rings as f32;
        // The seam's two columns at the same points, bit for bit (the angle of the last
        // column is the first's), so that the surface is one piece across it.
        let phi = TAU * (i % segments) as f32 / segments as f32;
        // j = 0 is the north pole (v = 1 in OBJ convention, the top of the texture); each
        // pole's ring at the pole exactly (sin(PI) is not zero in f32).
        let (sin, cos) = match j {
            0 => (0.0, 1.0),
            j if j == rings => (0.0, -1.0),
            _ => (PI * v).sin_cos(),
        };
        let p = Vec3::new(sin * phi.cos(), cos, -sin * phi.sin());
        (p, p, Vec2::new(u, 1.0 - v))
    })
}

/// A 2 x 2 plane in XZ facing +Y, UVs over the whole texture.
pub fn plane() -> Mesh {
    grid("plane", 1, 1, |i, j| {
        let (u, v) = (i as f32, j as f32);
        (
            Vec3::new(2.0 * u - 1.0, 0.0, 2.0 * v - 1.0),
            Vec3::Y,
            Vec2::new(u, 1.0 - v),
        )
    })
}

/// A 2 x 2 x 2 cube with hard edges; its faces are laid out in a 3 x 2 atlas of UV islands
/// with a small gap between them.
pub fn cube() -> Mesh {
    let faces = [
        Vec3::X,
        Vec3::NEG_X,
        Vec3::Y,
        Vec3::NEG_Y,
        Vec3::Z,
        Vec3::NEG_Z,
    ];
    let mut mesh = Mesh {
        name: "cube".into(),
        positions: vec![],
        normals: vec![],
        uvs: Some(vec![]),
        triangles: vec![],
        had_normals: true,
        labels: crate::Labels::default(),
    };
    for (f, &n) in faces.iter().enumerate() {
        // Two tangents with t1 x t2 = n.
        let t1 = if n.y.abs() > 0.5 {
            Vec3::X
        } else {
            Vec3::Y.cross(n)
        };
        let t2 = n.cross(t1);
        let cell = Vec2::new((f % 3) as f32, (f / 3) as f32);
        let base = mesh.positions.len() as u32;
        for (a, b) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
            mesh.positions
                .push(n + t1 * (2.0 * a - 1.0) + t2 * (2.0 * b - 1.0));
            mesh.normals.push(n);
            let uv = (cell + Vec2::new(0.02 + 0.96 * a, 0.02 + 0.96 * b)) / Vec2::new(3.0, 2.0);
            if let Some(uvs) = &mut mesh.uvs {
                uvs.push(uv);
            }
        }
        mesh.triangles.push([base, base + 1, base + 2]);
        mesh.triangles.push([base + 1, base + 3, base + 2]);
    }
    mesh
}

/// A torus around Y with major radius `major` and tube radius `minor`.
pub fn torus(major: f32, minor: f32, segments: u32, sides: u32) -> Mesh {
    let (segments, sides) = (segments.max(3), sides.max(3));
    grid("torus", segments, sides, |i, j| {
        let (u, v) = (i as f32 / segments as f32, j as f32 / sides as f32);
        // The tube angle runs backwards so that the grid winds outwards; the seams' columns
        // and rows at the same points, bit for bit, as for the sphere.
        let (a, b) = (
            TAU * (i % segments) as f32 / segments as f32,
            -TAU * (j % sides) as f32 / sides as f32,
        );
        let ring = Vec3::new(a.cos(), 0.0, -a.sin());
        let n = ring * b.cos() + Vec3::Y * b.sin();
        (ring * major + n * minor, n, Vec2::new(u, v))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outward(mesh: &Mesh, center: impl Fn(Vec3) -> Vec3) -> usize {
        mesh.triangles
            .iter()
            .filter(|t| {
                let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
                let face = (b - a).cross(c - a);
                face.dot((a + b + c) / 3.0 - center((a + b + c) / 3.0)) > 0.0
            })
            .count()
    }

    #[test]
    fn builtins_are_valid_closed_and_wound_outwards() {
        let sphere = uv_sphere(64, 32);
        sphere.validate().unwrap();
        assert_eq!(outward(&sphere, |_| Vec3::ZERO), sphere.triangles.len());
        assert_eq!(sphere.uv_islands(), 1);
        let cube = cube();
        cube.validate().unwrap();
        assert_eq!(outward(&cube, |_| Vec3::ZERO), 12);
        assert_eq!(cube.uv_islands(), 6);
        let torus = torus(1.0, 0.3, 48, 24);
        torus.validate().unwrap();
        let ring_center = |p: Vec3| Vec3::new(p.x, 0.0, p.z).normalize();
        assert_eq!(outward(&torus, ring_center), torus.triangles.len());
        let plane = plane();
        plane.validate().unwrap();
        assert!(plane.triangles.iter().all(|t| {
            let [a, b, c] = t.map(|i| plane.positions[i as usize]);
            (b - a).cross(c - a).y > 0.0
        }));
    }

    #[test]
    fn sphere_has_a_seam_and_poles() {
        let s = uv_sphere(16, 8);
        // Seam: vertices at u = 0 and u = 1 share positions.
        let uvs = s.uvs.as_ref().unwrap();
        let seam: Vec<_> = (0..s.vertex_count()).filter(|&i| uvs[i].x == 0.0).collect();
        for &i in &seam {
            let twin = (0..s.vertex_count())
                .find(|&k| uvs[k].x == 1.0 && uvs[k].y == uvs[i].y)
                .unwrap();
            assert!((s.positions[i] - s.positions[twin]).length() < 1e-6);
        }
        // Normals are unit and radial.
        for (p, n) in s.positions.iter().zip(&s.normals) {
            assert!((n.length() - 1.0).abs() < 1e-5 && (p - *n).length() < 1e-5);
        }
    }
}
