//! The scene's single-ray and packet queries against each other and
//! against known answers, on meshes, instances and spheres.

use super::*;
use crate::{PacketWidth, Packets};

fn unit_quad(device: &Device) -> Scene {
    let mut builder = SceneBuilder::new(device, SceneOptions::default()).unwrap();
    let vertices = vec![
        [-1.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
    ];
    let indices = vec![[0, 1, 2], [0, 2, 3]];
    builder
        .add_triangle_mesh(Arc::new(vertices.into()), Arc::new(indices.into()))
        .unwrap();
    builder.commit().unwrap()
}

fn ray(org: [f32; 3], dir: [f32; 3], tfar: f32) -> Ray {
    Ray {
        org,
        dir,
        tnear: 0.0,
        tfar,
    }
}

#[test]
fn hits_quad_and_reports_barycentrics() {
    let device = Device::new().unwrap();
    assert!(device.version() >= 40000, "Embree 4 expected");
    let scene = unit_quad(&device);
    let hit = scene
        .intersect1(&ray([0.5, -0.5, 2.0], [0.0, 0.0, -1.0], f32::INFINITY))
        .unwrap();
    assert!((hit.t - 2.0).abs() < 1e-6);
    assert_eq!(hit.geom_id, 0);
    assert_eq!(hit.prim_id, 0);
    assert_eq!(hit.inst_id, crate::INVALID_ID);
    // p = (1-u-v) v0 + u v1 + v v2 = (0.5, -0.5): u = 0.5, v = 0.25.
    assert!(
        (hit.u - 0.5).abs() < 1e-6 && (hit.v - 0.25).abs() < 1e-6,
        "{hit:?}"
    );
    assert!(hit.ng[2] > 0.0);
    assert!(scene
        .intersect1(&ray([2.0, 0.0, 2.0], [0.0, 0.0, -1.0], f32::INFINITY))
        .is_none());
}

/// Replay answers each query with the recorded answer of the query in
/// the same place, whatever its ray, counts what it handed out, and
/// traverses again past the recording's end or once stopped.
#[cfg(feature = "replay")]
#[test]
fn replay_answers_queries_in_recorded_order() {
    let device = Device::new().unwrap();
    let mut scene = unit_quad(&device);
    let down = [0.0, 0.0, -1.0];
    let hit_ray = ray([0.5, -0.5, 2.0], down, f32::INFINITY);
    let miss_ray = ray([2.0, 0.0, 2.0], down, f32::INFINITY);
    let blocked = ray([0.0, 0.0, 1.0], down, 2.0);
    let short = ray([0.0, 0.0, 1.0], down, 0.5);

    scene.record_queries();
    let hit = scene.intersect1(&hit_ray);
    assert!(hit.is_some());
    assert!(scene.intersect1(&miss_ray).is_none());
    assert!(scene.occluded1(&blocked));
    assert_eq!(scene.replay_queries(), (2, 1));

    // The rays swapped: the answers come in the recorded order.
    assert_eq!(scene.intersect1(&miss_ray), hit);
    assert!(scene.occluded1(&short));
    assert_eq!(scene.intersect1(&hit_ray), None);
    assert_eq!(scene.replayed_queries(), (2, 1));
    // Past the recording: traversal again.
    assert!(!scene.occluded1(&short));
    assert_eq!(scene.intersect1(&hit_ray), hit);
    assert_eq!(scene.replayed_queries(), (2, 1));

    // Replaying again starts over; stopping traverses.
    assert_eq!(scene.replay_queries(), (2, 1));
    assert_eq!(scene.intersect1(&miss_ray), hit);
    scene.stop_replay();
    assert!(scene.intersect1(&miss_ray).is_none());
    assert!(!scene.occluded1(&short));
}

#[test]
fn occlusion_respects_segment_length() {
    let device = Device::new().unwrap();
    let scene = unit_quad(&device);
    assert!(scene.occluded1(&ray([0.0, 0.0, 1.0], [0.0, 0.0, -1.0], 2.0)));
    assert!(!scene.occluded1(&ray([0.0, 0.0, 1.0], [0.0, 0.0, -1.0], 0.5)));
}

#[test]
fn spheres_are_hit_from_outside_and_inside() {
    let device = Device::new().unwrap();
    let mut builder = SceneBuilder::new(&device, SceneOptions::default()).unwrap();
    builder
        .add_spheres(Arc::new(vec![[0.0, 0.0, 0.0, 1.0]].into()))
        .unwrap();
    let scene = builder.commit().unwrap();
    let outside = scene
        .intersect1(&ray([0.0, 0.0, 5.0], [0.0, 0.0, -1.0], f32::INFINITY))
        .unwrap();
    assert!((outside.t - 4.0).abs() < 1e-5);
    let inside = scene
        .intersect1(&ray([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], f32::INFINITY))
        .unwrap();
    assert!((inside.t - 1.0).abs() < 1e-5);
}

#[test]
fn out_of_range_index_is_an_error() {
    let device = Device::new().unwrap();
    let mut builder = SceneBuilder::new(&device, SceneOptions::default()).unwrap();
    let err = builder
        .add_triangle_mesh(
            Arc::new(vec![[0.0; 3]; 3].into()),
            Arc::new(vec![[0, 1, 3]].into()),
        )
        .unwrap_err();
    assert!(err.message.contains("out of range"), "{err}");
}

/// A small deterministic generator (SplitMix64) for test rays.
struct Rng(u64);

impl Rng {
    fn next_f32(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in `[lo, hi)`.
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next_f32()
    }

    /// A uniform unit direction.
    fn direction(&mut self) -> [f32; 3] {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, std::f32::consts::TAU);
        let r = (1.0 - z * z).max(0.0).sqrt();
        [r * phi.cos(), r * phi.sin(), z]
    }
}

