//! Shading normals for meshes that come without them.
//!
//! Each corner of a triangle gets the area-weighted sum of the face normals
//! around its vertex, counting only faces within the crease angle of its own
//! face: smooth across gentle bends, sharp at creases (the "auto smooth" of
//! DCC tools). A vertex whose corners end up with different normals is split,
//! so the mesh keeps one normal per vertex and shading interpolates them as
//! it does for normals read from a file. The work is parallel over faces
//! and vertices.

use std::collections::HashMap;

use lumis_core::{Vec2, Vec3};
use rayon::prelude::*;

/// Positions, indices and per-vertex normals after generation; vertices on
/// creases are duplicated.
pub(crate) struct Generated {
    pub positions: Vec<[f32; 3]>,
    pub indices: Vec<[u32; 3]>,
    pub normals: Vec<Vec3>,
    /// The texture coordinates given, extended like the positions.
    pub uvs: Option<Vec<Vec2>>,
}

/// Generates normals with crease threshold `cos_crease` (the cosine of the
/// crease angle: faces meeting at a larger angle are not smoothed together).
///
/// Works per vertex, in parallel, so that no per-corner array is needed:
/// each vertex keeps the normal of its first incident corner, and only the
/// corners whose normal differs (on creases; few on scanned surfaces) are
/// listed and given a copy of the vertex afterwards. The temporary memory
/// is the face normals and the vertex-to-face table, about 26 bytes per
/// triangle.
pub(crate) fn generate(
    positions: Vec<[f32; 3]>,
    indices: Vec<[u32; 3]>,
    mut uvs: Option<Vec<Vec2>>,
    cos_crease: f32,
) -> Generated {
    let n_vertices = positions.len();
    // Unnormalised face normals: their length is twice the area, the weight.
    let faces: Vec<Vec3> = indices
        .par_iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| Vec3::from(positions[i as usize]));
            (b - a).cross(c - a)
        })
        .collect();

    // Vertex -> incident faces, compressed rows.
    let mut start = vec![0u32; n_vertices + 1];
    for t in &indices {
        for &v in t {
            start[v as usize + 1] += 1;
        }
    }
    for i in 0..n_vertices {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut incident = vec![0u32; indices.len() * 3];
    for (f, t) in indices.iter().enumerate() {
        for &v in t {
            incident[fill[v as usize] as usize] = f as u32;
            fill[v as usize] += 1;
        }
    }
    drop(fill);

    // The normal of face f's corner at a vertex whose faces are `around`.
    let corner_normal = |f: u32, around: &[u32]| -> Vec3 {
        let own = faces[f as usize].normalize_or_zero();
        let sum: Vec3 = around
            .iter()
            .filter(|&&g| g == f || faces[g as usize].normalize_or_zero().dot(own) >= cos_crease)
            .map(|&g| faces[g as usize])
            .sum();
        sum.normalize_or_zero()
    };
    let around = |v: usize| &incident[start[v] as usize..start[v + 1] as usize];
    // Per vertex: its first corner's normal, and whether other corners differ.
    let first: Vec<(Vec3, bool)> = (0..n_vertices)
        .into_par_iter()
        .map(|v| {
            let faces_here = around(v);
            let Some((&f0, rest)) = faces_here.split_first() else {
                return (Vec3::ZERO, false);
            };
            let n0 = corner_normal(f0, faces_here);
            let differs = rest.iter().any(|&f| corner_normal(f, faces_here) != n0);
            (n0, differs)
        })
        .collect();
    // The corners that differ: (face, corner, normal).
    let exceptions: Vec<(u32, u8, Vec3)> = first
        .par_iter()
        .enumerate()
        .filter(|(_, (_, differs))| *differs)
        .flat_map_iter(|(v, (n0, _))| {
            let faces_here = around(v);
            let indices = &indices;
            let corner_normal = &corner_normal;
            faces_here.iter().filter_map(move |&f| {
                let n = corner_normal(f, faces_here);
                let k = indices[f as usize].iter().position(|&i| i as usize == v)?;
                (n != *n0).then_some((f, k as u8, n))
            })
        })
        .collect();
    drop(faces);
    drop(incident);
    drop(start);

    let mut normals: Vec<Vec3> = Vec::with_capacity(n_vertices);
    normals.extend(first.iter().map(|(n, _)| *n));
    drop(first);
    let mut positions = positions;
    let mut indices = indices;
    // One copy per (vertex, distinct normal).
    let mut copies: HashMap<(u32, [u32; 3]), u32> = HashMap::new();
    for (f, k, n) in exceptions {
        let v = indices[f as usize][k as usize];
        let key = (v, n.to_array().map(f32::to_bits));
        let index = *copies.entry(key).or_insert_with(|| {
            positions.push(positions[v as usize]);
            if let Some(uvs) = &mut uvs {
                uvs.push(uvs[v as usize]);
            }
            normals.push(n);
            positions.len() as u32 - 1
        });
        indices[f as usize][k as usize] = index;
    }
    if !copies.is_empty() {
        // Growing by copies doubled the capacities; give the rest back
        // (keeping the spare element PaddedBuffer adds).
        positions.reserve_exact(1);
        positions.shrink_to(positions.len() + 1);
        normals.shrink_to_fit();
        if let Some(uvs) = &mut uvs {
            uvs.shrink_to_fit();
        }
    }
    Generated {
        positions,
        indices,
        normals,
        uvs,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two triangles folded along the x axis by `angle` degrees.
    fn hinge(angle_deg: f32) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
        let a = angle_deg.to_radians();
        let positions = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.5, 1.0, 0.0],
            [0.5, -a.cos(), a.sin()],
        ];
        (positions, vec![[0, 1, 2], [1, 0, 3]])
    }

    #[test]
    fn gentle_bend_is_smoothed_without_splitting() {
        let (p, i) = hinge(10.0);
        let g = generate(p, i, None, 30f32.to_radians().cos());
        assert_eq!(g.positions.len(), 4);
        // The shared edge's vertices average both faces.
        let n0 = g.normals[0];
        assert!((n0.length() - 1.0).abs() < 1e-5);
        let f0 = Vec3::Z;
        assert!(n0.dot(f0) < 0.9999 && n0.dot(f0) > 0.98, "{n0}");
    }

    #[test]
    fn crease_splits_shared_vertices() {
        let (p, i) = hinge(90.0);
        let g = generate(p, i, None, 30f32.to_radians().cos());
        // Vertices 0 and 1 are shared by faces 90 degrees apart: one copy each.
        assert_eq!(g.positions.len(), 6);
        for (t, face) in g.indices.iter().zip([Vec3::Z, Vec3::Y]) {
            for &v in t {
                assert!((g.normals[v as usize] - face).length() < 1e-5, "{t:?}");
            }
        }
        assert_eq!(g.positions[g.indices[1][0] as usize], [1.0, 0.0, 0.0]);
    }
}
