//! From a TOML scene file to a render-ready scene, in three one-way stages:
//!
//! 1. description: the document (with a location for every key, `--set`
//!    overrides applied) to a typed scene description in which every
//!    plugin is a [`PluginEntity`](lumis_core::PluginEntity);
//! 2. instantiation: plugins of every kind made by the one
//!    [`Registry::create`](lumis_core::Registry::create) path, only those
//!    the scene names;
//! 3. assembly: shapes into Embree geometry and BVHs, with an area light
//!    for every emissive surface.
//!
//! The OBJ and glTF importers return plain data (meshes, instances,
//! material entities) that the assembly places.

mod assembly;
mod bsdf_ref;
mod description;
mod document;
mod gltf;
mod instantiate;
mod load;
mod obj;
mod render_scene;
mod report;
mod scene_hash;
mod triangle_mesh;

pub use description::{scene_tables, Compaction, SceneTable, AUTO_COMPACT_TRIANGLES};
pub use document::SceneDocument;
pub use load::{load_file, load_str, LoadedScene, SceneDenoiser};
pub use render_scene::{LoadReport, RenderScene, SceneCounts};
pub use scene_hash::{scene_file_hash, scene_hash, Fnv1a};
