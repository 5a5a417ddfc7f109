//! A PBR texture layout: which files a PBR export writes and what each channel of each holds
//! (`textures: [(file: "{name}_ORM.png", channels: ["occlusion", "roughness", "metallic"])]`),
//! the way engines document their materials. The engine presets and the glTF export are
//! layouts; a user preset may name any other.

use serde::{Deserialize, Serialize};

/// What one channel of a PBR texture holds, as a preset spells it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub enum Channel {
    /// Base colour, one component, sRGB-encoded.
    Base(usize),
    /// Perceptual roughness (glTF's).
    Roughness,
    /// One minus roughness (Unity's smoothness).
    Smoothness,
    /// Metalness.
    Metallic,
    /// Ambient occlusion from the project's AO bake (1 unoccluded); 1 without one.
    Occlusion,
    /// A tangent-space normal component, `2 c - 1` (the green one by the preset's
    /// [`NormalGreen`]).
    Normal(usize),
    /// 255 everywhere.
    One,
    /// 0 everywhere.
    Zero,
}

impl Channel {
    /// Every channel, as spelled.
    pub const ALL: [(&'static str, Self); 12] = [
        ("base.r", Self::Base(0)),
        ("base.g", Self::Base(1)),
        ("base.b", Self::Base(2)),
        ("roughness", Self::Roughness),
        ("smoothness", Self::Smoothness),
        ("metallic", Self::Metallic),
        ("occlusion", Self::Occlusion),
        ("normal.x", Self::Normal(0)),
        ("normal.y", Self::Normal(1)),
        ("normal.z", Self::Normal(2)),
        ("one", Self::One),
        ("zero", Self::Zero),
    ];

    /// Its name, as a preset and the manifest spell it.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, c)| *c == self)
            .map_or("zero", |(n, _)| n)
    }

    /// Whether it is a normal map's component.
    pub fn is_normal(self) -> bool {
        matches!(self, Self::Normal(_))
    }

    /// Whether it holds the same value everywhere.
    pub fn is_constant(self) -> bool {
        matches!(self, Self::One | Self::Zero)
    }
}

impl TryFrom<String> for Channel {
    type Error = String;

    fn try_from(name: String) -> Result<Self, String> {
        Self::ALL
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, c)| *c)
            .ok_or_else(|| {
                let known: Vec<&str> = Self::ALL.iter().map(|(n, _)| *n).collect();
                format!("unknown channel {name:?} (known: {})", known.join(", "))
            })
    }
}

impl From<Channel> for String {
    fn from(c: Channel) -> Self {
        c.name().into()
    }
}

/// Which way a normal map's green channel points: glTF, Unity and Godot read +Y along the
/// bitangent (OpenGL's convention), Unreal and DirectX engines -Y.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum NormalGreen {
    /// +Y up (what the project keeps).
    #[default]
    OpenGl,
    /// -Y: green is one minus the stored green.
    DirectX,
}

impl NormalGreen {
    /// The convention in words.
    pub fn name(self) -> &'static str {
        match self {
            Self::OpenGl => "OpenGL (+Y)",
            Self::DirectX => "DirectX (-Y)",
        }
    }
}

/// One file of a PBR layout.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TextureFile {
    /// Its name in the set's folder, a PNG; `{name}` stands for the folder's name.
    pub file: String,
    /// What its channels hold, in order: one (grey), two (grey and alpha), three (RGB) or
    /// four (RGBA).
    pub channels: Vec<Channel>,
}

/// The placeholder a file name holds for the set's folder name.
pub const NAME: &str = "{name}";

/// Most files a layout may name.
pub const MAX_FILES: usize = 16;

impl TextureFile {
    /// A file of `channels`.
    pub fn new(file: &str, channels: &[Channel]) -> Self {
        Self {
            file: file.into(),
            channels: channels.to_vec(),
        }
    }

    /// Its name in the folder of a set called `set`.
    pub fn path(&self, set: &str) -> String {
        self.file.replace(NAME, set)
    }

    /// Whether it holds colour (base colour components, sRGB-encoded).
    pub fn is_colour(&self) -> bool {
        self.channels.iter().any(|c| matches!(c, Channel::Base(_)))
    }

    /// Whether it holds the normal map (at the normal map's own size).
    pub fn is_normal(&self) -> bool {
        self.channels.iter().any(|c| c.is_normal())
    }

    /// The channels in the manifest's words.
    pub fn layout(&self) -> Vec<String> {
        self.channels.iter().map(|c| c.name().to_string()).collect()
    }

