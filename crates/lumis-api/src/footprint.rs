//! How much of a surface one pixel sees, for filtering textures over it.
//!
//! pbrt-v4 (section 10.1.1, `CameraBase::Approximate_dp_dxy`) does not
//! carry ray differentials along whole paths: at every path vertex it asks
//! the camera how far the surface point moves from one pixel to the next,
//! as if the camera saw the point directly. For a pinhole camera and a
//! camera ray that is exact; deeper on a path it is the usual, slightly
//! sharp, approximation. Either way textures get a footprint and filter
//! over it (trilinear or EWA) instead of aliasing.

use glam::{Vec2, Vec3};

/// A pinhole camera's pixel spacing, as the footprint of a surface point
/// needs it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PixelFootprint {
    /// The camera's centre of projection.
    pub origin: Vec3,
    /// The unit viewing direction.
    pub forward: Vec3,
    /// The image plane at distance 1 along `forward`: one pixel to the
    /// right and one pixel down, in world space.
    pub per_pixel_x: Vec3,
    pub per_pixel_y: Vec3,
    /// The fraction of a pixel the footprint covers: with many samples
    /// per pixel the pixel filter already averages over the pixel, so the
    /// texture filter can be narrower (pbrt-v4: `max(1/8, 1/sqrt(spp))`).
    pub scale: f32,
}

impl PixelFootprint {
    /// The footprint scale of `spp` samples per pixel.
    pub fn spp_scale(spp: u32) -> f32 {
        (1.0 / (spp.max(1) as f32).sqrt()).max(0.125)
    }

    /// How the point `p` on a surface of normal `n` moves one pixel right
    /// and one pixel down: the rays through the neighbouring pixels meet
    /// the tangent plane at `p` at `p + dp/dx` and `p + dp/dy`. Zero when
    /// the point is behind the camera or the plane is seen edge-on.
    #[inline]
    pub fn dp_dxy(&self, p: Vec3, n: Vec3) -> (Vec3, Vec3) {
        let to_p = p - self.origin;
        let depth = to_p.dot(self.forward);
        if depth.is_nan() || depth <= 0.0 {
            return (Vec3::ZERO, Vec3::ZERO);
        }
        // The direction through p, scaled to reach the image plane at 1.
        let d = to_p / depth;
        let plane = n.dot(to_p);
        let offset = |step: Vec3| {
            let dir = d + step * self.scale;
            let t = plane / n.dot(dir);
            let moved = self.origin + t * dir - p;
            if moved.is_finite() {
                moved
            } else {
                Vec3::ZERO
            }
        };
        (offset(self.per_pixel_x), offset(self.per_pixel_y))
    }

    /// `(du/dx, dv/dx)` and `(du/dy, dv/dy)` at a surface point `p`,
    /// normal `n`, whose parameterization has partial derivatives `dpdu`,
    /// `dpdv`: what a texture lookup there filters over.
    #[inline]
    pub fn uv_footprint(&self, p: Vec3, n: Vec3, dpdu: Vec3, dpdv: Vec3) -> (Vec2, Vec2) {
        let (dpdx, dpdy) = self.dp_dxy(p, n);
        uv_derivatives(dpdu, dpdv, dpdx, dpdy)
    }
}

/// The uv footprint as a [`TextureQuery`](crate::texture::TextureQuery) carries it: `du/dx, dv/dx,
/// du/dy, dv/dy` in IEEE half precision. A hit is copied at every path
/// vertex, and at 128 bytes or less the copy stays inline (see
/// `interaction.rs`); four f32s would take it past that, and a footprint
/// only picks a mip level and an ellipse, for which 11 significant bits are
/// plenty. Only a texture that filters unpacks it. Magnitudes beyond
/// the f16 range are clamped (a footprint of 65504 texture widths covers
/// the texture anyway) and those below its normal range flush to zero
/// (a 1/16384-wide footprint is a bilinear lookup on any texture under
/// 16k texels).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PackedFootprint([u16; 4]);

impl PackedFootprint {
    /// No footprint: lookups are bilinear.
    pub const NONE: Self = Self([0; 4]);

    #[inline]
    pub fn new(duv_dx: Vec2, duv_dy: Vec2) -> Self {
        Self([duv_dx.x, duv_dx.y, duv_dy.x, duv_dy.y].map(f16_bits))
    }

    /// `(du/dx, dv/dx)` and `(du/dy, dv/dy)`.
    #[inline]
    pub fn unpack(self) -> (Vec2, Vec2) {
        let [a, b, c, d] = self.0.map(f16_value);
        (Vec2::new(a, b), Vec2::new(c, d))
    }
}

