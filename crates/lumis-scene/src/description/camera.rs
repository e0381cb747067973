//! `[camera]`: a perspective camera written out, or one of a glTF asset.

use std::path::PathBuf;

use lumis_core::doc::Table;
use lumis_core::glam::Mat4;
use lumis_core::params::LocatedTable;
use lumis_core::{Error, Location, Params, PluginParams, Result, UVec2, Vec3};
use lumis_render::PerspectiveCamera;

use super::document::{type_of, written_string, Located};
use super::transform::parse_transform;
use crate::gltf::camera::{find_camera, CameraChoice};

/// The keys of `[camera] type = "perspective"`.
#[derive(Debug, Clone, PluginParams)]
pub(crate) struct PerspectiveParams {
    /// eye position
    origin: Vec3,
    /// point looked at
    target: Vec3,
    /// up direction
    #[param(default = [0.0, 1.0, 0.0])]
    up: Vec3,
    /// full angle of the smaller image axis, degrees, in (0, 180)
    fov: f32,
}

/// The keys of `[camera] type = "gltf"`.
#[derive(Debug, Clone, PluginParams)]
pub(crate) struct GltfCameraParams {
    /// glTF 2.0 asset (.gltf or .glb), relative to the scene file
    file: PathBuf,
    /// the camera's name in the asset (default: the first camera a node
    /// uses)
    name: Option<String>,
    /// the camera's index in the asset's cameras array
    index: Option<i64>,
    /// placement applied on top of the node's, as for [[shape]] type =
    /// "gltf"
    transform: Option<LocatedTable>,
}

/// Reads `[camera]` for a film of `resolution`.
pub(crate) fn camera(
    (table, location): Located<Table>,
    resolution: UVec2,
) -> Result<PerspectiveCamera> {
    let (kind, kind_location) = type_of(&table, &location, "[camera]")?;
    match kind {
        "perspective" => perspective(&table, location, resolution),
        "gltf" => gltf_camera(&table, location, resolution),
        other => Err(Error::at(
            &kind_location,
            format!("unknown camera type \"{other}\"; available: perspective, gltf"),
        )),
    }
}

fn perspective(table: &Table, location: Location, resolution: UVec2) -> Result<PerspectiveCamera> {
    let cam = Params::new(
        "[camera] (type = \"perspective\")",
        table,
        location.clone(),
        PerspectiveParams::SPECS,
        &["type"],
    )?;
    let p = PerspectiveParams::read(&cam)?;
    let fov = p.fov;
    if !(fov > 0.0 && fov < 180.0) {
        return Err(cam.error(
            PerspectiveParams::KEYS.fov,
            format!("must be in (0, 180) degrees, got {fov}"),
        ));
    }
    let camera = PerspectiveCamera::new(p.origin, p.target, p.up, fov, resolution)
        .map_err(|e| Error::at(&location, format!("[camera]: {}", e.message)))?;
    cam.finish()?;
    Ok(camera)
}

/// `type = "gltf"`: the asset's camera, chosen by name or index, placed by
/// its node and the optional `transform`.
fn gltf_camera(table: &Table, location: Location, resolution: UVec2) -> Result<PerspectiveCamera> {
    let owner = "[camera] (type = \"gltf\")";
    let params = Params::new(
        owner,
        table,
        location.clone(),
        GltfCameraParams::SPECS,
        &["type"],
    )?;
    let p = GltfCameraParams::read(&params)?;
    let keys = GltfCameraParams::KEYS;
    let file = written_string(table, keys.file);
    let path = p.file;
    let base = match &p.transform {
        Some(t) => parse_transform(&format!("{owner} transform"), &t.table, t.location.clone())?,
        None => Mat4::IDENTITY,
    };
    let choice = match (p.name, p.index) {
        (Some(_), Some(_)) => {
            return Err(params.error(keys.index, "give either 'name' or 'index', not both"))
        }
        (Some(name), None) => CameraChoice::Named(name),
        (None, Some(index)) => CameraChoice::Index(index),
        (None, None) => CameraChoice::First,
    };
    let found =
        find_camera(&path, &file, &choice, base).map_err(|e| params.error(e.key, e.message))?;
    // lumis's fov is the full angle of the smaller image axis; glTF's yfov
    // is vertical, and the film's aspect ratio decides the horizontal one.
    let (w, h) = (resolution.x as f32, resolution.y as f32);
    let yfov = found.yfov;
    let fov = if w >= h {
        yfov
    } else {
        2.0 * ((0.5 * yfov).tan() * w / h).atan()
    };
    // A glTF camera looks down its local -z with +y up.
    let world = found.world;
    let origin = world.transform_point3(Vec3::ZERO);
    let target = world.transform_point3(Vec3::NEG_Z);
    let up = world.transform_vector3(Vec3::Y);
    let camera =
        PerspectiveCamera::new(origin, target, up, fov.to_degrees(), resolution).map_err(|e| {
            let placed = format!("the camera's node in '{file}' places it so that");
            Error::at(&location, format!("{owner}: {placed} {}", e.message))
        })?;
    params.finish()?;
    Ok(camera)
}
