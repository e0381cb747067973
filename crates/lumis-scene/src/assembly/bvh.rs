//! Building the BVHs: instanced meshes in parallel, then the top level,
//! compact or not as the whole scene's size decides.

use std::sync::Arc;

use lumis_core::{Error, Location, Result};
use lumis_embree::SceneBuilder;

use crate::render_scene::{Geometry, MeshData, Placement, Prototype};
use crate::report::{LoadReport, Phase};

/// A mesh used by several nodes: its own Embree scene, built with the
/// top-level one once the scene-wide build options are known.
pub(crate) struct PendingPrototype {
    pub builder: SceneBuilder,
    pub meshes: Vec<MeshData>,
    pub instances: Vec<PendingInstance>,
    /// Prefixes a build error: the shape and file it came from.
    pub owner: String,
    pub location: Location,
}

/// One node's placement of a [`PendingPrototype`].
pub(crate) struct PendingInstance {
    /// 3x4 column-major, as Embree takes it.
    pub transform: [f32; 12],
    pub placement: Placement,
    /// Per prototype mesh, the instance's light index per triangle.
    pub lights: Vec<Vec<u32>>,
}

/// Builds the instanced meshes' BVHs (in parallel), places their
/// instances and builds the top level, all compact or not as
/// `report.compact` says. Returns the scene and the prototypes, indexed
/// as the instances' `prototype`.
pub(crate) fn build_bvhs(
    mut builder: SceneBuilder,
    pending: Vec<PendingPrototype>,
    geometries: &mut Vec<Geometry>,
    report: &mut LoadReport,
) -> Result<(lumis_embree::Scene, Vec<Prototype>)> {
    let compact = report.compact;
    let (builders, rest): (Vec<_>, Vec<_>) = pending
        .into_iter()
        .map(|mut p| {
            p.builder.set_compact(compact);
            (p.builder, (p.meshes, p.instances, p.owner, p.location))
        })
        .unzip();
    let scenes = report.time(Phase::Bvh, || {
        use rayon::prelude::*;
        builders
            .into_par_iter()
            .map(SceneBuilder::commit)
            .collect::<Vec<_>>()
    });
    let mut prototypes = Vec::with_capacity(scenes.len());
    for (scene, (meshes, instances, owner, location)) in scenes.into_iter().zip(rest) {
        let err = |e: lumis_embree::EmbreeError| Error::at(&location, format!("{owner}: {e}"));
        let scene = Arc::new(scene.map_err(err)?);
        let prototype = prototypes.len() as u32;
        for instance in instances {
            builder
                .add_instance(scene.clone(), &instance.transform)
                .map_err(err)?;
            geometries.push(Geometry::Instance {
                prototype,
                placement: instance.placement,
                lights: instance.lights,
            });
        }
        prototypes.push(Prototype { meshes });
    }
    builder.set_compact(compact);
    let embree = report.time(Phase::Bvh, || {
        builder.commit().map_err(|e| Error::msg(e.to_string()))
    })?;
    Ok((embree, prototypes))
}

/// Bytes of geometry data held for shading and shared with Embree.
pub(crate) fn geometry_bytes(geometries: &[Geometry], prototypes: &[Prototype]) -> usize {
    let own: usize = geometries
        .iter()
        .map(|g| match g {
            Geometry::Mesh(m) => m.byte_size(),
            Geometry::Instance { lights, .. } => {
                lights.iter().map(|l| l.capacity() * 4).sum::<usize>()
                    + std::mem::size_of::<Geometry>()
            }
            Geometry::Sphere { .. } => std::mem::size_of::<Geometry>(),
        })
        .sum();
    own + prototypes
        .iter()
        .flat_map(|p| &p.meshes)
        .map(MeshData::byte_size)
        .sum::<usize>()
}
