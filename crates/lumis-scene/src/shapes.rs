//! `[[shape]]` tables: quads, inline meshes, OBJ files and spheres (glTF
//! assets have their own module, [`crate::gltf`]).

use std::path::Path;

use lumis_core::doc::Table;
use lumis_core::{Error, Location, ParamSpec, ParamType, ParamValue, Params, Result, Vec3};

/// Geometry of one shape, before it goes to Embree.
pub(crate) enum ShapeGeometry {
    Mesh {
        positions: Vec<[f32; 3]>,
        indices: Vec<[u32; 3]>,
        normals: Option<Vec<Vec3>>,
        /// Set for quads, whose emission is one quad light rather than two
        /// triangle lights.
        quad: Option<(Vec3, Vec3, Vec3)>,
    },
    Sphere {
        center: Vec3,
        radius: f32,
    },
}

/// A parsed `[[shape]]`.
pub(crate) struct ShapeDesc<'a> {
    pub geometry: ShapeGeometry,
    pub bsdf: String,
    pub bsdf_location: Location,
    /// The `emission` table and its location, if the shape emits.
    pub emission: Option<(&'a Table, Location)>,
    pub flip_normals: bool,
}

macro_rules! shape_params {
    ($($extra:expr),* $(,)?) => {
        &[
            $($extra,)*
            ParamSpec::required("bsdf", ParamType::String, "name of a [[bsdf]] table"),
            ParamSpec::optional(
                "emission",
                ParamType::Table,
                "makes the shape an area light: { radiance = [r, g, b], two_sided = false }",
            ),
            ParamSpec::with_default("flip_normals", ParamType::Bool, ParamValue::Bool(false), "swap the front and back sides"),
        ]
    };
}

pub(crate) const QUAD_PARAMS: &[ParamSpec] = shape_params![
    ParamSpec::required("corner", ParamType::Vec3, "one corner of the parallelogram"),
    ParamSpec::required("edge_u", ParamType::Vec3, "first edge from the corner"),
    ParamSpec::required(
        "edge_v",
        ParamType::Vec3,
        "second edge; the front faces edge_u x edge_v"
    ),
];
pub(crate) const MESH_PARAMS: &[ParamSpec] = shape_params![
    ParamSpec::required(
        "positions",
        ParamType::Vec3Array,
        "vertex positions [[x, y, z], ...]"
    ),
    ParamSpec::required(
        "indices",
        ParamType::IntArray,
        "three vertex indices per triangle; CCW = front"
    ),
    ParamSpec::optional(
        "normals",
        ParamType::Vec3Array,
        "per-vertex shading normals"
    ),
];
pub(crate) const OBJ_PARAMS: &[ParamSpec] = shape_params![ParamSpec::required(
    "file",
    ParamType::String,
    "Wavefront OBJ file, relative to the scene file; faces are triangulated"
)];
pub(crate) const SPHERE_PARAMS: &[ParamSpec] = shape_params![
    ParamSpec::required("center", ParamType::Vec3, "centre"),
    ParamSpec::required("radius", ParamType::Float, "radius > 0"),
];

pub(crate) const SHAPE_TYPES: &[(&str, &[ParamSpec])] = &[
    ("quad", QUAD_PARAMS),
    ("mesh", MESH_PARAMS),
    ("obj", OBJ_PARAMS),
    ("sphere", SPHERE_PARAMS),
    ("gltf", crate::gltf::GLTF_PARAMS),
];

/// Parses one shape table whose `type` is `kind`.
pub(crate) fn parse_shape<'a>(
    kind: &str,
    params: &Params<'a>,
    table: &'a Table,
    scene_dir: &Path,
) -> Result<ShapeDesc<'a>> {
    let geometry = match kind {
        "quad" => quad(params)?,
        "mesh" => mesh(params)?,
        "obj" => obj(params, scene_dir)?,
        "sphere" => {
            let center: Vec3 = params.get("center")?;
            let radius = params.get_positive("radius")?;
            ShapeGeometry::Sphere { center, radius }
        }
        other => unreachable!("shape type {other} checked by the caller"),
    };
    let bsdf: String = params.get("bsdf")?;
    let bsdf_location = table
        .get("bsdf")
        .map(|n| n.location.clone())
        .unwrap_or(Location::Builtin);
    Ok(ShapeDesc {
        geometry,
        bsdf,
        bsdf_location,
        emission: params.table("emission")?,
        flip_normals: params.get("flip_normals")?,
    })
}

