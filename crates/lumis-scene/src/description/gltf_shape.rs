//! `[[shape]] type = "gltf"`: the keys that say how to import an asset.

use std::path::PathBuf;

use lumis_core::doc::{Table, Value};
use lumis_core::glam::Mat4;
use lumis_core::{Error, Location, ParamSpec, ParamType, ParamValue, Params, Result};

use super::document::location_of;
use super::transform::parse_transform;
use crate::bsdf_ref::BsdfRef;
use crate::gltf::{ImportRequest, MissingNormals};

pub(crate) const GLTF_PARAMS: &[ParamSpec] = &[
    ParamSpec::required(
        "file",
        ParamType::Path,
        "glTF 2.0 asset (.gltf with its buffers, or .glb), relative to the scene file",
    ),
    ParamSpec::optional(
        "transform",
        ParamType::Table,
        "placement of the whole asset: { matrix = [16 numbers, row-major] } or { scale, rotate = [ax, ay, az, degrees], translate }",
    ),
    ParamSpec::optional(
        "bsdf",
        ParamType::String,
        "a [[bsdf]] for every primitive instead of the asset's materials (their emission stays)",
    ),
    ParamSpec::optional(
        "bsdf_overrides",
        ParamType::Table,
        "{ \"glTF material name\" = \"[[bsdf]] name\", ... }: replaces those materials' BSDFs",
    ),
    ParamSpec::with_default(
        "crease_angle",
        ParamType::Float,
        ParamValue::Float(30.0),
        "degrees; normals missing from the file are generated, smooth across edges whose faces meet at less than this; 0 = flat shading (nothing stored)",
    )
    .in_range(0.0, 180.0),
];

/// What the importer is asked for; `params` is the shape's table checked
/// against [`GLTF_PARAMS`].
pub(crate) fn gltf_request(owner: &str, params: &Params, table: &Table) -> Result<ImportRequest> {
    let label: String = params.get("file")?;
    let path: PathBuf = params.get("file")?;
    let transform = match params.table("transform")? {
        Some((t, at)) => parse_transform(&format!("{owner} transform"), t, at)?,
        None => Mat4::IDENTITY,
    };
    let bsdf = params.get_opt::<String>("bsdf")?.map(|name| BsdfRef {
        name,
        location: location_of(table, "bsdf", &Location::Builtin),
    });
    let mut overrides = Vec::new();
    if let Some((t, _)) = params.table("bsdf_overrides")? {
        for entry in &t.entries {
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
            "bsdf_overrides",
            "'bsdf' already replaces every material; give one or the other",
        ));
    }
    let crease = params.get_in_range("crease_angle")?;
    let missing_normals = if crease == 0.0 {
        MissingNormals::Flat
    } else {
        MissingNormals::Generate {
            cos_crease: crease.to_radians().cos(),
        }
    };
    Ok(ImportRequest {
        owner: owner.to_string(),
        path,
        file_location: location_of(table, "file", &Location::Builtin),
        label,
        transform,
        bsdf,
        overrides,
        missing_normals,
    })
}
