//! glTF 2.0 import (`.gltf` with its buffers, or `.glb`) through the `gltf` crate.
//!
//! Every mesh and primitive the scene instantiates, with node transforms applied (normals by
//! the inverse transpose; mirrored nodes keep their triangles facing out). Triangle strips
//! and fans are unrolled; points and lines are skipped. A primitive without normals gets
//! smooth normals over the vertices it shares, so the vertices the file splits stay hard
//! edges (a fully split primitive comes out flat, as the glTF specification describes). Accessors are checked against their buffers
//! before anything is read, so a hostile file is an error, never a panic.

use std::path::Path;

use glam::{Mat3, Mat4, Vec2, Vec3};
use gltf::Semantic;
use gltf::accessor::{DataType as T, Dimensions as D};
use gltf::mesh::Mode;

use super::{MAX_TRIANGLES, Mesh, MeshError};

mod open;

pub use self::open::{KHR_TEXTURE_BASISU, Opened, file_beside, names_basisu, open_gltf};

/// Deepest node hierarchy followed (deeper means a cycle or an absurd file).
const MAX_DEPTH: usize = 64;

/// Loads a `.gltf` or `.glb` file.
pub fn load_gltf(path: &Path) -> Result<Mesh, MeshError> {
    let invalid = |reason: String| MeshError::Invalid {
        path: path.to_path_buf(),
        reason,
    };
    let Opened {
        document, buffers, ..
    } = open_gltf(path)?;
    let buffers: Vec<&[u8]> = buffers.iter().map(Vec::as_slice).collect();

    // The default scene (else the first; else every mesh once, untransformed). A node graph
    // can reuse a node many times (2^40 instances from 40 nodes), so what the scene would
    // instantiate is counted before anything is expanded.
    let mut instances: Vec<Instance<'_>> = Vec::new();
    match document
        .default_scene()
        .or_else(|| document.scenes().next())
    {
        Some(scene) => {
            let mut counts = vec![None; document.nodes().len()];
            let total = scene
                .nodes()
                .try_fold(Count::default(), |sum, node| {
                    Ok::<_, String>(sum.add(count(&node, 0, &mut counts)?))
                })
                .map_err(&invalid)?;
            if total.triangles > MAX_TRIANGLES as u64 || total.instances > MAX_INSTANCES {
                return Err(invalid(format!(
                    "the scene instantiates {} meshes with {} triangles (nodes are reused), more than the {MAX_INSTANCES} instances and {MAX_TRIANGLES} triangles supported",
                    total.instances, total.triangles
                )));
            }
            for node in scene.nodes() {
                collect(&node, Mat4::IDENTITY, 0, &mut instances).map_err(&invalid)?;
            }
        }
        None => instances.extend(document.meshes().map(|m| Instance {
            name: m.name().map(str::to_string),
            mesh: m,
            transform: Mat4::IDENTITY,
        })),
    }

    let mut out = Builder::default();
    for instance in &instances {
        let mesh = &instance.mesh;
        let first = out.triangles.len() as u32;
        for (k, primitive) in mesh.primitives().enumerate() {
            let what = format!("mesh {:?} primitive {k}", mesh.name().unwrap_or("unnamed"));
            out.add(&primitive, instance.transform, &buffers)
                .map_err(|e| invalid(format!("{what}: {e}")))?;
        }
        if let Some(name) = &instance.name {
            let run = first..out.triangles.len() as u32;
            super::Labels::push(&mut out.labels.objects, name, run);
        }
    }
    let name = path
        .file_name()
        .map_or_else(|| "mesh".into(), |n| n.to_string_lossy().into_owned());
    let mesh = out.finish(name);
    mesh.validate().map_err(invalid)?;
    Ok(mesh)
}

/// Most mesh instances a scene may create.
const MAX_INSTANCES: u64 = 1_000_000;

/// What a node and its subtree instantiate (saturating: a hostile graph overflows `u64`).
#[derive(Clone, Copy, Debug, Default)]
struct Count {
    instances: u64,
    triangles: u64,
}

impl Count {
    fn add(self, other: Self) -> Self {
        Self {
            instances: self.instances.saturating_add(other.instances),
            triangles: self.triangles.saturating_add(other.triangles),
        }
    }
}

/// Triangles one instance of `mesh` adds, from its accessors' counts (nothing is read).
fn mesh_triangles(mesh: &gltf::Mesh<'_>) -> u64 {
    mesh.primitives()
        .map(|p| {
            let corners = p
                .indices()
                .map(|a| a.count())
                .or_else(|| p.get(&Semantic::Positions).map(|a| a.count()))
                .unwrap_or(0) as u64;
            match p.mode() {
                Mode::Triangles => corners / 3,
                Mode::TriangleStrip | Mode::TriangleFan => corners.saturating_sub(2),
                _ => 0,
            }
        })
        .fold(0, u64::saturating_add)
}

