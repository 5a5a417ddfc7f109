//! The commands that change a document, and the stroke tools and fill regions they name.

use std::sync::Arc;

use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};

use crate::brush::{BrushSettings, StrokePoint, SurfacePoint};
use crate::paint::GradientShape;
use crate::paint::projection::Projection;
use crate::paint_image::PaintImage;
use crate::texel::{Channel, Channels, MaterialValue};

pub use super::layer_command::{
    LayerCommand, LayerKind, LayerMove, LayerPlace, LayerRef, MaskCommand,
};
use kapaint_reflectance::{AmbientApprox, ShadingModel};

/// Tools that work as strokes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum StrokeTool {
    /// Paints the primary material.
    Brush,
    /// Paints the base material back.
    Eraser,
    /// Smooths the enabled channels.
    Blur,
    /// Paints what the maps held at the clone source, aligned (see
    /// [`SettingsCommand::SetCloneSource`]).
    Clone,
    /// Picks up what is under the brush and drags it along the stroke.
    Smudge,
}

impl StrokeTool {
    /// Whether the tool paints through the stencil (the brush, the eraser and clone).
    pub fn paints_through_stencil(self) -> bool {
        matches!(self, Self::Brush | Self::Eraser | Self::Clone)
    }
}

/// Which texels a fill writes.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum FillRegion {
    /// The whole map.
    All,
    /// The connected region around a texel whose channel is within `tolerance` (blend space).
    Similar {
        /// Seed texel column.
        x: u32,
        /// Seed texel row.
        y: u32,
        /// Channel compared.
        channel: Channel,
        /// Largest difference still filled, in `[0, 1]`.
        #[serde(deserialize_with = "crate::check::tolerance")]
        tolerance: f32,
    },
    /// The UV island under a texel (needs the document's mesh surface).
    Island {
        /// Texel column.
        x: u32,
        /// Texel row.
        y: u32,
    },
    /// The mesh part (connected piece of surface, across UV seams) under a texel.
    Part {
        /// Texel column.
        x: u32,
        /// Texel row.
        y: u32,
    },
}

/// Everything that changes a document, by room: each room's commands are their own enum,
/// and [`Document::apply`](super::Document::apply) hands each to the room that matches it
/// exhaustively. Scripts name the commands flat, as they always have: `script.rs` reads them.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// The tool settings: brush, materials, channels, shading.
    Settings(SettingsCommand),
    /// Strokes of the brush, eraser and blur.
    Stroke(StrokeCommand),
    /// The one-click tools: fills, gradients, picks.
    Paint(PaintCommand),
    /// What a worker made from a file: channels, materials, normal maps, meshes, resized maps.
    Import(ImportCommand),
    /// Undo and redo.
    History(HistoryCommand),
    /// The layer stack.
    Layer(LayerCommand),
    /// The selected layer's mask.
    Mask(MaskCommand),
}

/// Commands that change the tool settings (no undo step: they are not part of the material).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum SettingsCommand {
    /// Replaces the brush settings (sanitised).
    SetBrush(BrushSettings),
    /// Sets the primary material.
    SetPrimary(MaterialValue),
    /// Sets the secondary material.
    SetSecondary(MaterialValue),
    /// Swaps primary and secondary.
    SwapMaterials,
    /// Sets the channels tools write.
    SetChannels(Channels),
    /// Sets the shading model.
    SetModel(ShadingModel),
    /// Sets the approximation of `chi`.
    SetApprox(AmbientApprox),
    /// Paints the brush, the eraser and clone through an image on the canvas (see
    /// [`crate::paint::Stencil`]): `SetStencil(image: "stars.png", center: (512, 512),
    /// size: 256, rotation: 0, opacity: 1)`; with a `view`, on the screen of that view
    /// instead (centre and size in its pixels), for strokes on the mesh.
    SetStencil {
        /// The image (a relative path from the script's folder).
        image: PaintImage,
        /// Its centre, in texels.
        center: Vec2,
        /// Its width, in texels.
        size: f32,
        /// Its rotation, in degrees.
        #[serde(default)]
        rotation: f32,
        /// How much it holds the paint back (1: paint only through its light parts).
        #[serde(default = "crate::check::one")]
        opacity: f32,
        /// Whether the image repeats beyond its edges.
        #[serde(default)]
        tiled: bool,
        /// The view whose screen it lies on (none: the canvas).
        #[serde(default, deserialize_with = "crate::check::some")]
        view: Option<crate::paint::ScreenView>,
    },
    /// Takes the stencil away.
    ClearStencil,
    /// Sets the clone source, in texels: the next clone stroke copies from there, its first
    /// point taking the source's texel, and later strokes keep that offset (aligned) until a
    /// new source is set.
    SetCloneSource(Vec2),
    /// Sets the clone source on the mesh, a point of its surface in object space: a clone
    /// stroke on the mesh (`SurfaceStroke(tool: Clone, ...)`) copies from there, aligned in
    /// object space (across UV seams) as `SetCloneSource` aligns on the canvas.
    SetSurfaceCloneSource(Vec3),
}

