//! Automatic UVs: an atlas for a mesh that has no UVs, or whose UVs overlap, from the
//! `uvunwrap` crate (charts grown within a normal cone, flattened by LSCM and ARAP, packed by
//! shape). Charts are padded for the map they will be painted at, never overlap, and keep one
//! texel density over the whole surface.
//!
//! kapaint keeps OBJ's UV convention (`v` up, texel row `(1 - v) * height`); uvunwrap's `v`
//! grows with the row, so its `v` is flipped on the way out. Vertices on chart seams are split;
//! each keeps its source vertex's position and normal.

use glam::{Vec2, Vec3};
use kapaint_base::task::Progress;

use super::Mesh;

/// Bytes of work memory the unwrapper takes per triangle, measured high (charts, solver,
/// packing rasters), for the memory check before a large mesh.
const BYTES_PER_TRIANGLE: u64 = 1024;

/// The largest page the charts are packed on: a larger map gets the same layout scaled up,
/// its padding scaled down with it (packing a 2048 page took 4 times as long as a 1024 one
/// for 2 % more of the map covered).
const MAX_PACK_PAGE: u32 = 1024;

/// How the atlas is laid out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnwrapOptions {
    /// The map's side in texels: charts are packed for it.
    pub size: u32,
    /// Empty texels around each chart at that size (charts are twice this apart).
    pub padding: u32,
}

impl UnwrapOptions {
    /// For a map `size` texels a side: 2 texels of padding per 512 (4 at 1024, 8 at 2048),
    /// never less than 4, so mips down to 1/4 size keep charts apart.
    pub fn for_size(size: u32) -> Self {
        Self {
            size,
            padding: (size / 256).clamp(4, 16),
        }
    }
}

/// An unwrapped mesh and what its atlas is like.
#[derive(Clone, Debug)]
pub struct Unwrapped {
    /// The mesh with its new UVs (seam vertices split).
    pub mesh: Mesh,
    /// Charts in the atlas.
    pub charts: u32,
    /// Fraction of the map covered by the surface (the UV triangles' area; no overlap).
    pub coverage: f32,
}

