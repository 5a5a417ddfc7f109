//! The names scripts give commands: each room's own serde form (`SetPrimary((...))`,
//! `AddLayer(kind: Paint, name: "dirt")`), read flat, without the room. A script names a
//! command by its variant's name in its room ([`SettingsCommand`], [`StrokeCommand`], ...);
//! which room a name belongs to comes from the rooms' derived forms themselves, so there is
//! no list to keep. The script format is a contract: a name never changes meaning.
//! [`ImportCommand`](super::command::ImportCommand)s have no script form (their content comes
//! from a decoder or a worker), nor has the editor's `PreviewMaskGenerator`.

use std::sync::OnceLock;

use serde::de::{self, Deserialize, DeserializeSeed, Deserializer, EnumAccess, IntoDeserializer};

use super::command::{
    Command, HistoryCommand, LayerCommand, MaskCommand, PaintCommand, SettingsCommand,
    StrokeCommand,
};

/// A room of commands that scripts name.
#[derive(Clone, Copy, Debug)]
enum Room {
    Settings,
    Stroke,
    Paint,
    History,
    Layer,
    Mask,
}

impl Room {
    const ALL: [Self; 6] = [
        Self::Settings,
        Self::Stroke,
        Self::Paint,
        Self::History,
        Self::Layer,
        Self::Mask,
    ];

    /// The script names of the room's commands, as its derived form knows them (asked once
    /// per process, not once per command read).
    fn names(self) -> &'static [&'static str] {
        static NAMES: OnceLock<[&'static [&'static str]; 6]> = OnceLock::new();
        let names = NAMES.get_or_init(|| {
            Room::ALL.map(|room| match room {
                Self::Settings => variants::<SettingsCommand>(),
                Self::Stroke => variants::<StrokeCommand>(),
                Self::Paint => variants::<PaintCommand>(),
                Self::History => variants::<HistoryCommand>(),
                Self::Layer => variants::<LayerCommand>(),
                Self::Mask => variants::<MaskCommand>(),
            })
        });
        names[self as usize]
    }

    /// Reads the command `name` of this room from its content.
    fn read<'de, V: de::VariantAccess<'de>>(
        self,
        name: &str,
        content: V,
    ) -> Result<Command, V::Error> {
        let named = Named { name, content };
        Ok(match self {
            Self::Settings => SettingsCommand::deserialize(named)?.into(),
            Self::Stroke => StrokeCommand::deserialize(named)?.into(),
            Self::Paint => PaintCommand::deserialize(named)?.into(),
            Self::History => HistoryCommand::deserialize(named)?.into(),
            Self::Layer => LayerCommand::deserialize(named)?.into(),
            Self::Mask => MaskCommand::deserialize(named)?.into(),
        })
    }
}

/// Every script name, in the rooms' order: what an unknown name's error lists.
fn all_names() -> &'static [&'static str] {
    static NAMES: OnceLock<Vec<&'static str>> = OnceLock::new();
    NAMES.get_or_init(|| Room::ALL.iter().flat_map(|r| r.names()).copied().collect())
}

/// The variants an enum's derived `Deserialize` reads (its skipped ones left out): asked of
/// the derive itself, which hands them to `deserialize_enum`.
fn variants<'de, T: Deserialize<'de>>() -> &'static [&'static str] {
    let mut seen = None;
    // The probe answers every request with an error: only what it saw matters.
    let _ = T::deserialize(Probe(&mut seen));
    seen.unwrap_or(&[])
}

/// A deserializer that notes the variants of the enum asked of it, and reads nothing.
struct Probe<'a>(&'a mut Option<&'static [&'static str]>);

impl<'de> Deserializer<'de> for Probe<'_> {
    type Error = de::value::Error;

    fn deserialize_any<V: de::Visitor<'de>>(self, _: V) -> Result<V::Value, Self::Error> {
        Err(de::Error::custom("a probe reads nothing"))
    }

    fn deserialize_enum<V: de::Visitor<'de>>(
        self,
        _name: &'static str,
        variants: &'static [&'static str],
        _: V,
    ) -> Result<V::Value, Self::Error> {
        *self.0 = Some(variants);
        Err(de::Error::custom("a probe reads nothing"))
    }

    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string bytes byte_buf
        option unit unit_struct newtype_struct seq tuple tuple_struct map struct identifier
        ignored_any
    }
}

/// A command whose name was read already, with its content still to read: a room's derived
/// form reads it as if it had read the name itself.
struct Named<'a, V> {
    name: &'a str,
    content: V,
}

impl<'de, A: de::VariantAccess<'de>> Deserializer<'de> for Named<'_, A> {
    type Error = A::Error;

