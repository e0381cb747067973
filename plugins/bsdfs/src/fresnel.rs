//! Fresnel reflectance of smooth interfaces: dielectric, conductor, and the
//! hemispherical average a diffuse layer under a coat sees.

use lumis_api::{Rgb, Vec3};
use lumis_sampling::real::Real;

/// Unpolarised Fresnel reflectance of a dielectric interface (Born and
/// Wolf, section 1.5.2; pbrt-v4 `FrDielectric`). `cos_theta_i` is measured
/// on the side the light comes from; negative means it arrives from inside,
/// where the relative index is `1 / eta`. Total internal reflection gives 1.
pub fn dielectric(cos_theta_i: f32, eta: f32) -> f32 {
    let (cos_i, eta) = if cos_theta_i < 0.0 {
        (-cos_theta_i, 1.0 / eta)
    } else {
        (cos_theta_i, eta)
    };
    let cos_i = cos_i.min(1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let r_parallel = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perpendicular = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parallel * r_parallel + r_perpendicular * r_perpendicular)
}

/// A complex number, only as much as the conductor Fresnel term needs;
/// of one value or of SIMD lanes.
#[derive(Debug, Clone, Copy)]
struct Complex<F> {
    re: F,
    im: F,
}

impl<F: Real> Complex<F> {
    #[inline(always)]
    fn new(re: F, im: F) -> Self {
        Self { re, im }
    }
    #[inline(always)]
    fn real(re: F) -> Self {
        Self::new(re, F::splat(0.0))
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self::new(self.re + o.re, self.im + o.im)
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self::new(self.re - o.re, self.im - o.im)
    }
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Self::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
    #[inline(always)]
    fn scale(self, s: F) -> Self {
        Self::new(self.re * s, self.im * s)
    }
    #[inline(always)]
    fn norm(self) -> F {
        self.re * self.re + self.im * self.im
    }
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        let d = o.norm();
        Self::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
    /// Principal square root, stable for both signs of the real part.
    #[inline(always)]
    fn sqrt(self) -> Self {
        let zero = F::splat(0.0);
        let n = self.norm().sqrt();
        let t1 = (F::splat(0.5) * (n + self.re.abs())).sqrt();
        let t2 = F::splat(0.5) * self.im / t1;
        let right = self.re.ge(zero);
        let root = Self::new(
            F::select(right, t1, t2.abs()),
            F::select(right, t2, t1.copysign(self.im)),
        );
        let origin = n.eq(zero);
        Self::new(
            F::select(origin, zero, root.re),
            F::select(origin, zero, root.im),
        )
    }
}

/// Fresnel reflectance of a conductor with complex index `eta + i k`
/// relative to the outside (pbrt-v4 `FrComplex`, the same two amplitude
/// ratios as the dielectric with a complex eta). `cos_theta_i` in [0, 1].
pub fn conductor_channel(cos_theta_i: f32, eta: f32, k: f32) -> f32 {
    conductor_channel_lanes(cos_theta_i, eta, k)
}

/// [`conductor_channel`] lane by lane: the same operations, so the same
/// bits in each lane.
#[inline]
pub fn conductor_channel_lanes<F: Real>(cos_theta_i: F, eta: f32, k: f32) -> F {
    let s = F::splat;
    let cos_i = cos_theta_i.max(s(0.0)).min(s(1.0));
    let eta = Complex::new(s(eta), s(k));
    let sin2_i = s(1.0) - cos_i * cos_i;
    let sin2_t = Complex::real(sin2_i).div(eta.mul(eta));
    let cos_t = Complex::real(s(1.0)).sub(sin2_t).sqrt();
    let ci = Complex::real(cos_i);
    let r_parallel = eta.scale(cos_i).sub(cos_t).div(eta.scale(cos_i).add(cos_t));
    let r_perpendicular = ci.sub(eta.mul(cos_t)).div(ci.add(eta.mul(cos_t)));
    s(0.5) * (r_parallel.norm() + r_perpendicular.norm())
}

