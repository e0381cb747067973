//! Math helpers on top of glam: orthonormal frames and floating-point error
//! bookkeeping (pbrt-v4, section 6.8 "Managing Rounding Error").

use glam::{Vec3, Vec3A};

/// An orthonormal basis; `z` is the normal. Local coordinates are the ones a
/// BSDF sees: `cos theta = local.z`.
///
/// The axes are 16-byte SIMD vectors: every path vertex takes its outgoing
/// direction to local space and its sampled direction back, and with
/// 12-byte `Vec3`s each of those products spends more instructions
/// assembling lanes than multiplying.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    pub x: Vec3A,
    pub y: Vec3A,
    pub z: Vec3A,
}

impl Frame {
    /// A frame around the unit vector `n`, branchless and continuous except
    /// at `n.z = -1` (Duff et al. 2017, "Building an Orthonormal Basis,
    /// Revisited", JCGT 6(1), listing 3).
    #[inline]
    pub fn from_z(n: Vec3) -> Self {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let x = Vec3A::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let y = Vec3A::new(b, sign + n.y * n.y * a, -n.y);
        Self { x, y, z: n.into() }
    }

    /// The frame of a textured surface with unit normal `n`: `x` along the
    /// tangent part of `dp/du`, `y` toward the image's up (`-dp/dv`: uv
    /// (0, 0) is an image's top-left corner), as tangent-space normal maps
    /// mean them (glTF 2.0, 3.9.3; MikkTSpace's sign per triangle). Where
    /// the texture is mirrored the frame is left-handed, which reflection
    /// models symmetric under `y -> -y` (isotropic and anisotropic
    /// microfacet lobes alike) do not see. Degenerate tangents give
    /// [`Frame::from_z`].
    #[inline]
    pub fn from_tangents(n: Vec3, dpdu: Vec3, dpdv: Vec3) -> Self {
        let t = dpdu - n * n.dot(dpdu);
        let length_sq = t.length_squared();
        if !(length_sq > 1e-24 && length_sq.is_finite()) {
            return Self::from_z(n);
        }
        let x = t / length_sq.sqrt();
        let y = n.cross(x);
        let y = if y.dot(dpdv) > 0.0 { -y } else { y };
        Self {
            x: x.into(),
            y: y.into(),
            z: n.into(),
        }
    }

    /// The normal, `z`.
    #[inline]
    pub fn normal(&self) -> Vec3 {
        self.z.into()
    }

    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        let v = Vec3A::from(v);
        Vec3::new(v.dot(self.x), v.dot(self.y), v.dot(self.z))
    }

    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        (self.x * v.x + self.y * v.y + self.z * v.z).into()
    }
}

/// `n * eps / (1 - n * eps)`: the bound on relative error after `n` rounded
/// operations (pbrt-v4, eq. 6.28).
#[inline]
pub fn gamma(n: i32) -> f32 {
    let n_eps = n as f32 * (f32::EPSILON * 0.5);
    n_eps / (1.0 - n_eps)
}

/// The next representable float above `v` (pbrt-v4 `NextFloatUp`).
#[inline]
pub fn next_float_up(v: f32) -> f32 {
    if v.is_infinite() && v > 0.0 {
        return v;
    }
    let v = if v == -0.0 { 0.0 } else { v };
    let bits = v.to_bits();
    let bits = if v >= 0.0 { bits + 1 } else { bits - 1 };
    f32::from_bits(bits)
}

/// The next representable float below `v` (pbrt-v4 `NextFloatDown`).
#[inline]
pub fn next_float_down(v: f32) -> f32 {
    if v.is_infinite() && v < 0.0 {
        return v;
    }
    let v = if v == 0.0 { -0.0 } else { v };
    let bits = v.to_bits();
    let bits = if v > 0.0 { bits - 1 } else { bits + 1 };
    f32::from_bits(bits)
}

/// `sqrt(max(0, x))`: guards against tiny negative arguments from rounding.
#[inline]
pub fn safe_sqrt(x: f32) -> f32 {
    x.max(0.0).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tangent_frames_follow_u_and_the_images_up() {
        let n = Vec3::new(0.2, 0.1, 1.0).normalize();
        // u to the right (+x), v down the image (-y): a right-handed frame.
        let f = Frame::from_tangents(n, Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, -3.0, 0.0));
        assert!(f.x.dot(Vec3A::X) > 0.9 && f.y.dot(Vec3A::Y) > 0.9);
        assert!((f.x.cross(f.y) - f.z).length() < 1e-5);
        assert!(f.x.dot(f.z).abs() < 1e-6 && (f.x.length() - 1.0).abs() < 1e-6);
        // Mirrored in u: x follows u to the left, y stays the image's up.
        let m = Frame::from_tangents(n, Vec3::new(-2.0, 0.0, 0.0), Vec3::new(0.0, -3.0, 0.0));
        assert!(m.x.dot(Vec3A::X) < -0.9 && m.y.dot(Vec3A::Y) > 0.9);
        assert!((m.x.cross(m.y) + m.z).length() < 1e-5, "left-handed");
        let v = Vec3::new(0.1, 0.7, -0.2);
        assert!((m.to_world(m.to_local(v)) - v).length() < 1e-6);
        // A tangent along the normal has no direction in the plane.
        assert_eq!(
            Frame::from_tangents(Vec3::Z, Vec3::Z, Vec3::Y),
            Frame::from_z(Vec3::Z)
        );
    }

    #[test]
    fn frame_is_orthonormal_for_all_hemispheres() {
        for n in [
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            Vec3::new(0.3, -0.4, 0.866).normalize(),
            Vec3::new(1e-4, 0.0, -1.0).normalize(),
        ] {
            let f = Frame::from_z(n);
            for (a, b) in [(f.x, f.y), (f.y, f.z), (f.x, f.z)] {
                assert!(a.dot(b).abs() < 1e-5);
            }
            assert!((f.x.length() - 1.0).abs() < 1e-5);
            assert!((f.y.length() - 1.0).abs() < 1e-5);
            assert!((f.x.cross(f.y) - f.z).length() < 1e-5, "right-handed");
            let v = Vec3::new(0.1, 0.7, -0.2);
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-6);
        }
    }

    #[test]
    fn next_float_steps_by_one_ulp() {
        assert!(next_float_up(1.0) > 1.0);
        assert_eq!(next_float_up(1.0), 1.0 + f32::EPSILON);
        assert!(next_float_down(1.0) < 1.0);
        assert!(next_float_up(0.0) > 0.0);
        assert!(next_float_down(0.0) < 0.0);
        assert!(next_float_up(-1.0) > -1.0);
        assert_eq!(next_float_up(f32::INFINITY), f32::INFINITY);
    }
}
