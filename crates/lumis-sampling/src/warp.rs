//! Warps from `[0,1)^2` to shapes and directions, each with its density.
//!
//! Directions are in a local frame with `z` up; densities are w.r.t. solid
//! angle for directions and w.r.t. area for points.

use std::f32::consts::{FRAC_1_PI, FRAC_PI_4, PI};

use glam::{Vec2, Vec3};

use crate::real::{Real, V3};
use crate::special::{sin_cos_quarter_turn, sin_cos_turns};

/// Concentric map of the square to the unit disk (Shirley and Chiu 1997,
/// "A Low Distortion Map Between Disk and Square"): keeps strata compact.
/// Each wedge's angle is `pi/4 * t` for `t` in [-1, 1] (pbrt-v4's form),
/// measured from the x axis in the left/right wedges and from the y axis
/// (so sine and cosine swap) in the top/bottom ones.
#[inline]
pub fn square_to_concentric_disk(u: Vec2) -> Vec2 {
    concentric_disk_and_radius(u).0
}

/// [`square_to_concentric_disk`] and the radius of its point, which the map
/// knows before the angle.
#[inline(always)]
fn concentric_disk_and_radius(u: Vec2) -> (Vec2, f32) {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return (Vec2::ZERO, 0.0);
    }
    // The wedge is a coin flip for every sample: selects, not branches, so
    // the processor has nothing to mispredict. In the top/bottom wedges
    // theta = pi/2 - phi, so cos theta = sin phi and sin theta = cos phi.
    let vertical = o.y.abs() >= o.x.abs();
    let (r, along) = if vertical { (o.y, o.x) } else { (o.x, o.y) };
    let (sin, cos) = sin_cos_quarter_turn(FRAC_PI_4 * (along / r));
    let (x, y) = if vertical { (sin, cos) } else { (cos, sin) };
    (r * Vec2::new(x, y), r.abs())
}

/// [`concentric_disk_and_radius`] on SIMD lanes, the same operations in
/// the same order, so each lane is the scalar map's bits (tested). The
/// scalar map is not this with `F = f32`: written with [`Real::select`],
/// its two swaps compile to vector blends that cost the scalar path 1% of
/// its instructions (callgrind, Cornell box).
#[inline(always)]
fn concentric_disk_and_radius_lanes<F: Real>([u0, u1]: [F; 2]) -> ([F; 2], F) {
    let (zero, one, two) = (F::splat(0.0), F::splat(1.0), F::splat(2.0));
    let (ox, oy) = (two * u0 - one, two * u1 - one);
    let vertical = oy.abs().ge(ox.abs());
    let (r, along) = (F::select(vertical, oy, ox), F::select(vertical, ox, oy));
    let (sin, cos) = sin_cos_quarter_turn(F::splat(FRAC_PI_4) * (along / r));
    let (x, y) = (F::select(vertical, sin, cos), F::select(vertical, cos, sin));
    // The centre maps to itself (its angle above is 0/0).
    let centre = ox.eq(zero) & oy.eq(zero);
    let keep = |v: F| F::select(centre, zero, v);
    ([keep(r * x), keep(r * y)], keep(r.abs()))
}

/// Cosine-weighted hemisphere by Malley's method: project the concentric
/// disk up onto the hemisphere. Density `cos theta / pi`.
#[inline]
pub fn square_to_cosine_hemisphere(u: Vec2) -> Vec3 {
    let (d, r) = concentric_disk_and_radius(u);
    // From the radius rather than from |d|^2 (equal to within rounding):
    // the square root then runs alongside the division and the sine and
    // cosine instead of after them, off the chain of dependent latencies
    // that every diffuse bounce waits on before its next ray.
    let z = (1.0 - r * r).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

/// [`square_to_cosine_hemisphere`] on SIMD lanes, each lane the scalar
/// map's bits (tested).
#[inline(always)]
pub fn square_to_cosine_hemisphere_lanes<F: Real>(u: [F; 2]) -> V3<F> {
    let ([x, y], r) = concentric_disk_and_radius_lanes(u);
    let z = (F::splat(1.0) - r * r).max(F::splat(0.0)).sqrt();
    V3::new(x, y, z)
}

#[inline]
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    if cos_theta > 0.0 {
        cos_theta * FRAC_1_PI
    } else {
        0.0
    }
}

