//! A typical project for scale measurements: real image content, a gradient and brush
//! strokes, as an artist's document would hold after a session.

use std::path::Path;

use glam::{Vec2, Vec3};

use kapaint_model::brush::{BrushSettings, StrokePoint};
use kapaint_model::paint::GradientShape;
use kapaint_model::{
    Channel, Channels, Command, Document, DocumentSettings, MaterialValue, StrokeTool, import,
};
use kapaint_model::{PaintCommand, SettingsCommand, StrokeCommand};

/// [`textured`] with painting on `n` alone (what the documents then paint).
fn textured_n_only(side: u32, texture: Option<&Path>) -> Result<Document, String> {
    let mut doc = textured(side, texture)?;
    doc.apply(SettingsCommand::SetChannels(Channels {
        kd: false,
        ks: false,
        n: true,
    }))
    .map_err(|e| e.to_string())?;
    Ok(doc)
}

/// A `side x side` document of the default material with `texture` (if given) in `k_d`.
fn textured(side: u32, texture: Option<&Path>) -> Result<Document, String> {
    let mut doc =
        Document::new(side, side, DocumentSettings::default()).map_err(|e| e.to_string())?;
    if let Some(path) = texture {
        doc.import_file(Channel::Kd, path)
            .map_err(|e| e.to_string())?;
    }
    Ok(doc)
}

/// Builds a `side x side` document: `texture` (if given and readable) imported into `k_d`, a
/// radial gradient over `n`, then `strokes` brush strokes of 64 px radius with varied
/// materials, each one undo step.
pub fn typical_document(
    side: u32,
    texture: Option<&Path>,
    strokes: usize,
) -> Result<Document, String> {
    let mut doc = textured_n_only(side, texture)?;
    let s = side as f32;
    let apply = |doc: &mut Document, c: Command| doc.apply(c).map_err(|e| e.to_string());
    apply(
        &mut doc,
        SettingsCommand::SetPrimary(MaterialValue::new(Vec3::ZERO, Vec3::ZERO, 2000.0)).into(),
    )?;
    apply(
        &mut doc,
        SettingsCommand::SetSecondary(MaterialValue::new(Vec3::ZERO, Vec3::ZERO, 8.0)).into(),
    )?;
    apply(
        &mut doc,
        PaintCommand::Gradient {
            shape: GradientShape::Radial,
            start: Vec2::splat(s / 2.0),
            end: Vec2::new(s, s / 2.0),
        }
        .into(),
    )?;
    apply(&mut doc, SettingsCommand::SetChannels(Channels::ALL).into())?;
    apply(
        &mut doc,
        SettingsCommand::SetBrush(BrushSettings {
            radius_px: 64.0,
            hardness: 0.6,
            ..BrushSettings::default()
        })
        .into(),
    )?;
    let mut state = 0x0123_4567_89AB_CDEF_u64;
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    for _ in 0..strokes {
        let value = MaterialValue::new(
            Vec3::new(next(), next(), next()),
            Vec3::splat(next()),
            1.0 + 500.0 * next(),
        );
        apply(&mut doc, SettingsCommand::SetPrimary(value).into())?;
        let mut pos = Vec2::new(next() * s, next() * s);
        let mut points = Vec::new();
        for _ in 0..12 {
            points.push(StrokePoint {
                pos,
                pressure: 0.5 + 0.5 * next(),
            });
            pos += Vec2::new(next() - 0.5, next() - 0.5) * 160.0;
        }
        apply(
            &mut doc,
            StrokeCommand::Stroke {
                tool: StrokeTool::Brush,
                points,
            }
            .into(),
        )?;
    }
    Ok(doc)
}

/// The block-compression test project: `texture` (if given and readable) in
/// `k_d`, the default `k_s` (grey, constant) and `n`, and over that `n` two soft strokes
/// 200 px wide, one of `n = 3000` and one of `n = 2`, crossing the map (scaled with `side`
/// from 4096): the hard case for `n` in shared blocks, whose edges sweep `n` across its range.
///
/// # Errors
/// A document that cannot be made, or a texture that does not read.
pub fn stroke_edge_document(side: u32, texture: Option<&Path>) -> Result<Document, String> {
    let mut doc = textured_n_only(side, texture)?;
    let scale = side as f32 / 4096.0;
    let apply = |doc: &mut Document, c: Command| doc.apply(c).map_err(|e| e.to_string());
    apply(
        &mut doc,
        SettingsCommand::SetBrush(BrushSettings {
            radius_px: 100.0 * scale,
            hardness: 0.0,
            ..BrushSettings::default()
        })
        .into(),
    )?;
    for (n, from, to) in [
        (3000.0, Vec2::new(0.1, 0.3), Vec2::new(0.9, 0.7)),
        (2.0, Vec2::new(0.2, 0.85), Vec2::new(0.8, 0.15)),
    ] {
        apply(
            &mut doc,
            SettingsCommand::SetPrimary(MaterialValue::new(Vec3::ZERO, Vec3::ZERO, n)).into(),
        )?;
        let points = (0..=32)
            .map(|k| StrokePoint {
                pos: from.lerp(to, k as f32 / 32.0) * side as f32,
                pressure: 1.0,
            })
            .collect();
        apply(
            &mut doc,
            StrokeCommand::Stroke {
                tool: StrokeTool::Brush,
                points,
            }
            .into(),
        )?;
    }
    Ok(doc)
}

