//! High-poly assets: load-to-first-pixel, peak memory and ray throughput of
//! a glTF scene, against the bare Embree build and ray loop on the same
//! geometry. A benchmark, not a test: it prints numbers and asserts none.
//!
//! Two scenes, generated here (no scanned model can be had through the
//! package registries): a displaced subdivided icosphere of 1.31M
//! triangles (one mesh, no normals in the file: lumis generates them), and
//! 32 instances of a 328k-triangle one (10.5M triangles). Each is written as
//! a `.glb` with a TOML scene and loaded by a child process, so the peak
//! resident memory the OS reports (`VmHWM`) is that of loading the scene
//! alone.
//!
//! `cargo bench -p lumis-tests --bench high_poly [-- --quality medium --compact auto|true|false]`
//! (`--compact` alone means `true`; the default is `auto`, the scene's).
//!
//! `-- --sweep` measures what `[accel] compact = "auto"`'s threshold rests
//! on: single meshes of 20k to 1.3M triangles, each with and without a
//! compact BVH, their peak memory per triangle and rays per second.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Arc;
use std::time::Instant;

use lumis_core::{Scene, UVec2, Vec2, Vec3};
use lumis_embree::bare::{self, BareRay};
use lumis_embree::{BuildQuality, Device, PaddedBuffer, SceneBuilder, SceneOptions};
use lumis_scene::Compaction;
use lumis_tests::gltf_writer::{self, Asset, Container, Mesh, Node, Primitive};

/// A unit icosphere subdivided `levels` times (20 * 4^levels triangles),
/// displaced radially by a few octaves of sines so that it is not a sphere
/// a BVH could love.
fn displaced_sphere(levels: u32) -> (Vec<[f32; 3]>, Vec<u32>) {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut positions: Vec<Vec3> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .into_iter()
    .map(|p| Vec3::from(p).normalize())
    .collect();
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut midpoint = std::collections::HashMap::new();
        let mut mid = |a: u32, b: u32, positions: &mut Vec<Vec3>| -> u32 {
            *midpoint.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let p = (positions[a as usize] + positions[b as usize]).normalize();
                positions.push(p);
                positions.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(faces.len() * 4);
        for [a, b, c] in faces {
            let ab = mid(a, b, &mut positions);
            let bc = mid(b, c, &mut positions);
            let ca = mid(c, a, &mut positions);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        faces = next;
    }
    let displaced = positions
        .iter()
        .map(|p| {
            let d = 0.08 * (7.0 * p.x).sin() * (9.0 * p.y).sin() * (8.0 * p.z).sin()
                + 0.02 * (41.0 * p.x + 3.0 * p.y).sin() * (37.0 * p.z).cos()
                + 0.001 * (173.0 * p.y).sin() * (191.0 * p.x + p.z).cos();
            (*p * (1.0 + d)).to_array()
        })
        .collect();
    (displaced, faces.into_iter().flatten().collect())
}

fn write_scene(
    dir: &Path,
    name: &str,
    asset: &Asset,
    camera: (Vec3, Vec3),
    accel: &str,
) -> PathBuf {
    let file = gltf_writer::write(dir, name, asset, Container::Glb);
    let (origin, target) = camera;
    let toml = format!(
        "[film]\nresolution = [512, 512]\n[camera]\ntype = \"perspective\"\norigin = {:?}\ntarget = {:?}\nfov = 40.0\n\
         [sampler]\ntype = \"independent\"\nspp = 1\n[integrator]\ntype = \"path\"\n\
         [[light]]\ntype = \"point\"\nposition = [3.0, 4.0, 5.0]\nintensity = [20.0, 20.0, 20.0]\n\
         [[shape]]\ntype = \"gltf\"\nfile = \"{file}\"\n{accel}",
        origin.to_array(),
        target.to_array()
    );
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, toml).unwrap();
    path
}

fn status_kb(field: &str) -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find(|l| l.starts_with(field))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(0)
}