    /// Whether it is one a reader could take for this file: a PNG name that stays in the
    /// folder, with one to four channels that mean one thing each.
    fn check(&self) -> Result<(), String> {
        let plain = self.file.replace(NAME, "x");
        if plain.is_empty()
            || plain.len() > 200
            || plain.starts_with('.')
            || plain.contains(['/', '\\', ':', '{', '}'])
            || plain.chars().any(char::is_control)
        {
            return Err(format!(
                "file {:?} is not a plain file name ({NAME} stands for the set's name)",
                self.file
            ));
        }
        if !plain.to_ascii_lowercase().ends_with(".png") {
            return Err(format!("file {:?} must be a .png", self.file));
        }
        if !(1..=4).contains(&self.channels.len()) {
            return Err(format!(
                "{} holds {} channels; a PNG holds 1 to 4",
                self.file,
                self.channels.len()
            ));
        }
        let varying = || self.channels.iter().filter(|c| !c.is_constant());
        if self.is_normal() && varying().any(|c| !c.is_normal()) {
            return Err(format!(
                "{} mixes the normal map with other channels (the normal map has its own size)",
                self.file
            ));
        }
        // sRGB applies to a PNG's colour channels, never to its alpha.
        let colour = self.channels.iter().take(3);
        if self.is_colour() && colour.clone().any(|c| !matches!(c, Channel::Base(_))) {
            return Err(format!(
                "{} mixes base colour (sRGB) with data in its colour channels; data may share only the alpha",
                self.file
            ));
        }
        Ok(())
    }
}

/// A glTF PBR set's base colour image.
pub const BASE_COLOR_FILE: &str = "base_color.png";
/// A glTF PBR set's metallic-roughness image.
pub const METALLIC_ROUGHNESS_FILE: &str = "metallic_roughness.png";
/// A glTF PBR set's normal map (where the project has one).
pub const GLTF_NORMAL_FILE: &str = "normal.png";

/// glTF's metallic-roughness layout: base colour, (unused, roughness, metallic), the normal
/// map where the project has one.
pub fn gltf() -> Vec<TextureFile> {
    use Channel::{Base, Metallic, Normal, One, Roughness};
    vec![
        TextureFile::new(BASE_COLOR_FILE, &[Base(0), Base(1), Base(2)]),
        TextureFile::new(METALLIC_ROUGHNESS_FILE, &[One, Roughness, Metallic]),
        TextureFile::new(GLTF_NORMAL_FILE, &[Normal(0), Normal(1), Normal(2)]),
    ]
}

/// Whether `files` is a layout a PBR export can write: 1 to [`MAX_FILES`] PNGs (so none is
/// named as the manifest or the `.glb`), each checked, no two of the same name (case aside,
/// for the file systems that ignore it).
///
/// # Errors
/// What is wrong, in words.
pub fn check(files: &[TextureFile]) -> Result<(), String> {
    if files.is_empty() || files.len() > MAX_FILES {
        return Err(format!(
            "textures names {} files; a layout names 1 to {MAX_FILES}",
            files.len()
        ));
    }
    for (i, f) in files.iter().enumerate() {
        f.check()?;
        if let Some(twin) = files[..i]
            .iter()
            .find(|g| g.file.eq_ignore_ascii_case(&f.file))
        {
            return Err(format!(
                "the layout overlaps itself: {} and {} are one file",
                twin.file, f.file
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn channels_read_as_spelled_and_unknown_ones_are_named() {
        for (name, c) in Channel::ALL {
            assert_eq!(Channel::try_from(name.to_string()), Ok(c));
            assert_eq!(String::from(c), name);
        }
        let err = Channel::try_from("rough".to_string()).unwrap_err();
        assert!(
            err.starts_with("unknown channel \"rough\" (known: base.r"),
            "{err}"
        );
    }

    #[test]
    fn layouts_that_cannot_be_written_are_refused() {
        use Channel::*;
        let ok = TextureFile::new("{name}_ORM.png", &[Occlusion, Roughness, Metallic]);
        assert_eq!(check(std::slice::from_ref(&ok)), Ok(()));
        assert_eq!(check(&gltf()), Ok(()));
        let refused = [
            (vec![], "names 0 files"),
            (vec![ok.clone(), ok.clone()], "overlaps itself"),
            (
                vec![ok.clone(), TextureFile::new("{name}_orm.PNG", &[One])],
                "overlaps itself",
            ),
            (
                vec![TextureFile::new("{NAME}.png", &[One])],
                "plain file name",
            ),
            (
                vec![TextureFile::new("../x.png", &[One])],
                "plain file name",
            ),
            (vec![TextureFile::new("x.tga", &[One])], "must be a .png"),
            (vec![TextureFile::new("x.png", &[])], "1 to 4"),
            (vec![TextureFile::new("x.png", &[One; 5])], "1 to 4"),
            (
                vec![TextureFile::new(
                    "x.png",
                    &[Normal(0), Normal(1), Roughness],
                )],
                "own size",
            ),
            (
                vec![TextureFile::new("x.png", &[Base(0), Base(1), Metallic])],
                "sRGB",
            ),
            (
                vec![TextureFile::new("material.json", &[One])],
                "must be a .png",
            ),
        ];
        for (files, why) in refused {
            let err = check(&files).expect_err(why);
            assert!(err.contains(why), "{err}");
        }
        // Constants and alpha data may sit beside the colour and the normal.
        for file in [
            TextureFile::new("x.png", &[Base(0), Base(1), Base(2), Smoothness]),
            TextureFile::new("x.png", &[Normal(0), Normal(1), One]),
        ] {
            assert_eq!(check(&[file]), Ok(()));
        }
    }
}