/// A `side x side` stack of `layers` paint layers over the default base, each painted over
/// about 10 % of the map (every tenth band of tiles, a different band per layer: a uniform
/// material at varied coverage) with a varied mask there: the layered document of the layer
/// benchmarks.
pub fn layered_stack(side: u32, layers: usize) -> kapaint_model::layers::LayerStack {
    use kapaint_model::layers::{Layer, LayerStack, Mask, PaintTile, Stamped};
    use kapaint_model::tile::Plane;
    use std::sync::Arc;
    let mut stack = LayerStack::new(side, side, MaterialValue::default());
    stack.layers.clear();
    let tiles = stack.tile_count();
    for l in 0..layers {
        let mut layer = Layer::paint(format!("Layer {}", l + 1), tiles);
        let mut mask = Mask::white(tiles);
        let value = MaterialValue::new(
            Vec3::new(0.1 + 0.05 * l as f32, 0.5, 0.3),
            Vec3::splat(0.2),
            (l as f32).exp2(),
        );
        for id in (0..tiles).filter(|id| (id / 7 + l) % 10 == 0) {
            let Some(tile) = layer.paint_tile_mut(id) else {
                continue;
            };
            *tile = PaintTile::filled(value, [true, true, true]);
            for (i, a) in tile.alpha[0].data_mut().iter_mut().enumerate() {
                *a = ((i * 37) % 65_536) as u16;
            }
            let mut plane = Plane::Uniform(u16::MAX);
            for (i, m) in plane.data_mut().iter_mut().enumerate() {
                *m = ((i * 11) % 65_536) as u16;
            }
            mask.tiles[id] = Arc::new(Stamped::new(plane));
        }
        layer.mask = Some(mask);
        stack.layers.push(layer);
    }
    stack
}

/// Dabs along one row of [`stroke_path`], and its rows.
const PATH_ROW: (u32, u32) = (112, 12);

/// Points in [`stroke_path`] before it starts over.
pub const STROKE_PATH_POINTS: u32 = PATH_ROW.0 * PATH_ROW.1;

/// Point `k` of a long stroke across a 4096^2 map for dab benchmarks: 32 px apart (the
/// spacing of a 128 px-radius brush) along rows 320 px apart, back and forth, so every dab
/// reaches texels the stroke has not covered yet; after [`STROKE_PATH_POINTS`] (12 rows) it
/// starts over (a new stroke there paints over the first).
pub fn stroke_path(k: u32) -> glam::Vec2 {
    let (points, rows) = PATH_ROW;
    let (row, col) = ((k / points) % rows, k % points);
    let col = if row % 2 == 0 { col } else { points - 1 - col };
    glam::Vec2::new(256.5 + 32.0 * col as f32, 256.5 + 320.0 * row as f32)
}

/// The material dab benchmarks fill a layer with before painting over it (unlike the brush's).
pub fn under_paint() -> MaterialValue {
    MaterialValue::new(
        glam::Vec3::new(0.2, 0.45, 0.6),
        glam::Vec3::splat(0.08),
        900.0,
    )
}

/// Writes a `side x side` metallic-roughness set into `dir` as a PBR tool would export it:
/// `base.png` (sRGB, `texture` resampled, or a colour ramp without one) and
/// `metallic_roughness.png` (roughness in G, a ramp from 0.1 to 1 across; metallic in B,
/// 0 on the left half and 1 on the right, so both pure cases occur). Returns both paths.
///
/// # Errors
/// A texture that does not read, or a failed write.
pub fn write_pbr_set(
    dir: &Path,
    side: u32,
    texture: Option<&Path>,
) -> Result<(std::path::PathBuf, std::path::PathBuf), String> {
    let base = match texture {
        Some(t) => {
            let image = import::read_image(t).map_err(|e| e.to_string())?;
            image::imageops::resize(
                &image.to_rgb8(),
                side,
                side,
                image::imageops::FilterType::Triangle,
            )
        }
        None => image::RgbImage::from_fn(side, side, |x, y| {
            image::Rgb([(x * 255 / side) as u8, (y * 255 / side) as u8, 128])
        }),
    };
    let mr = image::RgbImage::from_fn(side, side, |x, y| {
        let rough = 0.1 + 0.9 * (y as f32 + 0.5) / side as f32;
        let metal = if x < side / 2 { 0 } else { 255 };
        image::Rgb([0, (rough * 255.0).round() as u8, metal])
    });
    let (b, m) = (dir.join("base.png"), dir.join("metallic_roughness.png"));
    base.save(&b).map_err(|e| e.to_string())?;
    mr.save(&m).map_err(|e| e.to_string())?;
    Ok((b, m))
}