/// What `node` instantiates, memoised per node (so a node reused a billion times is counted
/// once); the depth bound catches cycles.
fn count(node: &gltf::Node<'_>, depth: usize, memo: &mut [Option<Count>]) -> Result<Count, String> {
    if depth > MAX_DEPTH {
        return Err(format!(
            "the node hierarchy is deeper than {MAX_DEPTH} (a cycle?)"
        ));
    }
    if let Some(Some(c)) = memo.get(node.index()) {
        return Ok(*c);
    }
    let own = node.mesh().map_or(Count::default(), |m| Count {
        instances: 1,
        triangles: mesh_triangles(&m),
    });
    let total = node.children().try_fold(own, |sum, child| {
        Ok::<_, String>(sum.add(count(&child, depth + 1, memo)?))
    })?;
    if let Some(slot) = memo.get_mut(node.index()) {
        *slot = Some(total);
    }
    Ok(total)
}

/// A mesh the scene places: the name of the node that places it (else the mesh's own), and
/// where.
struct Instance<'a> {
    name: Option<String>,
    mesh: gltf::Mesh<'a>,
    transform: Mat4,
}

/// Walks the node tree, accumulating transforms.
fn collect<'a>(
    node: &gltf::Node<'a>,
    parent: Mat4,
    depth: usize,
    out: &mut Vec<Instance<'a>>,
) -> Result<(), String> {
    if depth > MAX_DEPTH {
        return Err(format!(
            "the node hierarchy is deeper than {MAX_DEPTH} (a cycle?)"
        ));
    }
    let local = Mat4::from_cols_array_2d(&node.transform().matrix());
    let world = parent * local;
    if !world.is_finite() {
        return Err(format!("node {} has a non-finite transform", node.index()));
    }
    if let Some(mesh) = node.mesh() {
        out.push(Instance {
            name: node.name().or(mesh.name()).map(str::to_string),
            mesh,
            transform: world,
        });
    }
    for child in node.children() {
        collect(&child, world, depth + 1, out)?;
    }
    Ok(())
}

/// Checks that an accessor has a type `allowed` and that its elements lie inside its buffer view and the view inside its
/// buffer, with overflow-free arithmetic, before the reader touches them.
fn check_accessor(
    accessor: &gltf::Accessor<'_>,
    buffers: &[&[u8]],
    allowed: &[(T, D)],
) -> Result<(), String> {
    let name = format!("accessor {}", accessor.index());
    let kind = (accessor.data_type(), accessor.dimensions());
    if !allowed.contains(&kind) {
        return Err(format!(
            "{name} holds {:?} {:?}, which this attribute cannot be",
            kind.0, kind.1
        ));
    }
    if accessor.sparse().is_some() {
        return Err(format!(
            "{name} is sparse, which is not supported for geometry"
        ));
    }
    let view = accessor
        .view()
        .ok_or_else(|| format!("{name} has no buffer view (no data)"))?;
    let count = accessor.count();
    if count == 0 {
        return Err(format!("{name} is empty"));
    }
    let size = accessor.size();
    let stride = view.stride().unwrap_or(size);
    let end = stride
        .checked_mul(count - 1)
        .and_then(|v| v.checked_add(size))
        .and_then(|v| v.checked_add(accessor.offset()))
        .ok_or_else(|| format!("{name} claims an absurd size ({count} elements)"))?;
    if end > view.length() {
        return Err(format!(
            "{name} needs {end} bytes but its buffer view holds {}",
            view.length()
        ));
    }
    let buffer = buffers
        .get(view.buffer().index())
        .ok_or_else(|| format!("{name} refers to a missing buffer"))?;
    let view_end = view
        .offset()
        .checked_add(view.length())
        .ok_or_else(|| format!("buffer view {} claims an absurd size", view.index()))?;
    if view_end > buffer.len() {
        return Err(format!(
            "buffer view {} ends at byte {view_end} but its buffer holds {} (truncated?)",
            view.index(),
            buffer.len()
        ));
    }
    Ok(())
}

/// A primitive's material by name (else by number; the default material where it names none).
fn material_name(primitive: &gltf::Primitive<'_>) -> String {
    let material = primitive.material();
    match (material.name(), material.index()) {
        (Some(name), _) => name.to_string(),
        (None, Some(i)) => format!("material {i}"),
        (None, None) => "default material".to_string(),
    }
}

/// Merges primitives into one mesh.
#[derive(Default)]
struct Builder {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    triangles: Vec<[u32; 3]>,
    any_uv: bool,
    missing_normals: bool,
    labels: super::Labels,
    /// Per vertex, its colour (white where a primitive has none); whether any has them.
    colors: Vec<Vec3>,
    any_color: bool,
}

