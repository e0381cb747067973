//! `[camera] type = "gltf"`: a perspective camera of a glTF asset, chosen by
//! name or index, placed by its node (and the optional TOML `transform`).

use std::path::Path;

use lumis_core::doc::Table;
use lumis_core::glam::Mat4;
use lumis_core::{Error, Location, ParamSpec, ParamType, Params, Result, UVec2, Vec3};
use lumis_render::PerspectiveCamera;

use super::buffers;
use super::scene_graph;
use crate::transform::parse_transform;

pub(crate) const CAMERA_PARAMS: &[ParamSpec] = &[
    ParamSpec::required(
        "file",
        ParamType::String,
        "glTF 2.0 asset (.gltf or .glb), relative to the scene file",
    ),
    ParamSpec::optional(
        "name",
        ParamType::String,
        "the camera's name in the asset (default: the first camera a node uses)",
    ),
    ParamSpec::optional(
        "index",
        ParamType::Int,
        "the camera's index in the asset's cameras array",
    ),
    ParamSpec::optional(
        "transform",
        ParamType::Table,
        "placement applied on top of the node's, as for [[shape]] type = \"gltf\"",
    ),
];

/// Builds the camera; `table` is the `[camera]` table, `resolution` the film's.
pub(crate) fn from_table(
    table: &Table,
    location: Location,
    scene_dir: &Path,
    resolution: UVec2,
) -> Result<PerspectiveCamera> {
    let owner = "[camera] (type = \"gltf\")";
    let params = Params::new(owner, table, location.clone(), CAMERA_PARAMS, &["type"])?;
    let file: String = params.get("file")?;
    let path = scene_dir.join(&file);
    let (document, _) = buffers::document(&path, &file).map_err(|e| params.error("file", e))?;
    let base = match params.table("transform")? {
        Some((t, at)) => parse_transform(&format!("{owner} transform"), t, at)?,
        None => Mat4::IDENTITY,
    };
    let name: Option<String> = params.get_opt("name")?;
    let index: Option<i64> = params.get_opt("index")?;
    let names: Vec<String> = document
        .cameras()
        .map(|c| {
            c.name()
                .map_or(format!("#{}", c.index()), |n| format!("\"{n}\""))
        })
        .collect();
    let wanted = match (&name, index) {
        (Some(_), Some(_)) => {
            return Err(params.error("index", "give either 'name' or 'index', not both"))
        }
        (Some(n), None) => Some(
            document
                .cameras()
                .find(|c| c.name() == Some(n.as_str()))
                .ok_or_else(|| {
                    params.error(
                        "name",
                        format!(
                            "'{file}' has no camera named \"{n}\"; cameras: {}",
                            list(&names)
                        ),
                    )
                })?
                .index(),
        ),
        (None, Some(i)) => {
            if i < 0 || i as usize >= names.len() {
                return Err(params.error(
                    "index",
                    format!(
                        "'{file}' has {} cameras; index {i} is out of range",
                        names.len()
                    ),
                ));
            }
            Some(i as usize)
        }
        (None, None) => None,
    };
    let placed = scene_graph::camera_nodes(&document, base)
        .map_err(|e| params.error("file", format!("'{file}': {e}")))?;
    let (camera_index, world) = placed
        .into_iter()
        .find(|(c, _)| wanted.is_none_or(|w| w == *c))
        .ok_or_else(|| {
            params.error(
                "file",
                match wanted {
                    Some(w) => format!(
                        "'{file}': camera {} is used by no node of the scene",
                        names[w]
                    ),
                    None => format!("'{file}' has no camera in its scene"),
                },
            )
        })?;
    let camera = document
        .cameras()
        .nth(camera_index)
        .expect("index from the document");
    let yfov = match camera.projection() {
        gltf::camera::Projection::Perspective(p) => p.yfov(),
        gltf::camera::Projection::Orthographic(_) => {
            return Err(params.error(
                "file",
                format!(
                    "'{file}': camera {} is orthographic; only perspective cameras are supported",
                    names[camera_index]
                ),
            ))
        }
    };
    // lumis's fov is the full angle of the smaller image axis; glTF's yfov
    // is vertical, and the film's aspect ratio decides the horizontal one.
    let (w, h) = (resolution.x as f32, resolution.y as f32);
    let fov = if w >= h {
        yfov
    } else {
        2.0 * ((0.5 * yfov).tan() * w / h).atan()
    };
    // A glTF camera looks down its local -z with +y up.
    let origin = world.transform_point3(Vec3::ZERO);
    let target = world.transform_point3(Vec3::NEG_Z);
    let up = world.transform_vector3(Vec3::Y);
    let camera = PerspectiveCamera::new(origin, target, up, fov.to_degrees(), resolution)
        .map_err(|e| Error::at(&location, format!("{owner}: {}", e.message)))?;
    params.finish()?;
    Ok(camera)
}

fn list(names: &[String]) -> String {
    if names.is_empty() {
        "none".into()
    } else {
        names.join(", ")
    }
}
