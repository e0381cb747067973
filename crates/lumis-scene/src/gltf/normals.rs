//! Shading normals for meshes that come without them.
//!
//! Each corner of a triangle gets the area-weighted sum of the face normals
//! around its vertex, counting only faces within the crease angle of its own
//! face: smooth across gentle bends, sharp at creases (the "auto smooth" of
//! DCC tools). A vertex whose corners end up with different normals is split,
//! so the mesh keeps one normal per vertex and shading interpolates them as
//! it does for normals read from a file. Face normals and corner normals are
//! computed in parallel.

use lumis_core::Vec3;
use rayon::prelude::*;

/// Positions, indices and per-vertex normals after generation; vertices on
/// creases are duplicated.
pub(crate) struct Generated {
    pub positions: Vec<[f32; 3]>,
    pub indices: Vec<[u32; 3]>,
    pub normals: Vec<Vec3>,
}

/// Generates normals with crease threshold `cos_crease` (the cosine of the
/// crease angle: faces meeting at a larger angle are not smoothed together).
pub(crate) fn generate(
    positions: Vec<[f32; 3]>,
    indices: Vec<[u32; 3]>,
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
    let units: Vec<Vec3> = faces.par_iter().map(|f| f.normalize_or_zero()).collect();

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

    let corner_normals: Vec<[Vec3; 3]> = indices
        .par_iter()
        .enumerate()
        .map(|(f, t)| {
            let own = units[f];
            t.map(|v| {
                let around = &incident[start[v as usize] as usize..start[v as usize + 1] as usize];
                let sum: Vec3 = around
                    .iter()
                    .filter(|&&g| g as usize == f || units[g as usize].dot(own) >= cos_crease)
                    .map(|&g| faces[g as usize])
                    .sum();
                sum.normalize_or_zero()
            })
        })
        .collect();
    drop(faces);
    drop(units);
    drop(incident);

    // One normal per vertex: the first corner's normal keeps the vertex,
    // each further distinct normal gets a copy of it.
    let mut positions = positions;
    let mut indices = indices;
    let mut normals: Vec<Option<Vec3>> = vec![None; n_vertices];
    // Copies made of vertex v so far, as (normal, new index), looked up
    // linearly: few vertices sit on creases, and those have few normals.
    let mut copies: Vec<Vec<(Vec3, u32)>> = Vec::new();
    let mut copy_slot: Vec<u32> = Vec::new();
    let mut extra_normals = Vec::new();
    for (t, corners) in indices.iter_mut().zip(&corner_normals) {
        for k in 0..3 {
            let v = t[k] as usize;
            let n = corners[k];
            match normals[v] {
                None => normals[v] = Some(n),
                Some(existing) if existing == n => {}
                Some(_) => {
                    if copy_slot.is_empty() {
                        copy_slot = vec![u32::MAX; n_vertices];
                    }
                    if copy_slot[v] == u32::MAX {
                        copy_slot[v] = copies.len() as u32;
                        copies.push(Vec::new());
                    }
                    let list = &mut copies[copy_slot[v] as usize];
                    let index = match list.iter().find(|(m, _)| *m == n) {
                        Some(&(_, i)) => i,
                        None => {
                            let i = positions.len() as u32;
                            positions.push(positions[v]);
                            extra_normals.push(n);
                            list.push((n, i));
                            i
                        }
                    };
                    t[k] = index;
                }
            }
        }
    }
    let mut normals: Vec<Vec3> = normals
        .into_iter()
        .map(|n| n.unwrap_or(Vec3::ZERO))
        .collect();
    normals.extend(extra_normals);
    Generated {
        positions,
        indices,
        normals,
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
        let g = generate(p, i, 30f32.to_radians().cos());
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
        let g = generate(p, i, 30f32.to_radians().cos());
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
