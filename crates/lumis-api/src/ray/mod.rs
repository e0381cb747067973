//! Rays and robust spawning of secondary rays (pbrt-v4, section 6.8.6).

mod ulp_step;

#[cfg(test)]
use ulp_step::step_bits;

use ulp_step::step_away_fast;

use glam::Vec3;

use crate::math::{gamma, next_float_down, next_float_up};

/// A ray segment `o + t d` for `t` in `[0, t_max]`. `d` need not be unit
/// length: shadow rays use `d = to - from` and `t_max` just below 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    pub o: Vec3,
    pub d: Vec3,
    pub t_max: f32,
}

/// How far short of its end point a shadow ray stops, as a fraction of its
/// length (pbrt-v4 `ShadowEpsilon`): the end point's own offset keeps it off
/// the light's surface, this keeps rounding in `t` from reaching it.
pub const SHADOW_EPSILON: f32 = 1e-4;

impl Ray {
    pub fn new(o: Vec3, d: Vec3) -> Self {
        Self {
            o,
            d,
            t_max: f32::INFINITY,
        }
    }

    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.o + self.d * t
    }
}

/// Moves `p` off its surface along the normal `n`, just far enough that the
/// true point (within `p_error` of `p`) lies behind it as seen along `w`, and
/// rounds away from the surface so the move survives the addition
/// (pbrt-v4 `OffsetRayOrigin`, eq. 6.30-6.31). No scene-scale epsilon.
#[inline]
pub fn offset_ray_origin(p: Vec3, p_error: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    // A select, not a branch: which side `w` leaves on is data-dependent.
    // Scaling by +-1 is exact, so either side is the negation of the other.
    let side = if w.dot(n) < 0.0 { -1.0 } else { 1.0 };
    let offset = normal_offset(p_error, n) * side;
    step_away(p + offset, offset)
}

/// The offset along `n` that clears a point's error box `p_error`
/// (pbrt-v4 eq. 6.30: `d = |n| . p_error`), toward the front side.
#[inline(always)]
fn normal_offset(p_error: Vec3, n: Vec3) -> Vec3 {
    n * n.abs().dot(p_error)
}

/// `po` moved one ulp further along `offset`, so that the offset survives
/// the rounding of the addition that made `po`. The common case (every
/// component finite and non-zero) is one integer step per component
/// without branches; zeros and infinities take the exact next_float path.
#[inline(always)]
fn step_away(po: Vec3, offset: Vec3) -> Vec3 {
    step_away_fast(po, offset).unwrap_or_else(|| {
        Vec3::new(
            step_toward(po.x, offset.x),
            step_toward(po.y, offset.y),
            step_toward(po.z, offset.z),
        )
    })
}

/// `next_float_up(v)` if `direction > 0`, `next_float_down(v)` if `< 0`,
/// else `v`.
#[inline]
fn step_toward(v: f32, direction: f32) -> f32 {
    if direction > 0.0 {
        next_float_up(v)
    } else if direction < 0.0 {
        next_float_down(v)
    } else {
        v
    }
}

/// A point on a surface with its rounding-error bound and geometric normal,
/// the two things needed to spawn rays from it without self-intersection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    pub p: Vec3,
    pub p_error: Vec3,
    /// Unit geometric normal, or zero for points not on a surface (point lights).
    pub n: Vec3,
}

impl SurfacePoint {
    /// A point with no surface and no error, e.g. a point light's position.
    pub fn isolated(p: Vec3) -> Self {
        Self {
            p,
            p_error: Vec3::ZERO,
            n: Vec3::ZERO,
        }
    }

    /// A ray leaving the surface in direction `d`.
    #[inline]
    pub fn spawn_ray(&self, d: Vec3) -> Ray {
        Ray::new(offset_ray_origin(self.p, self.p_error, self.n, d), d)
    }

    /// A shadow-ray segment from this point to `to`, both ends kept off
    /// their surfaces (pbrt-v4 `SpawnRayTo` between two interactions; the
    /// end as in [`RayOrigins::spawn_ray_to`]).
    #[inline]
    pub fn spawn_ray_to(&self, to: &SurfacePoint) -> Ray {
        self.ray_origins().spawn_ray_to(to)
    }

