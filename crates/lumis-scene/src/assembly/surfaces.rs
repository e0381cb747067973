//! Quads, inline meshes, OBJ meshes and spheres into Embree, with their
//! area lights.

use std::sync::Arc;

use lumis_core::{Error, LightShape, PluginEntity, Result, Vec2, Vec3};
use lumis_embree::PaddedBuffer;

use super::has_area;
use super::state::Assembly;
use crate::description::{Surface, SurfaceGeometry};
use crate::render_scene::{Geometry, MeshData, NO_LIGHT};
use crate::report::Phase;
use crate::triangle_mesh::TriangleMesh;

/// Adds one surface shape, reading its OBJ file if it has one.
pub(crate) fn add_surface(owner: &str, surface: Surface, asm: &mut Assembly) -> Result<()> {
    let bsdf = asm.bsdfs.index_of(&surface.bsdf, owner)?;
    let orientation = if surface.flip_normals { -1.0 } else { 1.0 };
    let emission = surface.emission.as_ref();
    let flip = surface.flip_normals;
    let geometry = match surface.geometry {
        SurfaceGeometry::Quad {
            corner,
            edge_u,
            edge_v,
        } => {
            let c = corner;
            let mesh = TriangleMesh {
                positions: [c, c + edge_u, c + edge_u + edge_v, c + edge_v]
                    .map(Into::into)
                    .to_vec(),
                indices: vec![[0, 1, 2], [0, 2, 3]],
                normals: None,
            };
            // The emitter is one quad light, not two triangle lights; its
            // front side follows the flipped edges.
            let (edge_u, edge_v) = if flip {
                (edge_v, edge_u)
            } else {
                (edge_u, edge_v)
            };
            let lights = match emission {
                Some(entity) => {
                    let quad = LightShape::Quad {
                        corner,
                        edge_u,
                        edge_v,
                    };
                    let textures = asm.textures;
                    vec![asm.add_area_light(entity, quad, textures)?; mesh.indices.len()]
                }
                None => Vec::new(),
            };
            // (u, v) runs along the edges from the corner, so a texture
            // covers the quad once.
            let uvs = [Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y].to_vec();
            let mut geometry = add_mesh(owner, mesh, bsdf, lights, orientation, asm)?;
            if let Geometry::Mesh(data) = &mut geometry {
                data.uvs = Some(uvs);
            }
            geometry
        }
        SurfaceGeometry::Mesh(mesh) => {
            let lights = triangle_lights(&mesh, emission, flip, asm)?;
            add_mesh(owner, mesh, bsdf, lights, orientation, asm)?
        }
        SurfaceGeometry::Obj(file) => {
            let mesh = asm
                .report
                .time(Phase::Parse, || crate::obj::import(&file.path))
                .map_err(|e| Error::at(&file.location, format!("{owner} key 'file': {e}")))?;
            let lights = triangle_lights(&mesh, emission, flip, asm)?;
            add_mesh(owner, mesh, bsdf, lights, orientation, asm)?
        }
        SurfaceGeometry::Sphere { center, radius } => {
            let light = match emission {
                Some(entity) => {
                    let sphere = LightShape::Sphere {
                        center,
                        radius,
                        inward: flip,
                    };
                    let textures = asm.textures;
                    Some(asm.add_area_light(entity, sphere, textures)?)
                }
                None => None,
            };
            asm.counts.spheres += 1;
            asm.builder
                .add_spheres(Arc::new(PaddedBuffer::new(vec![[
                    center.x, center.y, center.z, radius,
                ]])))
                .map_err(|e| Error::msg(format!("{owner}: {e}")))?;
            Geometry::Sphere {
                center,
                radius,
                bsdf,
                light,
                orientation,
            }
        }
    };
    asm.geometries.push(geometry);
    Ok(())
}

/// One triangle light per triangle of an emitting mesh (front side by
/// winding, swapped by `flip`); none when it does not emit.
fn triangle_lights(
    mesh: &TriangleMesh,
    emission: Option<&PluginEntity>,
    flip: bool,
    asm: &mut Assembly,
) -> Result<Vec<u32>> {
    let Some(entity) = emission else {
        return Ok(Vec::new());
    };
    let mut per_triangle = Vec::with_capacity(mesh.indices.len());
    for t in &mesh.indices {
        let [a, b, c] = t.map(|i| Vec3::from(mesh.positions[i as usize]));
        // Zero-area triangles cannot emit; they keep no light.
        if !has_area([a, b, c]) {
            per_triangle.push(NO_LIGHT);
            continue;
        }
        // The uvs a hit gets, its barycentrics in the mesh's own order.
        let [ua, ub, uc] = LightShape::BARYCENTRIC_UVS;
        let (p, uv) = if flip {
            ([a, c, b], [ua, uc, ub])
        } else {
            ([a, b, c], [ua, ub, uc])
        };
        let textures = asm.textures;
        per_triangle.push(asm.add_area_light(entity, LightShape::Triangle { p, uv }, textures)?);
    }
    Ok(per_triangle)
}

/// Adds a mesh to the top level.
fn add_mesh(
    owner: &str,
    mesh: TriangleMesh,
    bsdf: u32,
    lights: Vec<u32>,
    orientation: f32,
    asm: &mut Assembly,
) -> Result<Geometry> {
    let TriangleMesh {
        positions,
        indices,
        normals,
    } = mesh;
    asm.counts.meshes += 1;
    asm.counts.triangles += indices.len();
    asm.counts.unique_triangles += indices.len();
    asm.counts.shading_normals |= normals.is_some();
    let vertices = Arc::new(PaddedBuffer::new(positions));
    let indices = Arc::new(PaddedBuffer::new(indices));
    asm.builder
        .add_triangle_mesh(vertices.clone(), indices.clone())
        .map_err(|e| Error::msg(format!("{owner}: {e}")))?;
    Ok(Geometry::Mesh(MeshData {
        vertices,
        indices,
        normals,
        uvs: None,
        bsdf,
        lights,
        orientation,
        flat_frames: Vec::new(),
    }))
}