/// A cheap deterministic hash to [0, 1)^2 for the diffuse directions.
fn hash2(i: u64) -> Vec2 {
    let mut z = i.wrapping_add(0x9e3779b97f4a7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58476d1ce4e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d049bb133111eb);
    z ^= z >> 31;
    Vec2::new(
        (z >> 40) as f32 / (1u64 << 24) as f32,
        (z & 0xff_ffff) as f32 / (1u64 << 24) as f32,
    )
}

/// Child process: load the scene, report memory and times, then trace.
fn child(scene_path: &Path) {
    let baseline_kb = status_kb("VmRSS:");
    let registry = lumis_app::builtin_registry().unwrap();
    let start = Instant::now();
    let loaded = lumis_scene::load_file(scene_path, &[], &registry).unwrap();
    let res = loaded.camera.resolution();
    let center = loaded.camera.generate_ray(res / 2, Vec2::splat(0.5));
    let first = loaded.scene.intersect(&center).map(|h| h.p());
    let load_to_first_pixel = start.elapsed().as_secs_f64();
    let peak_kb = status_kb("VmHWM:");
    assert!(first.is_some(), "the camera sees the asset");
    let c = loaded.scene.counts().clone();
    let r = loaded.scene.load_report().clone();
    println!(
        "child load_to_first_pixel={load_to_first_pixel:.3} parse={:.3} attributes={:.3} bvh={:.3} \
         triangles={} unique={} instances={} geometry_bytes={} bvh_bytes={} compact={} baseline_kb={baseline_kb} peak_kb={peak_kb}",
        r.parse.as_secs_f64(),
        r.attributes.as_secs_f64(),
        r.bvh.as_secs_f64(),
        c.triangles,
        c.unique_triangles,
        c.instances,
        r.geometry_bytes,
        r.bvh_bytes,
        r.compact,
    );

    // Rays: one primary ray per pixel centre, then one cosine-distributed
    // diffuse ray from each primary hit.
    let mut primary = Vec::new();
    for y in 0..res.y {
        for x in 0..res.x {
            primary.push(
                loaded
                    .camera
                    .generate_ray(UVec2::new(x, y), Vec2::splat(0.5)),
            );
        }
    }
    let mut diffuse = Vec::new();
    for (i, ray) in primary.iter().enumerate() {
        if let Some(hit) = loaded.scene.intersect(ray) {
            let local = lumis_sampling::warp::square_to_cosine_hemisphere(hash2(i as u64));
            diffuse.push(hit.spawn_ray(hit.shading.to_world(local).normalize()));
        }
    }
    for (kind, rays) in [("primary", &primary), ("diffuse", &diffuse)] {
        let bare_rays: Vec<BareRay> = rays
            .iter()
            .map(|r| BareRay {
                org: r.o.into(),
                dir: r.d.into(),
                tfar: r.t_max,
                shadow: false,
            })
            .collect();
        let mut best_lumis = f64::INFINITY;
        let mut best_bare = f64::INFINITY;
        let mut hits = 0u64;
        // Best of 5 of each, interleaved: the machine is shared.
        for _ in 0..5 {
            let t = Instant::now();
            let mut sum = 0.0f32;
            for ray in rays.iter() {
                if let Some(h) = loaded.scene.intersect(ray) {
                    sum += h.shading.normal().x + h.p().y;
                }
            }
            std::hint::black_box(sum);
            best_lumis = best_lumis.min(t.elapsed().as_secs_f64());
            let t = Instant::now();
            hits = bare::trace(loaded.scene.embree(), &bare_rays);
            best_bare = best_bare.min(t.elapsed().as_secs_f64());
        }
        let n = rays.len() as f64;
        println!(
            "child {kind}: {} rays ({hits} hit), 1 thread: lumis intersect {:.2} Mrays/s, bare rtcIntersect1 {:.2} Mrays/s, ratio {:.2}",
            rays.len(),
            n / best_lumis * 1e-6,
            n / best_bare * 1e-6,
            best_bare / best_lumis
        );
    }
}