    /// Both origins a ray can leave this point from, for a point that
    /// spawns several rays (a path vertex: its continuation and its shadow
    /// rays).
    #[inline(always)]
    pub fn ray_origins(&self) -> RayOrigins {
        let offset = normal_offset(self.p_error, self.n);
        RayOrigins {
            p: self.p,
            n: self.n,
            front: step_away(self.p + offset, offset),
            back: step_away(self.p - offset, -offset),
        }
    }
}

/// The two offset origins of a [`SurfacePoint`] (eq. 6.30-6.31 with either
/// sign): the offset does not depend on the ray's direction, only which
/// side it leaves from does. Worked out once per path vertex, as soon as the
/// hit is known, they leave only a compare and a select between a sampled
/// direction or light point and its ray, where [`offset_ray_origin`] puts
/// the whole offset there. The rays are bit for bit those of
/// [`SurfacePoint::spawn_ray`] and [`SurfacePoint::spawn_ray_to`], since
/// negating the offset is exact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayOrigins {
    p: Vec3,
    n: Vec3,
    front: Vec3,
    back: Vec3,
}

impl RayOrigins {
    /// The origin for a ray leaving toward `w`.
    #[inline(always)]
    pub fn toward(&self, w: Vec3) -> Vec3 {
        if w.dot(self.n) < 0.0 {
            self.back
        } else {
            self.front
        }
    }

    /// As [`SurfacePoint::spawn_ray`].
    #[inline(always)]
    pub fn spawn_ray(&self, d: Vec3) -> Ray {
        Ray::new(self.toward(d), d)
    }

    /// The shadow ray from this point to `to`, stopping at `t_max = 1 -
    /// SHADOW_EPSILON`. It leaves from the origin on `to`'s side, and ends
    /// at `to.p` itself where stopping short already keeps it off `to`'s
    /// surface (`shadow_ray_clears_end`: all but 0.7% of the Cornell
    /// box's light samples); elsewhere (grazing that surface, or an error
    /// bound large next to the distance) at `to.p` offset off the surface
    /// as pbrt-v4's `SpawnRayTo` does.
    ///
    /// The test is a well-predicted branch on values known before the
    /// origin is picked, so the ray's direction waits on `to.p` alone, not
    /// on an offset computed from it: the shadow query starts that much
    /// earlier (the Cornell box 5% faster; docs/src/performance.md,
    /// "Levers"). pbrt-v4
    /// picks the offset end's side with `from - to.p`; `p - to.p` differs
    /// from it only when `p` lies within `from`'s offset of the plane at
    /// `to`, and it frees the end's offset from waiting on `from`.
    #[inline(always)]
    pub fn spawn_ray_to(&self, to: &SurfacePoint) -> Ray {
        let from = self.toward(to.p - self.p);
        // A bound on either origin's distance from p, per component: the
        // back one is the front one's mirror up to three roundings of p.
        let reach = 2.0 * (self.front - self.p).abs() + gamma(4) * self.p.abs();
        let end = if shadow_ray_clears_end(self.p, reach, to) {
            to.p
        } else {
            offset_ray_origin(to.p, to.p_error, to.n, self.p - to.p)
        };
        Ray {
            o: from,
            d: end - from,
            t_max: 1.0 - SHADOW_EPSILON,
        }
    }
}