    fn deserialize_any<W: de::Visitor<'de>>(self, visitor: W) -> Result<W::Value, Self::Error> {
        visitor.visit_enum(self)
    }

    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string bytes byte_buf
        option unit unit_struct newtype_struct seq tuple tuple_struct map struct enum
        identifier ignored_any
    }
}

impl<'de, A: de::VariantAccess<'de>> EnumAccess<'de> for Named<'_, A> {
    type Error = A::Error;
    type Variant = A;

    fn variant_seed<S: DeserializeSeed<'de>>(
        self,
        seed: S,
    ) -> Result<(S::Value, Self::Variant), Self::Error> {
        let name: de::value::StrDeserializer<'_, Self::Error> = self.name.into_deserializer();
        Ok((seed.deserialize(name)?, self.content))
    }
}

/// A command's name, read as an identifier (as a derived enum reads its variant's).
struct Name(String);

impl<'de> Deserialize<'de> for Name {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct NameVisitor;
        impl de::Visitor<'_> for NameVisitor {
            type Value = Name;

            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a command's name")
            }

            fn visit_str<E: de::Error>(self, v: &str) -> Result<Name, E> {
                Ok(Name(v.to_owned()))
            }
        }
        d.deserialize_identifier(NameVisitor)
    }
}

/// Reads a script's command: its name, then the room that has it reads its content.
struct CommandVisitor;

impl<'de> de::Visitor<'de> for CommandVisitor {
    type Value = Command;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a command, as SetPrimary((...)) or Undo")
    }

    fn visit_enum<A: EnumAccess<'de>>(self, data: A) -> Result<Command, A::Error> {
        let (Name(name), content): (Name, A::Variant) = data.variant()?;
        let Some(room) = Room::ALL
            .into_iter()
            .find(|r| r.names().contains(&name.as_str()))
        else {
            return Err(de::Error::unknown_variant(&name, all_names()));
        };
        room.read(&name, content)
    }
}

impl<'de> Deserialize<'de> for Command {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_enum("Command", all_names(), CommandVisitor)
    }
}

/// `SetMaskGenerator`'s content: `None`, or a generator, checked as it is read.
pub(super) fn mask_generator<'de, D: Deserializer<'de>>(
    d: D,
) -> Result<Option<crate::generator::Generator>, D::Error> {
    crate::generator::MaskGenerator::deserialize(d).map(|g| g.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_room_names_its_commands_and_no_name_is_in_two() {
        for (i, room) in Room::ALL.into_iter().enumerate() {
            assert_eq!(room as usize, i, "Room::ALL is in declaration order");
        }
        let names = all_names();
        assert!(
            names.contains(&"SetPrimary") && names.contains(&"Ungroup"),
            "{names:?}"
        );
        assert!(
            !names.contains(&"PreviewMaskGenerator"),
            "the editor's drag only"
        );
        assert!(
            !names.contains(&"ImportChannel"),
            "a worker's, not a script's"
        );
        let mut sorted = names.to_vec();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), names.len(), "a name in two rooms: {names:?}");
        // The script format is a contract: the names scripts have always used, each still
        // read (a renamed variant would fail here).
        let contract = [
            "SetBrush",
            "SetPrimary",
            "SetSecondary",
            "SwapMaterials",
            "SetChannels",
            "SetModel",
            "SetApprox",
            "SetStencil",
            "ClearStencil",
            "SetCloneSource",
            "SetSurfaceCloneSource",
            "BeginStroke",
            "StrokeTo",
            "EndStroke",
            "AbortStroke",
            "Stroke",
            "SurfaceStrokeTo",
            "SurfaceStroke",
            "Fill",
            "Gradient",
            "ProjectImage",
            "PlaceDecal",
            "Pick",
            "PickLayer",
            "Undo",
            "Redo",
            "HistoryJump",
            "AddLayer",
            "SelectLayer",
            "SelectPath",
            "SetLayerOpacity",
            "SetLayerVisible",
            "SetLayerLocked",
            "RenameLayer",
            "SetLayerBlend",
            "SetLayerChannels",
            "SetLayerFill",
            "SetLayerProjection",
            "AddProjectionFill",
            "MoveLayer",
            "MoveLayerTo",
            "DeleteLayer",
            "DuplicateLayer",
            "MergeDown",
            "Flatten",
            "AddMask",
            "DeleteMask",
            "ApplyMask",
            "SelectMask",
            "SelectContent",
            "InvertMask",
            "SetMaskEnabled",
            "MaskFromChannel",
            "SetMaskGenerator",
            "Group",
            "Ungroup",
        ];
        for name in contract {
            assert!(names.contains(&name), "{name} is no longer read");
        }
        assert_eq!(names.len(), contract.len(), "{names:?}");
    }
}
