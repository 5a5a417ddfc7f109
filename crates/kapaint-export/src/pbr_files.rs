//! A PBR set's images from a layout ([`TextureFile`]): each file's channels gathered from the
//! converted texels (base colour, roughness, metallic), the project's AO bake and its normal
//! map, and encoded as a PNG of one to four channels.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::file_kind::ColourSpace;
use super::preset::{Channel, NormalGreen, TextureFile};
use kapaint_mesh::bakes::{BakeMap, Baked};
use kapaint_model::Document;
use kapaint_model::normal::NormalMap;
use kapaint_pbr::round_trip::Converted;

/// One file of a PBR set, as its manifest lists it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PbrFile {
    /// File name, in the set's folder.
    pub path: String,
    /// What it holds, channel by channel (`base.r base.g base.b`, `one roughness metallic`).
    pub layout: Vec<String>,
    /// How its colour is encoded (images).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub colour_space: Option<ColourSpace>,
    /// Size in bytes.
    pub bytes: u64,
}

/// Where a set's occlusion channel came from.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Occlusion {
    /// Whether it is the project's AO bake (else white: no occlusion).
    pub baked: bool,
    /// Which bake, or why none was used, in words.
    pub note: String,
}

/// The AO bake a PBR set's occlusion is read from, with the note saying so; `None` (white)
/// with the note saying why where the project keeps none, or keeps one of another mesh.
pub fn occlusion_source(doc: &Document) -> (Option<&Baked>, Occlusion) {
    let (w, h) = (doc.maps().width(), doc.maps().height());
    let white = |note: &str| {
        (
            None,
            Occlusion {
                baked: false,
                note: format!("white: {note}"),
            },
        )
    };
    let Some(bake) = doc.bake_of(BakeMap::Ao) else {
        return white("the project has no AO bake");
    };
    if doc.surface().is_some_and(|s| s.mesh_hash != bake.mesh_hash) {
        return white("the project's AO bake is of another mesh (bake it again)");
    }
    if bake.data.len() as u64 != u64::from(bake.width) * u64::from(bake.height) || bake.width == 0 {
        return white("the project's AO bake is damaged (bake it again)");
    }
    let from = bake
        .from_high
        .as_ref()
        .map_or_else(String::new, |f| format!(" from {}", f.mesh));
    let note = format!(
        "the project's AO bake{from} ({}x{}, {} rays a texel{})",
        bake.width,
        bake.height,
        bake.options.rays,
        if (bake.width, bake.height) == (w, h) {
            String::new()
        } else {
            format!(", resampled to {w}x{h}")
        }
    );
    (Some(bake), Occlusion { baked: true, note })
}

/// The occlusion of [`occlusion_source`] at the maps' size, 8-bit (1 unoccluded).
pub fn occlusion(doc: &Document) -> (Option<Vec<u8>>, Occlusion) {
    let (w, h) = (doc.maps().width(), doc.maps().height());
    let (bake, note) = occlusion_source(doc);
    (bake.map(|b| resampled(b, w, h)), note)
}

/// A grey bake's samples as 8-bit values at `w x h`: as they are at the bake's own size,
/// else bilinear between texel centres.
fn resampled(bake: &Baked, w: u32, h: u32) -> Vec<u8> {
    let byte = |v: f32| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
    if (bake.width, bake.height) == (w, h) {
        return bake
            .data
            .par_iter()
            .map(|&s| byte(f32::from(s) / 65535.0))
            .collect();
    }
    let (bw, bh) = (bake.width as usize, bake.height as usize);
    let at = |x: usize, y: usize| f32::from(bake.data[y * bw + x]) / 65535.0;
    (0..(w as usize) * (h as usize))
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i % w as usize, i / w as usize);
            let u = ((x as f32 + 0.5) * bw as f32 / w as f32 - 0.5).clamp(0.0, (bw - 1) as f32);
            let v = ((y as f32 + 0.5) * bh as f32 / h as f32 - 0.5).clamp(0.0, (bh - 1) as f32);
            let (x0, y0) = (u as usize, v as usize);
            let (x1, y1) = ((x0 + 1).min(bw - 1), (y0 + 1).min(bh - 1));
            let (fx, fy) = (u - x0 as f32, v - y0 as f32);
            let top = at(x0, y0) + (at(x1, y0) - at(x0, y0)) * fx;
            let bottom = at(x0, y1) + (at(x1, y1) - at(x0, y1)) * fx;
            byte(top + (bottom - top) * fy)
        })
        .collect()
}

