//! The third stage: shapes into Embree geometry, BVHs and area lights.
//!
//! Shapes are added in file order; an OBJ file or glTF asset is imported
//! when its shape is reached, as plain data that is then placed here. Area
//! lights are created as their triangles, quads and spheres are added, so
//! light indices follow the file. Whether the BVHs are compact is decided
//! once every triangle is counted.

mod bvh;
mod gltf_asset;
mod state;
mod surfaces;

use std::sync::Arc;

use lumis_core::{Bsdf, Error, Light, LightKind, Registry, Result, Textures, Vec3};
use lumis_embree::{Device, SceneBuilder};

use crate::description::{AccelOptions, ShapeEntity, ShapeSource};
use crate::instantiate::BsdfTable;
use crate::render_scene::{self, Geometry, Prototype, SceneCounts};
use crate::report::LoadReport;
use state::Assembly;

/// A scene's geometry and lights, ready to render.
pub(crate) struct Assembled {
    pub embree: lumis_embree::Scene,
    /// Indexed by top-level geometry id.
    pub geometries: Vec<Geometry>,
    pub prototypes: Vec<Prototype>,
    pub bsdfs: Vec<Arc<dyn Bsdf>>,
    /// Area lights in shape order, then the scene's other lights.
    pub lights: Vec<Box<dyn Light>>,
    /// Indices of the infinite lights.
    pub infinite_lights: Vec<u32>,
    pub counts: SceneCounts,
    pub report: LoadReport,
    /// Whether an imported texture filters over the pixel footprint.
    pub footprint: bool,
    /// Whether a BSDF reads directions against texture tangents
    /// ([`Bsdf::uses_tangent_frame`]): hits then build their frames from
    /// `dp/du`.
    pub tangent_frames: bool,
}

/// Adds `shapes` to a new Embree scene, then the lights not attached to
/// shapes (`scene_lights`), and builds the BVHs.
pub(crate) fn assemble(
    registry: &Registry,
    textures: &Textures,
    shapes: Vec<ShapeEntity>,
    bsdfs: BsdfTable,
    scene_lights: Vec<Box<dyn Light>>,
    accel: &AccelOptions,
    report: LoadReport,
) -> Result<Assembled> {
    let device = Device::new().map_err(embree_error)?;
    let mut asm = Assembly {
        registry,
        textures,
        footprint: false,
        builder: SceneBuilder::new(&device, accel.embree).map_err(embree_error)?,
        device,
        options: accel.embree,
        geometries: Vec::new(),
        pending: Vec::new(),
        lights: Vec::new(),
        bsdfs,
        counts: SceneCounts::default(),
        report,
    };
    let memory_before = asm.device.memory_in_use();
    for shape in shapes {
        match shape.source {
            ShapeSource::Surface(surface) => {
                surfaces::add_surface(&shape.owner, surface, &mut asm)?
            }
            ShapeSource::Gltf(request) => {
                let asset = crate::gltf::import(&request, asm.registry)?;
                gltf_asset::add_gltf(&shape.owner, &request.file_location, asset, &mut asm)?;
            }
        }
    }

    let Assembly {
        builder,
        device,
        mut geometries,
        pending,
        mut lights,
        bsdfs,
        mut counts,
        mut report,
        footprint,
        ..
    } = asm;
    lights.extend(scene_lights);
    report.compaction = accel.compaction;
    report.compact = accel.compaction.decide(counts.unique_triangles);
    let bsdfs = bsdfs.into_bsdfs();
    let tangent_frames = bsdfs.iter().any(|b| b.uses_tangent_frame());
    if !report.compact && !tangent_frames {
        // Scenes that keep the fast BVH also keep flat meshes' frames; a
        // compact scene is one whose memory matters more. (Tangent frames
        // are built per hit, from the uvs.)
        for geometry in &mut geometries {
            if let Geometry::Mesh(mesh) = geometry {
                mesh.store_flat_frames();
            }
        }
    }
    let (embree, prototypes) = bvh::build_bvhs(builder, pending, &mut geometries, &mut report)?;
    report.bvh_bytes = (device.memory_in_use() - memory_before).max(0) as usize;
    report.geometry_bytes = bvh::geometry_bytes(&geometries, &prototypes);
    geometries.shrink_to_fit();
    let (center, radius) = render_scene::bounding_sphere(&embree);
    let infinite_lights = classify_lights(&mut lights, center, radius, &mut counts);
    Ok(Assembled {
        embree,
        geometries,
        prototypes,
        bsdfs,
        lights,
        infinite_lights,
        counts,
        report,
        footprint,
        tangent_frames,
    })
}

/// Hands infinite lights the scene bounds, counts lights by kind and
/// returns the indices of the infinite ones.
fn classify_lights(
    lights: &mut [Box<dyn Light>],
    center: Vec3,
    radius: f32,
    counts: &mut SceneCounts,
) -> Vec<u32> {
    let mut infinite = Vec::new();
    for (i, light) in lights.iter_mut().enumerate() {
        light.preprocess(center, radius);
        match light.kind() {
            LightKind::Infinite => {
                infinite.push(i as u32);
                counts.infinite_lights += 1;
            }
            LightKind::DeltaPosition => counts.delta_lights += 1,
            LightKind::Area => {}
        }
    }
    infinite
}

/// Whether a triangle can be an area light: a finite, non-zero area, which
/// the `triangle` light requires. Degenerate triangles (and non-finite
/// ones, which Embree skips too) emit nothing instead of failing the load.
fn has_area([a, b, c]: [Vec3; 3]) -> bool {
    let twice_area = (b - a).cross(c - a).length();
    twice_area > 0.0 && twice_area.is_finite()
}

fn embree_error(e: lumis_embree::EmbreeError) -> Error {
    Error::msg(e.to_string())
}
