//! An imported glTF asset into Embree: world-space meshes join the top
//! level, meshes used by several nodes become instanced prototypes, and
//! emissive materials make their triangles area lights.

use std::collections::HashMap;
use std::sync::Arc;

use lumis_core::doc::{Table, Value};
use lumis_core::glam::{Mat3, Mat4};
use lumis_core::texture::{Named, NO_TEXTURES};
use lumis_core::{
    Bsdf, BsdfScope, Error, LightShape, Location, PluginEntity, PluginKind, Result, Textures, Vec2,
    Vec3,
};
use lumis_embree::{PaddedBuffer, SceneBuilder};

use super::bvh::{PendingInstance, PendingPrototype};
use super::has_area;
use super::state::Assembly;
use crate::gltf::{normal_map_params, AssetEmission, GltfImport, ImportedMaterial, MaterialBsdf};
use crate::render_scene::{Geometry, MeshData, Placement, NO_LIGHT};

/// What a material became in the scene: its BSDF's index and, if it
/// emits, the light plugin of its triangles.
struct PlacedMaterial<'m> {
    bsdf: u32,
    emission: Option<&'m AssetEmission>,
}

/// Adds the asset `owner` (its `file` written at `at`) imported.
pub(crate) fn add_gltf(
    owner: &str,
    at: &Location,
    asset: GltfImport,
    asm: &mut Assembly,
) -> Result<()> {
    asm.report.parse += asset.parse_time;
    asm.report.attributes += asset.attributes_time;
    asm.report.warnings.extend(asset.warnings);
    asm.report.texture_bytes += asset.texture_bytes;
    let err = |e: String| Error::at(at, format!("{owner}: {e}"));
    let materials = place_materials(owner, &asset.materials, asm)?;

    // Meshes used once: already in world space, into the top-level BVH.
    for part in asset.world_parts {
        let material = &materials[&part.material];
        let triangles = part.indices.len();
        let lights = match material.emission {
            Some(emission) => {
                let tris = part
                    .indices
                    .iter()
                    .map(|t| (t.map(|i| Vec3::from(part.positions[i as usize])), *t));
                triangle_lights(tris, emission, part.uvs.as_deref(), asm)?
            }
            None => Vec::new(),
        };
        let mesh = MeshData {
            vertices: Arc::new(PaddedBuffer::new(part.positions)),
            indices: Arc::new(PaddedBuffer::new(part.indices)),
            normals: part.normals,
            uvs: part.uvs,
            bsdf: material.bsdf,
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

    // Meshes used by several nodes: one Embree scene each, built with the
    // top level once the scene's size decides compaction.
    for instanced in asset.instanced {
        let mut builder =
            SceneBuilder::new(&asm.device, asm.options).map_err(|e| err(e.to_string()))?;
        let mut meshes = Vec::with_capacity(instanced.parts.len());
        let mut emissions = Vec::with_capacity(instanced.parts.len());
        for part in instanced.parts {
            let material = &materials[&part.material];
            let mesh = MeshData {
                vertices: Arc::new(PaddedBuffer::new(part.positions)),
                indices: Arc::new(PaddedBuffer::new(part.indices)),
                normals: part.normals,
                uvs: part.uvs,
                bsdf: material.bsdf,
                lights: Vec::new(),
                orientation: 1.0,
                flat_frames: Vec::new(),
            };
            builder
                .add_triangle_mesh(mesh.vertices.clone(), mesh.indices.clone())
                .map_err(|e| err(e.to_string()))?;
            asm.counts.shading_normals |= mesh.normals.is_some();
            emissions.push(material.emission);
            meshes.push(mesh);
        }
        let triangles: usize = meshes.iter().map(|m| m.indices.len()).sum();
        let mut instances = Vec::with_capacity(instanced.placements.len());
        for world in &instanced.placements {
            let lights = instance_lights(&meshes, &emissions, world, asm)?;
            instances.push(PendingInstance {
                transform: embree_transform(world),
                placement: placement(world),
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

/// Creates the BSDFs of the asset's own materials (with their base colour
/// textures; wrapped for `doubleSided`) and finds the scene's
/// replacements, in the importer's material order: the default material,
/// then by index.
fn place_materials<'m>(
    owner: &str,
    materials: &'m HashMap<Option<usize>, ImportedMaterial>,
    asm: &mut Assembly,
) -> Result<HashMap<Option<usize>, PlacedMaterial<'m>>> {
    let mut order: Vec<&Option<usize>> = materials.keys().collect();
    order.sort();
    let mut placed = HashMap::with_capacity(materials.len());
    for index in order {
        let material = &materials[index];
        let bsdf = match &material.bsdf {
            MaterialBsdf::Scene(reference) => asm.bsdfs.index_of(reference, owner)?,
            MaterialBsdf::Asset(asset) => {
                asm.footprint |= asset.textures.values().any(|t| t.uses_footprint());
                let scope = BsdfScope::textures(&asset.textures);
                let mut bsdf = asm.registry.create::<dyn Bsdf>(&asset.entity, scope)?;
                if let Some(scale) = asset.normal_scale {
                    let params = normal_map_params(&asset.entity.location, scale);
                    bsdf = wrapped(
                        bsdf,
                        "normalmap",
                        params,
                        &asset.textures,
                        &asset.entity,
                        asm,
                    )?;
                }
                if asset.two_sided {
                    bsdf = wrapped(
                        bsdf,
                        "twosided",
                        Vec::new(),
                        &NO_TEXTURES,
                        &asset.entity,
                        asm,
                    )?;
                }
                asm.bsdfs.push_unnamed(bsdf)
            }
        };
        let emission = material.emission.as_ref();
        placed.insert(*index, PlacedMaterial { bsdf, emission });
    }
    Ok(placed)
}

/// `inner` in the adapter plugin `type_name` (`normalmap` for a
/// `normalTexture`, `twosided` for `doubleSided`), made as a scene's
/// `[[bsdf]]` naming it would be, with `params` besides the inner BSDF and
/// `textures` for them to name.
fn wrapped(
    inner: Arc<dyn Bsdf>,
    type_name: &str,
    mut params: Vec<(&str, Value)>,
    textures: &Textures,
    entity: &PluginEntity,
    asm: &Assembly,
) -> Result<Arc<dyn Bsdf>> {
    const INNER: &str = "material";
    let mut bsdfs = Named::<dyn Bsdf>::new();
    bsdfs.insert(INNER, inner);
    params.push(("bsdf", INNER.into()));
    let outer = PluginEntity::new(
        PluginKind::Bsdf,
        format!("{} ({type_name})", entity.owner),
        type_name,
        Table::built(&entity.location, params),
        entity.location.clone(),
    );
    let scope = BsdfScope {
        textures,
        bsdfs: &bsdfs,
    };
    asm.registry.create::<dyn Bsdf>(&outer, scope)
}

/// One triangle light per non-degenerate triangle (world-space vertices,
/// front side by winding, with the vertex indices for the uvs), `NO_LIGHT`
/// for degenerate ones.
fn triangle_lights(
    triangles: impl Iterator<Item = ([Vec3; 3], [u32; 3])>,
    emission: &AssetEmission,
    uvs: Option<&[Vec2]>,
    asm: &mut Assembly,
) -> Result<Vec<u32>> {
    let mut out = Vec::new();
    for (p, vertices) in triangles {
        if !has_area(p) {
            out.push(NO_LIGHT);
            continue;
        }
        // A textured emission has uvs (the importer requires them); an
        // untextured one reads none.
        let uv = uvs.map_or(LightShape::BARYCENTRIC_UVS, |uvs| {
            vertices.map(|i| uvs[i as usize])
        });
        let textures = &emission.textures;
        out.push(asm.add_area_light(&emission.entity, LightShape::Triangle { p, uv }, textures)?);
    }
    Ok(out)
}

/// The world-space triangle lights of one instance of a prototype.
fn instance_lights(
    meshes: &[MeshData],
    emissions: &[Option<&AssetEmission>],
    world: &Mat4,
    asm: &mut Assembly,
) -> Result<Vec<Vec<u32>>> {
    if emissions.iter().all(Option::is_none) {
        return Ok(Vec::new());
    }
    let mirrored = world.determinant() < 0.0;
    let mut out = Vec::with_capacity(meshes.len());
    for (mesh, emission) in meshes.iter().zip(emissions) {
        let Some(emission) = emission else {
            out.push(Vec::new());
            continue;
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
        out.push(triangle_lights(tris, emission, mesh.uvs.as_deref(), asm)?);
    }
    Ok(out)
}

/// A world transform as Embree's 3x4 column-major instance transform.
fn embree_transform(world: &Mat4) -> [f32; 12] {
    let c = world.to_cols_array();
    [
        c[0], c[1], c[2], c[4], c[5], c[6], c[8], c[9], c[10], c[12], c[13], c[14],
    ]
}

/// What shading needs to bring an instance's hits into world space.
fn placement(world: &Mat4) -> Placement {
    let linear = Mat3::from_mat4(*world);
    Placement {
        linear,
        translation: world.w_axis.truncate(),
        normal: linear.inverse().transpose(),
    }
}