/// Strokes: each is one undo step.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum StrokeCommand {
    /// Starts a stroke (one undo step).
    BeginStroke(StrokeTool),
    /// Moves the stroke to a new input point.
    StrokeTo(StrokePoint),
    /// Ends the stroke.
    EndStroke,
    /// Abandons the stroke, restoring the maps.
    AbortStroke,
    /// A whole stroke at once (scripts): begin, every point, end.
    Stroke {
        /// The tool.
        tool: StrokeTool,
        /// Input points in texel units.
        points: Vec<StrokePoint>,
    },
    /// Moves the stroke to a new point on the mesh (object-space brush; needs a surface).
    SurfaceStrokeTo(SurfacePoint),
    /// A whole stroke on the mesh at once (scripts).
    SurfaceStroke {
        /// The tool.
        tool: StrokeTool,
        /// Input points in object space.
        points: Vec<SurfacePoint>,
    },
}

/// The one-click tools.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum PaintCommand {
    /// Fills with the primary material.
    Fill(FillRegion),
    /// A gradient from the primary (at `start`) to the secondary material (at `end`).
    Gradient {
        /// Linear or radial.
        shape: GradientShape,
        /// Start point in texel units.
        #[serde(deserialize_with = "crate::check::finite_vec2")]
        start: Vec2,
        /// End point in texel units.
        #[serde(deserialize_with = "crate::check::finite_vec2")]
        end: Vec2,
    },
    /// Paints an image through a projection into the selected layer (one undo step): its
    /// colour into `k_d`, its luminance into `k_s`, its gray into `n` (as `kapaint import
    /// --channel n` maps it), each where `channels` enables it; its alpha times `opacity` is
    /// the coverage.
    ProjectImage {
        /// The image (a relative path from the script's folder).
        image: PaintImage,
        /// How it is laid on the surface.
        projection: Projection,
        /// The channels it paints (all by default).
        #[serde(default = "all_channels")]
        channels: Channels,
        /// Its strength (1 by default).
        #[serde(default = "crate::check::one")]
        opacity: f32,
    },
    /// Places an image on the surface as a decal (one undo step): a planar projection along
    /// the surface's normal at the surface point nearest `at`, `size` object units wide (its
    /// height by the image's aspect), turned by `rotation` degrees, bounded to the image.
    PlaceDecal {
        /// The image (a relative path from the script's folder).
        image: PaintImage,
        /// A point near the surface, in object space.
        at: Vec3,
        /// Width in object units.
        size: f32,
        /// Turn about the surface's normal, degrees (counter-clockwise seen from outside).
        #[serde(default)]
        rotation: f32,
        /// The channels it paints (all by default).
        #[serde(default = "all_channels")]
        channels: Channels,
        /// Its strength (1 by default).
        #[serde(default = "crate::check::one")]
        opacity: f32,
    },
    /// The editor's Decal tool while it places a decal: laid as `PlaceDecal` lays it, in
    /// place of the previous preview's placement and in its undo step (a drag and the
    /// fields' changes are one step, which the `PlaceDecal` that commits it joins too).
    #[serde(skip_deserializing)]
    PreviewDecal(Box<super::decal::Decal>),
    /// The Decal tool's Escape: the decal being placed is taken back out, its step with it
    /// (nothing, once another command ended the placement).
    #[serde(skip_deserializing)]
    DropDecal,
    /// Reads every channel at a texel into the primary material.
    Pick {
        /// Texel column.
        x: u32,
        /// Texel row.
        y: u32,
    },
    /// Reads the selected layer at a texel into the primary material: the channels it covers
    /// there (a paint layer), its material (a fill layer) or what its children merge to (a
    /// group); the other channels stay as they were.
    PickLayer {
        /// Texel column.
        x: u32,
        /// Texel row.
        y: u32,
    },
}