/// Uniform hemisphere: `z = u0`. Density `1 / (2 pi)`.
#[inline]
pub fn square_to_uniform_hemisphere(u: Vec2) -> Vec3 {
    let z = u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (sin_phi, cos_phi) = sin_cos_turns(u.y);
    Vec3::new(r * cos_phi, r * sin_phi, z)
}

#[inline]
pub fn uniform_hemisphere_pdf(cos_theta: f32) -> f32 {
    if cos_theta >= 0.0 {
        0.5 * FRAC_1_PI
    } else {
        0.0
    }
}

/// Uniform sphere: `z = 1 - 2 u0`. Density `1 / (4 pi)`.
#[inline]
pub fn square_to_uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (sin_phi, cos_phi) = sin_cos_turns(u.y);
    Vec3::new(r * cos_phi, r * sin_phi, z)
}

pub const UNIFORM_SPHERE_PDF: f32 = 0.25 * FRAC_1_PI;

/// Uniform barycentrics on a triangle: `b0 = 1 - sqrt(u0)`, `b1 = u1 sqrt(u0)`
/// (Shirley and Chiu / pbrt-v3 `UniformSampleTriangle`). Returns `(b0, b1)`;
/// `b2 = 1 - b0 - b1`. Density `1 / area` on the triangle.
#[inline]
pub fn square_to_uniform_triangle(u: Vec2) -> Vec2 {
    let s = u.x.sqrt();
    Vec2::new(1.0 - s, u.y * s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Pcg32;

    /// The polynomial sine and cosine stay within 2 ulp of the correctly
    /// rounded values over the whole quarter-turn range, including its ends.
    fn grid(n: usize) -> impl Iterator<Item = Vec2> {
        (0..n * n).map(move |i| {
            Vec2::new(
                ((i % n) as f32 + 0.5) / n as f32,
                ((i / n) as f32 + 0.5) / n as f32,
            )
        })
    }

    #[test]
    fn disk_points_lie_in_disk_and_cover_it_uniformly() {
        let mut inside_half = 0;
        let n = 200;
        for u in grid(n) {
            let d = square_to_concentric_disk(u);
            assert!(d.length() <= 1.0 + 1e-6);
            if d.length() < std::f32::consts::FRAC_1_SQRT_2 {
                inside_half += 1;
            }
        }
        // Area-preserving: the disk of radius 1/sqrt(2) holds half the points.
        let frac = inside_half as f32 / (n * n) as f32;
        assert!((frac - 0.5).abs() < 0.01, "{frac}");
    }

    #[test]
    fn hemisphere_warps_are_unit_and_upper() {
        for u in grid(64) {
            for w in [
                square_to_cosine_hemisphere(u),
                square_to_uniform_hemisphere(u),
            ] {
                assert!((w.length() - 1.0).abs() < 1e-5 && w.z >= 0.0);
            }
            assert!((square_to_uniform_sphere(u).length() - 1.0).abs() < 1e-5);
        }
    }

    /// Each lane of the cosine map on eight lanes is the scalar map's bits,
    /// at the square's corners, edges and centre (where the wedge's angle
    /// is 0/0) and at random points.
    #[test]
    fn cosine_hemisphere_lanes_are_the_scalar_bits() {
        use crate::real::F32x8;
        let top = 1.0 - f32::EPSILON / 2.0;
        let mut rng = Pcg32::new(11, 3);
        let mut points = vec![0.0, 0.5, top, 0.25, 0.75];
        points.extend((0..40).map(|_| rng.next_f32()));
        let us: Vec<Vec2> = points
            .iter()
            .flat_map(|&x| points.iter().map(move |&y| Vec2::new(x, y)))
            .collect();
        for chunk in us.chunks_exact(8) {
            let lanes = square_to_cosine_hemisphere_lanes([
                F32x8::from_fn(|i| chunk[i].x),
                F32x8::from_fn(|i| chunk[i].y),
            ]);
            for (i, &u) in chunk.iter().enumerate() {
                let w = square_to_cosine_hemisphere(u);
                let lane = lanes.lane(i);
                assert_eq!(
                    w.to_array().map(f32::to_bits),
                    lane.to_array().map(f32::to_bits),
                    "u = {u:?}"
                );
            }
        }
        assert_eq!(square_to_cosine_hemisphere(Vec2::splat(0.5)), Vec3::Z);
    }

    /// Monte Carlo check of E[g(w)] against the exact integral of g pdf:
    /// for the cosine warp, E[cos theta] = 2/3 and E[cos^2] = 1/2.
    #[test]
    fn cosine_hemisphere_moments() {
        let mut rng = Pcg32::new(3, 5);
        let n = 400_000;
        let (mut m1, mut m2) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let w = square_to_cosine_hemisphere(Vec2::new(rng.next_f32(), rng.next_f32()));
            m1 += w.z as f64;
            m2 += (w.z * w.z) as f64;
        }
        let (m1, m2) = (m1 / n as f64, m2 / n as f64);
        // Var[cos] = 1/2 - 4/9 = 1/18: sigma_mean = sqrt(1/18/n) ~ 3.7e-4.
        assert!((m1 - 2.0 / 3.0).abs() < 5.0 * 3.7e-4, "{m1}");
        assert!((m2 - 0.5).abs() < 2e-3, "{m2}");
    }

    #[test]
    fn triangle_barycentrics_are_valid_and_uniform() {
        let n = 200;
        let mut near_v0 = 0;
        for u in grid(n) {
            let b = square_to_uniform_triangle(u);
            assert!(b.x >= 0.0 && b.y >= 0.0 && b.x + b.y <= 1.0 + 1e-6);
            // The sub-triangle b0 > 1/2 has a quarter of the area.
            if b.x > 0.5 {
                near_v0 += 1;
            }
        }
        let frac = near_v0 as f32 / (n * n) as f32;
        assert!((frac - 0.25).abs() < 0.01, "{frac}");
    }
}

