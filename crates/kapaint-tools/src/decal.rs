//! The decal tool: a click on the mesh (or on the canvas, where the map lies on the mesh)
//! places the chosen image there as a decal, dragging moves it over the surface, its handles
//! (drawn with its outline in the viewport) and the fields scale and turn it, the fields fade
//! it, Enter commits it and Escape takes it back out. What is shown
//! while it is placed is the decal itself, laid in the selected layer by the model (one undo
//! step for the whole placement, which each move replaces).

use glam::Vec3;

use kapaint_model::paint_image::PaintImage;
use kapaint_model::{Command, Decal, DecalFrame, Document, PaintCommand};

use super::{
    OptionChange, OptionWidget, Overlay, Place, Tool, ToolCursor, ToolEvent, ToolKind, ToolMeta,
    ToolOption,
};

/// What a press on the decal being placed takes hold of.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Grip {
    /// The decal itself: a drag moves it.
    Move,
    /// The scale handle: a drag sets its size so the corner follows the pointer (in the frame
    /// the press found).
    Scale(DecalFrame),
    /// The turn handle: a drag turns it so the handle points at the pointer, from its
    /// rotation at the press.
    Turn(DecalFrame, f32),
}

/// How near a handle (a fraction of the decal's width, in its plane) a press takes hold of it.
const HANDLE_REACH: f32 = 0.12;

/// A change to the decal tool's options.
#[derive(Clone, Debug, PartialEq)]
pub enum DecalOption {
    /// Its width in object units.
    Size(f32),
    /// Its turn about the surface's normal, degrees.
    Rotation(f32),
    /// Its strength in `[0, 1]`.
    Opacity(f32),
}

/// The decal tool: its image and placement, and the decal being placed.
#[derive(Clone, Debug)]
pub struct DecalTool {
    /// The image it places (none until one is chosen).
    pub image: Option<PaintImage>,
    /// Width in object units (`None`: a fifth of the mesh's size, fixed at the first click).
    pub size: Option<f32>,
    /// Turn about the surface's normal, degrees.
    pub rotation: f32,
    /// Strength.
    pub opacity: f32,
    /// The point of the decal being placed (laid as a preview, not yet committed).
    placing: Option<Vec3>,
    /// Where it lies, as its last preview laid it.
    frame: Option<DecalFrame>,
    /// What the button, while down, holds.
    grip: Option<Grip>,
}

impl Default for DecalTool {
    fn default() -> Self {
        Self {
            image: None,
            size: None,
            rotation: 0.0,
            opacity: 1.0,
            placing: None,
            frame: None,
            grip: None,
        }
    }
}

impl ToolKind {
    /// The decal.
    pub const DECAL: Self = Self("decal");
}

/// The mesh's size: the diagonal of its bounds (1 without a mesh).
fn mesh_size(doc: &Document) -> f32 {
    doc.surface()
        .map(|s| {
            let (lo, hi) = s.mesh.bounds();
            lo.distance(hi)
        })
        .filter(|d| d.is_finite() && *d > 0.0)
        .unwrap_or(1.0)
}

/// The surface point under `at`: the mesh's point, or the baked position of the canvas's
/// texel where the map lies on the mesh.
fn surface_point(at: Place, doc: &Document) -> Option<Vec3> {
    match at {
        Place::Surface { pos, .. } => Some(pos.point),
        Place::Canvas(_) => {
            let surface = doc.surface()?;
            let (w, h) = (doc.maps().width(), doc.maps().height());
            let (x, y) = at.texel_index((w, h))?;
            let t = y as usize * w as usize + x as usize;
            surface.bake.triangle(t).map(|_| surface.bake.position(t))
        }
    }
}

impl DecalTool {
    /// The point of the decal being placed, if one is.
    pub fn placing(&self) -> Option<Vec3> {
        self.placing
    }