fn quad(params: &Params) -> Result<ShapeGeometry> {
    let corner: Vec3 = params.get("corner")?;
    let edge_u: Vec3 = params.get("edge_u")?;
    let edge_v: Vec3 = params.get("edge_v")?;
    let area = edge_u.cross(edge_v).length();
    if !(area > 0.0 && area.is_finite()) {
        return Err(params.error(
            "edge_v",
            "is parallel to edge_u (or zero): the quad has no area",
        ));
    }
    let c = corner;
    let positions = vec![c, c + edge_u, c + edge_u + edge_v, c + edge_v]
        .into_iter()
        .map(Into::into)
        .collect();
    Ok(ShapeGeometry::Mesh {
        positions,
        indices: vec![[0, 1, 2], [0, 2, 3]],
        normals: None,
        quad: Some((corner, edge_u, edge_v)),
    })
}

fn mesh(params: &Params) -> Result<ShapeGeometry> {
    let positions: Vec<Vec3> = params.get("positions")?;
    let flat: Vec<i64> = params.get("indices")?;
    if !flat.len().is_multiple_of(3) || flat.is_empty() {
        return Err(params.error(
            "indices",
            format!(
                "needs three indices per triangle, got {} values",
                flat.len()
            ),
        ));
    }
    let n = positions.len();
    if let Some((i, bad)) = flat
        .iter()
        .enumerate()
        .find(|(_, &v)| v < 0 || v as usize >= n)
    {
        return Err(params.error(
            "indices",
            format!("index {bad} (element {i}) is out of range for {n} positions"),
        ));
    }
    let normals: Option<Vec<Vec3>> = params.get_opt("normals")?;
    if let Some(ns) = &normals {
        if ns.len() != n {
            return Err(params.error(
                "normals",
                format!("has {} entries for {n} positions", ns.len()),
            ));
        }
    }
    Ok(ShapeGeometry::Mesh {
        positions: positions.into_iter().map(Into::into).collect(),
        indices: flat
            .chunks_exact(3)
            .map(|t| [t[0] as u32, t[1] as u32, t[2] as u32])
            .collect(),
        normals,
        quad: None,
    })
}

fn obj(params: &Params, scene_dir: &Path) -> Result<ShapeGeometry> {
    let file: String = params.get("file")?;
    let path = scene_dir.join(&file);
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _materials) = tobj::load_obj(&path, &options)
        .map_err(|e| params.error("file", format!("cannot load OBJ '{}': {e}", path.display())))?;
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    let mut normals = Vec::new();
    let mut all_have_normals = true;
    for model in &models {
        let mesh = &model.mesh;
        let base = positions.len() as u32;
        let count = mesh.positions.len() / 3;
        for (what, values) in [
            ("vertex position", &mesh.positions),
            ("normal", &mesh.normals),
        ] {
            if let Some(bad) = values
                .chunks_exact(3)
                .find(|v| !v.iter().all(|c| c.is_finite()))
            {
                return Err(params.error(
                    "file",
                    format!(
                        "'{}': {what} {bad:?} is not finite (NaN, or beyond the range of a 32-bit float)",
                        path.display()
                    ),
                ));
            }
        }
        positions.extend(mesh.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
        if mesh.normals.len() == mesh.positions.len() {
            normals.extend(
                mesh.normals
                    .chunks_exact(3)
                    .map(|n| Vec3::new(n[0], n[1], n[2])),
            );
        } else {
            all_have_normals = false;
        }
        for t in mesh.indices.chunks_exact(3) {
            if let Some(&bad) = t.iter().find(|&&i| i as usize >= count) {
                return Err(params.error(
                    "file",
                    format!(
                        "'{}': face index {bad} out of range for {count} vertices",
                        path.display()
                    ),
                ));
            }
            indices.push([base + t[0], base + t[1], base + t[2]]);
        }
    }
    if indices.is_empty() {
        return Err(params.error(
            "file",
            format!("'{}' contains no triangles", path.display()),
        ));
    }
    Ok(ShapeGeometry::Mesh {
        positions,
        indices,
        normals: all_have_normals
            .then_some(normals)
            .filter(|n| !n.is_empty()),
        quad: None,
    })
}

/// Errors for a shape `type` that is not one of [`SHAPE_TYPES`].
pub(crate) fn unknown_shape_type(kind: &str, location: &Location) -> Error {
    let names: Vec<&str> = SHAPE_TYPES.iter().map(|(n, _)| *n).collect();
    Error::at(
        location,
        format!(
            "unknown shape type \"{kind}\"; available: {}",
            names.join(", ")
        ),
    )
}
