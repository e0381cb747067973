//! Lights at the edges of their domain: a tiny sphere very far away, a quad
//! seen edge-on, shading points on the light, and both sides of the
//! solid-angle/area switch of triangles. Nothing may be NaN or infinite, and
//! where a sample is valid its density is finite, positive and what
//! `pdf_li` reports.

use lumis_core::{Light, LightSampleContext, Rgb, Vec2, Vec3};
use lumis_lights::{Emission, QuadLight, Sampling, SphereLight, TriangleLight};
use lumis_sampling::{Pcg32, SphericalTriangle, MIN_SPHERICAL_SAMPLE_AREA};

fn emission(two_sided: bool) -> Emission {
    Emission {
        radiance: Rgb::splat(3.0),
        two_sided,
    }
}

/// Draws `n` samples from `ctx`; every returned sample must be finite with a
/// positive density; returns them.
fn samples(light: &dyn Light, ctx: &LightSampleContext, n: usize) -> Vec<lumis_core::LightSample> {
    let mut rng = Pcg32::new(42, 7);
    let mut out = Vec::new();
    for _ in 0..n {
        let u = Vec2::new(rng.next_f32(), rng.next_f32());
        if let Some(s) = light.sample_li(ctx, u) {
            assert!(s.pdf.is_finite() && s.pdf > 0.0, "pdf {}", s.pdf);
            assert!(s.l.is_finite() && s.l.min_component() >= 0.0, "{:?}", s.l);
            assert!(
                s.wi.is_finite() && (s.wi.length() - 1.0).abs() < 1e-5,
                "{}",
                s.wi
            );
            assert!(s.p.p.is_finite() && s.p.p_error.is_finite());
            out.push(s);
        }
    }
    out
}

#[test]
fn tiny_sphere_very_far_away() {
    // Radius 1e-4 at distance 1e4: sin^2 theta_max = 1e-16, so 1 - cos
    // theta_max is 0 in f32 by the naive formula and the pdf would be inf.
    let center = Vec3::new(0.0, 1e4, 0.0);
    let light = SphereLight::new(center, 1e-4, false, emission(false)).unwrap();
    let ctx = LightSampleContext::at(Vec3::ZERO);
    assert!(light.samples_cone_from(ctx.p()));
    let expected = 1.0 / (std::f64::consts::PI * 1e-16); // 1 / (pi (r/d)^2)
    let drawn = samples(&light, &ctx, 1000);
    assert_eq!(drawn.len(), 1000, "every cone sample is valid");
    for s in &drawn {
        assert!((s.pdf as f64 / expected - 1.0).abs() < 1e-4, "{}", s.pdf);
        // The point is built from the centre, so it is on the sphere to
        // the sphere's own scale, not to the distance's.
        let r = (s.p.p - center).length();
        assert!((r - 1e-4).abs() < 2e-3 * 1e-4 + s.p.p_error.length(), "{r}");
        assert!(s.wi.y > 0.999_999);
    }
    // pdf_li along the axis is the same cone density; far off it, zero.
    let on_axis = light.pdf_li(&ctx, Vec3::Y);
    assert!((on_axis as f64 / expected - 1.0).abs() < 1e-4, "{on_axis}");
    assert_eq!(light.pdf_li(&ctx, Vec3::new(1e-3, 1.0, 0.0)), 0.0);
    // Area sampling of the same sphere: half its surface is hidden.
    let area = light.clone().with_sampling(Sampling::Area);
    let drawn = samples(&area, &ctx, 1000);
    assert!((300..700).contains(&drawn.len()), "{}", drawn.len());
    assert!(area.pdf_li(&ctx, Vec3::Y).is_finite());
}

#[test]
fn quad_seen_edge_on() {
    for sampling in [Sampling::Area, Sampling::SolidAngle] {
        for two_sided in [false, true] {
            let light = QuadLight::new(
                Vec3::new(-0.5, 1.0, -0.5),
                Vec3::X,
                Vec3::Z,
                emission(two_sided),
            )
            .unwrap()
            .with_sampling(sampling);
            // In the quad's plane, beside it: zero solid angle.
            let ctx = LightSampleContext::at(Vec3::new(3.0, 1.0, 0.0));
            assert!(!light.samples_solid_angle_from(ctx.p()));
            let drawn = samples(&light, &ctx, 1000);
            assert!(drawn.len() < 10, "{sampling:?}: {}", drawn.len());
            for w in [
                Vec3::new(-1.0, 0.0, 0.0),
                Vec3::new(-1.0, 1e-7, 0.0),
                Vec3::Y,
            ] {
                let pdf = light.pdf_li(&ctx, w);
                assert!(pdf.is_finite() && pdf >= 0.0, "{sampling:?} {w}: {pdf}");
            }
            // A hair below the plane: valid samples, finite densities that
            // pdf_li confirms.
            let ctx = LightSampleContext::at(Vec3::new(3.0, 1.0 - 1e-5, 0.0));
            for s in samples(&light, &ctx, 1000) {
                let pdf = light.pdf_li(&ctx, s.wi);
                assert!(pdf.is_finite(), "{sampling:?}: {pdf}");
            }
        }
    }
}