/// The bare Embree build of the same geometry: seconds and BVH bytes.
fn bare_build(
    positions: &[[f32; 3]],
    indices: &[u32],
    instances: &[[f32; 12]],
    options: SceneOptions,
) -> (f64, i64) {
    let device = Device::new().unwrap();
    let vertices = Arc::new(PaddedBuffer::new(positions.to_vec()));
    let triangles = Arc::new(PaddedBuffer::new(
        indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect(),
    ));
    let before = device.memory_in_use();
    let start = Instant::now();
    let mut builder = SceneBuilder::new(&device, options).unwrap();
    builder
        .add_triangle_mesh(vertices.clone(), triangles.clone())
        .unwrap();
    let mesh_scene = builder.commit().unwrap();
    if instances.is_empty() {
        let secs = start.elapsed().as_secs_f64();
        return (secs, device.memory_in_use() - before);
    }
    let prototype = Arc::new(mesh_scene);
    let mut top = SceneBuilder::new(&device, options).unwrap();
    for xf in instances {
        top.add_instance(prototype.clone(), xf).unwrap();
    }
    let _scene = top.commit().unwrap();
    (
        start.elapsed().as_secs_f64(),
        device.memory_in_use() - before,
    )
}

fn run_child(scene: &Path) -> String {
    let out = Command::new(std::env::current_exe().unwrap())
        .arg("--child")
        .arg(scene)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "child failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

fn field(report: &str, key: &str) -> f64 {
    report
        .split_whitespace()
        .find_map(|w| w.strip_prefix(&format!("{key}=")))
        .and_then(|v| v.parse().ok())
        .unwrap_or(f64::NAN)
}

fn summarise(name: &str, report: &str, bare_seconds: f64, bare_bytes: i64) {
    print!("{report}");
    let unique = field(report, "unique");
    let peak = field(report, "peak_kb") * 1024.0;
    let baseline = field(report, "baseline_kb") * 1024.0;
    let first = field(report, "load_to_first_pixel");
    println!(
        "{name}: {} triangles ({} unique), BVH {}: load-to-first-pixel {first:.2} s = {:.2}x the bare Embree build ({bare_seconds:.2} s); \
         peak RSS {:.0} MB, {:.1} B/unique triangle above the {:.0} MB baseline ({:.1} B total); \
         lumis geometry {:.1} + BVH {:.1} B/unique triangle (bare Embree BVH {:.1})",
        field(report, "triangles"),
        unique,
        if report.contains("compact=true") { "compact" } else { "not compact" },
        first / bare_seconds,
        peak * 1e-6,
        (peak - baseline) / unique,
        baseline * 1e-6,
        peak / unique,
        field(report, "geometry_bytes") / unique,
        field(report, "bvh_bytes") / unique,
        bare_bytes as f64 / unique,
    );
}

/// The `--compact` argument: `auto` (the default), `true` or `false`;
/// alone, `true`.
fn compaction(args: &[String]) -> Compaction {
    let Some(i) = args.iter().position(|a| a == "--compact") else {
        return Compaction::Auto;
    };
    match args.get(i + 1).map(String::as_str) {
        Some("auto") => Compaction::Auto,
        Some("false") => Compaction::Never,
        Some("true") | None => Compaction::Always,
        Some(a) if a.starts_with("--") => Compaction::Always,
        Some(a) => panic!("--compact takes auto, true or false, not {a}"),
    }
}

fn accel_table(quality: &str, compaction: Compaction) -> String {
    let compact = match compaction {
        Compaction::Auto => "\"auto\"",
        Compaction::Always => "true",
        Compaction::Never => "false",
    };
    format!("[accel]\nquality = \"{quality}\"\ncompact = {compact}\n")
}

fn one_mesh(positions: &[[f32; 3]], indices: &[u32]) -> Asset {
    Asset {
        meshes: vec![Mesh {
            name: "displaced-sphere".into(),
            primitives: vec![Primitive::triangles(positions.to_vec(), indices.to_vec())],
        }],
        nodes: vec![Node {
            mesh: Some(0),
            ..Node::default()
        }],
        roots: vec![0],
        ..Asset::default()
    }
}

/// Single meshes from 20k to 1.3M triangles, uncompacted and compact: peak
/// memory per triangle (with and without the process baseline) and rays
/// per second, one line each.
fn sweep(dir: &Path) {
    println!(
        "triangles, compact: peak B/triangle (above baseline); lumis primary, diffuse Mrays/s"
    );
    for levels in 5..=8 {
        let (positions, indices) = displaced_sphere(levels);
        let asset = one_mesh(&positions, &indices);
        for compaction in [Compaction::Never, Compaction::Always] {
            let scene = write_scene(
                dir,
                &format!("sweep-{levels}"),
                &asset,
                (Vec3::new(0.0, 0.0, 3.5), Vec3::ZERO),
                &accel_table("medium", compaction),
            );
            let report = run_child(&scene);
            let unique = field(&report, "unique");
            let peak = field(&report, "peak_kb") * 1024.0;
            let baseline = field(&report, "baseline_kb") * 1024.0;
            let rate = |kind: &str| {
                report
                    .lines()
                    .find(|l| l.starts_with(&format!("child {kind}:")))
                    .and_then(|l| l.split("lumis intersect ").nth(1))
                    .and_then(|l| l.split_whitespace().next())
                    .unwrap_or("?")
                    .to_string()
            };
            println!(
                "{unique}, {}: {:.1} ({:.1}); {}, {}",
                compaction == Compaction::Always,
                peak / unique,
                (peak - baseline) / unique,
                rate("primary"),
                rate("diffuse"),
            );
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(i) = args.iter().position(|a| a == "--child") {
        child(Path::new(&args[i + 1]));
        return;
    }
    let dir = std::env::temp_dir().join("lumis-high-poly");
    std::fs::create_dir_all(&dir).unwrap();
    if args.iter().any(|a| a == "--sweep") {
        sweep(&dir);
        return;
    }
    let quality = args
        .iter()
        .position(|a| a == "--quality")
        .map_or("medium", |i| args[i + 1].as_str())
        .to_string();
    let compaction = compaction(&args);
    let mut options = SceneOptions {
        quality: match quality.as_str() {
            "low" => BuildQuality::Low,
            "high" => BuildQuality::High,
            _ => BuildQuality::Medium,
        },
        robust: false,
        compact: false,
    };
    let accel = accel_table(&quality, compaction);
    println!(
        "quality {quality}, compact {compaction:?}; files in {}",
        dir.display()
    );

    // 1. One 1.31M-triangle mesh.
    let (positions, indices) = displaced_sphere(8);
    let asset = one_mesh(&positions, &indices);
    let scene = write_scene(
        &dir,
        "sphere-1m",
        &asset,
        (Vec3::new(0.0, 0.0, 3.5), Vec3::ZERO),
        &accel,
    );
    // The bare build is compact exactly when lumis decides to be.
    options.compact = compaction.decide(indices.len() / 3);
    let (bare_s, bare_b) = bare_build(&positions, &indices, &[], options);
    summarise("1.3M mesh", &run_child(&scene), bare_s, bare_b);

    // 2. 32 instances of a 328k-triangle mesh: 10.5M triangles.
    let (positions, indices) = displaced_sphere(7);
    let mut nodes = Vec::new();
    let mut transforms = Vec::new();
    for k in 0..32 {
        let (x, y) = ((k % 8) as f32 * 2.5 - 8.75, (k / 8) as f32 * 2.5 - 3.75);
        nodes.push(Node {
            mesh: Some(0),
            translation: Some([x, y, 0.0]),
            ..Node::default()
        });
        transforms.push([1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, x, y, 0.0]);
    }
    let asset = Asset {
        meshes: vec![Mesh {
            name: "displaced-sphere".into(),
            primitives: vec![Primitive::triangles(positions.clone(), indices.clone())],
        }],
        roots: (0..nodes.len()).collect(),
        nodes,
        ..Asset::default()
    };
    let scene = write_scene(
        &dir,
        "instanced-10m",
        &asset,
        (Vec3::new(1.25, -6.0, 16.0), Vec3::new(1.25, 1.25, 0.0)),
        &accel,
    );
    options.compact = compaction.decide(indices.len() / 3);
    let (bare_s, bare_b) = bare_build(&positions, &indices, &transforms, options);
    summarise("10.5M instanced", &run_child(&scene), bare_s, bare_b);
}
