//! `[[shape]]` tables: quads, inline meshes, OBJ files, spheres and glTF
//! assets, each to a [`ShapeEntity`].

use std::path::PathBuf;

use lumis_core::doc::Table;
use lumis_core::params::LocatedTable;
use lumis_core::{
    Error, Location, ParamSpec, Params, PluginEntity, PluginKind, PluginParams, Result, Vec3,
};

use super::document::{location_of, type_of, Located};
use super::gltf_shape::{gltf_request, GltfShapeParams};
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

/// The keys every surface shape shares.
#[derive(Debug, Clone, PluginParams)]
pub(crate) struct SurfaceParams {
    /// name of a [[bsdf]] table
    bsdf: String,
    /// makes the shape an area light: { radiance = [r, g, b], two_sided =
    /// false }
    emission: Option<LocatedTable>,
    /// swap the front and back sides
    #[param(default = false)]
    flip_normals: bool,
}

/// The keys of `[[shape]] type = "quad"`.
#[derive(Debug, Clone, PluginParams)]
pub(crate) struct QuadParams {
    /// one corner of the parallelogram
    corner: Vec3,
    /// first edge from the corner
    edge_u: Vec3,
    /// second edge; the front faces edge_u x edge_v
    edge_v: Vec3,
    #[param(flatten)]
    surface: SurfaceParams,
}

/// The keys of `[[shape]] type = "mesh"`.
#[derive(Debug, Clone, PluginParams)]
pub(crate) struct MeshParams {
    /// vertex positions [[x, y, z], ...]
    positions: Vec<Vec3>,
    /// three vertex indices per triangle; CCW = front
    indices: Vec<i64>,
    /// per-vertex shading normals
    normals: Option<Vec<Vec3>>,
    #[param(flatten)]
    surface: SurfaceParams,
}

/// The keys of `[[shape]] type = "obj"`.
#[derive(Debug, Clone, PluginParams)]
pub(crate) struct ObjParams {
    /// Wavefront OBJ file, relative to the scene file; faces are
    /// triangulated
    file: PathBuf,
    #[param(flatten)]
    surface: SurfaceParams,
}

/// The keys of `[[shape]] type = "sphere"`.
#[derive(Debug, Clone, PluginParams)]
pub(crate) struct SphereParams {
    /// centre
    center: Vec3,
    /// radius > 0
    radius: f32,
    #[param(flatten)]
    surface: SurfaceParams,
}

/// Each shape type: its name, what it is, its keys.
pub(crate) const SHAPE_TYPES: &[(&str, &str, &[ParamSpec])] = &[
    ("quad", "a parallelogram", QuadParams::SPECS),
    (
        "mesh",
        "triangles written in the scene file",
        MeshParams::SPECS,
    ),
    ("obj", "a Wavefront OBJ mesh", ObjParams::SPECS),
    ("sphere", "an analytic sphere", SphereParams::SPECS),
    (
        "gltf",
        "a glTF 2.0 asset: its meshes, materials, emissive surfaces and instances",
        GltfShapeParams::SPECS,
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
            let (geometry, keys) = surface_geometry(surface_kind, &params, &table)?;
            ShapeSource::Surface(surface(&owner, geometry, keys, &table)?)
        }
    };
    params.finish()?;
    Ok(ShapeEntity { owner, source })
}

/// The geometry of a surface shape of type `kind`, and the keys every
/// surface shares.
fn surface_geometry(
    kind: &str,
    params: &Params,
    table: &Table,
) -> Result<(SurfaceGeometry, SurfaceParams)> {
    match kind {
        "quad" => quad(params),
        "mesh" => mesh(params),
        "obj" => {
            let p = ObjParams::read(params)?;
            let location = location_of(table, ObjParams::KEYS.file, &Location::Builtin);
            let file = ObjFile {
                path: p.file,
                location,
            };
            Ok((SurfaceGeometry::Obj(file), p.surface))
        }
        "sphere" => {
            let p = SphereParams::read(params)?;
            if p.radius <= 0.0 {
                return Err(params.error(
                    SphereParams::KEYS.radius,
                    format!("must be a positive finite number, got {}", p.radius),
                ));
            }
            let sphere = SurfaceGeometry::Sphere {
                center: p.center,
                radius: p.radius,
            };
            Ok((sphere, p.surface))
        }
        other => unreachable!("shape type {other} is one of SHAPE_TYPES"),
    }
}

/// A surface of `geometry` with the keys every surface shape shares.
fn surface(
    owner: &str,
    geometry: SurfaceGeometry,
    keys: SurfaceParams,
    table: &Table,
) -> Result<Surface> {
    let bsdf = BsdfRef {
        name: keys.bsdf,
        location: location_of(table, SurfaceParams::KEYS.bsdf, &Location::Builtin),
    };
    let emission = match keys.emission {
        Some(LocatedTable { table, location }) => Some(PluginEntity::from_table_or(
            PluginKind::Light,
            format!("{owner} emission"),
            table,
            location,
            geometry.default_light(),
        )?),
        None => None,
    };
    Ok(Surface {
        geometry,
        bsdf,
        emission,
        flip_normals: keys.flip_normals,
    })
}

fn quad(params: &Params) -> Result<(SurfaceGeometry, SurfaceParams)> {
    let p = QuadParams::read(params)?;
    let area = p.edge_u.cross(p.edge_v).length();
    if !(area > 0.0 && area.is_finite()) {
        return Err(params.error(
            QuadParams::KEYS.edge_v,
            "is parallel to edge_u (or zero): the quad has no area",
        ));
    }
    let quad = SurfaceGeometry::Quad {
        corner: p.corner,
        edge_u: p.edge_u,
        edge_v: p.edge_v,
    };
    Ok((quad, p.surface))
}

fn mesh(params: &Params) -> Result<(SurfaceGeometry, SurfaceParams)> {
    let p = MeshParams::read(params)?;
    let keys = MeshParams::KEYS;
    let flat = p.indices;
    if !flat.len().is_multiple_of(3) || flat.is_empty() {
        return Err(params.error(
            keys.indices,
            format!(
                "needs three indices per triangle, got {} values",
                flat.len()
            ),
        ));
    }
    let n = p.positions.len();
    if let Some((i, bad)) = flat
        .iter()
        .enumerate()
        .find(|(_, &v)| v < 0 || v as usize >= n)
    {
        return Err(params.error(
            keys.indices,
            format!("index {bad} (element {i}) is out of range for {n} positions"),
        ));
    }
    if let Some(ns) = &p.normals {
        if ns.len() != n {
            return Err(params.error(
                keys.normals,
                format!("has {} entries for {n} positions", ns.len()),
            ));
        }
    }
    let mesh = TriangleMesh {
        positions: p.positions.into_iter().map(Into::into).collect(),
        indices: flat
            .chunks_exact(3)
            .map(|t| [t[0] as u32, t[1] as u32, t[2] as u32])
            .collect(),
        normals: p.normals,
    };
    Ok((SurfaceGeometry::Mesh(mesh), p.surface))
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