/// Whether a shadow ray from an origin within `reach` (per component) of
/// `p` to `to.p`, stopped at `t_max = 1 - SHADOW_EPSILON`, stays strictly
/// on its origin's side of every plane with normal `n = to.n` through a
/// point within `to.p_error` of `to.p`: then it cannot reach `to`'s
/// surface near its end, and `to.p` needs no offset.
///
/// With `h = n . (from - to.p)`, the stop lies `(1 - t_max) h` from the
/// plane at `to.p`, up to the rounding `rho <= 2^-24 |n| . (|from| +
/// |to.p|)` of the direction `to.p - from`; the true point lies within
/// `delta = |n| . p_error` of that plane (pbrt-v4 eq. 6.30). So `(1 -
/// t_max) |h| > delta + rho` suffices. `|h|` is at least
/// `|n . (p - to.p)| - |n| . reach`, less that dot product's rounding
/// (`gamma(3)`). Asking
/// for twice `delta + gamma(4) |n| . (|p| + |to.p|) + |n| . reach` covers
/// all of it, and the rounding of `t_max` and of the test itself:
///
/// ```text
/// SHADOW_EPSILON |n . (p - to.p)| > 2 |n| . (p_error + gamma(4) (|p| + |to.p|) + reach)
/// ```
///
/// A point without a surface (`n = 0`: point lights, environment
/// directions) fails with both sides zero, and takes the offset, which is
/// zero for it. (Written with
/// [`normal_offset`], whose length is the right-hand side's dot product
/// for a unit `n`: measured faster than the same test as a dot product.)
#[inline(always)]
fn shadow_ray_clears_end(p: Vec3, reach: Vec3, to: &SurfacePoint) -> bool {
    let height = (p - to.p).dot(to.n).abs();
    let slack = to.p_error + gamma(4) * (p.abs() + to.p.abs()) + reach;
    SHADOW_EPSILON * height > 2.0 * normal_offset(slack, to.n).length()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_moves_to_the_side_of_w() {
        let p = Vec3::new(1.0, 2.0, 0.0);
        let err = Vec3::splat(1e-6);
        let above = offset_ray_origin(p, err, Vec3::Z, Vec3::new(0.3, 0.0, 1.0));
        let below = offset_ray_origin(p, err, Vec3::Z, Vec3::new(0.3, 0.0, -1.0));
        assert!(above.z > 0.0 && below.z < 0.0);
        assert_eq!(above.x, p.x, "only normal components move");
    }

    #[test]
    fn integer_step_matches_next_float() {
        for v in [1.0f32, -1.0, 3.5e-38, -1e-45, -7.25e12, f32::MAX, f32::MIN] {
            let bits = v.to_bits();
            assert_eq!(step_bits(bits, 1.0), next_float_up(v).to_bits(), "{v}");
            assert_eq!(step_bits(bits, -2.0), next_float_down(v).to_bits(), "{v}");
            assert_eq!(step_bits(bits, 0.0), bits);
            assert_eq!(step_bits(bits, -0.0), bits);
        }
    }

    /// The lane-wise step agrees with the exact next_float step wherever it
    /// answers, and declines exactly the zeros, infinities and NaNs.
    #[test]
    fn fast_step_matches_next_float() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1);
            f32::from_bits((state >> 32) as u32)
        };
        let specials = [
            0.0,
            -0.0,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            1e-45,
            f32::MAX,
        ];
        for i in 0..20_000 {
            let pick = |v: f32, k: usize| {
                if i % 7 == k {
                    specials[i % specials.len()]
                } else {
                    v
                }
            };
            let po = Vec3::new(pick(next(), 0), pick(next(), 1), pick(next(), 2));
            // A NaN offset (from a NaN normal or error bound) has no sign
            // to step toward; the two paths need not agree on it.
            let dir = Vec3::new(pick(next(), 3), pick(next(), 4), next());
            if dir.is_nan() {
                continue;
            }
            let exact = Vec3::new(
                step_toward(po.x, dir.x),
                step_toward(po.y, dir.y),
                step_toward(po.z, dir.z),
            );
            let special = po.to_array().iter().any(|v| *v == 0.0 || !v.is_finite());
            match step_away_fast(po, dir) {
                Some(fast) => {
                    assert!(!special, "{po:?} must take the exact path");
                    for (f, e) in fast.to_array().iter().zip(exact.to_array()) {
                        assert_eq!(f.to_bits(), e.to_bits(), "{po:?} {dir:?}");
                    }
                }
                None => assert!(special, "{po:?} declined"),
            }
        }
    }

    #[test]
    fn zeros_and_infinities_take_the_exact_path() {
        // A component at exactly zero must step to the smallest subnormal
        // of the offset's sign, not wrap its bits around.
        let o = offset_ray_origin(Vec3::ZERO, Vec3::ZERO, Vec3::Z, Vec3::Z);
        assert_eq!(o, Vec3::ZERO, "no error, no move");
        let p = Vec3::new(0.0, -0.0, 1.0);
        let up = offset_ray_origin(p, Vec3::splat(1e-30), Vec3::new(0.0, 0.0, 1.0), Vec3::Z);
        assert_eq!(up.x.to_bits(), 0.0f32.to_bits());
        assert!(up.z > 1.0);
        // p + offset rounds to exactly zero: one step below it.
        let cancelled = offset_ray_origin(
            Vec3::new(1e-30, 1.0, 1.0),
            Vec3::new(1e-30, 0.0, 0.0),
            -Vec3::X,
            -Vec3::X,
        );
        assert_eq!(cancelled.x.to_bits(), next_float_down(0.0).to_bits());
        let far = offset_ray_origin(
            Vec3::new(f32::INFINITY, 1.0, 1.0),
            Vec3::ONE,
            Vec3::X,
            Vec3::X,
        );
        assert_eq!(far.x, f32::INFINITY);
    }

    #[test]
    fn offset_scales_with_the_error_bound() {
        // A point far from the origin has a larger error and moves further:
        // no fixed epsilon, so tiny and huge scenes both work.
        let small = offset_ray_origin(
            Vec3::new(1e-4, 0.0, 0.0),
            Vec3::splat(1e-11),
            Vec3::X,
            Vec3::X,
        );
        let large = offset_ray_origin(
            Vec3::new(1e5, 0.0, 0.0),
            Vec3::splat(1e-2),
            Vec3::X,
            Vec3::X,
        );
        assert!(small.x > 1e-4 && small.x - 1e-4 < 1e-9);
        assert!(large.x > 1e5 && large.x - 1e5 < 0.1);
    }

    #[test]
    fn shadow_ray_stops_short_of_its_end() {
        let a = SurfacePoint {
            p: Vec3::ZERO,
            p_error: Vec3::splat(1e-7),
            n: Vec3::Y,
        };
        let b = SurfacePoint {
            p: Vec3::new(0.0, 2.0, 0.0),
            p_error: Vec3::splat(1e-7),
            n: -Vec3::Y,
        };
        let r = a.spawn_ray_to(&b);
        assert!(r.o.y > 0.0);
        assert!(r.at(r.t_max).y < 2.0);
    }

    /// Uniform floats in [0, 1) from a xorshift generator.
    fn uniform_floats(mut state: u64) -> impl FnMut() -> f32 {
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    /// A surface point with a random position, error bound and unit normal.
    fn random_point(next: &mut impl FnMut() -> f32) -> SurfacePoint {
        let p = Vec3::new(next(), next(), next()) * 200.0 - 100.0;
        let n = (Vec3::new(next(), next(), next()) - 0.5).normalize_or(Vec3::Z);
        // Error bounds as the shapes report them, up to coarse ones whose
        // offset is large enough to matter for the side test below.
        let p_error = gamma(7) * p.abs() * (1.0 + 1e4 * next());
        SurfacePoint { p, p_error, n }
    }

    /// The origins worked out once per vertex give exactly the rays of the
    /// one-off `spawn_ray` and `spawn_ray_to`, on either side.
    #[test]
    fn ray_origins_match_one_off_spawns() {
        let mut next = uniform_floats(0x2545_f491_4f6c_dd1d);
        for _ in 0..10_000 {
            let a = random_point(&mut next);
            let b = random_point(&mut next);
            let d = Vec3::new(next(), next(), next()) - 0.5;
            let origins = a.ray_origins();
            assert_eq!(origins.spawn_ray(d), a.spawn_ray(d));
            assert_eq!(origins.spawn_ray(-d), a.spawn_ray(-d));
            assert_eq!(origins.spawn_ray_to(&b), a.spawn_ray_to(&b));
        }
    }

    /// Where the shadow ray's end is offset, it takes its side from the
    /// surface point, where pbrt-v4 takes it from the offset origin: the
    /// same end unless the point lies within its own offset of the plane at
    /// the end.
    #[test]
    fn offset_shadow_ray_ends_match_pbrt_off_the_plane() {
        let mut next = uniform_floats(0x9e37_79b9_7f4a_7c15);
        let (mut offset, mut at_the_point) = (0, 0);
        for _ in 0..10_000 {
            let a = random_point(&mut next);
            let b = random_point(&mut next);
            let from = offset_ray_origin(a.p, a.p_error, a.n, b.p - a.p);
            let height = (a.p - b.p).dot(b.n).abs();
            if height <= 2.0 * (from - a.p).length() {
                continue;
            }
            let r = a.spawn_ray_to(&b);
            assert_eq!(r.o, from);
            if r.d == b.p - from {
                at_the_point += 1;
            } else {
                offset += 1;
                let pbrt_end = offset_ray_origin(b.p, b.p_error, b.n, from - b.p);
                assert_eq!(r.d, pbrt_end - from);
            }
        }
        // random_point's error bounds are mostly too coarse for the end to
        // go without its offset.
        assert!(offset > 5_000, "{offset} offset, {at_the_point} not");
    }

    /// Where a shadow ray ends at the light point itself, its stop (`o +
    /// t_max d`, in f64) lies strictly on its origin's side of the end
    /// surface's plane moved by the end's whole error bound, so it cannot
    /// hit that surface. Over random points with the error bounds shapes
    /// report, points at every height above the end's plane down to 1e-6
    /// of the distance (grazing), and points 1e5 from the origin a unit
    /// apart; the lowest of them take the offset end instead.
    #[test]
    fn shadow_rays_ending_at_the_point_stop_clear_of_its_surface() {
        let mut next = uniform_floats(0x2545_f491_4f6c_dd1d);
        let (mut at_the_point, mut offset) = (0, 0);
        for i in 0..30_000 {
            let mut a = random_point(&mut next);
            let mut b = random_point(&mut next);
            if i % 2 == 1 {
                let shift = Vec3::new(1e5, -1e5, 1e5);
                a.p = a.p * 0.01 + shift;
                b.p = b.p * 0.01 + shift;
            }
            // a at a log-uniform fraction of its height above b's plane.
            let h = (a.p - b.p).dot(b.n);
            a.p -= b.n * (h * (1.0 - 10f32.powf(-6.0 * next())));
            a.p_error = gamma(7) * a.p.abs();
            b.p_error = gamma(6) * b.p.abs();
            let r = a.spawn_ray_to(&b);
            if r.d != b.p - r.o {
                offset += 1;
                continue;
            }
            at_the_point += 1;
            let (o, d, n) = (r.o.as_dvec3(), r.d.as_dvec3(), b.n.as_dvec3());
            let stop = o + d * r.t_max as f64;
            let error = b.n.abs().as_dvec3().dot(b.p_error.as_dvec3());
            let origin_side = n.dot(o - b.p.as_dvec3());
            let stop_side = n.dot(stop - b.p.as_dvec3());
            assert!(
                stop_side.signum() == origin_side.signum() && stop_side.abs() > error,
                "{a:?} -> {b:?}: stop {stop_side:e} from the plane, error {error:e}"
            );
        }
        assert!(
            at_the_point > 2_000 && offset > 3_000,
            "{at_the_point} {offset}"
        );
    }

    /// An ordinary light sample (a unit away, not grazing, ordinary error
    /// bounds) needs no offset: the ray ends at the point itself.
    #[test]
    fn ordinary_shadow_rays_end_at_the_light_point() {
        let a = SurfacePoint {
            p: Vec3::new(0.3, 0.0, -0.2),
            p_error: gamma(7) * Vec3::new(0.3, 0.0, 0.2),
            n: Vec3::Y,
        };
        let light = SurfacePoint {
            p: Vec3::new(0.1, 1.98, 0.05),
            p_error: gamma(6) * Vec3::new(0.1, 1.98, 0.05),
            n: -Vec3::Y,
        };
        let r = a.spawn_ray_to(&light);
        assert_eq!(r.d, light.p - r.o);
        // Seen almost edge-on, the same point is offset.
        let grazing = SurfacePoint {
            p: Vec3::new(0.3, 1.98 - 1e-5, -0.2),
            ..a
        };
        let r = grazing.spawn_ray_to(&light);
        assert!(r.d != light.p - r.o && (r.o + r.d).y < light.p.y);
    }
}
