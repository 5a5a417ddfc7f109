//! The tools without a window: events in, commands out, and the document after them.

#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::sync::Arc;

use glam::{Vec2, Vec3};
use kapaint_mesh::uv_sphere;
use kapaint_model::brush::SurfacePos;
use kapaint_model::paint::GradientShape;
use kapaint_model::surface::Surface;
use kapaint_model::texel::{Channel, MaterialValue, Texel};
use kapaint_model::{Command, Document, DocumentSettings, FillRegion, StrokeTool};
use kapaint_model::{HistoryCommand, PaintCommand, SettingsCommand, StrokeCommand};
use kapaint_tools::{Fill, FillMode, Gradient, OptionWidget, Place, ToolEvent, ToolKind, Tools};

fn document() -> Document {
    let mut doc = Document::new(128, 64, DocumentSettings::default()).expect("doc");
    doc.apply(SettingsCommand::SetPrimary(MaterialValue::new(
        Vec3::new(0.9, 0.1, 0.1),
        Vec3::splat(0.4),
        500.0,
    )))
    .expect("primary");
    doc
}

fn texels(doc: &Document) -> Vec<Texel> {
    let mut out = Vec::new();
    doc.maps().for_each_texel(|_, _, t| out.push(t));
    out
}

/// Runs events through the tools and applies every command; returns the commands.
fn run(tools: &mut Tools, doc: &mut Document, events: &[ToolEvent]) -> Vec<Command> {
    let mut all = Vec::new();
    for &event in events {
        for command in tools.handle(event, doc) {
            doc.apply(command.clone())
                .expect("a tool's command applies");
            all.push(command);
        }
    }
    all
}

fn press(x: f32, y: f32) -> ToolEvent {
    ToolEvent::Press {
        at: Place::Canvas(Vec2::new(x, y)),
        pressure: 1.0,
    }
}

fn drag(x: f32, y: f32) -> ToolEvent {
    ToolEvent::Drag {
        at: Place::Canvas(Vec2::new(x, y)),
        pressure: 1.0,
    }
}

/// A place on the sphere, with the texel its UV falls on.
fn on_surface(doc: &Document, point: Vec3) -> Place {
    let surface = doc.surface().expect("a mesh");
    let (w, h) = (surface.bake.width, surface.bake.height);
    let texel = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            surface.bake.coverage((y * w + x) as usize) != kapaint_mesh::bake::Coverage::Empty
        })
        .min_by(|a, b| {
            let d =
                |(x, y): (u32, u32)| surface.bake.position((y * w + x) as usize).distance(point);
            d(*a).total_cmp(&d(*b))
        })
        .expect("a covered texel");
    Place::Surface {
        pos: SurfacePos {
            point,
            normal: Vec3::ZERO,
        },
        texel: Some(Vec2::new(texel.0 as f32 + 0.5, texel.1 as f32 + 0.5)),
    }
}

fn with_sphere(doc: Document) -> Document {
    let surface =
        Surface::new(uv_sphere(32, 16), doc.maps().width(), doc.maps().height()).expect("bake");
    doc.with_surface(Some(Arc::new(surface))).expect("surface")
}

#[test]
fn a_brush_stroke_is_one_undo_step_from_press_to_release() {
    let mut doc = document();
    let before = texels(&doc);
    let mut tools = Tools::default();
    let commands = run(
        &mut tools,
        &mut doc,
        &[press(10.0, 10.0), drag(40.0, 20.0), drag(80.0, 30.0)],
    );
    assert!(matches!(
        commands[0],
        Command::Stroke(StrokeCommand::BeginStroke(StrokeTool::Brush))
    ));
    assert!(tools.busy(), "drawing until released");
    assert!(doc.stroking());
    run(&mut tools, &mut doc, &[ToolEvent::Release]);
    assert!(!tools.busy() && !doc.stroking());
    assert_ne!(texels(&doc), before, "painted");
    assert_eq!(doc.history().undo_steps().count(), 1, "one step");
    doc.apply(HistoryCommand::Undo).expect("undo");
    assert_eq!(texels(&doc), before, "undone bit-exactly");
}

