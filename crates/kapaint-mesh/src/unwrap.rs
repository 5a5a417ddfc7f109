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

/// About the most triangles one chart holds. The solver's cost grows faster than a chart's
/// size, so charts are kept below the share of the surface that this many triangles of the
/// mesh cover (on average): work then grows with the mesh, not faster (a 2M-triangle sphere
/// unwrapped in about 50 s with charts unbounded, 37 s bounded, on 2 cores). Meshes of fewer
/// triangles are charted as if there were no bound.
const MAX_CHART_TRIANGLES: usize = 50_000;

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

/// Why an unwrap did not finish: cancelled (the caller ends quietly), or failed (why).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum UnwrapError {
    /// Cancelled through its progress.
    #[error("cancelled")]
    Cancelled,
    /// The mesh or the options cannot be unwrapped, and why.
    #[error("{0}")]
    Failed(String),
}

impl From<String> for UnwrapError {
    fn from(reason: String) -> Self {
        Self::Failed(reason)
    }
}

impl From<&str> for UnwrapError {
    fn from(reason: &str) -> Self {
        Self::Failed(reason.into())
    }
}

/// Unwraps `mesh` into a new atlas (its own UVs, if any, are ignored). `progress` follows the
/// stages and cancels the work.
///
/// # Errors
/// A mesh with nothing to chart (only degenerate triangles), non-finite positions or a
/// bounding box too large to measure ([`MAX_DIAGONAL`](crate::frame::MAX_DIAGONAL)), more
/// triangles than the memory left can unwrap, or cancelled.
pub fn unwrap(
    mesh: &Mesh,
    options: UnwrapOptions,
    progress: Option<&Progress>,
) -> Result<Unwrapped, UnwrapError> {
    if !(64..=16384).contains(&options.size) {
        return Err(UnwrapError::Failed(format!(
            "an atlas of {} texels a side is outside 64 to 16384",
            options.size
        )));
    }
    let frame = crate::frame::UnitFrame::checked(&mesh.positions)?;
    kapaint_base::memory::check_fits(
        &format!("unwrapping {} triangles", mesh.triangles.len()),
        mesh.triangles.len() as u64 * BYTES_PER_TRIANGLE,
    )?;
    let positions: Vec<[f32; 3]> = mesh.positions.iter().map(Vec3::to_array).collect();
    let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    let mut input = uvunwrap::MeshInput::new(&positions, &indices);
    // The unwrapper computes in f64 from these positions times `scale`: a power of two (exact)
    // that brings the mesh to unit size, so that a mesh of 1e30 or 1e-20 units is charted as
    // the same shape at 1 unit is.
    input.scale = (frame.local_per_object() as f32).clamp(f32::MIN_POSITIVE, 2_f32.powi(127));
    let scale = f64::from(input.scale);
    let seams = crate::fans::fan_seams(mesh, &frame);
    input.seams = seams.as_deref();
    let page = options.size.min(MAX_PACK_PAGE);
    let settings = uvunwrap::Options {
        density: uvunwrap::Density::Auto { page_size: page },
        max_chart_area: max_chart_area(mesh, scale),
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
            UnwrapError::Cancelled
        } else {
            UnwrapError::Failed(format!("the mesh could not be unwrapped: {e}"))
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
        labels: crate::Labels::default(),
    };
    let coverage = uv_area(&unwrapped) as f32;
    Ok(Unwrapped {
        mesh: unwrapped,
        charts: atlas.chart_count,
        coverage,
    })
}

