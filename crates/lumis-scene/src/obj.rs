//! Wavefront OBJ files to one triangle mesh (faces triangulated, every
//! object merged).

use std::path::Path;

use lumis_core::Vec3;

use crate::triangle_mesh::TriangleMesh;

/// Reads `path`. Errors say what is wrong with the file (the caller says
/// which shape and key named it).
pub(crate) fn import(path: &Path) -> Result<TriangleMesh, String> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _materials) = tobj::load_obj(path, &options)
        .map_err(|e| format!("cannot load OBJ '{}': {e}", path.display()))?;
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
                return Err(format!(
                    "'{}': {what} {bad:?} is not finite (NaN, or beyond the range of a 32-bit float)",
                    path.display()
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
                return Err(format!(
                    "'{}': face index {bad} out of range for {count} vertices",
                    path.display()
                ));
            }
            indices.push([base + t[0], base + t[1], base + t[2]]);
        }
    }
    if indices.is_empty() {
        return Err(format!("'{}' contains no triangles", path.display()));
    }
    Ok(TriangleMesh {
        positions,
        indices,
        normals: all_have_normals
            .then_some(normals)
            .filter(|n| !n.is_empty()),
    })
}