#[test]
fn escape_abandons_a_stroke_in_every_stroke_tool_and_view() {
    for kind in [ToolKind::BRUSH, ToolKind::ERASER, ToolKind::BLUR] {
        for on_mesh in [false, true] {
            let mut doc = with_sphere(document());
            // Something for the eraser and the blur to change.
            doc.apply(PaintCommand::Fill(FillRegion::All))
                .expect("fill");
            doc.apply(SettingsCommand::SetPrimary(MaterialValue::new(
                Vec3::ZERO,
                Vec3::ZERO,
                2.0,
            )))
            .expect("primary");
            run(
                &mut Tools::default(),
                &mut doc,
                &[press(60.0, 30.0), ToolEvent::Release],
            );
            let before = texels(&doc);
            let steps = doc.history().undo_steps().count();
            let mut tools = Tools::default();
            tools.select(kind, &doc);
            let (a, b) = if on_mesh {
                (
                    on_surface(&doc, Vec3::new(0.0, 0.2, 0.98).normalize()),
                    on_surface(&doc, Vec3::new(0.5, 0.1, 0.86).normalize()),
                )
            } else {
                (
                    Place::Canvas(Vec2::new(40.0, 20.0)),
                    Place::Canvas(Vec2::new(90.0, 40.0)),
                )
            };
            let commands = run(
                &mut tools,
                &mut doc,
                &[
                    ToolEvent::Press {
                        at: a,
                        pressure: 1.0,
                    },
                    ToolEvent::Drag {
                        at: b,
                        pressure: 1.0,
                    },
                ],
            );
            assert!(!commands.is_empty(), "{kind:?} started a stroke");
            assert_ne!(texels(&doc), before, "{kind:?} painted before Escape");
            let aborted = run(&mut tools, &mut doc, &[ToolEvent::Escape]);
            assert_eq!(
                aborted,
                vec![Command::from(StrokeCommand::AbortStroke)],
                "{kind:?}"
            );
            assert_eq!(
                texels(&doc),
                before,
                "{kind:?} (mesh: {on_mesh}) left its stroke"
            );
            assert_eq!(doc.history().undo_steps().count(), steps, "no undo step");
            assert!(!tools.busy());
            assert!(
                run(&mut tools, &mut doc, &[ToolEvent::Release]).is_empty(),
                "the release after Escape does nothing"
            );
        }
    }
}

#[test]
fn a_gradient_dragged_on_the_mesh_lays_a_gradient_not_a_pick() {
    let mut doc = with_sphere(document());
    let before = texels(&doc);
    let primary = doc.settings().primary;
    let mut tools = Tools::default();
    tools.select(ToolKind::GRADIENT, &doc);
    let (a, b) = (
        on_surface(&doc, Vec3::new(0.0, 0.0, 1.0)),
        on_surface(&doc, Vec3::new(1.0, 0.0, 0.0)),
    );
    let commands = run(
        &mut tools,
        &mut doc,
        &[
            ToolEvent::Press {
                at: a,
                pressure: 1.0,
            },
            ToolEvent::Drag {
                at: b,
                pressure: 1.0,
            },
            ToolEvent::Release,
        ],
    );
    assert_eq!(commands.len(), 1, "{commands:?}");
    let Command::Paint(PaintCommand::Gradient { shape, start, end }) = commands[0] else {
        panic!("not a gradient: {commands:?}");
    };
    assert_eq!(shape, GradientShape::Linear);
    assert_eq!((Some(start), Some(end)), (a.texel(), b.texel()));
    assert_ne!(texels(&doc), before);
    assert_eq!(doc.settings().primary, primary, "nothing was picked");
}

#[test]
fn a_gradient_can_be_radial_and_escape_drops_it() {
    let mut doc = document();
    let mut tools = Tools::default();
    tools.select(ToolKind::GRADIENT, &doc);
    tools.get_mut::<Gradient>().expect("gradient").shape = GradientShape::Radial;
    let before = texels(&doc);
    let commands = run(
        &mut tools,
        &mut doc,
        &[
            press(64.0, 32.0),
            drag(100.0, 32.0),
            ToolEvent::Escape,
            ToolEvent::Release,
        ],
    );
    assert!(commands.is_empty(), "{commands:?}");
    assert_eq!(texels(&doc), before);
    let commands = run(
        &mut tools,
        &mut doc,
        &[press(64.0, 32.0), drag(100.0, 32.0), ToolEvent::Release],
    );
    assert!(matches!(
        commands[..],
        [Command::Paint(PaintCommand::Gradient {
            shape: GradientShape::Radial,
            ..
        })]
    ));
    // Radial: equal values at equal distances from the start.
    let (l, r) = (doc.maps().value(43, 32), doc.maps().value(84, 32)); // centres 20.5 away
    assert!((l.kd - r.kd).abs().max_element() < 1e-3, "{l:?} {r:?}");
}

