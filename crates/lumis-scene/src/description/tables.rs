//! The declarations of the scene's own tables, for the reference page
//! `lumis plugins --markdown` writes beside the plugins': the same
//! [`ParamSpec`] lists that check a scene file, so the page cannot
//! describe a key the loader does not read.

use lumis_core::{ParamSpec, PluginParams};

use super::{accel, adaptive, camera, film, plugin_libraries, shapes, transform};

/// A table of the scene file: how a scene writes it, what it is for, and
/// its keys.
#[derive(Debug, Clone)]
pub struct SceneTable {
    pub heading: String,
    pub doc: &'static str,
    pub params: &'static [ParamSpec],
}

/// Every table the loader reads itself, in the order of the scene-format
/// chapter. The plugin tables (`[sampler]`, `[integrator]`, `[[bsdf]]`,
/// `[[light]]`, ...) take the keys of the plugin their `type` names.
pub fn scene_tables() -> Vec<SceneTable> {
    let mut tables = vec![
        SceneTable {
            heading: "top level".into(),
            doc: "the keys outside every table",
            params: super::TopLevelParams::SPECS,
        },
        SceneTable {
            heading: "[film]".into(),
            doc: "the image: its size, where it is written, its pixel filter and the outputs beside the colour",
            params: film::FilmParams::SPECS,
        },
        SceneTable {
            heading: "[camera] type = \"perspective\"".into(),
            doc: "a pinhole camera written out",
            params: camera::PerspectiveParams::SPECS,
        },
        SceneTable {
            heading: "[camera] type = \"gltf\"".into(),
            doc: "a camera of a glTF asset, placed by its node",
            params: camera::GltfCameraParams::SPECS,
        },
    ];
    tables.extend(
        shapes::SHAPE_TYPES
            .iter()
            .map(|&(kind, doc, params)| SceneTable {
                heading: format!("[[shape]] type = \"{kind}\""),
                doc,
                params,
            }),
    );
    tables.extend([
        SceneTable {
            heading: "transform = { ... }".into(),
            doc: "an affine placement, in a glTF shape or camera: a matrix, or scale, rotate and translate applied in that order",
            params: transform::TransformParams::SPECS,
        },
        SceneTable {
            heading: "[adaptive]".into(),
            doc: "adaptive sampling, which the renderer does for every sampler alike: pixels stop once their estimated relative error is below the threshold (lumis 0.1.0 read it as [sampler] adaptive = { ... }, which still works, with a warning)",
            params: adaptive::AdaptiveParams::SPECS,
        },
        SceneTable {
            heading: "[accel]".into(),
            doc: "how Embree builds and traverses the scene's BVH",
            params: accel::AccelParams::SPECS,
        },
        SceneTable {
            heading: "[plugins]".into(),
            doc: "plugin libraries the scene needs",
            params: plugin_libraries::PluginsParams::SPECS,
        },
    ]);
    tables
}
