//! Wavefront OBJ import (through `tobj`): every object and group, polygons triangulated
//! ([`crate::polygon`]).

use std::collections::HashMap;
use std::ops::Range;
use std::path::Path;

use glam::{Vec2, Vec3};

use super::{Labels, Mesh, MeshError, smooth_normals};

/// Loads an OBJ file. Vertices are split per distinct (position, UV, normal) index triple;
/// missing normals are computed smooth per position index.
pub fn load_obj(path: &Path) -> Result<Mesh, MeshError> {
    let bytes = super::read_mesh_file(path)?;
    let name = path
        .file_name()
        .map_or_else(|| "mesh".into(), |n| n.to_string_lossy().into_owned());
    parse_obj(&bytes, name, path)
}

/// Reads an OBJ file's bytes as [`load_obj`] does; the mesh is called `name`, errors name
/// `path`.
#[expect(
    clippy::too_many_lines,
    reason = "one pass over the file's objects; splitting it hides the flow"
)]
pub fn parse_obj(bytes: &[u8], name: String, path: &Path) -> Result<Mesh, MeshError> {
    let invalid = |reason: String| MeshError::Invalid {
        path: path.to_path_buf(),
        reason,
    };
    // Faces come as polygons and are triangulated here: tobj fans them from their first corner.
    let options = tobj::LoadOptions {
        triangulate: false,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    // Materials are not used, so `mtllib` is never followed (it could name /dev/zero or a
    // FIFO).
    let (models, _materials) =
        tobj::load_obj_buf(&mut std::io::Cursor::new(bytes), &options, |_| {
            Ok((Vec::new(), std::collections::HashMap::new()))
        })
        .map_err(|e| invalid(format!("not a valid OBJ file: {e}")))?;

    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    let mut normals = Vec::new();
    let mut group = Vec::new();
    let mut triangles = Vec::new();
    let mut colors = Vec::new();
    let mut labels = Labels::default();
    // The material of each face (`usemtl` does not split tobj's models: no material library
    // is read).
    let (material_names, material_changes) = face_materials(bytes);
    let (mut face_count, mut material, mut next_change) = (0_usize, None, 0);
    let mut position_base = 0usize;
    let (mut any_uv, mut all_uv, mut all_normals) = (false, true, true);
    let mut all_colors = true;
    for model in &models {
        let m = &model.mesh;
        let count = m.positions.len() / 3;
        // No arities: every face is a triangle.
        let arities: Vec<usize> = if m.face_arities.is_empty() {
            vec![3; m.indices.len() / 3]
        } else {
            m.face_arities.iter().map(|&a| a as usize).collect()
        };
        if arities.iter().sum::<usize>() != m.indices.len() {
            return Err(invalid(format!(
                "object {:?} has faces whose corners do not add up",
                model.name
            )));
        }
        let has_color = !m.vertex_color.is_empty();
        all_colors &= has_color;
        let first_triangle = triangles.len() as u32;
        let has_uv = !m.texcoord_indices.is_empty();
        let has_n = !m.normal_indices.is_empty();
        if (has_uv && m.texcoord_indices.len() != m.indices.len())
            || (has_n && m.normal_indices.len() != m.indices.len())
        {
            return Err(invalid(format!(
                "object {:?} mixes faces with and without UVs or normals",
                model.name
            )));
        }
        any_uv |= has_uv;
        all_uv &= has_uv;
        all_normals &= has_n;
        let mut map: HashMap<(u32, u32, u32), u32> = HashMap::new();
        let mut corner = |k: usize| -> Result<u32, MeshError> {
            let p = m.indices[k];
            let t = if has_uv {
                m.texcoord_indices[k]
            } else {
                u32::MAX
            };
            let nn = if has_n { m.normal_indices[k] } else { u32::MAX };
            if p as usize >= count {
                return Err(invalid(format!(
                    "a face refers to vertex {} of {count}",
                    p + 1
                )));
            }
            if let Some(&v) = map.get(&(p, t, nn)) {
                return Ok(v);
            }
            let v =
                u32::try_from(positions.len()).map_err(|_| invalid("too many vertices".into()))?;
            let pi = p as usize * 3;
            positions.push(Vec3::new(
                m.positions[pi],
                m.positions[pi + 1],
                m.positions[pi + 2],
            ));
            group.push(position_base + p as usize);
            if has_color {
                let c = m.vertex_color.get(pi..pi + 3).unwrap_or(&[1.0; 3]);
                colors.push(Vec3::new(c[0], c[1], c[2]));
            }
            if has_uv {
                let ti = t as usize * 2;
                let uv = m.texcoords.get(ti..ti + 2).ok_or_else(|| {
                    invalid(format!(
                        "a face refers to UV {} of {}",
                        t + 1,
                        m.texcoords.len() / 2
                    ))
                })?;
                uvs.push(Vec2::new(uv[0], uv[1]));
            } else {
                uvs.push(Vec2::ZERO);
            }
            if has_n {
                let ni = nn as usize * 3;
                let n = m.normals.get(ni..ni + 3).ok_or_else(|| {
                    invalid(format!(
                        "a face refers to normal {} of {}",
                        nn + 1,
                        m.normals.len() / 3
                    ))
                })?;
                normals.push(Vec3::new(n[0], n[1], n[2]));
            } else {
                normals.push(Vec3::ZERO);
            }
            map.insert((p, t, nn), v);
            Ok(v)
        };
        let mut first = 0;
        for arity in arities {
            let face = first..first + arity;
            first += arity;
            let before = triangles.len() as u32;
            for [a, b, c] in face_triangles(m, face).map_err(&invalid)? {
                triangles.push([corner(a)?, corner(b)?, corner(c)?]);
            }
            while let Some(&(from, k)) = material_changes.get(next_change)
                && from <= face_count
            {
                material = Some(k);
                next_change += 1;
            }
            if let Some(k) = material {
                let run = before..triangles.len() as u32;
                Labels::push(&mut labels.materials, &material_names[k], run);
            }
            face_count += 1;
        }
        // tobj's name for faces before any `o` or `g` (or after a bare one).
        if !model.name.is_empty() && model.name != "unnamed_object" {
            let run = first_triangle..triangles.len() as u32;
            Labels::push(&mut labels.objects, &model.name, run);
        }
        position_base += count;
    }
    if any_uv && !all_uv {
        return Err(invalid("some objects have UVs and others do not".into()));
    }
    let had_normals = all_normals
        && !triangles.is_empty()
        && normals
            .iter()
            .all(|n: &Vec3| n.is_finite() && n.length_squared() > 0.0);
    let normals = if had_normals {
        // A unit normal is kept bit for bit (normalising it again moves its last bits, and a
        // mesh written and read back must be the same mesh).
        normals
            .into_iter()
            .map(|n| {
                if (n.length_squared() - 1.0).abs() < 1e-6 {
                    n
                } else {
                    n.normalize()
                }
            })
            .collect()
    } else {
        smooth_normals(&positions, &triangles, &group, position_base)
    };
    labels.colors = (all_colors && !positions.is_empty()).then_some(colors);
    let mesh = Mesh {
        name,
        positions,
        normals,
        uvs: any_uv.then_some(uvs),
        triangles,
        had_normals,
        labels,
    };
    mesh.validate().map_err(invalid)?;
    Ok(mesh)
}

/// The corners (indices into the model's face indices) of the triangles face `face` of `m`
/// splits into: a triangle or a quad as tobj splits them (the meshes that always loaded load
/// the same), a larger polygon by [`crate::polygon::triangulate`].
fn face_triangles(m: &tobj::Mesh, face: Range<usize>) -> Result<Vec<[usize; 3]>, String> {
    let k = face.start;
    match face.len() {
        0..3 => Ok(Vec::new()),
        3 => Ok(vec![[k, k + 1, k + 2]]),
        4 => Ok(vec![[k, k + 1, k + 2], [k, k + 2, k + 3]]),
        _ => {
            let count = m.positions.len() / 3;
            let positions_of: Vec<Vec3> = m.indices[face]
                .iter()
                .map(|&p| {
                    let pi = p as usize * 3;
                    m.positions
                        .get(pi..pi + 3)
                        .map(|c| Vec3::new(c[0], c[1], c[2]))
                        .ok_or_else(|| format!("a face refers to vertex {} of {count}", p + 1))
                })
                .collect::<Result<_, _>>()?;
            Ok(crate::polygon::triangulate(&positions_of)
                .into_iter()
                .map(|t| t.map(|i| k + i as usize))
                .collect())
        }
    }
}

/// The materials `usemtl` names, and where each takes over: `(face, material)`, faces counted
/// as tobj keeps them (`f` lines of three corners or more), in order.
fn face_materials(bytes: &[u8]) -> (Vec<String>, Vec<(usize, usize)>) {
    let mut names: Vec<String> = Vec::new();
    let mut changes = Vec::new();
    let mut faces = 0;
    for line in bytes.split(|&b| b == b'\n') {
        let line = line.trim_ascii();
        if !matches!(line.first(), Some(b'f' | b'u')) {
            continue;
        }
        let line = String::from_utf8_lossy(line);
        let mut words = line.split_whitespace();
        match words.next() {
            Some("f") if words.count() >= 3 => faces += 1,
            Some("usemtl") => {
                let name = line["usemtl".len()..].trim();
                if !name.is_empty() {
                    let k = names.iter().position(|n| n == name).unwrap_or_else(|| {
                        names.push(name.to_string());
                        names.len() - 1
                    });
                    changes.push((faces, k));
                }
            }
            _ => {}
        }
    }
    (names, changes)
}

/// The mesh as an OBJ file: positions, UVs (if any) and normals, one vertex each, and its
/// triangles. Vertices are written in the order the triangles first use them (the order
/// [`parse_obj`] gives them), so a written mesh reads back to itself and writes the same bytes
/// again; a vertex no triangle uses is left out.
pub fn write_obj(mesh: &Mesh) -> String {
    use std::fmt::Write;
    let mut new_index = vec![u32::MAX; mesh.vertex_count()];
    let mut order = Vec::with_capacity(mesh.vertex_count());
    for &v in mesh.triangles.iter().flatten() {
        if new_index[v as usize] == u32::MAX {
            new_index[v as usize] = order.len() as u32;
            order.push(v as usize);
        }
    }
    let mut out = String::with_capacity(order.len() * 96 + mesh.triangles.len() * 40);
    let _ = writeln!(
        out,
        "# {} written by kapaint {}",
        mesh.name.replace(['\n', '\r'], " "),
        env!("CARGO_PKG_VERSION")
    );
    // `{}` prints the shortest text that reads back to the same f32.
    for &v in &order {
        let p = mesh.positions[v];
        let _ = writeln!(out, "v {} {} {}", p.x, p.y, p.z);
    }
    if let Some(uvs) = &mesh.uvs {
        for &v in &order {
            let _ = writeln!(out, "vt {} {}", uvs[v].x, uvs[v].y);
        }
    }
    for &v in &order {
        let n = mesh.normals[v];
        let _ = writeln!(out, "vn {} {} {}", n.x, n.y, n.z);
    }
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| new_index[i as usize] + 1);
        let _ = if mesh.uvs.is_some() {
            writeln!(out, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}")
        } else {
            writeln!(out, "f {a}//{a} {b}//{b} {c}//{c}")
        };
    }
    out
}
