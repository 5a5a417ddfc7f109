//! What a document is painted on and with: its mesh and the mesh's bake (`SetMesh`), the
//! mesh its project keeps, the maps baked from the mesh (`SetBake`), the bake a loader
//! attaches, and the normal map (`SetNormal`); each change one undo step.

use std::sync::Arc;

use super::{AttachedMesh, Document};
use crate::ModelError;
use crate::normal::NormalMap;
use crate::surface::Surface;

impl Document {
    /// This document with `normal` as its normal map (a loader making it).
    #[must_use]
    pub fn with_normal(mut self, normal: Option<Arc<NormalMap>>) -> Self {
        self.state.normal = normal;
        self
    }

    /// The tangent-space normal map, if the material has one (not painted; never in `k_a`).
    pub fn normal(&self) -> Option<&Arc<NormalMap>> {
        self.state.normal.as_ref()
    }

    /// This document with the mesh its project keeps (a loader or `kapaint new --unwrap`
    /// making it; [`MeshRef::Embedded`](crate::MeshRef::Embedded) names it).
    #[must_use]
    pub fn with_embedded_mesh(mut self, mesh: Option<Arc<kapaint_mesh::Mesh>>) -> Self {
        self.state.embedded_mesh = mesh;
        self
    }

    /// The maps baked from the mesh (at most one of each), in the order
    /// [`BakeMap::ALL`](kapaint_mesh::bakes::BakeMap::ALL) lists them.
    pub fn bakes(&self) -> &[Arc<kapaint_mesh::bakes::Baked>] {
        &self.state.bakes
    }

    /// The bake of `map`, if the document keeps one.
    pub fn bake_of(
        &self,
        map: kapaint_mesh::bakes::BakeMap,
    ) -> Option<&Arc<kapaint_mesh::bakes::Baked>> {
        self.state.bakes.iter().find(|b| b.map == map)
    }

    /// This document with the bakes its project keeps (a loader making it).
    #[must_use]
    pub fn with_bakes(mut self, bakes: Vec<Arc<kapaint_mesh::bakes::Baked>>) -> Self {
        self.state.bakes = bakes;
        self.lay_generators();
        self
    }

    /// Whether a layer is laid on the mesh (a generator mask, or a projection fill that
    /// projects onto the surface): the composite is only right with the mesh's surface
    /// attached.
    pub fn needs_mesh(&self) -> bool {
        self.state.stack.walk().iter().any(|(_, l)| {
            l.mask.as_ref().is_some_and(|m| m.generator.is_some())
                || matches!(&l.content, crate::layers::LayerContent::Projected(p)
                    if p.fill().projection.needs_surface())
        })
    }

    /// The bakes a generator mask reads that the document does not keep, each with the name
    /// of the first layer whose mask reads it, in [`BakeMap::ALL`](kapaint_mesh::bakes::BakeMap::ALL)
    /// order.
    pub fn missing_bakes(&self) -> Vec<(kapaint_mesh::bakes::BakeMap, String)> {
        let mut out: Vec<(kapaint_mesh::bakes::BakeMap, String)> = Vec::new();
        for (_, layer) in self.state.stack.walk() {
            let Some(g) = layer.mask.as_ref().and_then(|m| m.generator()) else {
                continue;
            };
            for map in g.bakes_needed() {
                if self.bake_of(map).is_none() && out.iter().all(|(m, _)| *m != map) {
                    out.push((map, layer.props.name.clone()));
                }
            }
        }
        out.sort_by_key(|(m, _)| {
            kapaint_mesh::bakes::BakeMap::ALL
                .iter()
                .position(|(_, x)| x == m)
        });
        out
    }

    /// Lays the generator masks again on what they read now, and composites what changed.
    fn lay_generators(&mut self) {
        if super::masks::lay_generators(&mut self.state) {
            self.compositor.update(&self.state.stack, &mut self.maps);
        }
    }

    /// The mesh the project keeps inside itself, if it keeps one.
    pub fn embedded_mesh(&self) -> Option<&Arc<kapaint_mesh::Mesh>> {
        self.state.embedded_mesh.as_ref()
    }

    /// This document with the mesh surface that object-space strokes and island/part fills
    /// paint on (the bake of its mesh at the map size), or without one, as it is made or
    /// opened: no undo step (changing the mesh is
    /// [`ImportCommand::SetMesh`](super::ImportCommand::SetMesh)).
    ///
    /// # Errors
    /// When the bake's size differs from the maps'.
    pub fn with_surface(mut self, surface: Option<Arc<Surface>>) -> Result<Self, ModelError> {
        self.attach_surface(surface)?;
        Ok(self)
    }

