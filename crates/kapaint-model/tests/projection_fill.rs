//! Issue 56, item 1's last part: a fill layer holding a projection instead of one material.
//! It shows what `ProjectImage` paints into an empty layer, is laid again when the mesh
//! changes, is one undo step, and is saved, reopened and recovered as its parameters and
//! image (the texels laid again, never read from the file).
#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::io::Cursor;
use std::sync::Arc;

use glam::{Vec2, Vec3};
use image::{DynamicImage, Rgba, RgbaImage};
use kapaint_model::document::AttachedMesh;
use kapaint_model::layers::LayerContent;
use kapaint_model::paint::projection::Projection;
use kapaint_model::paint_image::PaintImage;
use kapaint_model::project::{from_reader, to_bytes};
use kapaint_model::surface::Surface;
use kapaint_model::texel::{Channels, MaterialValue, Texel};
use kapaint_model::{
    Document, DocumentSettings, HistoryCommand, ImportCommand, LayerCommand, LayerKind, MeshRef,
    PaintCommand,
};

const SIDE: u32 = 256;

/// A 48 x 32 picture: a colour ramp, a gray bar and a transparent corner.
fn picture() -> PaintImage {
    let img = RgbaImage::from_fn(48, 32, |x, y| {
        let a = if x < 8 && y < 8 { 0 } else { 255 };
        Rgba([
            (x * 5) as u8,
            (y * 7) as u8,
            if x > 30 { 200 } else { 40 },
            a,
        ])
    });
    PaintImage::decoded(
        std::path::Path::new("picture.png"),
        &DynamicImage::ImageRgba8(img),
    )
    .expect("image")
}

fn on_mesh(name: &str) -> Document {
    let settings = DocumentSettings {
        base: MaterialValue::new(Vec3::splat(0.1), Vec3::splat(0.05), 10.0),
        mesh: MeshRef::Builtin(name.into()),
        ..DocumentSettings::default()
    };
    let mut doc = Document::new(SIDE, SIDE, settings).expect("doc");
    kapaint_model::project::attach_own_mesh(&mut doc).expect("mesh");
    doc
}

fn texels(doc: &Document) -> Vec<Texel> {
    (0..SIDE)
        .flat_map(|y| (0..SIDE).map(move |x| (x, y)))
        .map(|(x, y)| doc.maps().texel(x, y))
        .collect()
}

/// The largest difference of any stored component between two composites (unorm16 and
/// half-float bits alike).
fn largest_difference(a: &[Texel], b: &[Texel]) -> u16 {
    a.iter()
        .zip(b)
        .flat_map(|(s, t)| {
            let s = [s.kd[0], s.kd[1], s.kd[2], s.ks[0], s.ks[1], s.ks[2], s.n];
            let t = [t.kd[0], t.kd[1], t.kd[2], t.ks[0], t.ks[1], t.ks[2], t.n];
            s.into_iter().zip(t).map(|(x, y)| x.abs_diff(y))
        })
        .max()
        .unwrap_or(0)
}

fn spherical() -> Projection {
    Projection::Spherical {
        origin: Vec3::ZERO,
        up: Vec3::Y,
        front: Vec3::Z,
    }
}

fn planar() -> Projection {
    Projection::Planar {
        origin: Vec3::new(0.0, 0.0, 1.0),
        normal: Vec3::Z,
        up: Vec3::Y,
        width: 1.2,
        height: 0.8,
    }
}

fn add_fill(doc: &mut Document, projection: Projection, channels: Channels) {
    doc.apply(LayerCommand::AddProjectionFill {
        name: "Label".into(),
        image: picture(),
        projection,
        channels,
    })
    .expect("projection fill");
}