#[test]
fn fill_modes_cover_islands_similar_texels_and_the_whole_map() {
    // Two halves: a red one painted, the other still the base.
    let mut doc = document();
    doc.apply(PaintCommand::Gradient {
        shape: GradientShape::Linear,
        start: Vec2::new(63.0, 0.0),
        end: Vec2::new(64.0, 0.0),
    })
    .expect("halves");
    let mut tools = Tools::default();
    tools.select(ToolKind::FILL, &doc);
    tools.get_mut::<Fill>().expect("fill").mode = FillMode::Similar {
        channel: Channel::Kd,
        tolerance: 0.01,
    };
    doc.apply(SettingsCommand::SetPrimary(MaterialValue::new(
        Vec3::new(0.0, 0.8, 0.0),
        Vec3::ZERO,
        4.0,
    )))
    .expect("green");
    let commands = run(
        &mut tools,
        &mut doc,
        &[press(10.0, 10.0), ToolEvent::Release],
    );
    assert!(matches!(
        commands[..],
        [Command::Paint(PaintCommand::Fill(FillRegion::Similar {
            x: 10,
            y: 10,
            channel: Channel::Kd,
            ..
        }))]
    ));
    assert!(
        doc.maps().value(10, 10).kd.y > 0.7,
        "the left half is filled"
    );
    assert!(
        doc.maps().value(120, 10).kd.y < 0.7,
        "the right half is not"
    );
    tools.get_mut::<Fill>().expect("fill").mode = FillMode::All;
    let commands = run(&mut tools, &mut doc, &[press(10.0, 10.0)]);
    assert_eq!(
        commands,
        vec![Command::from(PaintCommand::Fill(FillRegion::All))]
    );
    // Island: on the mesh's UVs an island, off them (no mesh here) the whole map.
    tools.get_mut::<Fill>().expect("fill").mode = FillMode::Island;
    assert_eq!(
        tools.handle(press(10.0, 10.0), &doc),
        vec![Command::from(PaintCommand::Fill(FillRegion::All))]
    );
    let doc = with_sphere(doc);
    assert!(matches!(
        tools.handle(press(10.0, 10.0), &doc)[..],
        [Command::Paint(PaintCommand::Fill(FillRegion::Island {
            x: 10,
            y: 10
        }))]
    ));
    // Off the map: nothing.
    assert!(tools.handle(press(-3.0, 10.0), &doc).is_empty());
}

#[test]
fn the_picker_reads_the_texel_under_the_pointer_in_either_view() {
    let mut doc = with_sphere(document());
    run(
        &mut Tools::default(),
        &mut doc,
        &[press(60.0, 30.0), ToolEvent::Release],
    );
    let mut tools = Tools::default();
    tools.select(ToolKind::PICKER, &doc);
    let commands = run(&mut tools, &mut doc, &[press(60.5, 30.5)]);
    assert_eq!(
        commands,
        vec![Command::from(PaintCommand::Pick { x: 60, y: 30 })]
    );
    let place = on_surface(&doc, Vec3::new(0.0, 0.0, 1.0));
    let (x, y) = place.texel_index((128, 64)).expect("on the map");
    let commands = run(
        &mut tools,
        &mut doc,
        &[ToolEvent::Press {
            at: place,
            pressure: 1.0,
        }],
    );
    assert_eq!(commands, vec![Command::from(PaintCommand::Pick { x, y })]);
    assert_eq!(doc.settings().primary, doc.maps().value(x, y));
}

