//! The cameras of a glTF asset: one chosen by name or index, placed by its
//! node.

use std::path::Path;

use lumis_core::glam::Mat4;

use super::buffers;
use super::scene_graph;

/// Which camera of the asset.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum CameraChoice {
    /// The first camera a node of the scene uses.
    First,
    Named(String),
    Index(i64),
}

/// A perspective camera of the asset.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct GltfCamera {
    /// Vertical field of view, radians.
    pub yfov: f32,
    /// Its node's world transform (on top of the caller's base).
    pub world: Mat4,
}

/// Why no camera was found, and which key of the `[camera]` table to blame:
/// `file`, `name` or `index`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct CameraError {
    pub key: &'static str,
    pub message: String,
}

fn at(key: &'static str, message: String) -> CameraError {
    CameraError { key, message }
}

/// Finds the camera `choice` of the asset at `path` (`label`: the path as
/// written), placed by its node on top of `base`.
pub(crate) fn find_camera(
    path: &Path,
    label: &str,
    choice: &CameraChoice,
    base: Mat4,
) -> Result<GltfCamera, CameraError> {
    let (document, _) = buffers::document(path, label).map_err(|e| at("file", e))?;
    let names: Vec<String> = document
        .cameras()
        .map(|c| {
            c.name()
                .map_or(format!("#{}", c.index()), |n| format!("\"{n}\""))
        })
        .collect();
    let wanted = match choice {
        CameraChoice::First => None,
        CameraChoice::Named(n) => Some(
            document
                .cameras()
                .find(|c| c.name() == Some(n.as_str()))
                .ok_or_else(|| {
                    at(
                        "name",
                        format!(
                            "'{label}' has no camera named \"{n}\"; cameras: {}",
                            list(&names)
                        ),
                    )
                })?
                .index(),
        ),
        &CameraChoice::Index(i) => {
            if i < 0 || i as usize >= names.len() {
                return Err(at(
                    "index",
                    format!(
                        "'{label}' has {} cameras; index {i} is out of range",
                        names.len()
                    ),
                ));
            }
            Some(i as usize)
        }
    };
    let placed = scene_graph::camera_nodes(&document, base)
        .map_err(|e| at("file", format!("'{label}': {e}")))?;
    let (camera_index, world) = placed
        .into_iter()
        .find(|(c, _)| wanted.is_none_or(|w| w == *c))
        .ok_or_else(|| {
            at(
                "file",
                match wanted {
                    Some(w) => format!(
                        "'{label}': camera {} is used by no node of the scene",
                        names[w]
                    ),
                    None => format!("'{label}' has no camera in its scene"),
                },
            )
        })?;
    let camera = document
        .cameras()
        .nth(camera_index)
        .expect("index from the document");
    match camera.projection() {
        gltf::camera::Projection::Perspective(p) => Ok(GltfCamera {
            yfov: p.yfov(),
            world,
        }),
        gltf::camera::Projection::Orthographic(_) => Err(at(
            "file",
            format!(
                "'{label}': camera {} is orthographic; only perspective cameras are supported",
                names[camera_index]
            ),
        )),
    }
}

fn list(names: &[String]) -> String {
    if names.is_empty() {
        "none".into()
    } else {
        names.join(", ")
    }
}