/// The smallest normal f16, and the largest finite one.
const F16_MIN_NORMAL: f32 = 6.103_515_6e-5;
const F16_MAX: f32 = 65504.0;

/// `x` in f16, rounded to nearest even; NaN and tiny values become zero.
#[inline]
fn f16_bits(x: f32) -> u16 {
    let sign = ((x.to_bits() >> 16) & 0x8000) as u16;
    let a = x.abs();
    if a.is_nan() || a < F16_MIN_NORMAL {
        return sign;
    }
    let a = a.min(F16_MAX);
    // Rebias the exponent (127 to 15) and round the mantissa from 23 bits
    // to 10, ties to even.
    let bits = a.to_bits() - ((127 - 15) << 23);
    let rounded = bits + 0x0fff + ((bits >> 13) & 1);
    sign | (rounded >> 13) as u16
}

/// `h` as f32: its exponent and mantissa bits moved into place, then
/// rebiased (15 to 127) by a multiplication by 2^112, which maps zero to
/// zero without a branch.
#[inline]
fn f16_value(h: u16) -> f32 {
    let magnitude = f32::from_bits(((h & 0x7fff) as u32) << 13) * f32::from_bits(0x7780_0000);
    f32::from_bits(magnitude.to_bits() | (((h & 0x8000) as u32) << 16))
}

/// `(du/dx, dv/dx)` and `(du/dy, dv/dy)` from the surface's `dp/du`,
/// `dp/dv` and the point's `dp/dx`, `dp/dy`: the least-squares solution of
/// `dp/dx = dp/du du/dx + dp/dv dv/dx` (pbrt-v4
/// `SurfaceInteraction::ComputeDifferentials`, eq. 10.1). Zero where the
/// parameterization is degenerate; clamped so that no lookup sees an
/// infinite footprint.
#[inline]
pub fn uv_derivatives(dpdu: Vec3, dpdv: Vec3, dpdx: Vec3, dpdy: Vec3) -> (Vec2, Vec2) {
    let (a00, a01, a11) = (dpdu.dot(dpdu), dpdu.dot(dpdv), dpdv.dot(dpdv));
    let inv_det = 1.0 / (a00 * a11 - a01 * a01);
    if !inv_det.is_finite() {
        return (Vec2::ZERO, Vec2::ZERO);
    }
    let solve = |dp: Vec3| {
        let (b0, b1) = (dpdu.dot(dp), dpdv.dot(dp));
        let d = Vec2::new(a11 * b0 - a01 * b1, a00 * b1 - a01 * b0) * inv_det;
        if d.is_finite() {
            d.clamp(Vec2::splat(-1e8), Vec2::splat(1e8))
        } else {
            Vec2::ZERO
        }
    };
    (solve(dpdx), solve(dpdy))
}

