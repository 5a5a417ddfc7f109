//! Property tests: random command sequences keep every texel valid, and undoing all of them
//! restores the starting maps bit-exactly.

use glam::{Vec2, Vec3};
use kapaint_model::brush::{BlendMode, BrushSettings, StrokePoint};
use kapaint_model::paint::GradientShape;
use kapaint_model::texel::{N_MAX, Texel};
use kapaint_model::{
    Channel, Channels, Command, Document, DocumentSettings, FillRegion, MaterialValue, StrokeTool,
};
use kapaint_model::{HistoryCommand, PaintCommand, SettingsCommand, StrokeCommand};
use proptest::prelude::*;

fn any_value() -> impl Strategy<Value = MaterialValue> {
    // Hostile values included: the model sanitises them.
    let c = prop_oneof![0.0f32..=1.0, Just(f32::NAN), Just(-3.0), Just(7.0)];
    (
        c.clone(),
        c.clone(),
        c,
        prop_oneof![0.0f32..20000.0, Just(f32::INFINITY), Just(f32::NAN)],
    )
        .prop_map(|(r, g, b, n)| MaterialValue {
            kd: Vec3::new(r, g, b),
            ks: Vec3::new(b, r, g),
            n,
        })
}

fn any_brush() -> impl Strategy<Value = BrushSettings> {
    (
        0.1f32..40.0,
        0.0f32..=1.0,
        0.0f32..=1.0,
        0.0f32..=1.0,
        1.0f32..200.0,
        0usize..4,
        any::<bool>(),
        any::<bool>(),
        any::<bool>(),
    )
        .prop_map(
            |(radius_px, hardness, opacity, flow, spacing_percent, mode, guard, mu, mv)| {
                BrushSettings {
                    radius_px,
                    hardness,
                    opacity,
                    flow,
                    spacing_percent,
                    blend: BlendMode::ALL[mode],
                    energy_guard: guard,
                    mirror_u: mu,
                    mirror_v: mv,
                    jitter: 0.3,
                    ..BrushSettings::default()
                }
            },
        )
}

fn any_command() -> impl Strategy<Value = Command> {
    let pt = (-20.0f32..120.0, -20.0f32..90.0, 0.0f32..=1.0).prop_map(|(x, y, p)| StrokePoint {
        pos: Vec2::new(x, y),
        pressure: p,
    });
    prop_oneof![
        any_value().prop_map(|v| Command::from(SettingsCommand::SetPrimary(v))),
        any_value().prop_map(|v| Command::from(SettingsCommand::SetSecondary(v))),
        any_brush().prop_map(|v| Command::from(SettingsCommand::SetBrush(v))),
        (any::<bool>(), any::<bool>(), any::<bool>())
            .prop_map(|(kd, ks, n)| SettingsCommand::SetChannels(Channels { kd, ks, n }).into()),
        (0usize..3, prop::collection::vec(pt, 1..6)).prop_map(|(t, points)| {
            StrokeCommand::Stroke {
                tool: [StrokeTool::Brush, StrokeTool::Eraser, StrokeTool::Blur][t],
                points,
            }
            .into()
        }),
        Just(Command::from(PaintCommand::Fill(FillRegion::All))),
        (0u32..100, 0u32..70, 0usize..3, 0.0f32..0.5).prop_map(|(x, y, c, tolerance)| {
            PaintCommand::Fill(FillRegion::Similar {
                x,
                y,
                channel: Channel::ALL[c],
                tolerance,
            })
            .into()
        }),
        (any::<bool>(), -10.0f32..110.0, -10.0f32..80.0).prop_map(|(radial, x, y)| {
            PaintCommand::Gradient {
                shape: if radial {
                    GradientShape::Radial
                } else {
                    GradientShape::Linear
                },
                start: Vec2::new(x, y),
                end: Vec2::new(100.0 - x, 70.0 - y),
            }
            .into()
        }),
        (0u32..100, 0u32..70).prop_map(|(x, y)| PaintCommand::Pick { x, y }.into()),
        Just(Command::from(SettingsCommand::SwapMaterials)),
        Just(Command::from(HistoryCommand::Undo)),
        Just(Command::from(HistoryCommand::Redo)),
    ]
}

fn snapshot(doc: &Document) -> Vec<Texel> {
    let mut out = Vec::new();
    doc.maps().for_each_texel(|_, _, t| out.push(t));
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn random_sessions_stay_valid_and_fully_undoable(commands in prop::collection::vec(any_command(), 1..25)) {
        let mut doc = Document::new(100, 70, DocumentSettings::default()).expect("size");
        let start = snapshot(&doc);
        for command in commands {
            doc.apply(command).expect("every generated command is valid");
            let mut ok = true;
            doc.maps().for_each_texel(|_, _, t| {
                let n = half::f16::from_bits(t.n).to_f32();
                ok &= n.is_finite() && (0.0..=N_MAX).contains(&n);
            });
            prop_assert!(ok, "an invalid n was stored");
            let s = doc.settings();
            prop_assert!(s.primary.kd.is_finite() && s.primary.n.is_finite());
        }
        while doc.history().undo_steps().next().is_some() {
            doc.apply(HistoryCommand::Undo).expect("undo");
        }
        prop_assert!(snapshot(&doc) == start, "undoing everything did not restore the start");
    }
}