#[test]
fn shading_point_on_the_light() {
    let quad =
        QuadLight::new(Vec3::new(-0.5, 1.0, -0.5), Vec3::X, Vec3::Z, emission(true)).unwrap();
    let tri = TriangleLight::new(
        [
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 1.0),
        ],
        emission(true),
    )
    .unwrap();
    for sampling in [Sampling::Area, Sampling::SolidAngle] {
        let lights: [(&str, Box<dyn Light>, Vec3); 3] = [
            (
                "quad centre",
                Box::new(quad.clone().with_sampling(sampling)),
                Vec3::new(0.0, 1.0, 0.0),
            ),
            (
                "triangle vertex",
                Box::new(tri.clone().with_sampling(sampling)),
                Vec3::new(0.0, 1.0, 0.0),
            ),
            (
                "triangle inside",
                Box::new(tri.clone().with_sampling(sampling)),
                Vec3::new(0.2, 1.0, 0.2),
            ),
        ];
        for (name, light, p) in &lights {
            let ctx = LightSampleContext::at(*p);
            // Every point of a flat light is seen edge-on from itself.
            let drawn = samples(light.as_ref(), &ctx, 1000);
            assert!(drawn.len() < 10, "{name} {sampling:?}: {}", drawn.len());
            for w in [Vec3::Y, -Vec3::Y, Vec3::X] {
                let pdf = light.pdf_li(&ctx, w);
                assert!(pdf.is_finite() && pdf >= 0.0, "{name}: {pdf}");
            }
        }
    }
    // On a sphere: an outward emitter cannot light its own surface; an
    // inward one (a dome) lights it with finite, consistent densities.
    let c = Vec3::new(0.0, 1.0, 0.0);
    let p = c + Vec3::new(0.6, -0.8, 0.0) * 0.3;
    let ctx = LightSampleContext::at(p);
    let outward = SphereLight::new(c, 0.3, false, emission(false)).unwrap();
    assert!(samples(&outward, &ctx, 1000).is_empty());
    let inward = SphereLight::new(c, 0.3, true, emission(false)).unwrap();
    assert!(!inward.samples_cone_from(p));
    let drawn = samples(&inward, &ctx, 1000);
    assert!(drawn.len() > 990, "{}", drawn.len());
    for s in &drawn {
        let pdf = inward.pdf_li(&ctx, s.wi);
        // From a point on a sphere, area sampling has density cos / pi
        // (Shirley et al. 1996): at most 1/pi.
        assert!(s.pdf <= 1.001 / std::f32::consts::PI, "{}", s.pdf);
        assert!(
            (pdf - s.pdf).abs() <= 1e-2 * s.pdf + 1e-6,
            "{} vs {pdf}",
            s.pdf
        );
    }
}

/// Estimates the solid angle as `E[1/pdf]` over `n` samples, with its
/// standard error.
fn solid_angle_estimate(light: &dyn Light, ctx: &LightSampleContext, n: usize) -> (f64, f64) {
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for s in samples(light, ctx, n) {
        let w = 1.0 / s.pdf as f64;
        sum += w;
        sum2 += w * w;
    }
    let mean = sum / n as f64;
    (
        mean,
        ((sum2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt(),
    )
}

#[test]
fn triangle_switches_to_area_sampling_below_the_threshold() {
    // A unit right triangle facing -y; from straight below at distance h it
    // subtends about 0.5 / h^2. Find distances just above and below the
    // switch by bisection on the exact solid angle.
    let tri = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
    ];
    let omega_at = |h: f32| {
        SphericalTriangle::new(tri, Vec3::new(0.3, -h, 0.3))
            .unwrap()
            .solid_angle() as f32
    };
    let (mut lo, mut hi) = (1.0f32, 1e3f32);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if omega_at(mid) > MIN_SPHERICAL_SAMPLE_AREA {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let light = TriangleLight::new(tri, emission(false))
        .unwrap()
        .with_sampling(Sampling::SolidAngle);
    for (side, h, spherical) in [("above", lo * 0.99, true), ("below", hi * 1.01, false)] {
        let ctx = LightSampleContext::at(Vec3::new(0.3, -h, 0.3));
        assert_eq!(light.samples_solid_angle_from(ctx.p()), spherical, "{side}");
        let omega = omega_at(h) as f64;
        let n = 200_000;
        let drawn = samples(&light, &ctx, n);
        assert_eq!(drawn.len(), n, "{side}");
        for s in drawn.iter().take(2000) {
            let pdf = light.pdf_li(&ctx, s.wi);
            assert!(
                (pdf - s.pdf).abs() <= 1e-3 * s.pdf,
                "{side}: {} vs {pdf}",
                s.pdf
            );
            if spherical {
                assert_eq!(s.pdf, (1.0 / omega) as f32, "{side}: uniform density");
            }
        }
        // Either way the samples cover exactly the solid angle.
        let (mean, se) = solid_angle_estimate(&light, &ctx, n);
        assert!(
            (mean - omega).abs() <= 5.0 * se + 1e-4 * omega,
            "{side}: {mean} +- {se} vs {omega}"
        );
    }
}

#[test]
fn huge_triangle_from_close_by_falls_back_to_area() {
    // 1e-3 below the middle of a 100-unit triangle: nearly a hemisphere
    // (> 6.22 sr), where the spherical construction is ill-conditioned.
    let tri = [
        Vec3::new(-50.0, 0.0, -50.0),
        Vec3::new(-50.0, 0.0, 100.0),
        Vec3::new(100.0, 0.0, -50.0),
    ];
    let light = TriangleLight::new(tri, emission(false))
        .unwrap()
        .with_sampling(Sampling::SolidAngle);
    let ctx = LightSampleContext::at(Vec3::new(0.0, -1e-3, 0.0));
    assert!(!light.samples_solid_angle_from(ctx.p()));
    let near = LightSampleContext::at(Vec3::new(0.0, -10.0, 0.0));
    assert!(light.samples_solid_angle_from(near.p()));
    for s in samples(&light, &ctx, 1000) {
        assert!(light.pdf_li(&ctx, s.wi).is_finite());
    }
}
