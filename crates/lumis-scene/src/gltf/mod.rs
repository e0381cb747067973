//! `[[shape]] type = "gltf"`: glTF 2.0 assets (`.gltf` with external or
//! embedded buffers, `.glb`).
//!
//! Every triangle primitive of every mesh the asset's scene uses is loaded,
//! placed by its node hierarchy and the shape's `transform`. A mesh used by
//! one node is transformed into world space and joins the top-level BVH; a
//! mesh used by several nodes is built once in its own Embree scene and
//! placed by Embree instances, so its vertices, indices, normals and BVH
//! exist once however often it appears. Materials map onto BSDF plugins
//! (see [`material`]) unless the TOML overrides them by name; emissive
//! materials make their triangles area lights.

mod buffers;
pub(crate) mod camera;
mod decode;
mod material;
mod normals;
mod resolve;
mod scene_graph;
mod texture;
mod two_sided;
mod unmodelled;
#[cfg(test)]
mod wrapper_tests;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use lumis_core::doc::{Table, Value};
use lumis_core::glam::{Mat3, Mat4};
use lumis_core::registry::TableRef;
use lumis_core::{
    Error, LightShape, Location, ParamSpec, ParamType, ParamValue, Params, Result, Vec2, Vec3,
};
use lumis_embree::{PaddedBuffer, SceneBuilder};
use rayon::prelude::*;

use crate::render_scene::{Geometry, MeshData, Placement, NO_LIGHT};
use crate::report::Phase;
use crate::transform::parse_transform;
use crate::{Assembly, PendingInstance, PendingPrototype};
use decode::{MissingNormals, Part};

