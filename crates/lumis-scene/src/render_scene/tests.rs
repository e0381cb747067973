//! The scene's queries against each other: packets and batches answer as
//! single rays do.

use lumis_core::light_sampler::NoLights;
use lumis_core::{BsdfContext, BsdfSample, Ray, Rgb, Scene, SurfaceInteraction};
use lumis_embree::{Device, SceneBuilder, SceneOptions, SpherePoint};

use super::*;

struct Black;

impl Bsdf for Black {
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::DIFFUSE_REFLECTION
    }
    fn f(&self, _: &BsdfContext, _: Vec3, _: Vec3) -> Rgb {
        Rgb::BLACK
    }
    fn sample_f(&self, _: &BsdfContext, _: Vec3, _: f32, _: Vec2) -> Option<BsdfSample> {
        None
    }
    fn pdf(&self, _: &BsdfContext, _: Vec3, _: Vec3) -> f32 {
        0.0
    }
}

/// A small deterministic generator (SplitMix64).
struct Rng(u64);

impl Rng {
    fn next_f32(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    }

    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next_f32()
    }

    fn direction(&mut self) -> Vec3 {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, std::f32::consts::TAU);
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }
}

/// A UV sphere mesh with smooth normals and texture coordinates.
fn uv_sphere(n: u32, bsdf: u32) -> MeshData {
    let (mut vertices, mut normals, mut uvs) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..=n {
        let theta = std::f32::consts::PI * i as f32 / n as f32;
        for j in 0..n {
            let phi = std::f32::consts::TAU * j as f32 / n as f32;
            let p = Vec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            vertices.push(p.to_array());
            normals.push(p);
            uvs.push(Vec2::new(j as f32 / n as f32, i as f32 / n as f32));
        }
    }
    let at = |i: u32, j: u32| i * n + j % n;
    let mut indices = Vec::new();
    for i in 0..n {
        for j in 0..n {
            indices.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            indices.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    MeshData {
        vertices: Arc::new(vertices.into()),
        indices: Arc::new(indices.into()),
        normals: Some(normals),
        uvs: Some(uvs),
        bsdf,
        lights: Vec::new(),
        orientation: 1.0,
        flat_frames: Vec::new(),
    }
}

/// A flat-shaded floor whose second triangle emits.
fn floor(bsdf: u32) -> MeshData {
    let vertices = vec![
        [-5.0, -5.0, -1.5],
        [5.0, -5.0, -1.5],
        [5.0, 5.0, -1.5],
        [-5.0, 5.0, -1.5],
    ];
    let mut mesh = MeshData {
        vertices: Arc::new(vertices.into()),
        indices: Arc::new(vec![[0, 1, 2], [0, 2, 3]].into()),
        normals: None,
        uvs: None,
        bsdf,
        lights: vec![NO_LIGHT, 0],
        orientation: 1.0,
        flat_frames: Vec::new(),
    };
    mesh.store_flat_frames();
    mesh
}

fn add(builder: &mut SceneBuilder, mesh: &MeshData) {
    builder
        .add_triangle_mesh(mesh.vertices.clone(), mesh.indices.clone())
        .unwrap();
}

/// A mesh with shading normals and uvs, a flat floor, two placed
/// instances of a prototype and spheres: every kind of hit shading
/// knows. Geometry ids follow the order of `geometries`.
fn scene(packets: bool) -> RenderScene {
    let device = Device::new().unwrap();
    let mut proto_builder = SceneBuilder::new(&device, SceneOptions::default()).unwrap();
    let proto_mesh = uv_sphere(12, 1);
    add(&mut proto_builder, &proto_mesh);
    let prototype = Arc::new(proto_builder.commit().unwrap());

    let mut builder = SceneBuilder::new(&device, SceneOptions::default()).unwrap();
    let mut geometries = Vec::new();
    let mesh = uv_sphere(24, 0);
    add(&mut builder, &mesh);
    geometries.push(Geometry::Mesh(mesh));
    let floor = floor(1);
    add(&mut builder, &floor);
    geometries.push(Geometry::Mesh(floor));
    for (angle, translation) in [
        (0.3f32, Vec3::new(2.2, 0.5, 0.0)),
        (1.1, Vec3::new(-2.0, 1.5, 0.5)),
    ] {
        let linear = Mat3::from_rotation_z(angle) * Mat3::from_diagonal(Vec3::new(0.6, 0.8, 0.7));
        let mut transform = [0.0; 12];
        transform[..9].copy_from_slice(&linear.to_cols_array());
        transform[9..].copy_from_slice(&translation.to_array());
        builder.add_instance(prototype.clone(), &transform).unwrap();
        geometries.push(Geometry::Instance {
            prototype: 0,
            placement: Placement {
                linear,
                translation,
                normal: linear.inverse().transpose(),
            },
            lights: Vec::new(),
        });
    }
    let spheres: Vec<SpherePoint> = vec![[0.5, -2.0, 0.0, 0.7]];
    builder.add_spheres(Arc::new(spheres.into())).unwrap();
    geometries.push(Geometry::Sphere {
        center: Vec3::new(0.5, -2.0, 0.0),
        radius: 0.7,
        bsdf: 1,
        light: Some(1),
        orientation: 1.0,
    });
    RenderScene {
        embree: builder.commit().unwrap(),
        geometries,
        prototypes: vec![Prototype {
            meshes: vec![proto_mesh],
        }],
        bsdfs: vec![
            SceneBsdf::new(Arc::new(Black)),
            SceneBsdf::new(Arc::new(Black)),
        ],
        lights: Vec::new(),
        infinite_lights: Vec::new(),
        light_sampler: Box::new(NoLights),
        counts: SceneCounts::default(),
        report: LoadReport::default(),
        packets,
        footprint: None,
        tangent_frames: false,
    }
}

/// A batch as a wavefront integrator makes one: incoherent rays from
/// anywhere, then runs of camera rays (one origin, nearby directions)
/// of lengths around the packet width; a third of all rays have a
/// finite `t_max`, often short of what they would hit.
fn batch(seed: u64) -> Vec<Ray> {
    let mut rng = Rng(seed);
    let mut rays = Vec::new();
    let limit = |rng: &mut Rng, o: Vec3, d: Vec3| {
        let t_max = if rng.next_f32() < 1.0 / 3.0 {
            rng.range(0.05, 5.0)
        } else {
            f32::INFINITY
        };
        Ray { o, d, t_max }
    };
    for run in [0, 3, 16, 17, 5, 40, 15, 32] {
        for _ in 0..60 {
            let o = Vec3::new(
                rng.range(-3.0, 3.0),
                rng.range(-3.0, 3.0),
                rng.range(-1.0, 3.0),
            );
            let d = rng.direction();
            rays.push(limit(&mut rng, o, d));
        }
        let eye = Vec3::new(0.3, -0.2, 6.0);
        let aim = Vec3::new(rng.range(-0.4, 0.4), rng.range(-0.4, 0.4), -1.0);
        for _ in 0..run {
            let jitter = Vec3::new(rng.range(-0.02, 0.02), rng.range(-0.02, 0.02), 0.0);
            rays.push(limit(&mut rng, eye, (aim + jitter).normalize()));
        }
    }
    rays
}

/// Whether two interactions agree up to the rounding of the traversal.
fn same(a: &SurfaceInteraction, b: &SurfaceInteraction) -> bool {
    let close =
        |x: Vec3, y: Vec3| (x - y).abs().max_element() <= 1e-4 * x.abs().max_element().max(1.0);
    close(a.point.p, b.point.p)
        && close(a.point.n, b.point.n)
        && close(a.shading.z.into(), b.shading.z.into())
        && close(a.shading.x.into(), b.shading.x.into())
        && (a.texture.uv - b.texture.uv).abs().max_element() <= 1e-4
        && std::ptr::addr_eq(a.bsdf, b.bsdf)
        && a.bsdf_flags == b.bsdf_flags
        && a.light == b.light
}

/// Both batch queries answer as the single-ray ones, with and without
/// `[accel] packets`, on whole batches and on lengths that are not
/// multiples of a packet, from offsets that cut camera runs apart.
#[test]
fn batches_answer_as_single_rays() {
    let rays = batch(11);
    for packets in [false, true] {
        let scene = scene(packets);
        let single: Vec<_> = rays.iter().map(|r| scene.intersect(r)).collect();
        let blocked: Vec<bool> = rays.iter().map(|r| scene.occluded(r)).collect();
        for n in [0, 1, 7, 9, 33, rays.len()] {
            for start in [0, 61, 70, 100, 171] {
                let end = (start + n).min(rays.len());
                let mut found = vec![None; end - start];
                scene.intersect_batch(&rays[start..end], &mut found);
                let mut occluded = vec![false; end - start];
                scene.occluded_batch(&rays[start..end], &mut occluded);
                for (k, (found, occluded)) in (start..end).zip(found.iter().zip(&occluded)) {
                    match (&single[k], found) {
                        (None, None) => {}
                        (Some(a), Some(b)) if same(a, b) => {}
                        (a, b) => panic!(
                            "packets {packets}, batch {start}..{end}, ray {k} {:?}: single {:?}, batch {:?}",
                            rays[k],
                            a.as_ref().map(|h| (h.point, h.texture.uv, h.light)),
                            b.as_ref().map(|h| (h.point, h.texture.uv, h.light)),
                        ),
                    }
                    assert_eq!(*occluded, blocked[k], "packets {packets}, ray {k}");
                }
            }
        }
        // The rays reach every geometry (and the emitting triangle),
        // and finite segments stop short of some hits.
        let hits: Vec<&SurfaceInteraction> = single.iter().flatten().collect();
        assert!(
            hits.len() > 200 && hits.len() < rays.len(),
            "{}",
            hits.len()
        );
        assert!(hits.iter().any(|h| h.light == LightIndex::new(0)));
        assert!(
            hits.iter().any(|h| h.light == LightIndex::new(1)),
            "a sphere hit"
        );
        assert!(
            hits.iter().any(|h| h.point.p.x > 1.5 && h.point.p.z > -1.0),
            "an instance hit"
        );
        let cut = rays
            .iter()
            .zip(&single)
            .filter(|(r, hit)| {
                hit.is_none()
                    && scene
                        .intersect(&Ray {
                            t_max: f32::INFINITY,
                            ..**r
                        })
                        .is_some()
            })
            .count();
        assert!(cut > 20, "{cut}");
    }
}

/// The comparison tells a wrong answer from rounding.
#[test]
fn interaction_comparison_rejects_wrong_answers() {
    let scene = scene(false);
    let ray = Ray {
        o: Vec3::new(0.1, 0.2, 5.0),
        d: Vec3::NEG_Z,
        t_max: f32::INFINITY,
    };
    let hit = scene.intersect(&ray).unwrap();
    assert!(same(&hit, &hit));
    let mut moved = hit;
    moved.point.p.z += 1e-3;
    assert!(!same(&hit, &moved));
    let mut other = hit;
    other.bsdf = scene.bsdfs[1].bsdf.as_ref();
    assert!(!same(&hit, &other));
    let mut lit = hit;
    lit.light = LightIndex::new(3);
    assert!(!same(&hit, &lit));
}