    /// Attaches the bake of the document's mesh (or another mesh a command paints on, such as
    /// `paint --mesh`), or detaches it, as a document is opened. A bake is derived data the
    /// project never stores, so this is no undo step; the project's mesh changes only through
    /// [`ImportCommand::SetMesh`](super::ImportCommand::SetMesh).
    ///
    /// # Errors
    /// When the bake's size differs from the maps'; nothing changes then.
    pub(crate) fn attach_surface(
        &mut self,
        surface: Option<Arc<Surface>>,
    ) -> Result<(), ModelError> {
        self.check_surface(surface.as_deref())?;
        self.end_stroke();
        // Bakes of another mesh (a mesh file changed since they were made) are stale.
        if let Some(s) = &surface {
            let hash = s.mesh.content_hash();
            self.state.bakes.retain(|b| b.mesh_hash == hash);
        }
        self.state.surface = surface;
        self.lay_generators();
        Ok(())
    }

    /// An error when a bake's size differs from the maps'.
    fn check_surface(&self, surface: Option<&Surface>) -> Result<(), ModelError> {
        match surface {
            Some(s) if (s.width(), s.height()) != (self.maps.width(), self.maps.height()) => {
                Err(ModelError::Internal(format!(
                    "the mesh is baked at {}x{} but the maps are {}x{}",
                    s.width(),
                    s.height(),
                    self.maps.width(),
                    self.maps.height()
                )))
            }
            _ => Ok(()),
        }
    }

    /// [`ImportCommand::SetMesh`](super::ImportCommand::SetMesh): the project's mesh and its bake, as one
    /// undo step.
    pub(super) fn set_mesh(&mut self, mesh: &AttachedMesh) -> Result<(), ModelError> {
        self.check_surface(Some(&mesh.surface))?;
        self.end_stroke();
        let before = self.state.clone();
        self.state.surface = Some(Arc::clone(&mesh.surface));
        self.state.mesh = mesh.mesh.clone();
        // A mesh the project keeps is the one just baked.
        self.state.embedded_mesh = mesh
            .mesh
            .is_embedded()
            .then(|| Arc::new(mesh.surface.mesh.clone()));
        // Bakes belong to the mesh they were made from.
        let hash = mesh.surface.mesh.content_hash();
        self.state.bakes.retain(|b| b.mesh_hash == hash);
        self.record("Mesh", before);
        Ok(())
    }

    /// [`ImportCommand::SetBake`](super::ImportCommand::SetBake) and
    /// [`SetBakes`](super::ImportCommand::SetBakes): maps baked from the mesh kept, each
    /// replacing the bake of the same map, as one undo step.
    ///
    /// # Errors
    /// A bake of another size than the maps, or of another mesh than the attached one;
    /// nothing is kept then.
    pub(super) fn set_bakes(
        &mut self,
        bakes: Vec<Arc<kapaint_mesh::bakes::Baked>>,
    ) -> Result<(), ModelError> {
        for bake in &bakes {
            if (bake.width, bake.height) != (self.maps.width(), self.maps.height()) {
                return Err(ModelError::Command(format!(
                    "the {} bake is {}x{} but the maps are {}x{}",
                    bake.map.name(),
                    bake.width,
                    bake.height,
                    self.maps.width(),
                    self.maps.height()
                )));
            }
            if let Some(s) = &self.state.surface
                && s.mesh.content_hash() != bake.mesh_hash
            {
                return Err(ModelError::Command(format!(
                    "the {} bake was made from another mesh than the project's",
                    bake.map.name()
                )));
            }
        }
        if bakes.is_empty() {
            return Ok(());
        }
        self.end_stroke();
        let before = self.state.clone();
        let order = |m| {
            kapaint_mesh::bakes::BakeMap::ALL
                .iter()
                .position(|(_, x)| *x == m)
        };
        let names: Vec<&str> = bakes.iter().map(|b| b.map.name()).collect();
        let label = format!("Bake {}", names.join(", "));
        for bake in bakes {
            self.state.bakes.retain(|b| b.map != bake.map);
            self.state.bakes.push(bake);
        }
        self.state.bakes.sort_by_key(|b| order(b.map));
        self.record(&label, before);
        Ok(())
    }

    /// [`ImportCommand::SetNormal`](super::ImportCommand::SetNormal): the normal map set or cleared, as one
    /// undo step.
    pub(super) fn set_normal(&mut self, normal: Option<Arc<NormalMap>>) {
        self.end_stroke();
        let label = if normal.is_some() {
            "Normal map"
        } else {
            "Clear normal map"
        };
        let before = self.state.clone();
        self.state.normal = normal;
        self.record(label, before);
    }
}
