//! `[[shape]]` tables: quads, inline meshes, OBJ files, spheres and glTF
//! assets, each to a [`ShapeEntity`].

use std::path::PathBuf;

use lumis_core::doc::Table;
use lumis_core::{
    Error, Location, ParamSpec, ParamType, ParamValue, Params, PluginEntity, PluginKind, Result,
    Vec3,
};

use super::document::{location_of, type_of, Located};
use super::gltf_shape::{gltf_request, GLTF_PARAMS};
use crate::bsdf_ref::BsdfRef;
use crate::gltf::ImportRequest;
use crate::triangle_mesh::TriangleMesh;

/// One `[[shape]]`, described.
pub(crate) struct ShapeEntity {
    /// Names the shape in messages: `[[shape]] #2 (type = "obj")`.
    pub owner: String,
    pub source: ShapeSource,
}

/// Where a shape's geometry comes from.
pub(crate) enum ShapeSource {
    Surface(Surface),
    /// A glTF asset: its meshes, instances and materials.
    Gltf(ImportRequest),
}

/// A shape of one BSDF, perhaps emitting.
pub(crate) struct Surface {
    pub geometry: SurfaceGeometry,
    pub bsdf: BsdfRef,
    /// The area light plugin its surface becomes, if it emits.
    pub emission: Option<PluginEntity>,
    pub flip_normals: bool,
}

/// The geometry of a [`Surface`].
pub(crate) enum SurfaceGeometry {
    /// A parallelogram: two triangles, one quad light if it emits.
    Quad {
        corner: Vec3,
        edge_u: Vec3,
        edge_v: Vec3,
    },
    /// An inline mesh.
    Mesh(TriangleMesh),
    /// A Wavefront OBJ file, read by the assembly.
    Obj(ObjFile),
    Sphere {
        center: Vec3,
        radius: f32,
    },
}

/// `file = "..."` of an OBJ shape.
pub(crate) struct ObjFile {
    /// Resolved against the scene file's directory.
    pub path: PathBuf,
    /// Where `file` was written: errors reading it point there.
    pub location: Location,
}

impl SurfaceGeometry {
    /// The light plugin an emitting surface of this geometry gets when its
    /// `emission` table names none.
    fn default_light(&self) -> &'static str {
        match self {
            SurfaceGeometry::Quad { .. } => "quad",
            SurfaceGeometry::Mesh(_) | SurfaceGeometry::Obj(_) => "triangle",
            SurfaceGeometry::Sphere { .. } => "sphere",
        }
    }
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

const QUAD_PARAMS: &[ParamSpec] = shape_params![
    ParamSpec::required("corner", ParamType::Vec3, "one corner of the parallelogram"),
    ParamSpec::required("edge_u", ParamType::Vec3, "first edge from the corner"),
    ParamSpec::required(
        "edge_v",
        ParamType::Vec3,
        "second edge; the front faces edge_u x edge_v"
    ),
];
const MESH_PARAMS: &[ParamSpec] = shape_params![
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
const OBJ_PARAMS: &[ParamSpec] = shape_params![ParamSpec::required(
    "file",
    ParamType::Path,
    "Wavefront OBJ file, relative to the scene file; faces are triangulated"
)];
const SPHERE_PARAMS: &[ParamSpec] = shape_params![
    ParamSpec::required("center", ParamType::Vec3, "centre"),
    ParamSpec::required("radius", ParamType::Float, "radius > 0"),
];

/// Each shape type: its name, what it is, its keys.
pub(crate) const SHAPE_TYPES: &[(&str, &str, &[ParamSpec])] = &[
    ("quad", "a parallelogram", QUAD_PARAMS),
    ("mesh", "triangles written in the scene file", MESH_PARAMS),
    ("obj", "a Wavefront OBJ mesh", OBJ_PARAMS),
    ("sphere", "an analytic sphere", SPHERE_PARAMS),
    (
        "gltf",
        "a glTF 2.0 asset: its meshes, materials, emissive surfaces and instances",
        GLTF_PARAMS,
    ),
];

/// Describes the `index`-th (from 0) `[[shape]]`.
pub(crate) fn shape(index: usize, (table, location): Located<Table>) -> Result<ShapeEntity> {
    // Numbered from 0, as `--set shape.N` addresses it.
    let owner = format!("[[shape]] #{index}");
    let (kind, kind_location) = type_of(&table, &location, &owner)?;
    let spec = SHAPE_TYPES
        .iter()
        .find(|(n, ..)| *n == kind)
        .map(|(.., s)| *s)
        .ok_or_else(|| unknown_shape_type(kind, &kind_location))?;
    let owner = format!("{owner} (type = \"{kind}\")");
    let params = Params::new(owner.clone(), &table, location.clone(), spec, &["type"])?;
    let source = match kind {
        "gltf" => ShapeSource::Gltf(gltf_request(&owner, &params, &table)?),
        surface_kind => {
            let geometry = surface_geometry(surface_kind, &params, &table)?;
            ShapeSource::Surface(surface(&owner, geometry, &params, &table)?)
        }
    };
    params.finish()?;
    Ok(ShapeEntity { owner, source })
}

/// The geometry keys of a surface shape of type `kind`.
fn surface_geometry(kind: &str, params: &Params, table: &Table) -> Result<SurfaceGeometry> {
    match kind {
        "quad" => quad(params),
        "mesh" => mesh(params),
        "obj" => obj(params, table),
        "sphere" => Ok(SurfaceGeometry::Sphere {
            center: params.get("center")?,
            radius: params.get_positive("radius")?,
        }),
        other => unreachable!("shape type {other} is one of SHAPE_TYPES"),
    }
}

/// The keys every surface shape shares: `bsdf`, `emission`, `flip_normals`.
fn surface(
    owner: &str,
    geometry: SurfaceGeometry,
    params: &Params,
    table: &Table,
) -> Result<Surface> {
    let bsdf = BsdfRef {
        name: params.get("bsdf")?,
        location: location_of(table, "bsdf", &Location::Builtin),
    };
    let emission = match params.table("emission")? {
        Some((emission, location)) => Some(PluginEntity::from_table_or(
            PluginKind::Light,
            format!("{owner} emission"),
            emission.clone(),
            location,
            geometry.default_light(),
        )?),
        None => None,
    };
    Ok(Surface {
        geometry,
        bsdf,
        emission,
        flip_normals: params.get("flip_normals")?,
    })
}

fn quad(params: &Params) -> Result<SurfaceGeometry> {
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
    Ok(SurfaceGeometry::Quad {
        corner,
        edge_u,
        edge_v,
    })
}

fn mesh(params: &Params) -> Result<SurfaceGeometry> {
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
    Ok(SurfaceGeometry::Mesh(TriangleMesh {
        positions: positions.into_iter().map(Into::into).collect(),
        indices: flat
            .chunks_exact(3)
            .map(|t| [t[0] as u32, t[1] as u32, t[2] as u32])
            .collect(),
        normals,
    }))
}

fn obj(params: &Params, table: &Table) -> Result<SurfaceGeometry> {
    Ok(SurfaceGeometry::Obj(ObjFile {
        path: params.get("file")?,
        location: location_of(table, "file", &Location::Builtin),
    }))
}

/// Errors for a shape `type` that is not one of [`SHAPE_TYPES`].
fn unknown_shape_type(kind: &str, location: &Location) -> Error {
    let names: Vec<&str> = SHAPE_TYPES.iter().map(|(n, ..)| *n).collect();
    Error::at(
        location,
        format!(
            "unknown shape type \"{kind}\"; available: {}",
            names.join(", ")
        ),
    )
}