/// Per-channel conductor reflectance.
pub fn conductor(cos_theta_i: f32, eta: Rgb, k: Rgb) -> Rgb {
    Rgb::new(
        conductor_channel(cos_theta_i, eta.r, k.r),
        conductor_channel(cos_theta_i, eta.g, k.g),
        conductor_channel(cos_theta_i, eta.b, k.b),
    )
}

/// Hemispherical average of the dielectric reflectance for light arriving
/// uniformly (cosine-weighted) from the side where the relative index is
/// `eta`: `2 int_0^1 F(mu) mu dmu`, by 256-point midpoint quadrature in
/// `mu^2` (exact enough: F is smooth in mu^2 except at the critical angle,
/// where it is continuous). Used once per material, not per sample.
pub fn diffuse_reflectance(eta: f32) -> f32 {
    const N: usize = 4096;
    let mut sum = 0.0f64;
    for i in 0..N {
        // With s = mu^2, 2 mu dmu = ds: a uniform grid in s.
        let s = (i as f64 + 0.5) / N as f64;
        sum += dielectric(s.sqrt() as f32, eta) as f64;
    }
    (sum / N as f64) as f32
}

/// Mirror reflection of `wo` about the normal `n` (both unit, same side).
#[inline]
pub fn reflect(wo: Vec3, n: Vec3) -> Vec3 {
    -wo + 2.0 * wo.dot(n) * n
}

/// Refraction of `wo` through an interface with normal `n` and relative
/// index `eta` (inside over outside). Returns the refracted direction and
/// the relative index along it (`eta` entering, `1/eta` leaving), or `None`
/// on total internal reflection (pbrt-v4 `Refract`).
#[inline]
pub fn refract(wo: Vec3, n: Vec3, eta: f32) -> Option<(Vec3, f32)> {
    let mut cos_i = n.dot(wo);
    let (mut n, mut eta) = (n, eta);
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
        n = -n;
    }
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-wo / eta + (cos_i / eta - cos_t) * n, eta))
}

/// A named metal: complex index of refraction at 650, 550 and 450 nm for
/// the R, G and B channels (refractiveindex.info data as tabulated by
/// Chaos Group, "Understanding metalness", 2017).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Metal {
    pub name: &'static str,
    pub eta: [f32; 3],
    pub k: [f32; 3],
}

pub const METALS: &[Metal] = &[
    Metal {
        name: "Ag",
        eta: [0.15943, 0.14512, 0.13547],
        k: [3.9291, 3.19, 2.3808],
    },
    Metal {
        name: "Al",
        eta: [1.3456, 0.96521, 0.61722],
        k: [7.4746, 6.3995, 5.3031],
    },
    Metal {
        name: "Au",
        eta: [0.18299, 0.42108, 1.3734],
        k: [3.4242, 2.3459, 1.7704],
    },
    Metal {
        name: "Cr",
        eta: [3.1071, 3.1812, 2.323],
        k: [3.3314, 3.3291, 3.135],
    },
    Metal {
        name: "Cu",
        eta: [0.27105, 0.67693, 1.3164],
        k: [3.6092, 2.6248, 2.2921],
    },
    Metal {
        name: "Fe",
        eta: [2.9114, 2.9497, 2.5845],
        k: [3.0893, 2.9318, 2.767],
    },
    Metal {
        name: "Pt",
        eta: [2.3757, 2.0847, 1.8453],
        k: [4.2655, 3.7153, 3.1365],
    },
];