/// Unwraps `mesh` into a new atlas (its own UVs, if any, are ignored). `progress` follows the
/// stages and cancels the work.
///
/// # Errors
/// A mesh with nothing to chart (only degenerate triangles), non-finite positions, more
/// triangles than the memory left can unwrap, or cancelled.
pub fn unwrap(
    mesh: &Mesh,
    options: UnwrapOptions,
    progress: Option<&Progress>,
) -> Result<Unwrapped, String> {
    if !(64..=16384).contains(&options.size) {
        return Err(format!(
            "an atlas of {} texels a side is outside 64 to 16384",
            options.size
        ));
    }
    if let Some(i) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(format!("vertex {i} has a non-finite position"));
    }
    kapaint_base::memory::check_fits(
        &format!("unwrapping {} triangles", mesh.triangles.len()),
        mesh.triangles.len() as u64 * BYTES_PER_TRIANGLE,
    )?;
    let positions: Vec<[f32; 3]> = mesh.positions.iter().map(Vec3::to_array).collect();
    let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    let input = uvunwrap::MeshInput::new(&positions, &indices);
    let page = options.size.min(MAX_PACK_PAGE);
    let settings = uvunwrap::Options {
        density: uvunwrap::Density::Auto { page_size: page },
        // At least the map's padding once scaled up to it.
        padding: (options.padding * page).div_ceil(options.size),
        ..uvunwrap::Options::default()
    };
    let report = |p: uvunwrap::Progress| {
        let Some(progress) = progress else {
            return true;
        };
        let stage = match p.stage {
            uvunwrap::Stage::Segmenting => "chart",
            uvunwrap::Stage::Parameterizing => "flatten",
            uvunwrap::Stage::Packing => "pack",
            _ => "write",
        };
        if progress.stage() != stage {
            progress.start(stage, p.total.unwrap_or(0) as u64);
        }
        let done = p.done as u64;
        progress.advance(done.saturating_sub(progress.done()));
        !progress.is_cancelled()
    };
    let atlas = uvunwrap::generate_with_progress(&[input], &settings, report).map_err(|e| {
        if e == uvunwrap::Error::Cancelled {
            "cancelled".to_string()
        } else {
            format!("the mesh could not be unwrapped: {e}")
        }
    })?;
    if atlas.chart_count == 0 {
        return Err("the mesh has no triangle with an area to chart (all degenerate)".into());
    }
    let out = atlas
        .meshes
        .into_iter()
        .next()
        .ok_or("the unwrapper returned no mesh")?;
    // UVs are in the (possibly cropped) page: scale them to the map, density kept the same
    // both ways, and flip `v` to kapaint's convention.
    let side = page as f32;
    let scale = Vec2::new(atlas.width as f32 / side, atlas.height as f32 / side);
    // Vertices in the order the triangles first use them: the order an OBJ reader gives them,
    // so the mesh a project keeps reads back as itself.
    let mut new_index = vec![u32::MAX; out.vertices.len()];
    let mut positions = Vec::with_capacity(out.vertices.len());
    let mut normals = Vec::with_capacity(out.vertices.len());
    let mut uvs = Vec::with_capacity(out.vertices.len());
    let mut triangles = Vec::with_capacity(out.indices.len() / 3);
    for t in out.indices.chunks_exact(3) {
        let mut corners = [0u32; 3];
        for (corner, &i) in corners.iter_mut().zip(t) {
            let slot = &mut new_index[i as usize];
            if *slot == u32::MAX {
                let v = &out.vertices[i as usize];
                let from = v.xref as usize;
                *slot = positions.len() as u32;
                positions.push(mesh.positions[from]);
                normals.push(mesh.normals.get(from).copied().unwrap_or(Vec3::Z));
                let uv = Vec2::from(v.uv) * scale;
                uvs.push(Vec2::new(uv.x, 1.0 - uv.y));
            }
            *corner = *slot;
        }
        triangles.push(corners);
    }
    let unwrapped = Mesh {
        name: mesh.name.clone(),
        positions,
        normals,
        uvs: Some(uvs),
        triangles,
        // Its normals are the source's, computed or not, and go with it wherever it is written.
        had_normals: true,
    };
    let coverage = uv_area(&unwrapped) as f32;
    Ok(Unwrapped {
        mesh: unwrapped,
        charts: atlas.chart_count,
        coverage,
    })
}

/// The summed area of the mesh's UV triangles (0 without UVs): the fraction of the map they
/// cover when no two overlap.
pub fn uv_area(mesh: &Mesh) -> f64 {
    let Some(uvs) = &mesh.uvs else {
        return 0.0;
    };
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| uvs[i as usize].as_dvec2());
            (b - a).perp_dot(c - a).abs() / 2.0
        })
        .sum()
}

/// The fraction of the texels a `size`^2 map gives the surface that more than one triangle
/// claims (0 without UVs): texel centres inside two triangles' UVs, a shared edge counted once.
/// Above zero, the UV bake gives one texel to two places of the surface, so painting one
/// paints the other.
pub fn uv_overlap(mesh: &Mesh, size: u32) -> f64 {
    let Some(uvs) = &mesh.uvs else {
        return 0.0;
    };
    let side = size as usize;
    let mut hits = vec![0u8; side * side];
    for t in &mesh.triangles {
        let corners = t.map(|i| {
            let uv = uvs[i as usize].as_dvec2();
            glam::DVec2::new(uv.x, 1.0 - uv.y) * f64::from(size)
        });
        cover_centres(corners, side, |i| hits[i] = hits[i].saturating_add(1));
    }
    let covered = hits.iter().filter(|&&h| h > 0).count();
    if covered == 0 {
        return 0.0;
    }
    hits.iter().filter(|&&h| h > 1).count() as f64 / covered as f64
}