/// A closed UV sphere of `2 n^2` triangles: many primitives, and rays
/// from inside hit it too.
fn uv_sphere(center: [f32; 3], radius: f32, n: u32) -> (Vec<Vertex>, Vec<Triangle>) {
    let mut vertices = Vec::new();
    for i in 0..=n {
        let theta = std::f32::consts::PI * i as f32 / n as f32;
        for j in 0..n {
            let phi = std::f32::consts::TAU * j as f32 / n as f32;
            vertices.push([
                center[0] + radius * theta.sin() * phi.cos(),
                center[1] + radius * theta.sin() * phi.sin(),
                center[2] + radius * theta.cos(),
            ]);
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
    (vertices, indices)
}

fn add_mesh(builder: &mut SceneBuilder, (vertices, indices): (Vec<Vertex>, Vec<Triangle>)) {
    builder
        .add_triangle_mesh(Arc::new(vertices.into()), Arc::new(indices.into()))
        .unwrap();
}

/// A floor quad under everything, so that most rays find something.
fn floor() -> (Vec<Vertex>, Vec<Triangle>) {
    let vertices = vec![
        [-4.0, -4.0, -1.5],
        [4.0, -4.0, -1.5],
        [4.0, 4.0, -1.5],
        [-4.0, 4.0, -1.5],
    ];
    (vertices, vec![[0, 1, 2], [0, 2, 3]])
}

/// Meshes only: two UV spheres and the floor.
fn mesh_scene(device: &Device) -> Scene {
    let mut builder = SceneBuilder::new(device, SceneOptions::default()).unwrap();
    add_mesh(&mut builder, uv_sphere([-1.0, 0.0, 0.0], 1.0, 24));
    add_mesh(&mut builder, uv_sphere([1.2, 0.5, 0.2], 0.7, 16));
    add_mesh(&mut builder, floor());
    builder.commit().unwrap()
}

/// Three rotated, scaled and moved instances of one two-mesh
/// prototype, beside a mesh of the top scene.
fn instance_scene(device: &Device) -> Scene {
    let mut builder = SceneBuilder::new(device, SceneOptions::default()).unwrap();
    add_mesh(&mut builder, uv_sphere([0.0, 0.0, 0.0], 0.5, 16));
    add_mesh(&mut builder, unit_quad_mesh());
    let prototype = Arc::new(builder.commit().unwrap());
    let mut builder = SceneBuilder::new(device, SceneOptions::default()).unwrap();
    add_mesh(&mut builder, floor());
    for (k, translation) in [[-1.5, 0.0, 0.0], [0.0, 1.2, 0.3], [1.5, -0.5, 0.0]]
        .into_iter()
        .enumerate()
    {
        let (s, c) = (0.7 * k as f32).sin_cos();
        let scale = 0.8 + 0.3 * k as f32;
        // Columns: a rotation about z, scaled; then the translation.
        let transform = [
            scale * c,
            scale * s,
            0.0,
            -scale * s,
            scale * c,
            0.0,
            0.0,
            0.0,
            scale,
            translation[0],
            translation[1],
            translation[2],
        ];
        builder.add_instance(prototype.clone(), &transform).unwrap();
    }
    builder.commit().unwrap()
}

/// Many spheres (one geometry, a primitive each) and the floor.
fn sphere_scene(device: &Device) -> Scene {
    let mut rng = Rng(7);
    let points: Vec<SpherePoint> = (0..40)
        .map(|_| {
            [
                rng.range(-2.5, 2.5),
                rng.range(-2.5, 2.5),
                rng.range(-1.0, 1.0),
                rng.range(0.1, 0.6),
            ]
        })
        .collect();
    let mut builder = SceneBuilder::new(device, SceneOptions::default()).unwrap();
    builder.add_spheres(Arc::new(points.into())).unwrap();
    add_mesh(&mut builder, floor());
    builder.commit().unwrap()
}

fn unit_quad_mesh() -> (Vec<Vertex>, Vec<Triangle>) {
    let vertices = vec![
        [-1.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
    ];
    (vertices, vec![[0, 1, 2], [0, 2, 3]])
}

/// Incoherent rays from all over the scene in all directions, and
/// camera-like bundles (one origin, nearby directions); one in three
/// has a finite `tfar`, often short of what it would hit.
fn test_rays(seed: u64, n: usize) -> Vec<Ray> {
    let mut rng = Rng(seed);
    let mut rays = Vec::with_capacity(n);
    while rays.len() < n {
        let bundle = rng.next_f32() < 0.5;
        let org = [
            rng.range(-3.0, 3.0),
            rng.range(-3.0, 3.0),
            rng.range(-1.0, 3.0),
        ];
        let aim = rng.direction();
        for _ in 0..if bundle { 16 } else { 1 } {
            let dir = if bundle {
                let d = [
                    aim[0] + rng.range(-0.05, 0.05),
                    aim[1] + rng.range(-0.05, 0.05),
                    aim[2] + rng.range(-0.05, 0.05),
                ];
                let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                d.map(|x| x / len)
            } else {
                rng.direction()
            };
            let tfar = if rng.next_f32() < 1.0 / 3.0 {
                rng.range(0.05, 4.0)
            } else {
                f32::INFINITY
            };
            rays.push(Ray {
                org,
                dir,
                tnear: 0.0,
                tfar,
            });
        }
    }
    rays.truncate(n);
    rays
}

/// Whether a packet answer is the single-ray answer: the same
/// primitive, and `t`, the barycentrics and the normal equal up to
/// rounding.
fn same_hit(single: Option<Hit>, packet: Option<Hit>) -> Result<(), String> {
    // Relative to the magnitude: of t, of the barycentrics' range
    // [0, 1], of the normal's largest component.
    let close = |x: f32, y: f32, scale: f32| (x - y).abs() <= 1e-5 * scale;
    match (single, packet) {
        (None, None) => Ok(()),
        (Some(a), Some(b))
            if (a.geom_id, a.prim_id, a.inst_id) == (b.geom_id, b.prim_id, b.inst_id)
                && close(a.t, b.t, a.t.abs())
                && close(a.u, b.u, 1.0)
                && close(a.v, b.v, 1.0)
                && (0..3).all(|k| {
                    close(
                        a.ng[k],
                        b.ng[k],
                        a.ng.map(f32::abs).into_iter().fold(0.0, f32::max),
                    )
                }) =>
        {
            Ok(())
        }
        (a, b) => Err(format!("single {a:?}, packet {b:?}")),
    }
}

/// Every width, with and without the coherence hint, answers as single
/// rays, on the whole batch and on batches whose lengths are not
/// multiples of the width. Returns, for the caller to check that the
/// rays exercise the scene: how many single rays hit, how many distinct
/// (instance, geometry) pairs they hit, and how many hits a finite
/// `tfar` cut off.
fn check_packets(scene: &Scene, rays: &[Ray]) -> (usize, usize, usize) {
    let single: Vec<Option<Hit>> = rays.iter().map(|r| scene.intersect1(r)).collect();
    let blocked: Vec<bool> = rays.iter().map(|r| scene.occluded1(r)).collect();
    for width in PacketWidth::ALL {
        for coherent in [false, true] {
            let packets = Packets { width, coherent };
            for n in [0, 1, 7, 9, 33, rays.len()] {
                // Batches from an odd offset too, so that packets
                // regroup the rays.
                for start in [0, 5] {
                    let end = (start + n).min(rays.len());
                    let mut hits = vec![None; end - start];
                    scene.intersect_packets(packets, &rays[start..end], &mut hits);
                    let mut occluded = vec![false; end - start];
                    scene.occluded_packets(packets, &rays[start..end], &mut occluded);
                    for (i, (hit, occluded)) in hits.iter().zip(&occluded).enumerate() {
                        let k = start + i;
                        if let Err(e) = same_hit(single[k], *hit) {
                            panic!(
                                "{packets:?}, batch {start}..{end}, ray {k} {:?}: {e}",
                                rays[k]
                            );
                        }
                        assert_eq!(*occluded, blocked[k], "{packets:?}, ray {k} {:?}", rays[k]);
                    }
                }
            }
        }
    }
    let kinds: std::collections::BTreeSet<_> = single
        .iter()
        .flatten()
        .map(|h| (h.inst_id, h.geom_id))
        .collect();
    let cut = rays
        .iter()
        .zip(&single)
        .filter(|(r, hit)| {
            let unlimited = Ray {
                tfar: f32::INFINITY,
                ..**r
            };
            hit.is_none() && scene.intersect1(&unlimited).is_some()
        })
        .count();
    (single.iter().flatten().count(), kinds.len(), cut)
}

#[test]
fn packets_answer_as_single_rays_on_meshes() {
    let device = Device::new().unwrap();
    let scene = mesh_scene(&device);
    let rays = test_rays(1, 3000);
    let (hits, kinds, cut) = check_packets(&scene, &rays);
    assert!(hits > 500 && hits < 2900, "{hits}");
    assert!(cut > 50, "{cut}");
    assert_eq!(kinds, 3);
}

#[test]
fn packets_answer_as_single_rays_through_instances() {
    let device = Device::new().unwrap();
    let scene = instance_scene(&device);
    let rays = test_rays(2, 3000);
    let (hits, kinds, cut) = check_packets(&scene, &rays);
    assert!(hits > 500 && hits < 2900, "{hits}");
    assert!(cut > 50, "{cut}");
    // The floor, and both prototype meshes in each of three instances.
    assert_eq!(kinds, 7);
}

#[test]
fn packets_answer_as_single_rays_on_spheres() {
    let device = Device::new().unwrap();
    let scene = sphere_scene(&device);
    let rays = test_rays(3, 3000);
    let (hits, kinds, cut) = check_packets(&scene, &rays);
    assert!(hits > 500 && hits < 2900, "{hits}");
    assert!(cut > 50, "{cut}");
    assert_eq!(kinds, 2);
    let spheres: std::collections::BTreeSet<u32> = rays
        .iter()
        .filter_map(|r| scene.intersect1(r))
        .filter(|h| h.geom_id == 0)
        .map(|h| h.prim_id)
        .collect();
    assert!(spheres.len() > 20, "{} spheres hit", spheres.len());
}

/// The comparison above can fail: a hit on another primitive, a
/// different distance or a missing hit are told apart from rounding.
#[test]
fn packet_comparison_rejects_wrong_answers() {
    let hit = Hit {
        t: 2.0,
        u: 0.25,
        v: 0.5,
        ng: [0.0, 0.0, 4.0],
        geom_id: 1,
        prim_id: 7,
        inst_id: crate::INVALID_ID,
    };
    let rounded = Hit {
        t: 2.0 * (1.0 + f32::EPSILON),
        ..hit
    };
    assert!(same_hit(Some(hit), Some(rounded)).is_ok());
    assert!(same_hit(None, None).is_ok());
    for wrong in [
        Hit { prim_id: 8, ..hit },
        Hit { inst_id: 0, ..hit },
        Hit { t: 2.001, ..hit },
        Hit { u: 0.26, ..hit },
    ] {
        assert!(same_hit(Some(hit), Some(wrong)).is_err(), "{wrong:?}");
    }
    assert!(same_hit(Some(hit), None).is_err());
    assert!(same_hit(None, Some(hit)).is_err());
}

/// Packet queries are recorded lane by lane with the single-ray ones and
/// replayed either way, in order; past the recording they traverse.
#[cfg(feature = "replay")]
#[test]
fn replay_serves_packets_and_single_rays_alike() {
    let device = Device::new().unwrap();
    let mut scene = mesh_scene(&device);
    let rays = test_rays(4, 40);
    let packets = Packets {
        width: PacketWidth::Eight,
        coherent: false,
    };
    scene.record_queries();
    let mut recorded = vec![None; 21];
    scene.intersect_packets(packets, &rays[..21], &mut recorded);
    recorded.push(scene.intersect1(&rays[21]));
    let mut blocked = vec![false; 10];
    scene.occluded_packets(packets, &rays[..10], &mut blocked);
    assert_eq!(scene.replay_queries(), (22, 10));

    // Other rays, same answers: single rays then packets of another
    // width, and the batch running past the recording traverses.
    let other = &rays[18..];
    let first: Vec<_> = other[..3].iter().map(|r| scene.intersect1(r)).collect();
    assert_eq!(first, recorded[..3]);
    let mut rest = vec![None; 22];
    let sixteen = Packets {
        width: PacketWidth::Sixteen,
        coherent: true,
    };
    scene.intersect_packets(sixteen, &other[..22], &mut rest);
    assert_eq!(rest[..19], recorded[3..]);
    for (r, hit) in other[19..22].iter().zip(&rest[19..]) {
        assert_eq!(*hit, scene_free_answer(&device, r));
    }
    let mut occluded = vec![false; 10];
    scene.occluded_packets(sixteen, &other[..10], &mut occluded);
    assert_eq!(occluded, blocked);
    assert_eq!(scene.replayed_queries(), (22, 10));
    scene.stop_replay();
}

/// What a fresh copy of the replay test's scene answers, without tape.
#[cfg(feature = "replay")]
fn scene_free_answer(device: &Device, ray: &Ray) -> Option<Hit> {
    mesh_scene(device).intersect1(ray)
}

#[test]
fn instances_share_one_prototype_and_report_their_id() {
    let device = Device::new().unwrap();
    let prototype = Arc::new(unit_quad(&device));
    let mut builder = SceneBuilder::new(&device, SceneOptions::default()).unwrap();
    let identity = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
    let mut moved = identity;
    moved[9] = 10.0; // translate by +10 in x
    let a = builder.add_instance(prototype.clone(), &identity).unwrap();
    let b = builder.add_instance(prototype, &moved).unwrap();
    let scene = builder.commit().unwrap();
    let down = [0.0, 0.0, -1.0];
    let hit_a = scene
        .intersect1(&ray([0.5, -0.5, 2.0], down, f32::INFINITY))
        .unwrap();
    let hit_b = scene
        .intersect1(&ray([10.5, -0.5, 2.0], down, f32::INFINITY))
        .unwrap();
    assert_eq!((hit_a.inst_id, hit_b.inst_id), (a, b));
    assert_eq!((hit_a.geom_id, hit_b.geom_id), (0, 0));
    // Same object-space point, so the same primitive and barycentrics.
    assert_eq!(
        (hit_a.prim_id, hit_a.u, hit_a.v),
        (hit_b.prim_id, hit_b.u, hit_b.v)
    );
    assert!(scene
        .intersect1(&ray([5.0, 0.0, 2.0], down, f32::INFINITY))
        .is_none());
    assert!(scene.occluded1(&ray([10.0, 0.0, 1.0], down, 2.0)));
}

#[test]
fn memory_monitor_counts_the_bvh() {
    let device = Device::new().unwrap();
    let before = device.memory_in_use();
    let scene = unit_quad(&device);
    assert!(device.memory_in_use() > before);
    drop(scene);
}

#[test]
fn embree_errors_become_rust_errors() {
    let device = Device::new().unwrap();
    let builder = SceneBuilder::new(&device, SceneOptions::default()).unwrap();
    // REFIT is a geometry-only build quality: Embree reports
    // an error through the device callback.
    // SAFETY: a live, uncommitted scene.
    unsafe { sys::rtcSetSceneBuildQuality(builder.raw, sys::RTCBuildQuality::REFIT) };
    let err = device.take_error().unwrap_err();
    assert!(err.message.contains("build quality"), "{err}");
    assert!(device.take_error().is_ok(), "an error is reported once");
}
