//! Issue 56, item 4: the clone tool on the mesh. Ctrl+click on the surface sets the source
//! there (and at its texel, for the canvas); a drag on the mesh then clones in object space,
//! one undo step.

use std::sync::Arc;

use glam::{Vec2, Vec3};
use kapaint_model::brush::SurfacePos;
use kapaint_model::surface::Surface;
use kapaint_model::texel::MaterialValue;
use kapaint_model::{Command, Document, DocumentSettings, SettingsCommand};
use kapaint_tools::{Place, ToolEvent, ToolKind, Tools};

fn on_surface(point: Vec3, texel: Option<Vec2>) -> Place {
    Place::Surface {
        pos: SurfacePos {
            point,
            normal: point.normalize(),
        },
        texel,
    }
}

#[test]
fn ctrl_click_on_the_mesh_sets_a_surface_source_and_a_drag_there_clones() {
    let settings = DocumentSettings {
        base: MaterialValue::new(Vec3::splat(0.3), Vec3::splat(0.04), 10.0),
        ..DocumentSettings::default()
    };
    let surface = Surface::new(kapaint_mesh::uv_sphere(32, 16), 128, 128).expect("bake");
    let mut doc = Document::new(128, 128, settings)
        .expect("doc")
        .with_surface(Some(Arc::new(surface)))
        .expect("surface");
    let mut tools = Tools::default();
    tools.select(ToolKind::CLONE, &doc);
    let source = Vec3::Y;
    let picked = tools.handle(
        ToolEvent::PickSource {
            at: on_surface(source, Some(Vec2::new(64.0, 2.0))),
        },
        &doc,
    );
    assert_eq!(
        picked,
        [
            Command::from(SettingsCommand::SetSurfaceCloneSource(source)),
            Command::from(SettingsCommand::SetCloneSource(Vec2::new(64.0, 2.0))),
        ]
    );
    for c in picked {
        doc.apply(c).expect("source");
    }
    let events = [
        ToolEvent::Press {
            at: on_surface(Vec3::Z, None),
            pressure: 1.0,
        },
        ToolEvent::Drag {
            at: on_surface(Vec3::new(0.3, 0.0, 1.0).normalize(), None),
            pressure: 1.0,
        },
        ToolEvent::Release,
    ];
    for event in events {
        for c in tools.handle(event, &doc) {
            doc.apply(c).expect("a clone stroke on the mesh applies");
        }
    }
    let labels: Vec<_> = doc
        .history()
        .undo_steps()
        .map(|s| s.label.clone())
        .collect();
    assert_eq!(labels, ["Clone stroke"]);
    assert_eq!(
        doc.surface_clone_source().map(|(s, o)| (s, o.is_some())),
        Some((source, true))
    );
}
