//! A triangle mesh as shapes and importers hand it to the assembly.

use lumis_core::Vec3;

/// Vertices and triangles, front side counter-clockwise.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct TriangleMesh {
    pub positions: Vec<[f32; 3]>,
    pub indices: Vec<[u32; 3]>,
    /// Per-vertex shading normals; `None`: flat shading.
    pub normals: Option<Vec<Vec3>>,
}
