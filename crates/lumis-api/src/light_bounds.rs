//! Bounds on where a light is and which way it emits, so that a light
//! sampler can estimate from a shading point how much a group of lights may
//! contribute there without looking at each one (pbrt-v4 `LightBounds`,
//! section 12.6.3; Conty Estevez and Kulla 2018, "Importance Sampling of
//! Many Lights with Adaptive Tree Splitting").

use std::f32::consts::PI;

use glam::{Quat, Vec3};

/// An axis-aligned box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    /// The box holding nothing: the identity of [`Aabb::union`].
    pub const EMPTY: Self = Self {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    /// The box of one point.
    pub fn point(p: Vec3) -> Self {
        Self { min: p, max: p }
    }

    /// The smallest box holding all `points`.
    pub fn of_points(points: impl IntoIterator<Item = Vec3>) -> Self {
        points
            .into_iter()
            .fold(Self::EMPTY, |b, p| b.union(Self::point(p)))
    }

    pub fn union(self, other: Self) -> Self {
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    pub fn center(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }

    pub fn diagonal(&self) -> Vec3 {
        self.max - self.min
    }

    pub fn surface_area(&self) -> f32 {
        let d = self.diagonal();
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }
}

/// A cone of directions: every `w'` with `w . w' >= cos_theta` (pbrt-v4
/// `DirectionCone`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirectionCone {
    /// Unit axis.
    pub w: Vec3,
    pub cos_theta: f32,
}

impl DirectionCone {
    /// Every direction.
    pub const SPHERE: Self = Self {
        w: Vec3::Z,
        cos_theta: -1.0,
    };

    /// The smallest cone (about the bisecting axis) holding both cones
    /// (pbrt-v4 `Union(DirectionCone, DirectionCone)`).
    pub fn union(self, other: Self) -> Self {
        let (theta_a, theta_b) = (safe_acos(self.cos_theta), safe_acos(other.cos_theta));
        let theta_d = angle_between(self.w, other.w);
        if (theta_d + theta_b).min(PI) <= theta_a {
            return self;
        }
        if (theta_d + theta_a).min(PI) <= theta_b {
            return other;
        }
        let theta_o = 0.5 * (theta_a + theta_d + theta_b);
        if theta_o >= PI {
            return Self::SPHERE;
        }
        // Rotate `self.w` toward `other.w` until the cone touches both.
        let Some(axis) = self.w.cross(other.w).try_normalize() else {
            return Self::SPHERE;
        };
        let w = Quat::from_axis_angle(axis, theta_o - theta_a) * self.w;
        Self {
            w: w.normalize(),
            cos_theta: theta_o.cos(),
        }
    }

    /// The directions from `p` toward the box `b`, bounded by its
    /// bounding sphere; all of them from inside that sphere (pbrt-v4
    /// `BoundSubtendedDirections`).
    pub fn subtended_by(b: &Aabb, p: Vec3) -> Self {
        let center = b.center();
        let radius2 = (0.25 * b.diagonal().length_squared()).max(0.0);
        let dist2 = p.distance_squared(center);
        match (center - p).try_normalize() {
            Some(w) if dist2 >= radius2 => Self {
                w,
                cos_theta: (1.0 - radius2 / dist2).max(0.0).sqrt(),
            },
            // Inside the sphere, or exactly at a point light.
            _ => Self::SPHERE,
        }
    }
}

/// `acos` of a cosine clamped to `[-1, 1]`.
fn safe_acos(c: f32) -> f32 {
    c.clamp(-1.0, 1.0).acos()
}

/// The angle between unit vectors, accurate near 0 and pi (pbrt-v4
/// `AngleBetween`).
fn angle_between(a: Vec3, b: Vec3) -> f32 {
    if a.dot(b) < 0.0 {
        PI - 2.0 * safe_asin(0.5 * (a + b).length())
    } else {
        2.0 * safe_asin(0.5 * (b - a).length())
    }
}

fn safe_asin(s: f32) -> f32 {
    s.clamp(-1.0, 1.0).asin()
}