impl super::decal::Decal {
    /// The command that places it for good (joining the step of a preview of it).
    pub fn place(self) -> PaintCommand {
        PaintCommand::PlaceDecal {
            image: self.image,
            at: self.at,
            size: self.size,
            rotation: self.rotation,
            channels: self.channels,
            opacity: self.opacity,
        }
    }
}

/// What a worker made from a file, each put in place as one undo step. Not for scripts: their
/// content comes from a decoder or a worker.
#[derive(Clone, Debug, PartialEq)]
pub enum ImportCommand {
    /// Replaces a channel with an image already resampled to the map size (see
    /// [`crate::import`]).
    ImportChannel(ImportedChannel),
    /// Replaces `k_d`, `k_s` and `n` of the selected paint layer with maps of the document's
    /// size (a PBR material converted on a worker), with its normal map and report.
    ImportMaterial(ImportedMaterial),
    /// Sets or clears the material's normal map.
    SetNormal(AttachedNormal),
    /// Makes a mesh, baked at the map size on a worker, the project's mesh.
    SetMesh(AttachedMesh),
    /// Keeps a map baked from the mesh on a worker (AO, curvature, ...), replacing the bake of
    /// the same map.
    SetBake(AttachedBake),
    /// Keeps several maps baked together ("Bake all"), as one step.
    SetBakes(Vec<AttachedBake>),
    /// Installs maps resized on a worker ([`crate::resize::resized`]) with the mesh
    /// surface baked at their size.
    Resize(crate::resize::ResizedMaps),
}

impl ImportCommand {
    /// Keeping maps baked from a high mesh onto the project's mesh (whose hash is
    /// `low_hash`), as one step: a tangent-space normal (alone) becomes the normal map, the
    /// others the project's bakes of the maps they stand for (what generator masks read),
    /// each saying it came from `source`. The one place a bake from a high mesh becomes what
    /// a project keeps: the editor and the command line both call it.
    ///
    /// # Errors
    /// No bakes, the normal map with other maps, a map a project does not keep (height,
    /// IDs).
    pub fn keep_high(
        bakes: Vec<kapaint_mesh::bakes::HighBake>,
        low_hash: u64,
        source: &kapaint_mesh::bakes::HighSource,
    ) -> Result<Self, String> {
        use kapaint_mesh::bakes::{HighMap, NormalSpace};
        let count = bakes.len();
        let mut kept = Vec::with_capacity(count);
        for bake in bakes {
            match bake.into_baked(low_hash, source) {
                Ok(b) => kept.push(AttachedBake(Arc::new(b))),
                Err(b) if b.map == HighMap::Normal(NormalSpace::Tangent) && count == 1 => {
                    let normal = crate::normal::NormalMap::from_rgb16(b.width, b.height, &b.data)?;
                    return Ok(Self::SetNormal(AttachedNormal(Some(Arc::new(normal)))));
                }
                Err(b) => {
                    return Err(format!(
                        "a project keeps no {} map baked from a high mesh{}",
                        b.map.name(),
                        if count > 1 { " among other maps" } else { "" }
                    ));
                }
            }
        }
        if kept.is_empty() {
            return Err("no map was baked".into());
        }
        Ok(Self::SetBakes(kept))
    }
}

/// Moves through the undo history.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum HistoryCommand {
    /// Undoes the last step.
    Undo,
    /// Redoes the last undone step.
    Redo,
    /// Undoes or redoes until this many steps are applied (0: the state before the oldest
    /// step kept; the history panel's click on a step).
    HistoryJump(usize),
}

macro_rules! room {
    ($room:ident, $ty:ty) => {
        impl From<$ty> for Command {
            fn from(command: $ty) -> Self {
                Self::$room(command)
            }
        }
    };
}
room!(Settings, SettingsCommand);
room!(Stroke, StrokeCommand);
room!(Paint, PaintCommand);
room!(Import, ImportCommand);
room!(History, HistoryCommand);
room!(Layer, LayerCommand);
room!(Mask, MaskCommand);

/// A channel's planes made by [`crate::import::resample`], shared so that the command
/// clones cheaply.
#[derive(Clone, Debug, PartialEq)]
pub struct ImportedChannel(pub Arc<crate::import::ChannelPlanes>);

/// A material converted on a worker for [`ImportCommand::ImportMaterial`]: its maps, the normal map
/// it brought and the report of its conversion, all undone together. Shared so that the
/// command clones cheaply (equal when they are the same maps).
#[derive(Clone, Debug)]
pub struct ImportedMaterial {
    /// The maps, at the document's size.
    pub maps: Arc<crate::MaterialMaps>,
    /// Its normal map (none: the document keeps no normal map).
    pub normal: Option<Arc<crate::normal::NormalMap>>,
    /// How it was converted, with the measured error.
    pub report: Option<crate::provenance::ImportReport>,
}

