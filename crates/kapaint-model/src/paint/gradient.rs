//! The shapes of a gradient (the layer engine lays gradients: `model::document`).

/// Shape of a gradient.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum GradientShape {
    /// Along the line from start to end.
    Linear,
    /// Around the start, reaching the end value at the end point's distance.
    Radial,
}