/// Where a light (or a group of lights) is, which way it emits and how
/// much: every emitting point lies in `bounds`, every surface normal within
/// `theta_o` of `w`, and light leaves each point only within `theta_e` of
/// its normal (pi/2 for a Lambertian surface).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightBounds {
    pub bounds: Aabb,
    /// Unit axis of the normals' cone.
    pub w: Vec3,
    /// Emitted power (a scalar, as the light sampler weighs it).
    pub phi: f32,
    /// `cos theta_o`: the spread of the normals about `w`.
    pub cos_theta_o: f32,
    /// `cos theta_e`: how far from its normal a point emits.
    pub cos_theta_e: f32,
    /// Whether the surfaces also emit on their back side.
    pub two_sided: bool,
}

/// Importances at or above this count as this, so that the sum of two
/// children stays finite (only a point exactly on a point light reaches it).
const MAX_IMPORTANCE: f32 = 1e30;

impl LightBounds {
    /// No light: the identity of [`LightBounds::union`].
    pub const EMPTY: Self = Self {
        bounds: Aabb::EMPTY,
        w: Vec3::Z,
        phi: 0.0,
        cos_theta_o: 1.0,
        cos_theta_e: 1.0,
        two_sided: false,
    };

    /// A point emitting `phi` equally in every direction.
    pub fn isotropic_point(p: Vec3, phi: f32) -> Self {
        Self {
            bounds: Aabb::point(p),
            w: Vec3::Z,
            phi,
            cos_theta_o: -1.0,
            cos_theta_e: 0.0,
            two_sided: false,
        }
    }

    /// A flat Lambertian emitter of normal `n` (front side).
    pub fn planar(bounds: Aabb, n: Vec3, phi: f32, two_sided: bool) -> Self {
        Self {
            bounds,
            w: n,
            phi,
            cos_theta_o: 1.0,
            cos_theta_e: 0.0,
            two_sided,
        }
    }

    /// Bounds of both groups; a group of zero power adds nothing.
    pub fn union(self, other: Self) -> Self {
        if self.phi == 0.0 {
            return other;
        }
        if other.phi == 0.0 {
            return self;
        }
        let cone = DirectionCone {
            w: self.w,
            cos_theta: self.cos_theta_o,
        }
        .union(DirectionCone {
            w: other.w,
            cos_theta: other.cos_theta_o,
        });
        Self {
            bounds: self.bounds.union(other.bounds),
            w: cone.w,
            phi: self.phi + other.phi,
            cos_theta_o: cone.cos_theta,
            cos_theta_e: self.cos_theta_e.min(other.cos_theta_e),
            two_sided: self.two_sided || other.two_sided,
        }
    }

    /// An upper-bound-like estimate of what the lights contribute at `p`
    /// on a surface of normal `n` (zero `n`: a point in space): power over
    /// the (clamped) squared distance, times the cosine of the smallest
    /// angle at which any bounded point can emit toward `p`, and, on a
    /// surface, the cosine of the smallest incident angle. Zero only where
    /// no light in the bounds can reach `p` (pbrt-v4
    /// `LightBounds::Importance`, eq. 12.6).
    #[inline]
    pub fn importance(&self, p: Vec3, n: Vec3) -> f32 {
        if self.phi <= 0.0 {
            return 0.0;
        }
        let pc = self.bounds.center();
        // The bounding sphere's radius squared: the half diagonal's.
        let radius2 = 0.25 * self.bounds.diagonal().length_squared();
        let to_p = p - pc;
        let dist2 = to_p.length_squared();
        // Clamped to the half diagonal, so that points inside or near the
        // bounds are not given an unbounded importance.
        let d2 = dist2.max(radius2);
        // theta_b: the half-angle of the cone from `p` holding the bounding
        // sphere (`DirectionCone::subtended_by`, here sharing its distance),
        // and `wi` from the centre toward `p`. Inside the sphere the cone is
        // every direction and `wi` is unused but by the cosine at a surface,
        // which the whole-sphere theta_b clamps to 1.
        let (cos_b, sin_b, wi) = if dist2 >= radius2 && dist2 > 0.0 {
            let sin2_b = radius2 / dist2;
            let wi = to_p * dist2.sqrt().recip();
            ((1.0 - sin2_b).max(0.0).sqrt(), sin2_b.sqrt(), wi)
        } else {
            (-1.0, 0.0, Vec3::Z)
        };
        let mut cos_w = self.w.dot(wi);
        if self.two_sided {
            cos_w = cos_w.abs();
        }
        // theta' = max(0, theta_w - theta_o - theta_b), as cosines; 1 (and
        // no sines needed) where `p` lies within the normals' cone.
        let cos_o = self.cos_theta_o;
        let cos_p = if cos_w > cos_o {
            1.0
        } else {
            let (sin_w, sin_o) = (sin_of(cos_w), sin_of(cos_o));
            let cos_x = cos_w * cos_o + sin_w * sin_o;
            let sin_x = sin_w * cos_o - cos_w * sin_o;
            cos_sub_clamped(sin_x, cos_x, sin_b, cos_b)
        };
        if cos_p <= self.cos_theta_e {
            return 0.0;
        }
        let mut importance = self.phi * cos_p / d2;
        if n != Vec3::ZERO {
            // theta_i' = max(0, theta_i - theta_b).
            let cos_i = n.dot(wi).abs();
            if cos_i <= cos_b {
                importance *= cos_i * cos_b + sin_of(cos_i) * sin_b;
            }
        }
        if importance.is_nan() {
            return 0.0;
        }
        importance.clamp(0.0, MAX_IMPORTANCE)
    }
}