/// Calls `hit` with the index of every texel whose centre lies inside the triangle (texel
/// coordinates), by the top-left rule so that two triangles sharing an edge never both claim a
/// centre on it.
fn cover_centres(c: [glam::DVec2; 3], side: usize, mut hit: impl FnMut(usize)) {
    let area = (c[1] - c[0]).perp_dot(c[2] - c[0]);
    if area == 0.0 || !area.is_finite() {
        return;
    }
    // Counter-clockwise in texel space (rows down), so the edge tests are one sign.
    let c = if area < 0.0 { [c[0], c[2], c[1]] } else { c };
    let lo = c[0].min(c[1]).min(c[2]).floor().max(glam::DVec2::ZERO);
    let hi = c[0]
        .max(c[1])
        .max(c[2])
        .ceil()
        .min(glam::DVec2::splat(side as f64));
    let edges = [(c[0], c[1]), (c[1], c[2]), (c[2], c[0])];
    // An edge owns the centres on it when it is a top or left edge.
    let owns = |(a, b): (glam::DVec2, glam::DVec2)| {
        let d = b - a;
        (d.y == 0.0 && d.x < 0.0) || d.y > 0.0
    };
    for y in lo.y as usize..hi.y as usize {
        for x in lo.x as usize..hi.x as usize {
            let p = glam::DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
            let inside = edges.iter().all(|&(a, b)| {
                let w = (b - a).perp_dot(p - a);
                w > 0.0 || (w == 0.0 && owns((a, b)))
            });
            if inside {
                hit(y * side + x);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mesh_without_uvs_gets_a_valid_atlas() {
        let mut torus = crate::torus(1.0, 0.35, 48, 24);
        torus.uvs = None;
        let out = unwrap(&torus, UnwrapOptions::for_size(512), None).expect("unwraps");
        assert!(out.mesh.validate().is_ok());
        assert_eq!(out.mesh.triangles.len(), torus.triangles.len());
        let uvs = out.mesh.uvs.as_ref().expect("uvs");
        assert!(
            uvs.iter()
                .all(|t| (0.0..=1.0).contains(&t.x) && (0.0..=1.0).contains(&t.y))
        );
        assert!(out.charts >= 1);
        assert!(out.coverage > 0.3, "coverage {}", out.coverage);
        assert_eq!(uv_overlap(&out.mesh, 512), 0.0);
        // Every triangle keeps its corners' positions.
        for (a, b) in out.mesh.triangles.iter().zip(&torus.triangles) {
            for k in 0..3 {
                assert_eq!(
                    out.mesh.positions[a[k] as usize],
                    torus.positions[b[k] as usize]
                );
            }
        }
    }

    #[test]
    fn an_unwrapped_mesh_written_as_obj_reads_back_as_itself() {
        let mut torus = crate::torus(1.0, 0.35, 24, 12);
        torus.uvs = None;
        torus.had_normals = false;
        let out = unwrap(&torus, UnwrapOptions::for_size(256), None).expect("unwraps");
        let text = crate::write_obj(&out.mesh);
        let back = crate::parse_obj(text.as_bytes(), out.mesh.name.clone(), "t.obj".as_ref())
            .expect("reads");
        assert!(back == out.mesh, "the same mesh");
        assert_eq!(crate::write_obj(&back), text, "the same bytes");
    }

    #[test]
    fn overlap_is_seen_and_a_clean_atlas_has_none() {
        let sphere = crate::uv_sphere(32, 16);
        assert_eq!(uv_overlap(&sphere, 256), 0.0);
        // Mirror the right half's UVs onto the left half: half the texels are shared.
        let mut mirrored = sphere.clone();
        if let Some(uvs) = &mut mirrored.uvs {
            for t in uvs.iter_mut() {
                if t.x > 0.5 {
                    t.x = 1.0 - t.x;
                }
            }
        }
        assert!(uv_overlap(&mirrored, 256) > 0.9);
    }

    #[test]
    fn degenerate_and_cancelled_unwraps_are_errors() {
        let flat = Mesh {
            name: "flat".into(),
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0],
            normals: vec![Vec3::Z; 3],
            uvs: None,
            triangles: vec![[0, 1, 2]],
            had_normals: false,
        };
        let e = unwrap(&flat, UnwrapOptions::for_size(256), None).expect_err("nothing to chart");
        assert!(e.contains("degenerate"), "{e}");
        let progress = Progress::default();
        progress.cancel();
        let e = unwrap(
            &crate::torus(1.0, 0.35, 48, 24),
            UnwrapOptions::for_size(256),
            Some(&progress),
        )
        .expect_err("cancelled");
        assert_eq!(e, "cancelled");
    }
}