/// The area no chart may grow beyond, in the units the unwrapper sees (object units times
/// `scale`): [`MAX_CHART_TRIANGLES`] triangles' share of the surface; 0 (no bound) for a mesh
/// of fewer triangles.
fn max_chart_area(mesh: &Mesh, scale: f64) -> f32 {
    let n = mesh.triangles.len();
    if n <= MAX_CHART_TRIANGLES {
        return 0.0;
    }
    let area: f64 = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize].as_dvec3() * scale);
            (b - a).cross(c - a).length() / 2.0
        })
        .sum();
    (area * MAX_CHART_TRIANGLES as f64 / n as f64) as f32
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
    fn a_mesh_unwraps_the_same_at_every_scale() {
        let mut torus = crate::torus(1.0, 0.35, 32, 16);
        torus.uvs = None;
        let at = |scale: f32| {
            let mut mesh = torus.clone();
            mesh.positions.iter_mut().for_each(|p| *p *= scale);
            unwrap(&mesh, UnwrapOptions::for_size(256), None)
                .unwrap_or_else(|e| panic!("at {scale}: {e}"))
        };
        let unit = at(1.0);
        // A power of two scales exactly: the same atlas.
        for scale in [2.0_f32.powi(-70), 2.0_f32.powi(100)] {
            assert_eq!(at(scale).mesh.uvs, unit.mesh.uvs, "at {scale}");
        }
        // Any other scale rounds the positions once, and charts grow from the rounded ones:
        // about the same atlas.
        for scale in [1e-20_f32, 1e30] {
            let out = at(scale);
            assert!(
                out.charts.abs_diff(unit.charts) <= 2,
                "at {scale}: {}",
                out.charts
            );
            assert!((out.coverage - unit.coverage).abs() < 0.05, "at {scale}");
            assert_eq!(uv_overlap(&out.mesh, 256), 0.0);
        }
    }

    /// An OBJ file of one polygon with `corners`.
    fn polygon_obj(corners: &[glam::DVec2]) -> Mesh {
        use std::fmt::Write as _;
        let mut obj = String::with_capacity(corners.len() * 48);
        for p in corners {
            writeln!(obj, "v {} {} 0", p.x, p.y).expect("writes");
        }
        obj.push('f');
        for i in 1..=corners.len() {
            write!(obj, " {i}").expect("writes");
        }
        obj.push('\n');
        crate::parse_obj(obj.as_bytes(), "polygon".into(), "polygon.obj".as_ref()).expect("loads")
    }

    #[test]
    fn a_polygon_of_100000_corners_is_triangulated_inside_its_outline() {
        // A disc with a wedge cut out, the centre its last corner: a fan from the first corner
        // covers the wedge, and piles 100,000 needles on that corner.
        let n = 100_000;
        let corners: Vec<glam::DVec2> = (0..n - 1)
            .map(|i| {
                let a = 0.5 + (std::f64::consts::TAU - 1.0) * i as f64 / (n - 2) as f64;
                glam::DVec2::new(a.cos(), a.sin())
            })
            .chain([glam::DVec2::ZERO])
            .collect();
        let mesh = polygon_obj(&corners);
        assert_eq!(mesh.triangles.len(), n - 2);
        let positions = &mesh.positions;
        let first = mesh.triangles.iter().flatten().filter(|&&v| v == 0).count();
        assert!(first < 10, "the first corner is in {first} triangles");
        // Every triangle faces the way the outline winds (+z), none covers the wedge: their
        // area is the outline's.
        let signed = |[a, b, c]: [glam::DVec2; 3]| (b - a).perp_dot(c - a) / 2.0;
        let areas: Vec<f64> = mesh
            .triangles
            .iter()
            .map(|t| signed(t.map(|i| positions[i as usize].truncate().as_dvec2())))
            .collect();
        assert!(areas.iter().all(|&a| a >= 0.0));
        let outline: f64 = (0..n)
            .map(|i| corners[i].perp_dot(corners[(i + 1) % n]) / 2.0)
            .sum();
        let area: f64 = areas.iter().sum();
        assert!(
            (area / outline - 1.0).abs() < 1e-6,
            "{area} against {outline}"
        );
    }

    #[test]
    fn a_polygon_of_100000_corners_unwraps_in_moments() {
        // Fanned from one corner it took more than 14 minutes: the overlap test compared every
        // pair of the needles around that corner.
        let n = 100_000_u32;
        let corners: Vec<glam::DVec2> = (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * f64::from(i) / f64::from(n);
                glam::DVec2::new(a.cos(), a.sin())
            })
            .collect();
        let mesh = polygon_obj(&corners);
        let out = unwrap(&mesh, UnwrapOptions::for_size(256), None).expect("unwraps");
        assert!(
            out.charts >= 1 && out.coverage > 0.3,
            "{} {}",
            out.charts,
            out.coverage
        );
        assert_eq!(uv_overlap(&out.mesh, 256), 0.0);
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
            labels: crate::Labels::default(),
        };
        let e = unwrap(&flat, UnwrapOptions::for_size(256), None).expect_err("nothing to chart");
        assert!(e.to_string().contains("degenerate"), "{e}");
        let progress = Progress::default();
        progress.cancel();
        let e = unwrap(
            &crate::torus(1.0, 0.35, 48, 24),
            UnwrapOptions::for_size(256),
            Some(&progress),
        )
        .expect_err("cancelled");
        assert_eq!(e, UnwrapError::Cancelled);
    }
}