/// The metal called `name`, if lumis knows it.
pub fn metal(name: &str) -> Option<&'static Metal> {
    METALS.iter().find(|m| m.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dielectric_normal_incidence_and_total_internal_reflection() {
        // ((eta - 1) / (eta + 1))^2 at normal incidence, from either side.
        let r0 = (0.5f32 / 2.5).powi(2);
        assert!((dielectric(1.0, 1.5) - r0).abs() < 1e-6);
        assert!((dielectric(-1.0, 1.5) - r0).abs() < 1e-6);
        assert_eq!(dielectric(1.0, 1.0), 0.0);
        assert_eq!(dielectric(0.0, 1.5), 1.0, "grazing reflects everything");
        // From inside glass, beyond the critical angle asin(1/1.5) = 41.8 deg.
        assert_eq!(dielectric(-0.7, 1.5), 1.0);
        assert!(dielectric(-0.8, 1.5) < 1.0);
    }

    #[test]
    fn conductor_with_zero_absorption_is_the_dielectric() {
        for c in [0.01f32, 0.3, 0.7, 1.0] {
            let a = conductor_channel(c, 1.5, 0.0);
            let b = dielectric(c, 1.5);
            assert!((a - b).abs() < 1e-5, "cos {c}: {a} vs {b}");
        }
    }

    #[test]
    fn conductor_normal_incidence_closed_form() {
        // |(eta + ik - 1) / (eta + ik + 1)|^2.
        for m in METALS {
            for c in 0..3 {
                let (n, k) = (m.eta[c], m.k[c]);
                let want = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
                let got = conductor_channel(1.0, n, k);
                assert!((got - want).abs() < 1e-5, "{} {c}: {got} vs {want}", m.name);
                assert!(conductor_channel(1e-4, n, k) > 0.99, "grazing is a mirror");
            }
        }
        let gold = metal("Au").unwrap();
        let f = conductor(1.0, gold.eta.into(), gold.k.into());
        assert!(f.r > f.g && f.g > f.b, "gold is yellow: {f:?}");
    }

    /// On SIMD lanes the conductor term is the scalar one bit for bit,
    /// for every metal, at cosines from beyond both ends of [0, 1] to
    /// grazing and normal incidence, and with no absorption (where the
    /// square root's argument changes sign).
    #[test]
    fn conductor_lanes_are_the_scalar_bit_for_bit() {
        use lumis_sampling::real::F32x8;
        let cosines: Vec<f32> = [-0.5, 0.0, 1e-6, 1e-4, 1.0, 1.5]
            .into_iter()
            .chain((0..1000).map(|i| i as f32 / 999.0))
            .collect();
        let mut indices: Vec<(f32, f32)> = METALS
            .iter()
            .flat_map(|m| (0..3).map(|c| (m.eta[c], m.k[c])))
            .collect();
        indices.extend([(1.5, 0.0), (0.5, 0.0), (1.0, 0.0)]);
        for (eta, k) in indices {
            for chunk in cosines.chunks(8) {
                let lanes = F32x8::from_fn(|i| chunk[i % chunk.len()]);
                let lanes = conductor_channel_lanes(lanes, eta, k);
                for (i, &c) in chunk.iter().enumerate() {
                    assert_eq!(
                        lanes.lane(i).to_bits(),
                        conductor_channel(c, eta, k).to_bits(),
                        "eta {eta} k {k} cos {c}"
                    );
                }
            }
        }
    }

    #[test]
    fn refraction_obeys_snell_and_reverses() {
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let (wt, eta) = refract(wo, Vec3::Z, 1.5).unwrap();
        assert_eq!(eta, 1.5);
        assert!((wt.length() - 1.0).abs() < 1e-6 && wt.z < 0.0);
        // sin theta_t = sin theta_i / eta.
        assert!((wt.x.abs() - 0.6 / 1.5).abs() < 1e-6);
        let (back, eta_back) = refract(wt, Vec3::Z, 1.5).unwrap();
        assert!((back - wo).length() < 1e-6 && eta_back == 1.0 / 1.5);
        assert!(refract(Vec3::new(0.8, 0.0, -0.6), Vec3::Z, 1.5).is_none());
    }

    #[test]
    fn diffuse_reflectance_matches_published_values() {
        // Light from outside onto glass, eta = 1.5: about 0.092 (the
        // hemispherical average); from inside it adds the total internal
        // reflection, 1 - (1 - 0.092) / 1.5^2 = 0.596.
        let outside = diffuse_reflectance(1.5);
        assert!((outside - 0.0918).abs() < 2e-3, "{outside}");
        let inside = diffuse_reflectance(1.0 / 1.5);
        let want = 1.0 - (1.0 - outside) / 2.25;
        assert!((inside - want).abs() < 1e-3, "{inside} vs {want}");
    }
}