impl Builder {
    fn add(
        &mut self,
        primitive: &gltf::Primitive<'_>,
        transform: Mat4,
        buffers: &[&[u8]],
    ) -> Result<(), String> {
        let mode = primitive.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            return Ok(()); // points and lines have no surface
        }
        // The reader hits `unreachable!` on a type the specification does not allow, so the
        // types of what is read are checked here as well as the bounds.
        for (semantic, accessor) in primitive.attributes() {
            let allowed: &[(T, D)] = match semantic {
                Semantic::Positions | Semantic::Normals => &[(T::F32, D::Vec3)],
                Semantic::TexCoords(0) => &[(T::F32, D::Vec2), (T::U8, D::Vec2), (T::U16, D::Vec2)],
                Semantic::Colors(0) => &[
                    (T::F32, D::Vec3),
                    (T::F32, D::Vec4),
                    (T::U8, D::Vec3),
                    (T::U8, D::Vec4),
                    (T::U16, D::Vec3),
                    (T::U16, D::Vec4),
                ],
                _ => continue, // not read
            };
            check_accessor(&accessor, buffers, allowed)?;
        }
        if let Some(indices) = primitive.indices() {
            check_accessor(
                &indices,
                buffers,
                &[(T::U8, D::Scalar), (T::U16, D::Scalar), (T::U32, D::Scalar)],
            )?;
        }
        let reader = primitive.reader(|b| buffers.get(b.index()).copied());
        let positions: Vec<Vec3> = reader
            .read_positions()
            .ok_or("has no POSITION attribute")?
            .map(Vec3::from)
            .collect();
        let count = positions.len();
        let normals: Option<Vec<Vec3>> = reader.read_normals().map(|n| n.map(Vec3::from).collect());
        let uvs: Option<Vec<Vec2>> = reader
            .read_tex_coords(0)
            .map(|t| t.into_f32().map(|[u, v]| Vec2::new(u, 1.0 - v)).collect());
        let colors: Option<Vec<Vec3>> = reader
            .read_colors(0)
            .map(|c| c.into_rgb_f32().map(Vec3::from).collect());
        if normals.as_ref().is_some_and(|n| n.len() != count)
            || uvs.as_ref().is_some_and(|t| t.len() != count)
            || colors.as_ref().is_some_and(|c| c.len() != count)
        {
            return Err("attribute counts differ".into());
        }
        let indices: Vec<u32> = match reader.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..u32::try_from(count).map_err(|_| "too many vertices")?).collect(),
        };
        if let Some(bad) = indices.iter().find(|&&i| i as usize >= count) {
            return Err(format!("index {bad} is out of range for {count} vertices"));
        }
        let corners = unroll(mode, &indices);
        if self.triangles.len() + corners.len() > MAX_TRIANGLES {
            return Err(format!("more than the {MAX_TRIANGLES} triangles supported"));
        }
        let normal_matrix = Mat3::from_mat4(transform).inverse().transpose();
        let flip = transform.determinant() < 0.0;
        let base = u32::try_from(self.positions.len()).map_err(|_| "too many vertices")?;
        let world: Vec<Vec3> = positions
            .iter()
            .map(|&p| transform.transform_point3(p))
            .collect();
        self.missing_normals |= normals.is_none();
        self.any_uv |= uvs.is_some();
        // A missing UV set reads as (0, 0): those triangles have no texels to paint.
        let uv_of = |i: usize| uvs.as_ref().map_or(Vec2::ZERO, |t| t[i]);
        let triangles: Vec<[u32; 3]> = corners
            .iter()
            .map(|&[a, b, c]| if flip { [a, c, b] } else { [a, b, c] })
            .collect();
        let vertex_normals: Vec<Vec3> = if let Some(n) = &normals {
            n.iter()
                .map(|&v| (normal_matrix * v).try_normalize().unwrap_or(Vec3::Y))
                .collect()
        } else {
            // Smooth normals over the vertices the file shares; where it splits a vertex
            // (a hard edge, a UV seam) the copies keep their own side's normal.
            let identity: Vec<usize> = (0..count).collect();
            super::smooth_normals(&world, &triangles, &identity, count)
        };
        for i in 0..count {
            self.positions.push(world[i]);
            self.normals.push(vertex_normals[i]);
            self.uvs.push(uv_of(i));
            self.colors
                .push(colors.as_ref().map_or(Vec3::ONE, |c| c[i]));
        }
        self.any_color |= colors.is_some();
        let first = self.triangles.len() as u32;
        self.triangles
            .extend(triangles.iter().map(|t| t.map(|i| base + i)));
        let run = first..self.triangles.len() as u32;
        super::Labels::push(&mut self.labels.materials, &material_name(primitive), run);
        Ok(())
    }

    fn finish(self, name: String) -> Mesh {
        Mesh {
            name,
            positions: self.positions,
            normals: self.normals,
            uvs: self.any_uv.then_some(self.uvs),
            triangles: self.triangles,
            had_normals: !self.missing_normals,
            labels: super::Labels {
                colors: self.any_color.then_some(self.colors),
                ..self.labels
            },
        }
    }
}

/// Triangles of a triangle list, strip or fan.
fn unroll(mode: Mode, indices: &[u32]) -> Vec<[u32; 3]> {
    match mode {
        Mode::TriangleStrip => indices
            .windows(3)
            .enumerate()
            .map(|(k, w)| {
                if k % 2 == 0 {
                    [w[0], w[1], w[2]]
                } else {
                    [w[1], w[0], w[2]]
                }
            })
            .collect(),
        Mode::TriangleFan => indices
            .windows(2)
            .skip(1)
            .map(|w| [indices[0], w[0], w[1]])
            .collect(),
        _ => indices
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect(),
    }
}