#[test]
fn a_projection_fill_shows_what_projecting_into_an_empty_layer_paints() {
    for projection in [
        spherical(),
        planar(),
        Projection::Triplanar {
            scale: 1.5,
            blend: 0.5,
        },
        Projection::Uv {
            offset: Vec2::new(0.1, 0.2),
            scale: Vec2::new(2.0, 3.0),
            rotation: 30.0,
        },
    ] {
        let channels = Channels {
            kd: true,
            ks: false,
            n: true,
        };
        let mut painted = on_mesh("sphere");
        painted
            .apply(LayerCommand::AddLayer {
                kind: LayerKind::Paint,
                name: "Paint".into(),
            })
            .expect("layer");
        painted
            .apply(PaintCommand::ProjectImage {
                image: picture(),
                projection,
                channels,
                opacity: 1.0,
            })
            .expect("projects");
        let mut filled = on_mesh("sphere");
        add_fill(&mut filled, projection, channels);
        let (a, b) = (texels(&painted), texels(&filled));
        assert_ne!(
            b,
            texels(&on_mesh("sphere")),
            "{projection:?} fills something"
        );
        // The same texels laid by the same function; the paint layer's blend from nothing
        // rounds once more (at most a unit in the last place of a 16-bit value).
        let d = largest_difference(&a, &b);
        assert!(d <= 1, "{projection:?}: {d}");
        let layer = filled.stack().layers.last().expect("added");
        assert_eq!(layer.kind_name(), "fill");
        assert!(matches!(layer.content, LayerContent::Projected(_)));
    }
}

#[test]
fn it_is_one_step_follows_the_mesh_and_turns_back_into_a_flat_fill() {
    let mut doc = on_mesh("sphere");
    let before = texels(&doc);
    add_fill(&mut doc, planar(), Channels::ALL);
    let on_sphere = texels(&doc);
    assert_ne!(on_sphere, before);
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert_eq!(texels(&doc), before, "one step took it out");
    assert_eq!(
        doc.stack().layers.len(),
        1,
        "the new document's layer alone"
    );
    doc.apply(HistoryCommand::Redo).expect("redo");
    assert_eq!(texels(&doc), on_sphere);
    // A new mesh: laid again there, as a fill made on that mesh lays it.
    let cube = Arc::new(Surface::new(kapaint_mesh::cube(), SIDE, SIDE).expect("bake"));
    doc.apply(ImportCommand::SetMesh(AttachedMesh {
        surface: Arc::clone(&cube),
        mesh: MeshRef::Builtin("cube".into()),
    }))
    .expect("mesh");
    let mut fresh = on_mesh("cube");
    add_fill(&mut fresh, planar(), Channels::ALL);
    assert_ne!(texels(&doc), on_sphere, "laid again on the cube");
    assert_eq!(texels(&doc), texels(&fresh));
    // Changing the projection is a step; a material makes it a flat fill again.
    doc.apply(LayerCommand::SetLayerProjection {
        image: picture(),
        projection: spherical(),
        channels: Channels::ALL,
    })
    .expect("set");
    assert_ne!(texels(&doc), texels(&fresh));
    let flat = MaterialValue::new(Vec3::new(0.5, 0.2, 0.1), Vec3::splat(0.3), 40.0);
    doc.apply(LayerCommand::SetLayerFill(flat)).expect("flat");
    assert!(matches!(
        doc.stack().layers[1].content,
        LayerContent::Fill(v) if v == flat.sanitized()
    ));
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert!(matches!(
        doc.stack().layers[1].content,
        LayerContent::Projected(_)
    ));
}

#[test]
fn bad_projection_fills_are_refused_and_change_nothing() {
    let mut doc = on_mesh("sphere");
    doc.apply(LayerCommand::AddLayer {
        kind: LayerKind::Paint,
        name: "Paint".into(),
    })
    .expect("layer");
    let before = (texels(&doc), doc.stack().clone());
    let set = |projection, channels| LayerCommand::SetLayerProjection {
        image: picture(),
        projection,
        channels,
    };
    let none = Channels {
        kd: false,
        ks: false,
        n: false,
    };
    let off_mesh = Projection::Planar {
        origin: Vec3::new(30.0, 0.0, 0.0),
        normal: Vec3::Z,
        up: Vec3::Y,
        width: 0.1,
        height: 0.1,
    };
    let degenerate = Projection::Planar {
        origin: Vec3::ZERO,
        normal: Vec3::Y,
        up: Vec3::Y,
        width: 1.0,
        height: 1.0,
    };
    for (command, says) in [
        (set(planar(), Channels::ALL), "not a fill layer"),
        (set(planar(), none), "at least one channel"),
        (
            LayerCommand::AddProjectionFill {
                name: "Off".into(),
                image: picture(),
                projection: off_mesh,
                channels: Channels::ALL,
            },
            "reaches no texel",
        ),
        (
            LayerCommand::AddProjectionFill {
                name: "Bad".into(),
                image: picture(),
                projection: degenerate,
                channels: Channels::ALL,
            },
            "parallel",
        ),
        (
            LayerCommand::AddProjectionFill {
                name: "Unloaded".into(),
                image: PaintImage::named("nowhere.png"),
                projection: spherical(),
                channels: Channels::ALL,
            },
            "not loaded",
        ),
    ] {
        let e = doc.apply(command).expect_err(says);
        assert!(e.to_string().contains(says), "{e} (expected {says})");
        assert_eq!(texels(&doc), before.0);
        assert_eq!(doc.stack(), &before.1);
    }
    // Without a mesh, a projection onto the surface is refused; the UV one needs none.
    let mut bare = Document::new(64, 64, DocumentSettings::default()).expect("doc");
    let e = bare
        .apply(LayerCommand::AddProjectionFill {
            name: "Label".into(),
            image: picture(),
            projection: spherical(),
            channels: Channels::ALL,
        })
        .expect_err("no mesh");
    assert!(e.to_string().contains("needs a mesh"), "{e}");
    bare.apply(LayerCommand::AddProjectionFill {
        name: "Tiles".into(),
        image: picture(),
        projection: Projection::Uv {
            offset: Vec2::ZERO,
            scale: Vec2::ONE,
            rotation: 0.0,
        },
        channels: Channels::ALL,
    })
    .expect("a UV projection needs no mesh");
}

