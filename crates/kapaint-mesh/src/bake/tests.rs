//! Tests of the bake: the touch test, spans, overlapping UVs, open texels, compact texels.

use super::*;

#[test]
fn the_touch_test_is_exact_for_a_simple_triangle() {
    let (a, b, c) = (
        Vec2::new(0.0, 0.0),
        Vec2::new(4.0, 0.0),
        Vec2::new(0.0, 4.0),
    );
    assert!(touches(a, b, c, Vec2::new(0.5, 0.5), 0.5));
    // The square [2.5, 3.5] x [2.5, 3.5] lies beyond the hypotenuse x + y = 4.
    assert!(!touches(a, b, c, Vec2::new(3.0, 3.0), 0.5));
    // [1.5, 2.5]^2 touches it at the corner (1.5, 2.5)... 1.5 + 2.5 = 4: touching counts.
    assert!(touches(a, b, c, Vec2::new(2.0, 2.0), 0.5));
    assert!(!touches(a, b, c, Vec2::new(-1.0, 2.0), 0.4));
}

#[test]
fn slab_spans_are_the_triangles_extent_in_each_row() {
    let (a, b, c) = (
        Vec2::new(0.0, 0.0),
        Vec2::new(4.0, 0.0),
        Vec2::new(0.0, 4.0),
    );
    assert_eq!(slab_span(a, b, c, 0.0, 1.0), Some((0.0, 4.0)));
    assert_eq!(slab_span(a, b, c, 2.0, 3.0), Some((0.0, 2.0)));
    assert_eq!(slab_span(a, b, c, 3.5, 4.5), Some((0.0, 0.5)));
    assert_eq!(slab_span(a, b, c, 5.0, 6.0), None);
    // A sliver on one row.
    let flat = slab_span(
        Vec2::new(1.0, 2.5),
        Vec2::new(7.0, 2.5),
        Vec2::new(3.0, 2.5),
        2.0,
        3.0,
    );
    assert_eq!(flat, Some((1.0, 7.0)));
}

#[test]
fn overlapping_uvs_cost_what_the_covered_texels_cost() {
    // 10,000 copies of one triangle over half the UV square: each covered texel is
    // settled by the first copy, so the others only retest its edge.
    let copies = 10_000_u32;
    let mesh = Mesh {
        name: "stack".into(),
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
        normals: vec![Vec3::Z; 3],
        uvs: Some(vec![Vec2::ZERO, Vec2::X, Vec2::Y]),
        triangles: vec![[0, 1, 2]; copies as usize],
        had_normals: true,
        labels: crate::Labels::default(),
    };
    let side = 1024;
    let b = bake(&mesh, side, side, 0).unwrap();
    let covered = b
        .coverage_grid()
        .iter()
        .filter(|c| **c == Coverage::Surface)
        .count() as u64;
    assert!(covered > u64::from(side * side) / 2);
    // The edge: at most a few texels per row per copy beyond the covered area.
    let bound = covered + u64::from(copies) * u64::from(side) * 4;
    assert!(
        b.touch_tests < bound,
        "{} texel tests, more than {bound} (covered {covered})",
        b.touch_tests
    );
}

#[test]
fn a_texel_keeps_eight_bytes_and_its_point_to_a_part_in_65535_of_its_triangle() {
    let mesh = crate::uv_sphere(48, 24);
    let b = bake(&mesh, 256, 256, 4).unwrap();
    assert_eq!(b.texel_bytes(), 256 * 256 * 8);
    let uvs = mesh.uvs.as_ref().unwrap();
    let mut checked = 0;
    for i in (0..b.len()).step_by(97) {
        let Some(t) = b.triangle(i) else { continue };
        if b.coverage(i) != Coverage::Surface {
            continue;
        }
        // The exact nearest point of the texel's centre, as the bake found it.
        let (x, y) = ((i % 256) as f32 + 0.5, (i / 256) as f32 + 0.5);
        let tri = mesh.triangles[t as usize];
        let [a, bb, c] =
            tri.map(|v| Vec2::new(uvs[v as usize].x * 256.0, (1.0 - uvs[v as usize].y) * 256.0));
        let (w, _) = nearest_barycentric(Vec2::new(x, y), a, bb, c);
        let [pa, pb, pc] = tri.map(|v| mesh.positions[v as usize]);
        let exact = pa * w.x + pb * w.y + pc * w.z;
        let edge = (pb - pa).length().max((pc - pa).length());
        assert!(
            b.position(i).distance(exact) <= edge * 2.0 / 65535.0,
            "texel {i}"
        );
        assert!((b.normal(i).length() - 1.0).abs() < 1e-4);
        checked += 1;
    }
    assert!(checked > 100);
}

#[test]
fn open_texels_list_what_is_left_in_order() {
    let mut open = OpenTexels::new(200, 2);
    let mut out = Vec::new();
    open.open_in(1, 60, 70, &mut out);
    assert_eq!(out, (60..=70).collect::<Vec<_>>());
    for x in 0..200 {
        if x != 3 && x != 130 && x != 199 {
            open.close(1, x);
        }
    }
    open.open_in(1, 0, 199, &mut out);
    assert_eq!(out, vec![3, 130, 199]);
    open.open_in(1, 4, 198, &mut out);
    assert_eq!(out, vec![130]);
    open.open_in(0, 190, 199, &mut out);
    assert_eq!(out.len(), 10, "other rows untouched");
}

#[test]
fn nearest_point_is_inside_or_on_an_edge() {
    let (a, b, c) = (Vec2::ZERO, Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0));
    let (bary, d2) = nearest_barycentric(Vec2::new(0.2, 0.2), a, b, c);
    assert_eq!(d2, 0.0);
    assert!((bary.x - 0.6).abs() < 1e-6);
    let (bary, d2) = nearest_barycentric(Vec2::new(1.0, 1.0), a, b, c);
    assert!((d2 - 0.5).abs() < 1e-6);
    assert!((bary.y - 0.5).abs() < 1e-6 && (bary.z - 0.5).abs() < 1e-6);
}

#[test]
fn full_dilation_fills_every_cell_from_its_nearest_island() {
    // Two filled cells at the ends of a 7x1 row: each fills its own half.
    let mut filled = [true, false, false, false, false, false, true];
    let mut value = [1, 0, 0, 0, 0, 0, 2];
    dilate_grid(&mut filled, 7, 1, u32::MAX, |k, s| value[k] = value[s]);
    assert!(filled.iter().all(|f| *f));
    assert_eq!(value, [1, 1, 1, 1, 2, 2, 2]);
    // Nothing filled: nothing to grow from.
    let mut none = [false; 4];
    dilate_grid(&mut none, 2, 2, u32::MAX, |_, _| unreachable!());
    assert!(none.iter().all(|f| !*f));
}
