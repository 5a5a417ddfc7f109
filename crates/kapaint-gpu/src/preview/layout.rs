//! How a frame is laid out: one picture, a split, or two or three side by side, as parts that
//! each name a pipeline, a scissor and a viewport.

use super::PipelineKey;
use kapaint_core::render::Compare;

/// A pixel rectangle `(x, y, width, height)` of the target.
pub type Scissor = (u32, u32, u32, u32);

/// One draw of a frame: a pipeline, the pixels it may shade (scissor) and the rectangle its
/// picture fills (viewport).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DrawPart {
    /// The pipeline.
    pub key: PipelineKey,
    /// Pixels outside it are not shaded.
    pub scissor: Scissor,
    /// Where the camera's picture goes.
    pub viewport: Scissor,
}

impl DrawPart {
    /// One pipeline over the whole `(width, height)` target.
    pub fn whole(key: PipelineKey, (w, h): (u32, u32)) -> Self {
        Self {
            key,
            scissor: (0, 0, w, h),
            viewport: (0, 0, w, h),
        }
    }
}

/// How one frame shows the shading models it compares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// One picture, one model (the left key's).
    Single,
    /// One picture wiped at column `at`: the left key left of it, the right key right of it;
    /// the hidden part of each is never shaded.
    Split(u32),
    /// Two whole pictures, one per half of the target, seen by the one camera.
    SideBySide,
    /// Three whole pictures, one per third of the target (the three models).
    ThreeWay,
}

impl Layout {
    /// How a `width`-pixel frame draws `compare`, the split's divider at `split_at` (a
    /// fraction of the width); `None` for the difference, which is no one picture.
    pub fn of(compare: Compare, split_at: f32, width: u32) -> Option<Self> {
        match compare {
            Compare::Single => Some(Self::Single),
            Compare::Split => Some(Self::Split(
                ((split_at.clamp(0.0, 1.0) * width as f32) as u32).min(width),
            )),
            Compare::SideBySide => Some(Self::SideBySide),
            Compare::ThreeWay => Some(Self::ThreeWay),
            Compare::Difference => None,
        }
    }

    /// The parts of a `(width, height)` frame: `keys` are the sides' pipelines from the left
    /// (one used by `Single`, two by `Split` and `SideBySide`, three by `ThreeWay`).
    pub fn parts(self, keys: [PipelineKey; 3], (w, h): (u32, u32)) -> Vec<DrawPart> {
        let whole = (0, 0, w, h);
        let [left, right, _] = keys;
        let columns = |count: u32| -> Vec<DrawPart> {
            // Columns of equal width, so every picture has one aspect ratio; the spare pixels
            // (at most count - 1) go between them.
            let width = w / count;
            keys.iter()
                .take(count as usize)
                .enumerate()
                .map(|(i, &key)| {
                    let x = if count == 1 {
                        0
                    } else {
                        (w - width) * i as u32 / (count - 1)
                    };
                    let rect = (x, 0, width, h);
                    DrawPart {
                        key,
                        scissor: rect,
                        viewport: rect,
                    }
                })
                .collect()
        };
        match self {
            Self::Single => vec![DrawPart::whole(left, (w, h))],
            Self::Split(at) => {
                let at = at.min(w);
                vec![
                    DrawPart {
                        key: left,
                        scissor: (0, 0, at, h),
                        viewport: whole,
                    },
                    DrawPart {
                        key: right,
                        scissor: (at, 0, w - at, h),
                        viewport: whole,
                    },
                ]
            }
            Self::SideBySide => columns(2),
            Self::ThreeWay => columns(3),
        }
    }
}
