//! A furnace: from inside a sphere whose wall reflects a fraction `a` of
//! the light (Lambertian) and emits radiance `Le`, every path of `n`
//! segments sees `Le (1 + a + ... + a^(n-1))`. With cosine-weighted BSDF
//! sampling each path's estimate is exactly that (`f cos / pdf = a`), so
//! the test checks the path throughput and the depth count, sample by
//! sample.

use std::f32::consts::FRAC_1_PI;

use lumis_core::ray::SurfacePoint;
use lumis_core::{
    Bsdf, BsdfContext, BsdfFlags, BsdfSample, Frame, Integrator, Light, LightIndex, LightKind,
    LightSample, LightSampleContext, LightSampler, PluginKind, Ray, Registry, RenderStats, Rgb,
    SampledLight, Sampler, Scene, SurfaceInteraction, TextureQuery, UVec2, Vec2, Vec3,
};
use lumis_sampling::{warp, Pcg32};

use {{lib}}::BsdfPathTracer;

/// The wall's Lambertian reflection, sampled by cosine.
struct Wall {
    albedo: Rgb,
}

impl Bsdf for Wall {
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::DIFFUSE_REFLECTION
    }

    fn f(&self, _ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z > 0.0 && wi.z > 0.0 {
            self.albedo * FRAC_1_PI
        } else {
            Rgb::BLACK
        }
    }

    fn sample_f(&self, ctx: &BsdfContext, wo: Vec3, _u1: f32, u2: Vec2) -> Option<BsdfSample> {
        let wi = warp::square_to_cosine_hemisphere(u2);
        (wo.z > 0.0 && wi.z > 0.0).then(|| BsdfSample {
            f: self.f(ctx, wo, wi),
            wi,
            pdf: self.pdf(ctx, wo, wi),
            flags: BsdfFlags::DIFFUSE_REFLECTION,
            eta: 1.0,
        })
    }

    fn pdf(&self, _ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z > 0.0 && wi.z > 0.0 {
            warp::cosine_hemisphere_pdf(wi.z)
        } else {
            0.0
        }
    }
}

/// The wall's emission, toward the inside.
struct Glow {
    radiance: Rgb,
}

impl Light for Glow {
    fn kind(&self) -> LightKind {
        LightKind::Area
    }

    fn sample_li(&self, _ctx: &LightSampleContext, _u: Vec2) -> Option<LightSample> {
        None
    }

    fn pdf_li(&self, _ctx: &LightSampleContext, _wi: Vec3) -> f32 {
        0.0
    }

    fn l(&self, _p: Vec3, n: Vec3, _uv: Vec2, w: Vec3) -> Rgb {
        if n.dot(w) > 0.0 {
            self.radiance
        } else {
            Rgb::BLACK
        }
    }

    fn power(&self) -> Rgb {
        self.radiance * (4.0 * std::f32::consts::PI * std::f32::consts::PI)
    }
}

struct OnlyLight;

impl LightSampler for OnlyLight {
    fn sample(&self, _ctx: &LightSampleContext, _u: f32) -> Option<SampledLight> {
        Some(SampledLight { index: 0, pmf: 1.0 })
    }

    fn pmf(&self, _ctx: &LightSampleContext, index: u32) -> f32 {
        if index == 0 {
            1.0
        } else {
            0.0
        }
    }
}

/// The inside of the unit sphere at the origin.
struct Furnace {
    wall: Wall,
    lights: Vec<Box<dyn Light>>,
}

impl Scene for Furnace {
    fn intersect(&self, ray: &Ray) -> Option<SurfaceInteraction<'_>> {
        // |o + t d| = 1 for the far root (o is inside).
        let (b, c) = (ray.o.dot(ray.d), ray.o.length_squared() - 1.0);
        let t = -b + (b * b - c).max(0.0).sqrt();
        let p = ray.at(t);
        let n = -p.normalize();
        Some(SurfaceInteraction {
            point: SurfacePoint {
                p,
                p_error: Vec3::splat(1e-5),
                n,
            },
            shading: Frame::from_z(n),
            texture: TextureQuery::at(Vec2::ZERO),
            bsdf: &self.wall,
            bsdf_flags: self.wall.flags(),
            light: LightIndex::new(0),
        })
    }

    fn occluded(&self, _ray: &Ray) -> bool {
        true
    }

    fn lights(&self) -> &[Box<dyn Light>] {
        &self.lights
    }

    fn infinite_lights(&self) -> &[u32] {
        &[]
    }

    fn light_sampler(&self) -> &dyn LightSampler {
        &OnlyLight
    }
}

/// Independent uniform numbers.
#[derive(Clone)]
struct Uniform(Pcg32);

impl Sampler for Uniform {
    fn samples_per_pixel(&self) -> u32 {
        1
    }

    fn start_pixel_sample(&mut self, _pixel: UVec2, _index: u32, _seed: u64) {}

    fn get_1d(&mut self) -> f32 {
        self.0.next_f32()
    }

    fn get_2d(&mut self) -> Vec2 {
        Vec2::new(self.0.next_f32(), self.0.next_f32())
    }

    fn get_pixel_2d(&mut self) -> Vec2 {
        self.get_2d()
    }

    fn clone_sampler(&self) -> Box<dyn Sampler> {
        Box::new(self.clone())
    }
}

#[test]
fn furnace_sums_the_geometric_series() {
    let (albedo, emitted) = (0.7f32, 0.5f32);
    let scene = Furnace {
        wall: Wall {
            albedo: Rgb::splat(albedo),
        },
        lights: vec![Box::new(Glow {
            radiance: Rgb::splat(emitted),
        })],
    };
    let mut sampler = Uniform(Pcg32::new(7, 11));
    let mut stats = RenderStats::default();
    for max_depth in [1u32, 2, 5, 20] {
        let integrator = BsdfPathTracer::new(max_depth);
        let expected = emitted * (1.0 - albedo.powi(max_depth as i32)) / (1.0 - albedo);
        for _ in 0..1000 {
            let u = sampler.get_2d();
            let d = warp::square_to_uniform_sphere(u);
            let origin = Vec3::new(0.1, -0.2, 0.3);
            let l = integrator.li(&Ray::new(origin, d), &scene, &mut sampler, &mut stats);
            assert!(
                (l.g - expected).abs() <= 1e-4 * expected,
                "max_depth {max_depth}: {l:?}, expected {expected}"
            );
        }
    }
}

#[test]
fn registers_as_an_integrator() {
    let mut registry = Registry::new();
    {{lib}}::register(&mut registry).unwrap();
    assert!(registry
        .find(PluginKind::Integrator, {{lib}}::SPEC.name)
        .is_some());
}
