//! Parts matched by name (`X_low` with `X_high`) and ID maps by the file's objects, materials
//! and vertex colours: meshes read from OBJ text, as a user's files are.

use super::high::{
    HighBake, HighMap, HighOptions, HighRays, IdSource, Matching, bake_from_high,
    bake_from_high_with,
};
use crate::Mesh;
use crate::bake::{Coverage, bake};

/// Sample `c` of texel `i` in `[0, 1]`.
fn value(b: &HighBake, i: usize, c: usize) -> f32 {
    f32::from(b.data[i * b.map.channels() + c]) / 65535.0
}

/// An OBJ's text read as a file of that name.
fn obj(text: &str, name: &str) -> Mesh {
    crate::parse_obj(text.as_bytes(), name.into(), name.as_ref()).expect("loads")
}

/// A unit square at height `z` named `name`, its UVs across `u0..u0 + 0.5`, its first vertex
/// `first` (OBJ counts from 1); `extra` lines go before its face.
fn square(name: &str, z: f32, u0: f32, first: u32, extra: &str) -> String {
    let [a, b, c, d] = [first, first + 1, first + 2, first + 3];
    format!(
        "o {name}\nv 0 0 {z}\nv 1 0 {z}\nv 1 1 {z}\nv 0 1 {z}\nvt {u0} 0\nvt {u1} 0\nvt {u1} 1\nvt {u0} 1\n{extra}f {a}/{a} {b}/{b} {c}/{c} {d}/{d}\n",
        u1 = u0 + 0.5
    )
}

/// Two low parts lying over each other (as parts do before a bake is exploded), each with its
/// high part just above it: without matching the lower part's rays meet the upper part's high
/// surface first; matched by name each meets its own.
#[test]
fn parts_matched_by_name_never_bake_onto_each_other() {
    let low = obj(
        &(square("A_low", 0.0, 0.0, 1, "") + &square("b_low", 0.01, 0.5, 5, "")),
        "low.obj",
    );
    let high = obj(
        &(square("a_high", 0.002, 0.0, 1, "") + &square("B_HIGH", 0.012, 0.5, 5, "")),
        "high.obj",
    );
    assert_eq!(low.labels.objects.len(), 2);
    let uv = bake(&low, 32, 32, 2).expect("bakes");
    let options = HighOptions {
        front: Some(0.02),
        rear: Some(0.02),
        ..HighOptions::new(HighMap::Height)
    };
    let pairs = HighRays::new(&low, &high, Matching::ByName).expect("pairs");
    assert_eq!(pairs.pairs, ["a", "b"]);
    assert_eq!((pairs.unpaired_low, pairs.unpaired_high), (0, 0));
    let matched =
        bake_from_high_with(&low, &uv, (&high, &pairs), None, options, None).expect("bakes");
    let all = bake_from_high(&low, &uv, &high, None, options, None).expect("bakes");
    // Texel (8, 16) is on A (u < 0.5), (24, 16) on B.
    let (on_a, on_b) = (16 * 32 + 8, 16 * 32 + 24);
    assert_eq!(uv.coverage(on_a), Coverage::Surface);
    let own = (0.002 + 0.02) / 0.04;
    assert!(
        (value(&matched, on_a, 0) - own).abs() < 1e-3,
        "{}",
        value(&matched, on_a, 0)
    );
    assert!((value(&matched, on_b, 0) - own).abs() < 1e-3);
    let onto_b = (0.012 + 0.02) / 0.04;
    assert!(
        (value(&all, on_a, 0) - onto_b).abs() < 1e-3,
        "{}",
        value(&all, on_a, 0)
    );
    assert_eq!(matched.missed, 0);

    // A low part of no pair bakes from the high parts of no pair.
    let extra = obj(
        &(square("A_low", 0.0, 0.0, 1, "") + &square("lid", 0.01, 0.5, 5, "")),
        "low.obj",
    );
    let rays = HighRays::new(&extra, &high, Matching::ByName).expect("pairs");
    assert_eq!((rays.unpaired_low, rays.unpaired_high), (2, 2));
    let b = bake_from_high_with(&extra, &uv, (&high, &rays), None, options, None).expect("bakes");
    assert!((value(&b, on_b, 0) - own).abs() < 1e-3);
    // BVHs matched for one low mesh are refused for another.
    let other = bake(&crate::plane(), 8, 8, 2).expect("bakes");
    assert!(
        bake_from_high_with(&crate::plane(), &other, (&high, &rays), None, options, None).is_err()
    );
}

