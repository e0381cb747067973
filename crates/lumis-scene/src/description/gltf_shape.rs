//! `[[shape]] type = "gltf"`: the keys that say how to import an asset.

use std::path::PathBuf;

use lumis_core::doc::{Table, Value};
use lumis_core::glam::Mat4;
use lumis_core::params::LocatedTable;
use lumis_core::{Error, Location, Params, PluginParams, Result};

use super::document::{location_of, written_string};
use super::transform::parse_transform;
use crate::bsdf_ref::BsdfRef;
use crate::gltf::{ImportRequest, MissingNormals};

/// The keys of `[[shape]] type = "gltf"`.
#[derive(Debug, Clone, PluginParams)]
pub(crate) struct GltfShapeParams {
    /// glTF 2.0 asset (.gltf with its buffers, or .glb), relative to the
    /// scene file
    file: PathBuf,
    /// placement of the whole asset: { matrix = [16 numbers, row-major] }
    /// or { scale, rotate = [ax, ay, az, degrees], translate }
    transform: Option<LocatedTable>,
    /// a [[bsdf]] for every primitive instead of the asset's materials
    /// (their emission stays)
    bsdf: Option<String>,
    /// { "glTF material name" = "[[bsdf]] name", ... }: replaces those
    /// materials' BSDFs
    bsdf_overrides: Option<LocatedTable>,
    /// degrees; normals missing from the file are generated, smooth across
    /// edges whose faces meet at less than this; 0 = flat shading (nothing
    /// stored)
    #[param(default = 30.0, range = (0.0, 180.0))]
    crease_angle: f32,
}

/// What the importer is asked for; `params` is the shape's table checked
/// against [`GltfShapeParams`].
pub(crate) fn gltf_request(owner: &str, params: &Params, table: &Table) -> Result<ImportRequest> {
    let p = GltfShapeParams::read(params)?;
    let keys = GltfShapeParams::KEYS;
    let label = written_string(table, keys.file);
    let transform = match &p.transform {
        Some(t) => parse_transform(&format!("{owner} transform"), &t.table, t.location.clone())?,
        None => Mat4::IDENTITY,
    };
    let bsdf = p.bsdf.map(|name| BsdfRef {
        name,
        location: location_of(table, keys.bsdf, &Location::Builtin),
    });
    let mut overrides = Vec::new();
    if let Some(t) = &p.bsdf_overrides {
        for entry in &t.table.entries {
            match &entry.node.value {
                Value::String(s) => overrides.push((
                    entry.key.clone(),
                    BsdfRef {
                        name: s.clone(),
                        location: entry.node.location.clone(),
                    },
                )),
                v => {
                    return Err(Error::at(
                        &entry.node.location,
                        format!(
                            "{owner} bsdf_overrides.\"{}\": expected the name of a [[bsdf]] (a string), found {}",
                            entry.key,
                            v.type_name()
                        ),
                    ))
                }
            }
        }
    }
    if bsdf.is_some() && !overrides.is_empty() {
        return Err(params.error(
            keys.bsdf_overrides,
            "'bsdf' already replaces every material; give one or the other",
        ));
    }
    let crease = p.crease_angle;
    let missing_normals = if crease == 0.0 {
        MissingNormals::Flat
    } else {
        MissingNormals::Generate {
            cos_crease: crease.to_radians().cos(),
        }
    };
    Ok(ImportRequest {
        owner: owner.to_string(),
        path: p.file,
        file_location: location_of(table, keys.file, &Location::Builtin),
        label,
        transform,
        bsdf,
        overrides,
        missing_normals,
    })
}