impl PartialEq for ImportedMaterial {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.maps, &other.maps)
    }
}

/// A normal map for [`ImportCommand::SetNormal`] (none: cleared); equal when it is the same map.
#[derive(Clone, Debug)]
pub struct AttachedNormal(pub Option<Arc<crate::normal::NormalMap>>);

impl PartialEq for AttachedNormal {
    fn eq(&self, other: &Self) -> bool {
        match (&self.0, &other.0) {
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            (a, b) => a.is_none() && b.is_none(),
        }
    }
}

/// A map baked from the mesh for [`ImportCommand::SetBake`]; equal when it is the same bake.
#[derive(Clone, Debug)]
pub struct AttachedBake(pub Arc<kapaint_mesh::bakes::Baked>);

impl PartialEq for AttachedBake {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

/// A mesh for [`ImportCommand::SetMesh`]: how the project names it and its bake at the map size;
/// equal when it is the same bake.
#[derive(Clone, Debug)]
pub struct AttachedMesh {
    /// The mesh as the project stores it.
    pub mesh: crate::MeshRef,
    /// Its bake at the map size.
    pub surface: Arc<crate::surface::Surface>,
}

impl PartialEq for AttachedMesh {
    fn eq(&self, other: &Self) -> bool {
        self.mesh == other.mesh && Arc::ptr_eq(&self.surface, &other.surface)
    }
}

impl Command {
    /// The images the command paints through: whoever applies it loads them first
    /// ([`PaintImage::load`]).
    pub fn images_mut(&mut self) -> Vec<&mut PaintImage> {
        // Every room and every command that may carry an image named: a new one does not
        // compile until it says whether it does.
        let image = match self {
            Self::Settings(c) => match c {
                SettingsCommand::SetStencil { image, .. } => Some(image),
                SettingsCommand::SetBrush(_)
                | SettingsCommand::SetPrimary(_)
                | SettingsCommand::SetSecondary(_)
                | SettingsCommand::SwapMaterials
                | SettingsCommand::SetChannels(_)
                | SettingsCommand::SetModel(_)
                | SettingsCommand::SetApprox(_)
                | SettingsCommand::ClearStencil
                | SettingsCommand::SetCloneSource(_)
                | SettingsCommand::SetSurfaceCloneSource(_) => None,
            },
            Self::Paint(c) => match c {
                PaintCommand::ProjectImage { image, .. }
                | PaintCommand::PlaceDecal { image, .. } => Some(image),
                PaintCommand::PreviewDecal(decal) => Some(&mut decal.image),
                PaintCommand::DropDecal
                | PaintCommand::Fill(_)
                | PaintCommand::Gradient { .. }
                | PaintCommand::Pick { .. }
                | PaintCommand::PickLayer { .. } => None,
            },
            Self::Layer(
                LayerCommand::SetLayerProjection { image, .. }
                | LayerCommand::AddProjectionFill { image, .. },
            ) => Some(image),
            // Strokes, imports (decoded on a worker), history, other layer commands and masks
            // name no file.
            Self::Stroke(_)
            | Self::Import(_)
            | Self::History(_)
            | Self::Layer(_)
            | Self::Mask(_) => None,
        };
        image.into_iter().collect()
    }

    /// Whether the command paints on the mesh (and so needs
    /// [`Document::with_surface`](super::Document::with_surface)).
    pub fn needs_surface(&self) -> bool {
        matches!(
            self,
            Self::Stroke(StrokeCommand::SurfaceStrokeTo(_) | StrokeCommand::SurfaceStroke { .. })
                | Self::Paint(PaintCommand::Fill(
                    FillRegion::Island { .. } | FillRegion::Part { .. }
                ))
        ) || matches!(
            self,
            Self::Paint(PaintCommand::PlaceDecal { .. } | PaintCommand::PreviewDecal(_))
        ) || matches!(self, Self::Paint(PaintCommand::ProjectImage { projection, .. }) if projection.needs_surface())
            || matches!(self, Self::Layer(LayerCommand::SetLayerProjection { projection, .. } | LayerCommand::AddProjectionFill { projection, .. }) if projection.needs_surface())
    }
}

/// Every channel: what a projection paints unless it says otherwise.
fn all_channels() -> Channels {
    Channels::ALL
}
