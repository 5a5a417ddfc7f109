//! `kapaint bake`: a map of the project's mesh (AO, curvature, thickness, position, normal)
//! at the project's size, kept in the project (a cache tied to the mesh) or written out as a
//! 16-bit PNG.

use std::path::PathBuf;
use std::time::Instant;

use super::{CliError, model_error};
use crate::mesh::bakes::{BakeMap, BakeOptions, BakeStats, Baked, RAYS, bake_map};
use crate::model::project;

/// A map baked from a project's mesh.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum MapArg {
    /// Ambient occlusion: the share of the hemisphere that sees open sky (1 = open).
    Ao,
    /// Curvature: 0.5 flat, above convex, below concave.
    Curvature,
    /// Thickness: the mean distance to the mesh inwards, over the maximum distance.
    Thickness,
    /// Object-space position, normalised to the bounding box (RGB).
    Position,
    /// Object-space normal, 0.5 + 0.5 n (RGB); with --high, the high mesh's normal.
    Normal,
    /// With --high: the high surface's height over the project's mesh, by the ray distances.
    Height,
    /// With --high: the high mesh's materials, objects, pieces or vertex colours, a colour
    /// each (RGB; see --id-from).
    Id,
}

impl MapArg {
    /// The map baked from the project's own mesh, if it is one.
    fn own(self) -> Option<BakeMap> {
        match self {
            Self::Ao => Some(BakeMap::Ao),
            Self::Curvature => Some(BakeMap::Curvature),
            Self::Thickness => Some(BakeMap::Thickness),
            Self::Position => Some(BakeMap::Position),
            Self::Normal => Some(BakeMap::Normal),
            Self::Height | Self::Id => None,
        }
    }
}

/// Bake a map of the project's mesh at the project's size (every texel the mesh's UVs give a
/// surface point, seams padded like the maps): kept in the project, or with --out written as
/// a 16-bit PNG (grey, or RGB for position and normal) and the project left as it is.
#[derive(Debug, clap::Args)]
pub struct BakeArgs {
    /// The project.
    project: PathBuf,
    /// The map to bake.
    #[arg(long, value_enum)]
    map: MapArg,
    /// Rays per texel (ao, thickness), 1 to 65536. Time grows with rays times texels: on 2
    /// cores about 18 minutes at 65536 rays and 256^2 (a bar with an estimate shows on a
    /// terminal).
    #[arg(long, default_value_t = 128, value_parser = clap::value_parser!(u32).range(i64::from(*RAYS.start())..=i64::from(*RAYS.end())))]
    rays: u32,
    /// How far a ray looks, in object units (default: unbounded for ao, the bounding box's
    /// diagonal for thickness).
    #[arg(long)]
    max_distance: Option<f32>,
    /// The PNG to write instead of keeping the bake in the project.
    #[arg(long)]
    out: Option<PathBuf>,
    /// A high-poly mesh (OBJ or glTF) to bake from, onto the project's mesh; given more than
    /// once, the meshes are baked as one. Rays from the project's mesh meet the nearest high
    /// surface: a tangent-space normal is kept as the project's normal map (one undo step),
    /// ao, thickness, curvature, position and object-space normal as the project's bakes of
    /// those maps (what generator masks read); height and id need --out.
    #[arg(long)]
    high: Vec<PathBuf>,
    /// With --high: a cage (OBJ or glTF), the project's mesh with its vertices pushed out
    /// (the same triangles): each ray starts on it and goes towards the project's mesh, and
    /// --rear past it.
    #[arg(long, requires = "high")]
    cage: Option<PathBuf>,
    /// With --high: samples per texel, 1, 4 (2 x 2) or 16 (4 x 4), averaged (antialiasing).
    #[arg(long, requires = "high", default_value_t = 1)]
    samples: u32,
    /// With --high: also write the skew view, an 8-bit grey PNG, the angle between each
    /// texel's rays and its triangle's face (black 0, white 90 degrees): where the project's
    /// averaged normals tilt the rays.
    #[arg(long, requires = "high")]
    skew: Option<PathBuf>,
    /// The space of a normal baked from --high: tangent (the project's mesh's MikkTSpace
    /// frame, what the preview and the exports read) or object (needs --out).
    #[arg(long, requires = "high", value_enum, default_value_t = super::bake_high::SpaceArg::Tangent)]
    space: super::bake_high::SpaceArg,
    /// How far above the project's mesh a ray from it starts, in object units (default 2 %
    /// of the diagonal of the box both meshes fill).
    #[arg(long, requires = "high")]
    front: Option<f32>,
    /// How far below the project's mesh a ray still looks, in object units (default as
    /// --front).
    #[arg(long, requires = "high")]
    rear: Option<f32>,
    /// With --high: also write the miss map, an 8-bit grey PNG, white where a texel's ray met
    /// nothing.
    #[arg(long, requires = "high")]
    misses: Option<PathBuf>,
    /// With --high: pair the project's mesh's parts with the high mesh's by name (OBJ
    /// objects and groups, glTF nodes): `X_low` bakes only from `X_high`, so parts never bake
    /// onto each other; parts of no pair bake from the high parts of no pair.
    #[arg(long = "match", requires = "high", value_enum)]
    matching: Option<super::bake_high::MatchArg>,
    /// With --high and --map id: what the colours tell apart: the high mesh's materials,
    /// objects (OBJ objects and groups, glTF nodes), pieces (surfaces joined by shared
    /// positions) or its vertex colours themselves (default: materials where it names more
    /// than one, else objects where it names more than one, else pieces).
    #[arg(long, requires = "high", value_enum)]
    id_from: Option<super::bake_high::IdArg>,
    /// With --high, for ao and thickness: where the rays run: auto (a hardware GPU where
    /// this machine has one, else the CPU), cpu, or gpu (any adapter, software ones included).
    /// Parts matched by name bake on the CPU.
    #[arg(long, requires = "high", value_enum, default_value_t = super::bake_high::DeviceArg::Auto)]
    device: super::bake_high::DeviceArg,
    /// Overwrite an existing file.
    #[arg(long)]
    force: bool,
}