#[test]
fn switching_tools_mid_stroke_keeps_the_stroke_and_drops_a_gradient() {
    let mut doc = document();
    let mut tools = Tools::default();
    run(&mut tools, &mut doc, &[press(10.0, 10.0), drag(50.0, 10.0)]);
    let ended = tools.select(ToolKind::PICKER, &doc);
    assert_eq!(ended, vec![Command::from(StrokeCommand::EndStroke)]);
    doc.apply(StrokeCommand::EndStroke).expect("end");
    assert_eq!(doc.history().undo_steps().count(), 1, "the stroke is kept");
    tools.select(ToolKind::GRADIENT, &doc);
    run(&mut tools, &mut doc, &[press(10.0, 10.0), drag(50.0, 10.0)]);
    assert!(
        tools.select(ToolKind::BRUSH, &doc).is_empty(),
        "no gradient laid"
    );
    assert_eq!(doc.history().undo_steps().count(), 1);
}

#[test]
fn a_stroke_stays_in_the_view_it_began_in() {
    let mut doc = with_sphere(document());
    let mut tools = Tools::default();
    let on_mesh = on_surface(&doc, Vec3::new(0.0, 0.0, 1.0));
    let commands = run(
        &mut tools,
        &mut doc,
        &[
            ToolEvent::Press {
                at: on_mesh,
                pressure: 1.0,
            },
            drag(10.0, 10.0),
            ToolEvent::Release,
        ],
    );
    assert!(matches!(
        commands[1],
        Command::Stroke(StrokeCommand::SurfaceStrokeTo(_))
    ));
    assert!(
        !commands
            .iter()
            .any(|c| matches!(c, Command::Stroke(StrokeCommand::StrokeTo(_)))),
        "the canvas drag is not part of a mesh stroke: {commands:?}"
    );
}

/// Every tool says who it is, and its options, set the way the panel sets them, change what
/// its next command does.
#[test]
fn every_tool_describes_itself_and_its_options_drive_it() {
    let all = Tools::all();
    assert_eq!(all.len(), 9);
    for (i, a) in all.iter().enumerate() {
        assert!(!a.label.is_empty() && !a.key_help.is_empty(), "{a:?}");
        for b in &all[i + 1..] {
            assert_ne!(a.kind, b.kind);
            assert!(
                a.key.is_none() || a.key != b.key,
                "{a:?} and {b:?} share a key"
            );
        }
    }
    let mut doc = Document::new(100, 70, DocumentSettings::default()).expect("doc");
    let mut tools = Tools::default();
    // The fill: similar texels in n, tolerance 0.2, through the options the panel draws.
    tools.select(ToolKind::FILL, &doc);
    let options = tools.options(&doc);
    assert_eq!(options.len(), 1, "island mode shows only the mode");
    assert!(choose(&mut tools, &doc, "Similar texels").is_empty());
    let labels: Vec<_> = tools.options(&doc).iter().map(|o| o.label).collect();
    assert_eq!(labels, ["Fill", "Compared channel", "Tolerance"]);
    choose(&mut tools, &doc, "n");
    slide(&mut tools, &doc, "Tolerance", 0.2);
    slide(&mut tools, &doc, "Tolerance", f32::NAN);
    // Choosing the mode it has keeps its parameters.
    choose(&mut tools, &doc, "Similar texels");
    assert_eq!(
        tools.handle(press(10.0, 10.0), &doc),
        vec![Command::from(PaintCommand::Fill(FillRegion::Similar {
            x: 10,
            y: 10,
            channel: Channel::N,
            tolerance: 0.2,
        }))]
    );
    // The blur's radius is a brush setting: the option answers with the command.
    tools.select(ToolKind::BLUR, &doc);
    let commands = slide(&mut tools, &doc, "Blur radius", 7.4);
    for c in commands {
        doc.apply(c).expect("radius");
    }
    assert_eq!(doc.settings().brush.blur_radius_px, 7);
    let Some(OptionWidget::Slider { value, .. }) =
        tools.options(&doc).first().map(|o| o.widget.clone())
    else {
        panic!("the blur radius is a slider");
    };
    assert!((value - 7.0).abs() < 1e-6);
    // The gradient's shape and its overlay while dragged.
    tools.select(ToolKind::GRADIENT, &doc);
    choose(&mut tools, &doc, "Radial");
    assert_eq!(tools.overlay(), None);
    tools.handle(press(10.0, 10.0), &doc);
    tools.handle(
        ToolEvent::Drag {
            at: Place::Canvas(Vec2::new(50.0, 20.0)),
            pressure: 1.0,
        },
        &doc,
    );
    assert_eq!(
        tools.overlay(),
        Some(kapaint_tools::Overlay::Arrow {
            from: Vec2::new(10.0, 10.0),
            to: Vec2::new(50.0, 20.0)
        })
    );
    let laid = tools.handle(ToolEvent::Release, &doc);
    assert!(matches!(
        laid[..],
        [Command::Paint(PaintCommand::Gradient {
            shape: GradientShape::Radial,
            ..
        })]
    ));
    assert!(tools.lays_material(&laid[0]));
    // The picker reads the selected layer when asked.
    tools.select(ToolKind::PICKER, &doc);
    choose(&mut tools, &doc, "Selected layer");
    assert_eq!(
        tools.handle(press(3.0, 4.0), &doc),
        vec![Command::from(PaintCommand::PickLayer { x: 3, y: 4 })]
    );
    assert!(!tools.lays_material(&PaintCommand::PickLayer { x: 3, y: 4 }.into()));
    // The tools' own state stays reachable by type.
    assert!(tools.get_mut::<Gradient>().is_some());
    assert!(matches!(
        tools.get_mut::<Fill>().map(|f| f.mode),
        Some(FillMode::Similar { .. })
    ));
}