/// `dp/du` and `dp/dv` of the triangle `p` with texture coordinates `uv`
/// (pbrt-v4 `Triangle::InteractionFromIntersection`), or `None` where the
/// uvs are degenerate.
#[inline]
pub fn triangle_dp_duv(p: [Vec3; 3], uv: [Vec2; 3]) -> Option<(Vec3, Vec3)> {
    let (duv02, duv12) = (uv[0] - uv[2], uv[1] - uv[2]);
    let (dp02, dp12) = (p[0] - p[2], p[1] - p[2]);
    let det = duv02.x * duv12.y - duv02.y * duv12.x;
    if det.abs() < 1e-12 {
        return None;
    }
    let inv = 1.0 / det;
    let dpdu = (duv12.y * dp02 - duv02.y * dp12) * inv;
    let dpdv = (duv02.x * dp12 - duv12.x * dp02) * inv;
    (dpdu.is_finite() && dpdv.is_finite()).then_some((dpdu, dpdv))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A camera at the origin looking down -z with 0.01-wide pixels.
    fn camera() -> PixelFootprint {
        PixelFootprint {
            origin: Vec3::ZERO,
            forward: Vec3::NEG_Z,
            per_pixel_x: Vec3::new(0.01, 0.0, 0.0),
            per_pixel_y: Vec3::new(0.0, -0.01, 0.0),
            scale: 1.0,
        }
    }

    #[test]
    fn a_facing_plane_moves_by_the_pixel_width_times_the_depth() {
        let (dx, dy) = camera().dp_dxy(Vec3::new(0.0, 0.0, -4.0), Vec3::Z);
        assert!((dx - Vec3::new(0.04, 0.0, 0.0)).length() < 1e-6, "{dx}");
        assert!((dy - Vec3::new(0.0, -0.04, 0.0)).length() < 1e-6, "{dy}");
    }

    /// A plane tilted by 60 degrees about x stretches the y footprint by
    /// 1 / cos 60 = 2 (to first order at the image centre).
    #[test]
    fn a_tilted_plane_stretches_the_footprint() {
        let n = Vec3::new(0.0, 60f32.to_radians().sin(), 60f32.to_radians().cos());
        let (dx, dy) = camera().dp_dxy(Vec3::new(0.0, 0.0, -4.0), n);
        assert!((dx.length() - 0.04).abs() < 1e-4, "{dx}");
        // (1.97: the step of one pixel is finite, the stretch first order.)
        assert!((dy.length() / 0.04 - 2.0).abs() < 0.05, "{dy}");
        // Behind the camera and edge-on: no footprint.
        assert_eq!(
            camera().dp_dxy(Vec3::new(0.0, 0.0, 4.0), Vec3::Z),
            (Vec3::ZERO, Vec3::ZERO)
        );
        let (ex, _) = camera().dp_dxy(Vec3::new(0.0, 0.0, -4.0), Vec3::X);
        assert!(ex.is_finite());
    }

    /// On a plane whose uv is its xy scaled by 1/2, a footprint of 0.04 in
    /// x is 0.02 in u; the derivatives of a triangle agree.
    #[test]
    fn uv_derivatives_invert_the_parameterization() {
        let p = [
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        ];
        let uv = [Vec2::ZERO, Vec2::X, Vec2::Y];
        let (dpdu, dpdv) = triangle_dp_duv(p, uv).unwrap();
        assert!((dpdu - Vec3::new(2.0, 0.0, 0.0)).length() < 1e-6);
        assert!((dpdv - Vec3::new(0.0, 2.0, 0.0)).length() < 1e-6);
        let (dx, dy) = camera().uv_footprint(Vec3::new(0.0, 0.0, -4.0), Vec3::Z, dpdu, dpdv);
        assert!((dx - Vec2::new(0.02, 0.0)).length() < 1e-6, "{dx:?}");
        assert!((dy - Vec2::new(0.0, -0.02)).length() < 1e-6, "{dy:?}");
        // Degenerate uvs give no derivatives and no footprint.
        assert!(triangle_dp_duv(p, [Vec2::ZERO; 3]).is_none());
        assert_eq!(
            uv_derivatives(Vec3::X, Vec3::X, Vec3::X, Vec3::Y),
            (Vec2::ZERO, Vec2::ZERO)
        );
    }

    #[test]
    fn the_packed_footprint_keeps_eleven_bits() {
        for x in [
            0.0,
            1.0,
            -1.0,
            0.1,
            1e-3,
            -3.3e-2,
            1234.5,
            65504.0,
            F16_MIN_NORMAL,
        ] {
            let back = f16_value(f16_bits(x));
            assert!(
                (back - x).abs() <= x.abs() * 2f32.powi(-11),
                "{x} -> {back}"
            );
        }
        // Halfway between 1 and the next f16 rounds to even (down).
        assert_eq!(f16_value(f16_bits(1.0 + 2f32.powi(-11))), 1.0);
        assert_eq!(f16_value(f16_bits(1e9)), F16_MAX);
        assert_eq!(f16_value(f16_bits(-1e9)), -F16_MAX);
        assert_eq!(f16_value(f16_bits(1e-6)), 0.0);
        assert_eq!(f16_value(f16_bits(f32::NAN)), 0.0);
        assert_eq!(f16_value(f16_bits(f32::INFINITY)), F16_MAX);
        let packed = PackedFootprint::new(Vec2::new(0.25, -0.5), Vec2::new(0.0, 2.0));
        assert_eq!(
            packed.unpack(),
            (Vec2::new(0.25, -0.5), Vec2::new(0.0, 2.0))
        );
        assert_eq!(PackedFootprint::NONE.unpack(), (Vec2::ZERO, Vec2::ZERO));
    }

    #[test]
    fn many_samples_per_pixel_narrow_the_footprint_to_an_eighth() {
        assert_eq!(PixelFootprint::spp_scale(1), 1.0);
        assert_eq!(PixelFootprint::spp_scale(16), 0.25);
        assert_eq!(PixelFootprint::spp_scale(4096), 0.125);
        assert_eq!(PixelFootprint::spp_scale(0), 1.0);
    }
}
