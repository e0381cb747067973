//! A scene under construction: the Embree builder and everything shading
//! will index by the geometry ids Embree hands out.

use lumis_core::{Light, LightInput, LightShape, PluginEntity, Registry, Result, Textures};
use lumis_embree::{Device, SceneBuilder, SceneOptions};

use super::bvh::PendingPrototype;
use crate::instantiate::BsdfTable;
use crate::render_scene::{Geometry, SceneCounts};
use crate::report::LoadReport;

pub(crate) struct Assembly<'r> {
    /// Creates area lights and imported materials' BSDFs.
    pub registry: &'r Registry,
    /// The scene's `[[texture]]`s, which a shape's emission may name.
    pub textures: &'r Textures,
    /// Whether an imported material's texture filters over the pixel
    /// footprint.
    pub footprint: bool,
    pub device: Device,
    /// Quality and robustness of every BVH; compaction is decided once
    /// every shape is counted.
    pub options: SceneOptions,
    pub builder: SceneBuilder,
    /// Indexed by top-level geometry id: one entry per `builder.add_*`.
    pub geometries: Vec<Geometry>,
    /// Instanced meshes, built with the top level at the end.
    pub pending: Vec<PendingPrototype>,
    /// Area lights, in the order shapes create them.
    pub lights: Vec<Box<dyn Light>>,
    pub bsdfs: BsdfTable,
    pub counts: SceneCounts,
    pub report: LoadReport,
}

impl Assembly<'_> {
    /// Creates the area light `entity` describes on `shape`, its
    /// parameters naming `textures`; returns its index.
    pub fn add_area_light(
        &mut self,
        entity: &PluginEntity,
        shape: LightShape,
        textures: &Textures,
    ) -> Result<u32> {
        let input = LightInput {
            shape: &shape,
            textures,
        };
        let light = self.registry.create::<dyn Light>(entity, input)?;
        Ok(self.push_area_light(light))
    }

    /// Adds an area light created (and perhaps wrapped) by the caller.
    pub fn push_area_light(&mut self, light: Box<dyn Light>) -> u32 {
        self.lights.push(light);
        self.counts.area_lights += 1;
        self.lights.len() as u32 - 1
    }
}