    /// Its width: the one set, else a fifth of the mesh's size.
    fn width(&self, doc: &Document) -> f32 {
        self.size.unwrap_or_else(|| 0.2 * mesh_size(doc))
    }

    /// The decal at `at` as the options say, if an image is chosen.
    fn decal(&self, at: Vec3, doc: &Document) -> Option<Decal> {
        Some(Decal {
            image: self.image.clone()?,
            at,
            size: self.width(doc),
            rotation: self.rotation,
            channels: doc.settings().channels,
            opacity: self.opacity,
        })
    }

    /// The preview of the decal being placed, as the options now say (and where it lies).
    fn preview(&mut self, doc: &Document) -> Vec<Command> {
        let decal = self.placing.and_then(|at| self.decal(at, doc));
        self.frame = decal
            .as_ref()
            .zip(doc.surface())
            .and_then(|(d, s)| d.frame(s).ok());
        decal
            .map(|d| PaintCommand::PreviewDecal(Box::new(d)).into())
            .into_iter()
            .collect()
    }

    /// What a press at surface point `p` takes hold of: a handle of the decal being placed
    /// when it is near one, else the decal (moved there).
    fn grip_at(&self, p: Vec3) -> Grip {
        let Some(frame) = self.frame else {
            return Grip::Move;
        };
        let reach = HANDLE_REACH * frame.width;
        let at = frame.local(p);
        if at.distance(frame.local(frame.scale_handle())) < reach {
            Grip::Scale(frame)
        } else if at.distance(frame.local(frame.turn_handle())) < reach {
            Grip::Turn(frame, self.rotation)
        } else {
            Grip::Move
        }
    }

    /// A drag to surface point `p` with `grip`: the decal moved, scaled or turned; whether it
    /// changed enough to lay it again.
    fn drag_to(&mut self, grip: Grip, p: Vec3, doc: &Document) -> bool {
        match grip {
            Grip::Move => {
                // Moves under a hundredth of its size are not worth laying it again.
                let step = 0.01 * self.width(doc);
                if self.placing.is_some_and(|q| q.distance(p) < step) {
                    return false;
                }
                self.placing = Some(p);
            }
            Grip::Scale(frame) => {
                // The corner under the pointer: its half-diagonal is the pointer's distance.
                let aspect = frame.height / frame.width;
                let width = 2.0 * frame.local(p).length() / (1.0 + aspect * aspect).sqrt();
                let old = self.width(doc);
                if !(width.is_finite() && width > 0.0) || (width - old).abs() < 0.01 * old {
                    return false;
                }
                self.size = Some(width);
            }
            Grip::Turn(frame, from) => {
                // Counter-clockwise seen from outside turns the top towards the left.
                let at = frame.local(p);
                if at.length() <= 1e-6 * frame.width {
                    return false;
                }
                let turn = (-at.x).atan2(at.y).to_degrees();
                let rotation = (from + turn + 180.0).rem_euclid(360.0) - 180.0;
                if (rotation - self.rotation).abs() < 0.5 {
                    return false;
                }
                self.rotation = rotation;
            }
        }
        true
    }

    /// Commits the decal being placed.
    fn commit(&mut self, doc: &Document) -> Vec<Command> {
        self.grip = None;
        self.frame = None;
        self.placing
            .take()
            .and_then(|at| self.decal(at, doc))
            .map(|d| d.place().into())
            .into_iter()
            .collect()
    }
}

impl Tool for DecalTool {
    fn meta(&self) -> ToolMeta {
        ToolMeta {
            kind: ToolKind::DECAL,
            label: "Decal",
            key: Some('D'),
            key_help: "D; Enter commits, Escape takes it back",
            summary: "decal (click places, drag moves, Enter commits)",
            cursor: ToolCursor::Crosshair,
        }
    }