/// What a layout's images are made from.
pub struct Sources<'a> {
    /// The maps' size.
    pub size: (u32, u32),
    /// The texels as glTF's 8-bit PBR values.
    pub converted: &'a Converted,
    /// The occlusion, 8-bit, at the maps' size (`None`: white).
    pub occlusion: Option<&'a [u8]>,
    /// The normal map, where the project has one.
    pub normal: Option<&'a NormalMap>,
    /// Which way the written normal map's green points.
    pub green: NormalGreen,
}

/// One layout file encoded: its manifest entry and its bytes.
pub struct Encoded {
    /// The manifest's entry.
    pub entry: PbrFile,
    /// The PNG.
    pub bytes: Vec<u8>,
}

/// A file's texels (its channels interleaved, 8-bit) and size.
pub type Plane = (Vec<u8>, (u32, u32));

impl Sources<'_> {
    /// `file` as a PNG named `path`, or `None` for a normal map's file where the project
    /// has none.
    ///
    /// # Errors
    /// The encoder's.
    pub fn encode(&self, file: &TextureFile, path: String) -> Option<Result<Encoded, String>> {
        let (data, size) = self.plane(file)?;
        let channels = &file.channels;
        let colour = [
            image::ExtendedColorType::L8,
            image::ExtendedColorType::La8,
            image::ExtendedColorType::Rgb8,
            image::ExtendedColorType::Rgba8,
        ][channels.len() - 1];
        Some(
            kapaint_model::import::encode_png(&data, size, colour).map(|bytes| Encoded {
                entry: PbrFile {
                    path,
                    layout: file.layout(),
                    colour_space: Some(if file.is_colour() {
                        ColourSpace::Srgb
                    } else {
                        ColourSpace::Linear
                    }),
                    bytes: bytes.len() as u64,
                },
                bytes,
            }),
        )
    }

    /// `file`'s texels (its channels interleaved, 8-bit) and size, or `None` for a normal
    /// map's file where the project has none.
    pub fn plane(&self, file: &TextureFile) -> Option<Plane> {
        let channels = &file.channels;
        let (data, size) = if file.is_normal() {
            let normal = self.normal?;
            let stored = normal.image().as_raw();
            let data = gather(channels, stored.len() / 3, |c, i| match c {
                Channel::Normal(1) if self.green == NormalGreen::DirectX => 255 - stored[i * 3 + 1],
                Channel::Normal(k) => stored[i * 3 + k],
                _ => constant(c),
            });
            (data, (normal.width(), normal.height()))
        } else {
            let (base, mr) = (&self.converted.base, &self.converted.metallic_roughness);
            let data = gather(channels, base.len(), |c, i| match c {
                Channel::Base(k) => base[i][k],
                Channel::Roughness => mr[i][1],
                Channel::Smoothness => 255 - mr[i][1],
                Channel::Metallic => mr[i][2],
                Channel::Occlusion => self.occlusion.map_or(255, |o| o[i]),
                Channel::Normal(_) | Channel::One | Channel::Zero => constant(c),
            });
            (data, self.size)
        };
        Some((data, size))
    }
}

/// `texels` texels of `channels`, interleaved, each byte `value(channel, texel)`.
fn gather(
    channels: &[Channel],
    texels: usize,
    value: impl Fn(Channel, usize) -> u8 + Sync,
) -> Vec<u8> {
    let mut data = vec![0_u8; texels * channels.len()];
    data.par_chunks_mut(channels.len() << 12)
        .enumerate()
        .for_each(|(chunk, out)| {
            let first = chunk << 12;
            for (j, px) in out.chunks_exact_mut(channels.len()).enumerate() {
                for (b, &c) in px.iter_mut().zip(channels) {
                    *b = value(c, first + j);
                }
            }
        });
    data
}

/// A constant channel's byte (0 for any other).
fn constant(c: Channel) -> u8 {
    if c == Channel::One { 255 } else { 0 }
}