/// No pair: refused, naming what each side has.
#[test]
fn matching_without_a_pair_says_what_the_parts_are_called() {
    let low = obj(&square("body_low", 0.0, 0.0, 1, ""), "low.obj");
    let high = obj(&square("head_high", 0.0, 0.0, 1, ""), "high.obj");
    let e = HighRays::new(&low, &high, Matching::ByName)
        .err()
        .expect("no pairs")
        .to_string();
    assert!(
        e.contains("no pairs") && e.contains("body_low") && e.contains("head_high"),
        "{e}"
    );
    let unnamed = crate::plane();
    assert!(HighRays::new(&unnamed, &high, Matching::ByName).is_err());
}

/// An ID map tells the high mesh's objects, materials or vertex colours apart; one by what the
/// mesh does not have is refused.
#[test]
fn id_maps_by_objects_materials_and_vertex_colours() {
    let low = obj(&square("flat", 0.0, 0.0, 1, ""), "low.obj");
    let mut uvs = low.uvs.clone().expect("uvs");
    for t in &mut uvs {
        t.x *= 2.0;
    }
    let low = Mesh {
        uvs: Some(uvs),
        ..low
    };
    // Two triangles of one object, a material each, vertex colours red to blue along x.
    let high_text = "o one\nv 0 0 0.001 1 0 0\nv 1 0 0.001 0 0 1\nv 1 1 0.001 0 0 1\nv 0 1 0.001 1 0 0\nusemtl left\nf 1 2 4\nusemtl right\nf 2 3 4\n";
    let high = obj(high_text, "high.obj");
    assert_eq!(high.labels.materials.len(), 2);
    assert!(high.labels.colors.is_some());
    assert_eq!(IdSource::for_mesh(&high), IdSource::Material);
    let uv = bake(&low, 32, 32, 2).expect("bakes");
    let id = |source| {
        let options = HighOptions::new(HighMap::Id(source));
        bake_from_high(&low, &uv, &high, None, options, None).expect("bakes")
    };
    let colour = |b: &HighBake, x: usize, y: usize| [0, 1, 2].map(|c| value(b, y * 32 + x, c));
    // Below the diagonal from (1, 0) to (0, 1) is "left"; texel rows grow downwards (v up).
    let by_material = id(IdSource::Material);
    assert_ne!(colour(&by_material, 4, 27), colour(&by_material, 27, 4));
    let by_object = id(IdSource::Object);
    assert_eq!(colour(&by_object, 4, 27), colour(&by_object, 27, 4));
    let by_colour = id(IdSource::Color);
    let [r, _, b] = colour(&by_colour, 2, 16);
    assert!(r > 0.85 && b < 0.15, "red at the left: {r} {b}");
    let [r, _, b] = colour(&by_colour, 29, 16);
    assert!(r < 0.15 && b > 0.85, "blue at the right: {r} {b}");
    let plain = obj(&square("flat", 0.001, 0.0, 1, ""), "plain.obj");
    for source in [IdSource::Color, IdSource::Material] {
        let options = HighOptions::new(HighMap::Id(source));
        let e = bake_from_high(&low, &uv, &plain, None, options, None)
            .expect_err("refused")
            .to_string();
        assert!(e.contains("plain.obj") && e.contains("has none"), "{e}");
    }
    assert_eq!(IdSource::for_mesh(&plain), IdSource::Piece);
}

/// What an OBJ file names is read without changing its geometry: `usemtl` and `o` lines give
/// runs of triangles (a quad's two included), `v x y z r g b` the colours.
#[test]
fn an_obj_file_names_its_objects_and_materials() {
    let text = square("A_low", 0.0, 0.0, 1, "usemtl red\n")
        + &square("b_low", 0.01, 0.5, 5, "usemtl blue\n");
    let named = obj(&text, "n.obj");
    let bare: String = text
        .lines()
        .filter(|l| !l.starts_with("usemtl") && !l.starts_with("o "))
        .flat_map(|l| [l, "\n"])
        .collect();
    let plain = obj(&bare, "n.obj");
    assert_eq!(named.positions, plain.positions);
    assert_eq!(named.triangles, plain.triangles);
    let runs = |r: &[crate::Run]| {
        r.iter()
            .map(|r| (r.name.clone(), r.triangles.clone()))
            .collect::<Vec<_>>()
    };
    assert_eq!(
        runs(&named.labels.objects),
        [("A_low".to_string(), 0..2), ("b_low".to_string(), 2..4)]
    );
    assert_eq!(
        runs(&named.labels.materials),
        [("red".to_string(), 0..2), ("blue".to_string(), 2..4)]
    );
    assert!(named.labels.colors.is_none() && plain.labels.objects.is_empty());
    let merged = Mesh::merged(vec![named.clone(), named]).expect("merges");
    assert_eq!(merged.labels.objects[3].triangles, 6..8);
    assert!(merged.validate().is_ok());
}
