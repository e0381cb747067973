//! The queries' plain data: a ray segment and the closest hit along it, as
//! the single-ray and the packet queries take and answer them.

/// A ray segment `org + t dir`, `t` in `[tnear, tfar]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    pub org: [f32; 3],
    pub dir: [f32; 3],
    pub tnear: f32,
    pub tfar: f32,
}

/// The closest hit along a ray, as Embree reports it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    pub t: f32,
    /// Barycentric coordinates of the hit: weights of vertices 1 and 2.
    pub u: f32,
    pub v: f32,
    /// Unnormalized geometric normal (for triangles `(v1 - v0) x (v2 - v0)`).
    pub ng: [f32; 3],
    /// The geometry within the instanced scene when `inst_id` is set.
    pub geom_id: u32,
    pub prim_id: u32,
    /// The instance hit ([`crate::INVALID_ID`] for geometry of the top scene).
    pub inst_id: u32,
}