pub(crate) const GLTF_PARAMS: &[ParamSpec] = &[
    ParamSpec::required(
        "file",
        ParamType::String,
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

/// A parsed `[[shape]] type = "gltf"`.
pub(crate) struct GltfShape {
    path: PathBuf,
    /// `file` as written, for messages.
    label: String,
    file_location: Location,
    transform: Mat4,
    bsdf: Option<(String, Location)>,
    /// (glTF material name, `[[bsdf]]` name, where the override is written).
    overrides: Vec<(String, String, Location)>,
    missing_normals: MissingNormals,
}

pub(crate) fn parse(
    owner: &str,
    params: &Params,
    table: &Table,
    scene_dir: &Path,
) -> Result<GltfShape> {
    let label: String = params.get("file")?;
    let located = |key: &str| {
        table
            .get(key)
            .map_or(Location::Builtin, |n| n.location.clone())
    };
    let transform = match params.table("transform")? {
        Some((t, at)) => parse_transform(&format!("{owner} transform"), t, at)?,
        None => Mat4::IDENTITY,
    };
    let bsdf = params
        .get_opt::<String>("bsdf")?
        .map(|b| (b, located("bsdf")));
    let mut overrides = Vec::new();
    if let Some((t, _)) = params.table("bsdf_overrides")? {
        for entry in &t.entries {
            match &entry.node.value {
                Value::String(s) => {
                    overrides.push((entry.key.clone(), s.clone(), entry.node.location.clone()))
                }
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
    Ok(GltfShape {
        path: scene_dir.join(&label),
        label,
        file_location: located("file"),
        transform,
        bsdf,
        overrides,
        missing_normals,
    })
}
/// Loads the asset and adds its meshes, instances and emissive triangles.
pub(crate) fn add(owner: &str, shape: GltfShape, asm: &mut Assembly) -> Result<()> {
    let at = shape.file_location.clone();
    let err = |e: String| Error::at(&at, format!("{owner}: {e}"));
    let mut asset = asm
        .report
        .time(Phase::Parse, || buffers::load(&shape.path, &shape.label))
        .map_err(err)?;
    let uses = scene_graph::mesh_uses(&asset.document, shape.transform)
        .map_err(|e| err(format!("'{}': {e}", shape.label)))?;

    asm.report.warnings.extend(
        unmodelled::unmodelled_features(&asset.document)
            .into_iter()
            .map(|w| format!("'{}': {w}", shape.label)),
    );
    let resolved = resolve::resolve_materials(owner, &shape, &asset, asm)?;
    let uv_set = |material: Option<usize>| resolved.get(&material).and_then(|r| r.uv_set);
    let missing_normals = shape.missing_normals;
    let mut decoded: Vec<Option<Vec<Part>>> = asm
        .report
        .time(Phase::Attributes, || {
            let meshes: Vec<gltf::Mesh> = asset.document.meshes().collect();
            meshes
                .par_iter()
                .map(|m| {
                    if uses[m.index()].is_empty() {
                        Ok(None)
                    } else {
                        decode::mesh(&asset, m, missing_normals, &uv_set).map(Some)
                    }
                })
                .collect::<std::result::Result<Vec<_>, String>>()
        })
        .map_err(err)?;
    // The raw buffers are decoded: free them before generating normals and
    // building BVHs, the two phases that need the most memory.
    asset.buffers = Vec::new();
    asm.report.time(Phase::Attributes, || {
        decoded
            .par_iter_mut()
            .flatten()
            .flat_map(|parts| parts.par_iter_mut())
            .for_each(Part::generate_normals)
    });

    let light_owner = format!("{owner} emission");

    // Meshes used once: into world space, into the top-level BVH.
    let mut instanced = Vec::new();
    for (mesh_index, parts) in decoded.into_iter().enumerate() {
        let Some(parts) = parts else { continue };
        let worlds = &uses[mesh_index];
        if worlds.len() > 1 {
            instanced.push((mesh_index, parts));
            continue;
        }
        let world = worlds[0];
        for mut part in parts {
            let r = &resolved[&part.material];
            let triangles = part.indices.len();
            asm.report
                .time(Phase::Attributes, || bake(&mut part, &world));
            let Part {
                positions,
                indices,
                normals,
                uvs,
                ..
            } = part;
            let lights = match &r.emission {
                Some(table) => {
                    let tris = indices
                        .iter()
                        .map(|t| (t.map(|i| Vec3::from(positions[i as usize])), *t));
                    let emission = Emission {
                        table,
                        texture: r.emission_texture.as_ref().zip(uvs.as_deref()),
                    };
                    triangle_lights(tris, &emission, &light_owner, &at, asm)?
                }
                None => Vec::new(),
            };
            let mesh = MeshData {
                vertices: Arc::new(PaddedBuffer::new(positions)),
                indices: Arc::new(PaddedBuffer::new(indices)),
                normals,
                uvs,
                bsdf: r.bsdf,
                lights,
                orientation: 1.0,
                flat_frames: Vec::new(),
            };
            asm.counts.shading_normals |= mesh.normals.is_some();
            asm.builder
                .add_triangle_mesh(mesh.vertices.clone(), mesh.indices.clone())
                .map_err(|e| err(e.to_string()))?;
            asm.geometries.push(Geometry::Mesh(mesh));
            asm.counts.meshes += 1;
            asm.counts.triangles += triangles;
            asm.counts.unique_triangles += triangles;
        }
    }

    // Meshes used by several nodes: one Embree scene each, built with the
    // top level (`build_bvhs`) once the scene's size decides compaction.
    for (mesh_index, parts) in instanced {
        let mut builder =
            SceneBuilder::new(&asm.device, asm.options).map_err(|e| err(e.to_string()))?;
        let mut meshes = Vec::with_capacity(parts.len());
        let mut emissions = Vec::with_capacity(parts.len());
        for part in parts {
            let r = &resolved[&part.material];
            let mesh = MeshData {
                vertices: Arc::new(PaddedBuffer::new(part.positions)),
                indices: Arc::new(PaddedBuffer::new(part.indices)),
                normals: part.normals,
                uvs: part.uvs,
                bsdf: r.bsdf,
                lights: Vec::new(),
                orientation: 1.0,
                flat_frames: Vec::new(),
            };
            builder
                .add_triangle_mesh(mesh.vertices.clone(), mesh.indices.clone())
                .map_err(|e| err(e.to_string()))?;
            asm.counts.shading_normals |= mesh.normals.is_some();
            emissions.push((r.emission.clone(), r.emission_texture.clone()));
            meshes.push(mesh);
        }
        let triangles: usize = meshes.iter().map(|m| m.indices.len()).sum();
        let mut instances = Vec::with_capacity(uses[mesh_index].len());
        for world in &uses[mesh_index] {
            let lights = instance_lights(&meshes, &emissions, world, &light_owner, &at, asm)?;
            let columns = world.to_cols_array();
            let transform: [f32; 12] = [
                columns[0],
                columns[1],
                columns[2],
                columns[4],
                columns[5],
                columns[6],
                columns[8],
                columns[9],
                columns[10],
                columns[12],
                columns[13],
                columns[14],
            ];
            let linear = Mat3::from_mat4(*world);
            instances.push(PendingInstance {
                transform,
                placement: Placement {
                    linear,
                    translation: world.w_axis.truncate(),
                    normal: linear.inverse().transpose(),
                },
                lights,
            });
            asm.counts.instances += 1;
            asm.counts.triangles += triangles;
        }
        asm.counts.meshes += meshes.len();
        asm.counts.prototypes += 1;
        asm.counts.unique_triangles += triangles;
        asm.pending.push(PendingPrototype {
            builder,
            meshes,
            instances,
            owner: owner.to_string(),
            location: at.clone(),
        });
    }
    Ok(())
}

/// Transforms a part into world space. A mirroring transform (negative
/// determinant) reverses the winding, as the glTF spec says it does, so
/// the front side stays where the asset meant it.
fn bake(part: &mut Part, world: &Mat4) {
    if *world == Mat4::IDENTITY {
        return;
    }
    part.positions
        .par_iter_mut()
        .for_each(|p| *p = world.transform_point3(Vec3::from(*p)).into());
    let normal_matrix = Mat3::from_mat4(*world).inverse().transpose();
    if let Some(ns) = &mut part.normals {
        ns.par_iter_mut()
            .for_each(|n| *n = (normal_matrix * *n).normalize_or_zero());
    }
    if world.determinant() < 0.0 {
        part.indices.par_iter_mut().for_each(|t| t.swap(1, 2));
    }
}

/// How an emissive material's triangles emit: the light table they share
/// and, with an emissive texture, the texture and the mesh's uvs.
struct Emission<'a> {
    table: &'a Table,
    texture: Option<(&'a Arc<texture::Texture>, &'a [Vec2])>,
}

/// One triangle light per non-degenerate triangle (world-space vertices,
/// front side by winding, with the vertex indices for the uvs), `NO_LIGHT`
/// for degenerate ones.
fn triangle_lights(
    triangles: impl Iterator<Item = ([Vec3; 3], [u32; 3])>,
    emission: &Emission,
    owner: &str,
    at: &Location,
    asm: &mut Assembly,
) -> Result<Vec<u32>> {
    let mut out = Vec::new();
    for (p, vertices) in triangles {
        let [a, b, c] = p;
        if (b - a).cross(c - a).length_squared() == 0.0 {
            out.push(NO_LIGHT);
            continue;
        }
        let light = asm.registry.create_light(
            &TableRef {
                owner,
                table: emission.table,
                location: at,
                type_name: "triangle",
                type_location: at,
                structural: &["type"],
            },
            &LightShape::Triangle { p },
        )?;
        let light: Box<dyn lumis_core::Light> = match emission.texture {
            Some((texture, uvs)) => Box::new(texture::TexturedEmitter {
                inner: light,
                texture: texture.clone(),
                p,
                uv: vertices.map(|i| uvs[i as usize]),
            }),
            None => light,
        };
        asm.lights.push(light);
        asm.counts.area_lights += 1;
        out.push(asm.lights.len() as u32 - 1);
    }
    Ok(out)
}

/// The world-space triangle lights of one instance of a prototype.
fn instance_lights(
    meshes: &[MeshData],
    emissions: &[(Option<Table>, Option<Arc<texture::Texture>>)],
    world: &Mat4,
    owner: &str,
    at: &Location,
    asm: &mut Assembly,
) -> Result<Vec<Vec<u32>>> {
    if emissions.iter().all(|(t, _)| t.is_none()) {
        return Ok(Vec::new());
    }
    let mirrored = world.determinant() < 0.0;
    let mut out = Vec::with_capacity(meshes.len());
    for (mesh, (table, texture)) in meshes.iter().zip(emissions) {
        let Some(table) = table else {
            out.push(Vec::new());
            continue;
        };
        let emission = Emission {
            table,
            texture: texture.as_ref().zip(mesh.uvs.as_deref()),
        };
        let vertices = &mesh.vertices;
        let tris = mesh.indices.iter().map(|t| {
            let [a, b, c] = t.map(|i| world.transform_point3(Vec3::from(vertices[i as usize])));
            if mirrored {
                ([a, c, b], [t[0], t[2], t[1]])
            } else {
                ([a, b, c], *t)
            }
        });
        out.push(triangle_lights(tris, &emission, owner, at, asm)?);
    }
    Ok(out)
}