impl BakeArgs {
    /// Runs the command; returns what it prints.
    ///
    /// # Errors
    /// A project or mesh that does not load, a mesh without UVs, bad values, an existing file
    /// without `--force`, a failed write. Nothing is written then.
    pub fn run(self) -> Result<String, CliError> {
        if let Some(out) = &self.out {
            let ext = out
                .extension()
                .and_then(|e| e.to_str())
                .map(str::to_ascii_lowercase);
            let height = matches!(self.map, MapArg::Height);
            if ext.as_deref() != Some("png") && !(height && ext.as_deref() == Some("exr")) {
                return Err(CliError::usage(format!(
                    "{}: --out must end in .png{}",
                    out.display(),
                    if height { " or .exr" } else { "" }
                )));
            }
        }
        for file in [&self.out, &self.misses, &self.skew].into_iter().flatten() {
            if file.exists() && !self.force {
                return Err(CliError::usage(format!(
                    "{} exists; pass --force to overwrite it",
                    file.display()
                )));
            }
        }
        if let Some(d) = self.max_distance
            && !(d.is_finite() && d > 0.0)
        {
            return Err(CliError::usage(format!(
                "--max-distance {d} is not a positive number"
            )));
        }
        if !self.high.is_empty() {
            use crate::mesh::bakes::{HighMap, NormalSpace};
            let map = match self.map {
                MapArg::Normal => HighMap::Normal(match self.space {
                    super::bake_high::SpaceArg::Tangent => NormalSpace::Tangent,
                    super::bake_high::SpaceArg::Object => NormalSpace::Object,
                }),
                MapArg::Height => HighMap::Height,
                MapArg::Ao => HighMap::Ao,
                MapArg::Thickness => HighMap::Thickness,
                MapArg::Curvature => HighMap::Curvature,
                MapArg::Position => HighMap::Position,
                // Which source, once the high mesh is read (by --id-from, or what it names).
                MapArg::Id => HighMap::Id(crate::mesh::bakes::IdSource::Piece),
            };
            let options = crate::mesh::bakes::HighOptions {
                map,
                front: self.front,
                rear: self.rear,
                rays: self.rays,
                max_distance: self.max_distance,
                samples: self.samples,
            };
            return super::bake_high::run(&super::bake_high::HighRequest {
                project: &self.project,
                high: &self.high,
                cage: self.cage.as_deref(),
                options,
                out: self.out.as_ref(),
                misses: self.misses.as_ref(),
                skew: self.skew.as_ref(),
                matching: self.matching.is_some(),
                id_from: self.id_from.map(super::bake_high::IdArg::source),
                device: self.device.choice(),
            });
        }
        let Some(map) = self.map.own() else {
            return Err(CliError::usage(
                "--map height and --map id are baked from a high mesh: give --high HIGH",
            ));
        };
        let (mut doc, surface, on_disk) = super::bake_high::open_to_bake(&self.project)?;
        let options = BakeOptions {
            rays: self.rays,
            max_distance: self.max_distance,
        };
        let start = Instant::now();
        let progress = crate::task::Progress::default();
        let baked = super::progress::with_bar("bake", &progress, || {
            bake_map(&surface.mesh, &surface.bake, map, options, Some(&progress))
        })
        .map_err(|e| CliError::usage(e.to_string()))?;
        let seconds = start.elapsed().as_secs_f64();
        let stats = baked.stats(&surface.bake);
        let line = summary(&self.project, &surface.mesh.name, &baked, &stats, seconds);
        if let Some(out) = &self.out {
            let png = project::bake_png(&baked).map_err(CliError::io)?;
            crate::atomic::write_atomic(out, &png)
                .map_err(|e| CliError::of_io(format!("{}: {e}", out.display()), &e))?;
            return Ok(format!("{line}\nwrote {}\n", out.display()));
        }
        let bake = crate::model::document::AttachedBake(std::sync::Arc::new(baked));
        doc.apply(crate::model::ImportCommand::SetBake(bake))
            .map_err(model_error)?;
        project::save_checked(&doc, &self.project, on_disk.as_ref()).map_err(model_error)?;
        Ok(format!("{line}\nkept in {}\n", self.project.display()))
    }
}

/// One line on what was baked.
fn summary(
    project: &std::path::Path,
    mesh: &str,
    baked: &Baked,
    stats: &BakeStats,
    seconds: f64,
) -> String {
    let mut line = format!(
        "baked {} of {} ({mesh}): {}x{}, {} texels, mean {:.4}, min {:.4}, {seconds:.2} s",
        baked.map.name(),
        project.display(),
        baked.width,
        baked.height,
        stats.texels,
        stats.mean,
        stats.min,
    );
    if stats.rays_cast > 0 {
        use std::fmt::Write as _;
        let _ = write!(
            line,
            ", {} rays ({:.1} M rays/s)",
            stats.rays_cast,
            stats.rays_cast as f64 / seconds.max(1e-9) / 1e6
        );
    }
    line
}