/// `1 - cos theta` from `sin^2 theta` for `theta` in `[0, pi/2]`, without the
/// cancellation of `1 - sqrt(1 - s)`: by the half-angle identity
/// `1 - cos theta = sin^2 theta / (1 + cos theta)`. Exact to a few ulps even
/// for `s = 1e-16` (a sphere of radius 1e-4 at distance 1e4), where
/// `1 - sqrt(1 - s)` is 0 in `f32`.
/// Generic over [`Real`], so that a batched light runs it on SIMD lanes.
#[inline(always)]
pub fn one_minus_cos_from_sin2<F: Real>(sin2: F) -> F {
    sin2 / (F::splat(1.0) + (F::splat(1.0) - sin2).max(F::splat(0.0)).sqrt())
}

/// A direction uniform in the cone of half-angle `theta_max` around `+z`,
/// given `h_max = 1 - cos theta_max` (pbrt-v4 `SampleUniformCone`, written in
/// `h = 1 - cos theta` so that narrow cones keep their precision:
/// `sin theta = sqrt(h (2 - h))`). Density [`uniform_cone_pdf`].
#[inline]
pub fn square_to_uniform_cone(u: Vec2, h_max: f32) -> Vec3 {
    square_to_uniform_cone_lanes([u.x, u.y], h_max).into()
}

/// [`square_to_uniform_cone`] of a sample per lane, each lane its bits.
#[inline(always)]
pub fn square_to_uniform_cone_lanes<F: Real>([u0, u1]: [F; 2], h_max: F) -> V3<F> {
    let h = u0 * h_max;
    let sin_theta = (h * (F::splat(2.0) - h)).max(F::splat(0.0)).sqrt();
    let (sin_phi, cos_phi) = sin_cos_turns(u1);
    V3::new(sin_theta * cos_phi, sin_theta * sin_phi, F::splat(1.0) - h)
}

/// `1 / (2 pi (1 - cos theta_max))`, the solid angle of the cone inverted.
#[inline(always)]
pub fn uniform_cone_pdf<F: Real>(h_max: F) -> F {
    F::splat(1.0) / (F::splat(2.0 * PI) * h_max)
}

#[cfg(test)]
mod cone_tests {
    use super::*;

    #[test]
    fn half_angle_form_survives_tiny_cones() {
        let s = 1e-16f32;
        let h = one_minus_cos_from_sin2(s);
        assert!((h / 5e-17 - 1.0).abs() < 1e-6, "{h}");
        assert_eq!(1.0 - (1.0 - s).sqrt(), 0.0, "the naive form cancels");
        let d = square_to_uniform_cone(Vec2::new(1.0, 0.25), h);
        assert!((d.y - 1e-8).abs() < 1e-13 && d.z == 1.0, "{d}");
        assert!(uniform_cone_pdf(h).is_finite());
    }

    #[test]
    fn full_hemisphere_cone() {
        let h = one_minus_cos_from_sin2(1.0);
        assert_eq!(h, 1.0);
        assert!((uniform_cone_pdf(h) - 0.5 * FRAC_1_PI).abs() < 1e-7);
    }
}
