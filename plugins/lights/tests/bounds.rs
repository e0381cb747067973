//! Every built-in light's [`LightBounds`] hold what it emits: the points it
//! samples lie in the box, and from any point where the bounds' importance
//! is zero the light sends nothing (else a light sampler that trusts the
//! bounds would never pick a light that matters).

use lumis_core::{Light, LightSampleContext, Rgb, Vec2, Vec3};
use lumis_lights::{
    ConstantLight, Emission, PointLight, QuadLight, Sampling, SphereLight, SpotLight, TriangleLight,
};
use lumis_sampling::{warp, Pcg32};

fn emission(two_sided: bool) -> Emission {
    Emission {
        radiance: Rgb::splat(3.0),
        two_sided,
    }
}

fn lights() -> Vec<(&'static str, Box<dyn Light>)> {
    let quad = |two_sided| {
        QuadLight::new(
            Vec3::new(-0.5, 1.0, -0.5),
            Vec3::new(1.0, 0.2, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
            emission(two_sided),
        )
        .unwrap()
    };
    let triangle = TriangleLight::new(
        [
            Vec3::ZERO,
            Vec3::new(1.0, 0.0, 0.3),
            Vec3::new(0.0, 1.0, 0.5),
        ],
        emission(false),
    )
    .unwrap();
    let sphere = SphereLight::new(Vec3::new(0.3, -0.2, 0.1), 0.4, false, emission(false)).unwrap();
    vec![
        ("one-sided quad", Box::new(quad(false))),
        ("two-sided quad", Box::new(quad(true))),
        (
            "one-sided quad, solid angle",
            Box::new(quad(false).with_sampling(Sampling::SolidAngle)),
        ),
        ("triangle", Box::new(triangle)),
        ("sphere", Box::new(sphere)),
        (
            "point",
            Box::new(PointLight::new(Vec3::new(0.2, 0.3, -0.1), Rgb::splat(2.0))),
        ),
        (
            "spot",
            Box::new(
                SpotLight::new(
                    Vec3::Y,
                    Vec3::new(0.3, 0.0, 0.0),
                    Rgb::splat(5.0),
                    35.0,
                    20.0,
                )
                .unwrap(),
            ),
        ),
    ]
}

#[test]
fn bounds_hold_the_samples_and_zero_importance_means_dark() {
    let mut rng = Pcg32::new(5, 11);
    for (name, light) in lights() {
        let b = light
            .bounds()
            .unwrap_or_else(|| panic!("{name}: no bounds"));
        assert!(b.phi > 0.0 && b.phi.is_finite(), "{name}");
        let slack = 1e-4 * (1.0 + b.bounds.diagonal().length());
        let (mut dark, mut lit) = (0, 0);
        for i in 0..400 {
            let scale = if i % 4 == 0 { 20.0 } else { 3.0 };
            let u3 = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
            let p = scale * (2.0 * u3 - Vec3::ONE);
            let n = if i % 2 == 0 {
                warp::square_to_uniform_sphere(Vec2::new(rng.next_f32(), rng.next_f32()))
            } else {
                Vec3::ZERO
            };
            let mut ctx = LightSampleContext::at(p);
            ctx.ns = n;
            let importance = b.importance(p, n);
            assert!(
                importance.is_finite() && importance >= 0.0,
                "{name}: {importance}"
            );
            for k in 0..16 {
                let u = Vec2::new((k % 4) as f32 + 0.5, (k / 4) as f32 + 0.5) / 4.0;
                let Some(s) = light.sample_li(&ctx, u) else {
                    continue;
                };
                let q = s.p.p;
                assert!(
                    q.cmpge(b.bounds.min - slack).all() && q.cmple(b.bounds.max + slack).all(),
                    "{name}: sampled {q} outside {:?}",
                    b.bounds
                );
                if !s.l.is_black() {
                    assert!(
                        importance > 0.0,
                        "{name}: dark bounds from {p} (n {n}) but radiance {:?}",
                        s.l
                    );
                }
            }
            if importance == 0.0 {
                dark += 1;
            } else {
                lit += 1;
            }
        }
        // Each light is seen from somewhere; the one-sided ones and the
        // spot are dark from somewhere too.
        assert!(lit > 0, "{name}");
        if name.starts_with("one-sided") || name == "triangle" || name == "spot" {
            assert!(dark > 0, "{name}: the bounds never rule anything out");
        }
    }
}

#[test]
fn environments_have_no_bounds() {
    assert!(ConstantLight::new(Rgb::WHITE).bounds().is_none());
}
