//! glTF 2.0 assets (`.gltf` with external or embedded buffers, `.glb`) to
//! plain data: meshes, instances and materials.
//!
//! Every triangle primitive of every mesh the asset's scene uses is loaded
//! and placed by its node hierarchy and the shape's `transform`. A mesh
//! used by one node is returned in world space; a mesh used by several
//! nodes is returned once, in object space, with the placements of its
//! nodes, so the assembly builds its vertices, indices, normals and BVH
//! once however often it appears. Materials become BSDF plugin entities
//! (see [`material`]) unless the scene replaces them by name, and emissive
//! materials the light entity their triangles share. The importer reads
//! only the request; it changes nothing of its caller's.

mod buffers;
pub(crate) mod camera;
mod decode;
mod material;
mod normals;
mod resolve;
mod scene_graph;
mod unmodelled;

use std::collections::HashMap;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use lumis_core::glam::{Mat3, Mat4};
use lumis_core::{Error, Location, Registry, Result, Vec3};
use rayon::prelude::*;

use crate::bsdf_ref::BsdfRef;
pub(crate) use decode::{MissingNormals, Part};
pub(crate) use material::normal_map_params;
pub(crate) use resolve::{AssetEmission, ImportedMaterial, MaterialBsdf};

/// What a `[[shape]] type = "gltf"` asks of the importer.
pub(crate) struct ImportRequest {
    /// Names the shape in errors: `[[shape]] #2 (type = "gltf")`.
    pub owner: String,
    pub path: PathBuf,
    /// `file` as written, for messages.
    pub label: String,
    /// Where `file` was written: errors about the asset point there.
    pub file_location: Location,
    /// Placement of the whole asset.
    pub transform: Mat4,
    /// A `[[bsdf]]` for every primitive instead of the asset's materials.
    pub bsdf: Option<BsdfRef>,
    /// (glTF material name, the `[[bsdf]]` replacing it).
    pub overrides: Vec<(String, BsdfRef)>,
    pub missing_normals: MissingNormals,
}

/// An asset as plain data.
pub(crate) struct GltfImport {
    /// Meshes used by one node, in world space, in mesh then primitive
    /// order.
    pub world_parts: Vec<Part>,
    /// Meshes used by several nodes, in mesh order.
    pub instanced: Vec<InstancedMesh>,
    /// Every material a primitive uses, by glTF index (`None`: the default
    /// material).
    pub materials: HashMap<Option<usize>, ImportedMaterial>,
    /// What the importer could not model, said once per asset and material.
    pub warnings: Vec<String>,
    pub texture_bytes: usize,
    /// Reading the JSON and buffers.
    pub parse_time: Duration,
    /// Decoding attributes, generating normals, transforming to world space.
    pub attributes_time: Duration,
}

/// A mesh placed by several nodes: its primitives in object space.
pub(crate) struct InstancedMesh {
    pub parts: Vec<Part>,
    /// World transform of each node that uses it.
    pub placements: Vec<Mat4>,
}

/// Reads the asset `request` names.
pub(crate) fn import(request: &ImportRequest, registry: &Registry) -> Result<GltfImport> {
    let at = &request.file_location;
    let err = |e: String| Error::at(at, format!("{}: {e}", request.owner));
    let start = Instant::now();
    let mut asset = buffers::load(&request.path, &request.label).map_err(err)?;
    let parse_time = start.elapsed();
    let uses = scene_graph::mesh_uses(&asset.document, request.transform)
        .map_err(|e| err(format!("'{}': {e}", request.label)))?;

    let mut warnings: Vec<String> = unmodelled::unmodelled_features(&asset.document)
        .into_iter()
        .chain(uses.warnings)
        .map(|w| format!("'{}': {w}", request.label))
        .collect();
    let uses = uses.placements;
    let resolved = resolve::resolve_materials(request, &asset, registry)?;
    warnings.extend(resolved.warnings);
    let materials = resolved.materials;
    let uv_set = |material: Option<usize>| materials.get(&material).and_then(|m| m.uv_set);
    let missing_normals = request.missing_normals;

    let start = Instant::now();
    let mut decoded: Vec<Option<Vec<Part>>> = {
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
            .map_err(err)?
    };
    // The raw buffers are decoded: free them before generating normals and
    // building BVHs, the two phases that need the most memory.
    asset.buffers = Vec::new();
    decoded
        .par_iter_mut()
        .flatten()
        .flat_map(|parts| parts.par_iter_mut())
        .for_each(Part::generate_normals);

    let mut world_parts = Vec::new();
    let mut instanced = Vec::new();
    for (parts, placements) in decoded.into_iter().zip(uses) {
        let Some(mut parts) = parts else { continue };
        for placement in &placements {
            check_placed_bounds(&parts, placement)
                .map_err(|e| err(format!("'{}': {e}", request.label)))?;
        }
        match placements.as_slice() {
            [] => unreachable!("only meshes some node uses are decoded"),
            [placement] => {
                for part in &mut parts {
                    bake(part, &placement.world);
                }
                world_parts.extend(parts);
            }
            [_, _, ..] => instanced.push(InstancedMesh {
                parts,
                placements: placements.iter().map(|p| p.world).collect(),
            }),
        }
    }
    Ok(GltfImport {
        world_parts,
        instanced,
        materials,
        warnings,
        texture_bytes: resolved.texture_bytes,
        parse_time,
        attributes_time: start.elapsed(),
    })
}

/// Refuses a placement that carries the mesh's vertices to where Embree
/// would drop them silently (a scale of 1e20, a translation of 3.4e38):
/// the corners of the parts' bounds, placed, must lie within
/// [`lumis_embree::MAX_COORDINATE`].
fn check_placed_bounds(parts: &[Part], placement: &scene_graph::Placement) -> Result<(), String> {
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for p in parts.iter().flat_map(|part| &part.positions) {
        lo = lo.min(Vec3::from(*p));
        hi = hi.max(Vec3::from(*p));
    }
    if lo.x > hi.x {
        return Ok(());
    }
    let corners = (0..8).map(|i| {
        Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    });
    for corner in corners {
        let placed = placement.world.transform_point3(corner);
        let within =
            placed.is_finite() && placed.abs().max_element() < lumis_embree::MAX_COORDINATE;
        if !within {
            return Err(format!(
                "{} places its mesh's vertices out of range: its world transform maps \
                 {corner} to {placed}, beyond the {:e} at which Embree drops triangles",
                placement.node,
                lumis_embree::MAX_COORDINATE
            ));
        }
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