#[test]
fn a_saved_projection_fill_opens_laid_again_on_its_mesh() {
    let mut doc = on_mesh("sphere");
    add_fill(&mut doc, spherical(), Channels::ALL);
    let bytes = to_bytes(&doc).expect("saves");
    let mut zip = zip::ZipArchive::new(Cursor::new(&bytes)).expect("zip");
    let manifest: serde_json::Value =
        serde_json::from_reader(zip.by_name("manifest.json").expect("manifest")).expect("json");
    assert_eq!(manifest["version"], 5);
    let entry = &manifest["layers"][1]["projection"];
    assert_eq!(entry["source"], "picture.png");
    assert!(zip.by_name("layer1_projection_rgba.png").is_ok());
    assert!(zip.by_name("layer1_projection_gray.png").is_ok());
    let back = from_reader(Cursor::new(&bytes)).expect("reads");
    assert!(back.surface().is_some(), "the sphere is attached");
    assert_eq!(texels(&back), texels(&doc));
    let LayerContent::Projected(p) = &back.stack().layers[1].content else {
        panic!("a projection fill reopens as one");
    };
    assert_eq!(p.fill().projection, spherical());
    let LayerContent::Projected(q) = &doc.stack().layers[1].content else {
        panic!("projected");
    };
    assert_eq!(
        p.fill().image.pixels().expect("kept"),
        q.fill().image.pixels().expect("kept"),
        "the image is kept exactly"
    );
    // A damaged image entry or a projection that makes no frame is refused.
    let mut damaged = Vec::new();
    {
        let mut out = zip::ZipWriter::new(Cursor::new(&mut damaged));
        for i in 0..zip.len() {
            let mut f = zip.by_index(i).expect("entry");
            let name = f.name().expect("name").to_string();
            let mut data = Vec::new();
            std::io::Read::read_to_end(&mut f, &mut data).expect("read");
            if name == "layer1_projection_gray.png" {
                data.truncate(data.len() / 2);
            }
            out.start_file(name, zip::write::SimpleFileOptions::default())
                .expect("start");
            std::io::Write::write_all(&mut out, &data).expect("write");
        }
        out.finish().expect("finish");
    }
    let e = from_reader(Cursor::new(&damaged)).expect_err("damaged");
    assert!(e.contains("projection"), "{e}");
}

#[test]
fn a_uv_projection_fill_opens_without_a_mesh_and_its_composite_is_checked() {
    let mut doc = Document::new(128, 128, DocumentSettings::default()).expect("doc");
    doc.apply(LayerCommand::AddProjectionFill {
        name: "Tiles".into(),
        image: picture(),
        projection: Projection::Uv {
            offset: Vec2::ZERO,
            scale: Vec2::splat(2.0),
            rotation: 10.0,
        },
        channels: Channels::ALL,
    })
    .expect("fill");
    let bytes = to_bytes(&doc).expect("saves");
    let back = from_reader(Cursor::new(&bytes)).expect("reads");
    let all = |d: &Document| -> Vec<Texel> {
        (0..128)
            .flat_map(|y| (0..128).map(move |x| (x, y)))
            .map(|(x, y)| d.maps().texel(x, y))
            .collect()
    };
    assert_eq!(all(&back), all(&doc));
}