/// A `side x side` document whose every texel holds a different material (no tile uniform),
/// for dab and resampling benchmarks.
///
/// # Errors
/// When the size is refused.
pub fn varied_document(side: u32) -> Result<Document, String> {
    use kapaint_model::texel::Texel;
    use kapaint_model::tile::TILE_TEXELS;
    let mut maps = kapaint_model::MaterialMaps::new(side, side, MaterialValue::default())
        .map_err(|e| e.to_string())?;
    for id in 0..maps.tile_count() {
        let tile = maps.tile_mut(id);
        for i in 0..TILE_TEXELS {
            let h = (id * TILE_TEXELS + i) as u32;
            let f =
                |k: u32| ((h.wrapping_mul(2_654_435_761).rotate_left(k)) % 1000) as f32 / 1000.0;
            tile.set_texel(
                i,
                Texel::encode(MaterialValue::new(
                    Vec3::new(f(1), f(5), f(9)),
                    Vec3::splat(f(13)),
                    f(17) * 2000.0,
                )),
            );
        }
    }
    Ok(Document::from_parts(maps, DocumentSettings::default()))
}

/// Dab `k` of the painting tools' benchmark: 250 dabs a row, 12.8 texels apart (10 % of a
/// 128 px radius), rows 320 texels apart across a 4096^2 map, 12 rows before it starts over.
pub fn tool_dab_path(k: u32) -> Vec2 {
    let (row, col) = ((k / 250) % 12, k % 250);
    Vec2::new(256.5 + 12.8 * col as f32, 256.5 + 320.0 * row as f32)
}

/// The painting tools' benchmark document: [`varied_document`] at 4096^2, a 128 px brush
/// (hardness 0.5, flow 0.5, spacing 10 %), a clone source 160 texels along the first row
/// and, with `stencil`, a tiled 256^2 checker stencil over the map turned 15 degrees.
///
/// # Errors
/// When a command is refused.
pub fn tool_dab_document(stencil: bool) -> Result<Document, String> {
    let mut doc = varied_document(4096)?;
    let run = |doc: &mut Document, c: Command| doc.apply(c).map_err(|e| e.to_string());
    let brush = BrushSettings {
        radius_px: 128.0,
        hardness: 0.5,
        flow: 0.5,
        spacing_percent: 10.0,
        ..BrushSettings::default()
    };
    run(&mut doc, SettingsCommand::SetBrush(brush).into())?;
    let source = tool_dab_path(0) + Vec2::new(160.0, 0.0);
    run(&mut doc, SettingsCommand::SetCloneSource(source).into())?;
    if stencil {
        let checker =
            image::DynamicImage::ImageLuma8(image::GrayImage::from_fn(256, 256, |x, y| {
                image::Luma([if (x / 32 + y / 32) % 2 == 0 { 255 } else { 40 }])
            }));
        let image =
            kapaint_model::paint_image::PaintImage::decoded(Path::new("checker.png"), &checker)
                .map_err(|e| e.to_string())?;
        let set = SettingsCommand::SetStencil {
            image,
            center: Vec2::splat(2048.0),
            size: 4096.0,
            rotation: 15.0,
            opacity: 1.0,
            tiled: true,
            view: None,
        };
        run(&mut doc, set.into())?;
    }
    Ok(doc)
}

/// Dab `k` of the painting tools' benchmark on the mesh: around the equator of
/// [`mesh_tool_dab_document`]'s sphere, 12.8 texels apart (10 % of a 128 px radius, in object
/// units through the surface's texel size `units`), 200 dabs a stroke.
pub fn mesh_tool_dab_point(k: u32, units: f32) -> kapaint_model::brush::SurfacePoint {
    let phi = (k % 250) as f32 * 12.8 * units;
    let p = Vec3::new(phi.cos(), 0.0, -phi.sin());
    kapaint_model::brush::SurfacePoint {
        pos: kapaint_model::brush::SurfacePos {
            point: p,
            normal: p,
        },
        pressure: 1.0,
    }
}

/// The painting tools' benchmark document on the mesh: [`tool_dab_document`] (4096^2, every
/// texel different, the 128 px brush at 10 % spacing) on the built-in UV sphere (128 x 64),
/// with a clone source on the sphere a little above the strokes' start, as an artist picks
/// one.
///
/// # Errors
/// When the bake or a command is refused.
pub fn mesh_tool_dab_document() -> Result<Document, String> {
    let surface =
        kapaint_model::surface::Surface::new(kapaint_mesh::uv_sphere(128, 64), 4096, 4096)?;
    let mut doc = tool_dab_document(false)?
        .with_surface(Some(std::sync::Arc::new(surface)))
        .map_err(|e| e.to_string())?;
    let source = SettingsCommand::SetSurfaceCloneSource(Vec3::new(1.0, 0.3, 0.0).normalize());
    doc.apply(source).map_err(|e| e.to_string())?;
    Ok(doc)
}