/// Makes the change the active tool's choice named `name` offers, as the panel does.
fn choose(tools: &mut Tools, doc: &Document, name: &str) -> Vec<Command> {
    let change = tools
        .options(doc)
        .into_iter()
        .find_map(|o| match o.widget {
            OptionWidget::Choice { choices, .. } => choices
                .into_iter()
                .find(|(n, _)| *n == name)
                .map(|(_, c)| c),
            OptionWidget::Slider { .. } | OptionWidget::Image { .. } => None,
        })
        .expect("the tool offers the choice");
    tools.set_option(change, doc)
}

/// Sets the active tool's slider labelled `label` to `value`, as the panel does.
fn slide(tools: &mut Tools, doc: &Document, label: &str, value: f32) -> Vec<Command> {
    let change = tools
        .options(doc)
        .into_iter()
        .find_map(|o| match o.widget {
            OptionWidget::Slider { change, .. } if o.label == label => Some(change(value)),
            _ => None,
        })
        .expect("the tool offers the slider");
    tools.set_option(change, doc)
}

/// Clone: Ctrl+click sets the source (no stroke, no undo step), the stroke after it copies,
/// and its overlay is the source's marker; smudge strokes as the brush does.
#[test]
fn clone_takes_its_source_from_a_ctrl_click_and_smudge_strokes() {
    let mut doc = document();
    let mut tools = Tools::default();
    tools.select(ToolKind::CLONE, &doc);
    assert_eq!(tools.overlay(), Some(kapaint_tools::Overlay::CloneSource));
    // Before a source, a stroke is refused by the document (the editor shows why).
    let begin = tools.handle(press(40.0, 40.0), &doc);
    assert!(doc.apply(begin[0].clone()).is_err());
    tools.handle(ToolEvent::Release, &doc);
    let pick = ToolEvent::PickSource {
        at: Place::Canvas(Vec2::new(20.0, 30.0)),
    };
    let commands = run(&mut tools, &mut doc, &[pick]);
    assert_eq!(
        commands,
        [Command::Settings(SettingsCommand::SetCloneSource(
            Vec2::new(20.0, 30.0)
        ))]
    );
    assert_eq!(doc.clone_source(), Some((Vec2::new(20.0, 30.0), None)));
    let steps = doc.history().undo_steps().count();
    run(
        &mut tools,
        &mut doc,
        &[press(60.0, 40.0), drag(70.0, 40.0), ToolEvent::Release],
    );
    assert_eq!(doc.history().undo_steps().count(), steps + 1);
    assert_eq!(
        doc.clone_source(),
        Some((Vec2::new(20.0, 30.0), Some(Vec2::new(-40.0, -10.0))))
    );
    tools.select(ToolKind::SMUDGE, &doc);
    assert!(tools.handle(pick, &doc).is_empty(), "smudge has no source");
    run(
        &mut tools,
        &mut doc,
        &[press(20.0, 20.0), drag(40.0, 20.0), ToolEvent::Release],
    );
    assert_eq!(doc.history().undo_steps().count(), steps + 2);
}