    fn handle(&mut self, event: ToolEvent, doc: &Document) -> Vec<Command> {
        match event {
            ToolEvent::Press { at, .. } => {
                let Some(p) = surface_point(at, doc) else {
                    return Vec::new();
                };
                if self.image.is_none() {
                    return Vec::new();
                }
                self.size = Some(self.width(doc));
                let grip = match self.placing {
                    Some(_) => self.grip_at(p),
                    None => Grip::Move,
                };
                self.grip = Some(grip);
                if grip != Grip::Move {
                    return Vec::new();
                }
                self.placing = Some(p);
                self.preview(doc)
            }
            ToolEvent::Drag { at, .. } if self.grip.is_some() => {
                let (Some(p), Some(grip)) = (surface_point(at, doc), self.grip) else {
                    return Vec::new();
                };
                if !self.drag_to(grip, p, doc) {
                    return Vec::new();
                }
                self.preview(doc)
            }
            ToolEvent::Release => {
                self.grip = None;
                Vec::new()
            }
            ToolEvent::Commit => self.commit(doc),
            ToolEvent::Escape => {
                self.grip = None;
                self.frame = None;
                match self.placing.take() {
                    Some(_) => vec![PaintCommand::DropDecal.into()],
                    None => Vec::new(),
                }
            }
            ToolEvent::Drag { .. } | ToolEvent::PickSource { .. } => Vec::new(),
        }
    }

    fn busy(&self) -> bool {
        self.placing.is_some()
    }

    fn overlay(&self) -> Option<Overlay> {
        let frame = self.frame.filter(|_| self.placing.is_some())?;
        Some(Overlay::Decal {
            corners: frame.corners(),
            handles: [frame.scale_handle(), frame.turn_handle()],
        })
    }

    /// Another tool chosen: the decal being placed is kept.
    fn leave(&mut self, doc: &Document) -> Vec<Command> {
        self.commit(doc)
    }

    fn options(&self, doc: &Document) -> Vec<ToolOption> {
        let size = mesh_size(doc);
        vec![
            ToolOption {
                label: "Image",
                hover: "The picture the decal lays: colour into k_d, luminance into k_s, gray into n, alpha the coverage",
                widget: OptionWidget::Image {
                    path: self.image.as_ref().map(|i| i.path().to_path_buf()),
                },
            },
            ToolOption {
                label: "Size",
                hover: "Width in object units (the height by the image's aspect)",
                widget: OptionWidget::Slider {
                    value: self.width(doc),
                    min: 0.001 * size,
                    max: size,
                    integer: false,
                    change: |v| OptionChange::Decal(DecalOption::Size(v)),
                },
            },
            ToolOption {
                label: "Rotation",
                hover: "Degrees about the surface's normal, counter-clockwise seen from outside",
                widget: OptionWidget::Slider {
                    value: self.rotation,
                    min: -180.0,
                    max: 180.0,
                    integer: false,
                    change: |v| OptionChange::Decal(DecalOption::Rotation(v)),
                },
            },
            ToolOption {
                label: "Decal opacity",
                hover: "How strongly the decal covers what is under it",
                widget: OptionWidget::Slider {
                    value: self.opacity,
                    min: 0.0,
                    max: 1.0,
                    integer: false,
                    change: |v| OptionChange::Decal(DecalOption::Opacity(v)),
                },
            },
        ]
    }

    fn set_option(&mut self, change: OptionChange, doc: &Document) -> Vec<Command> {
        match change {
            OptionChange::Image(image) => self.image = Some(image),
            OptionChange::Decal(DecalOption::Size(v)) if v.is_finite() && v > 0.0 => {
                self.size = Some(v);
            }
            OptionChange::Decal(DecalOption::Rotation(v)) if v.is_finite() => {
                self.rotation = v;
            }
            OptionChange::Decal(DecalOption::Opacity(v)) if v.is_finite() => {
                self.opacity = v.clamp(0.0, 1.0);
            }
            _ => return Vec::new(),
        }
        self.preview(doc)
    }
}