#[inline]
fn sin_of(cos: f32) -> f32 {
    (1.0 - cos * cos).max(0.0).sqrt()
}

/// `cos(max(0, a - b))` from the sines and cosines of `a` and `b`.
fn cos_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        1.0
    } else {
        cos_a * cos_b + sin_a * sin_b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_sided_emitters_are_dark_from_behind() {
        let b = LightBounds::planar(
            Aabb::of_points([Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 0.0, 1.0)]),
            Vec3::Y,
            1.0,
            false,
        );
        assert!(b.importance(Vec3::new(0.0, 2.0, 0.0), Vec3::ZERO) > 0.0);
        assert_eq!(b.importance(Vec3::new(0.0, -2.0, 0.0), Vec3::ZERO), 0.0);
        let two_sided = LightBounds {
            two_sided: true,
            ..b
        };
        assert!(two_sided.importance(Vec3::new(0.0, -2.0, 0.0), Vec3::ZERO) > 0.0);
    }

    #[test]
    fn a_union_reaches_wherever_its_parts_do() {
        let a = LightBounds::planar(Aabb::point(Vec3::X), Vec3::Y, 2.0, false);
        let b = LightBounds::planar(Aabb::point(-Vec3::X), -Vec3::Y, 1.0, false);
        let u = a.union(b);
        for p in [
            Vec3::new(0.3, 2.0, 0.1),
            Vec3::new(-2.0, -1.0, 0.5),
            Vec3::ZERO,
        ] {
            for n in [Vec3::ZERO, Vec3::Y, Vec3::X] {
                let (ia, ib, iu) = (a.importance(p, n), b.importance(p, n), u.importance(p, n));
                assert!(iu.is_finite() && (iu > 0.0 || ia.max(ib) == 0.0), "{p} {n}");
            }
        }
    }

    #[test]
    fn a_point_light_seen_from_itself_stays_finite() {
        let b = LightBounds::isotropic_point(Vec3::ONE, 4.0);
        let i = b.importance(Vec3::ONE, Vec3::Y);
        assert!(i.is_finite() && i > 0.0);
    }

    #[test]
    fn cone_union_holds_both_axes() {
        let a = DirectionCone {
            w: Vec3::X,
            cos_theta: 1.0,
        };
        let b = DirectionCone {
            w: Vec3::Y,
            cos_theta: 1.0,
        };
        let u = a.union(b);
        assert!(u.w.dot(Vec3::X) >= u.cos_theta - 1e-5);
        assert!(u.w.dot(Vec3::Y) >= u.cos_theta - 1e-5);
        assert!((u.cos_theta - (PI / 4.0).cos()).abs() < 1e-5);
    }
}
