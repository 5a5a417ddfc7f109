//! Which mesh a document is painted on, as its project stores it.

use serde::{Deserialize, Serialize};

/// The mesh a document is painted on.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(try_from = "MeshRefFile")]
pub enum MeshRef {
    /// The built-in UV sphere.
    #[default]
    Sphere,
    /// A mesh file, by path.
    File(String),
    /// Another built-in mesh (plane, cube, torus), by name.
    Builtin(String),
    /// A mesh kept inside the project file (an automatically unwrapped mesh, say), with the
    /// name it is shown by; the document holds it
    /// ([`Document::embedded_mesh`](crate::Document::embedded_mesh)).
    Embedded(String),
}

/// A mesh reference as a file spells it, before it is checked.
#[derive(Deserialize)]
enum MeshRefFile {
    Sphere,
    File(String),
    Builtin(String),
    Embedded(String),
}

impl TryFrom<MeshRefFile> for MeshRef {
    type Error = String;

    fn try_from(f: MeshRefFile) -> Result<Self, String> {
        use crate::check::{MAX_PATH_BYTES, bounded_text};
        match f {
            MeshRefFile::Sphere => Ok(Self::Sphere),
            MeshRefFile::File(path) => {
                if path.is_empty() {
                    return Err("the mesh path is empty".into());
                }
                bounded_text("the mesh path", &path, MAX_PATH_BYTES)?;
                Ok(Self::File(path))
            }
            MeshRefFile::Builtin(name) if kapaint_mesh::BUILTIN_NAMES.contains(&name.as_str()) => {
                Ok(Self::Builtin(name))
            }
            MeshRefFile::Builtin(name) => Err(format!(
                "no built-in mesh is named {name:?} (known: {})",
                kapaint_mesh::BUILTIN_NAMES.join(", ")
            )),
            MeshRefFile::Embedded(name) => {
                bounded_text("the embedded mesh's name", &name, MAX_PATH_BYTES)?;
                Ok(Self::Embedded(name))
            }
        }
    }
}

impl MeshRef {
    /// What `kapaint` commands take for it: a built-in name or a path (an embedded mesh's
    /// name, which is neither: see [`is_embedded`](Self::is_embedded)).
    pub fn spec(&self) -> &str {
        match self {
            Self::Sphere => "sphere",
            Self::File(p) | Self::Builtin(p) | Self::Embedded(p) => p,
        }
    }

    /// Whether the mesh is kept inside the project.
    pub fn is_embedded(&self) -> bool {
        matches!(self, Self::Embedded(_))
    }

    /// From a built-in name or a path.
    pub fn from_spec(spec: &str) -> Self {
        match spec {
            "sphere" => Self::Sphere,
            s if kapaint_mesh::BUILTIN_NAMES.contains(&s) => Self::Builtin(s.to_string()),
            s => Self::File(s.to_string()),
        }
    }
}
