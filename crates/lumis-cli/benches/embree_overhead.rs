//! lumis vs a bare Embree ray loop on the same rays.
//!
//! 1. Renders the Cornell box once through a recording scene that logs every
//!    closest-hit and shadow query the path tracer makes.
//! 2. Times the full path tracer (one thread) on the same scene, seed and spp.
//! 3. Times a bare `embree4-sys` loop over the recorded rays (one thread).
//!
//! The ratio lumis/bare of rays per second says how much throughput
//! everything that is not traversal (sampling, shading, light sampling, MIS,
//! film) costs: 0.5 means as much time outside Embree as inside it. A second
//! bare loop makes each ray wait for the previous one, as a path tracer's
//! rays do, to show how much of the gap is lost overlap rather than work.
//!
//! With the `replay` feature it then renders once more recording Embree's
//! answers (0.65 GB more at 64 spp) and times renders that replay them:
//! lumis's own work with no traversal at all, on the same queries.
//!
//! Last, it compares Embree's packet queries with single rays on the rays
//! the `wavefront` integrator traces in batches (same scene, seed and spp):
//! camera rays, bounce rays and shadow rays, each kind on its own, at every
//! packet width with and without the coherence hint (bare Embree); then
//! whole batches as the integrator hands them over, through the renderer's
//! own `intersect_batch` and `occluded_batch` (with shading), with and
//! without `[accel] packets`, against its single-ray queries. Differences
//! under about 10% between two code paths are within what code placement
//! alone does here: the same loop over `intersect` ran 8% slower compiled
//! into `intersect_batch` than into the bench, all of it inside Embree.
//!
//! `cargo bench -p lumis-cli --bench embree_overhead [--features replay] [-- SCENE.toml SPP [packets]]`
//!
//! (`packets`: only the packet comparison.) The scene path must be absolute
//! (cargo runs benches from the crate's directory).
//!
//! The default is the Cornell box at 64 spp, the setting the throughput
//! target is stated for (25M rays, 0.8 GB of recorded rays); fewer samples
//! per pixel weigh per-pixel set-up (such as the Sobol' sampler's) more.

use std::sync::Mutex;
use std::time::Instant;

use lumis_core::{Light, LightSampler, Ray, Registry, Scene, SurfaceInteraction, UVec2, Vec2};
use lumis_embree::bare::{self, BareRay};
use lumis_embree::{PacketWidth, Packets};
use lumis_render::{render, RenderSettings};

/// Delegates to the real scene and records every query.
struct Recording<'a> {
    inner: &'a dyn Scene,
    rays: Mutex<Vec<BareRay>>,
}

impl Recording<'_> {
    fn record(&self, ray: &Ray, shadow: bool) {
        self.rays.lock().unwrap().push(BareRay {
            org: ray.o.into(),
            dir: ray.d.into(),
            tfar: ray.t_max,
            shadow,
        });
    }
}

impl Scene for Recording<'_> {
    fn intersect(&self, ray: &Ray) -> Option<SurfaceInteraction<'_>> {
        self.record(ray, false);
        self.inner.intersect(ray)
    }
    fn occluded(&self, ray: &Ray) -> bool {
        self.record(ray, true);
        self.inner.occluded(ray)
    }
    fn lights(&self) -> &[Box<dyn Light>] {
        self.inner.lights()
    }
    fn infinite_lights(&self) -> &[u32] {
        self.inner.infinite_lights()
    }
    fn light_sampler(&self) -> &dyn LightSampler {
        self.inner.light_sampler()
    }
}

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let scene_path = args.first().cloned().unwrap_or_else(|| {
        concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/cornell-box.toml").to_string()
    });
    let spp: u32 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(64);
    let packets_only = args.get(2).is_some_and(|a| a == "packets");
    let registry = lumis_app::builtin_registry().expect("plugins register");
    if !packets_only {
        overhead(&scene_path, spp, &registry);
    }
    packets(&scene_path, spp, &registry);
}

/// lumis against the bare loop, and (feature `replay`) lumis's own work.
fn overhead(scene_path: &str, spp: u32, registry: &Registry) {
    #[allow(unused_mut)] // mutated only with the `replay` feature
    let mut loaded = lumis_scene::load_file(
        scene_path.as_ref(),
        &[format!("sampler.spp={spp}")],
        registry,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let settings = RenderSettings {
        spp,
        seed: loaded.seed,
        threads: 1,
        progress: false,
        clamp: loaded.clamp,
    };
    let run = |scene: &dyn Scene| {
        render(
            &loaded.camera,
            scene,
            loaded.integrator.as_ref(),
            loaded.sampler.as_ref(),
            &settings,
        )
        .unwrap()
    };

    let recording = Recording {
        inner: &loaded.scene,
        rays: Mutex::new(Vec::new()),
    };
    run(&recording);
    let rays = recording.rays.into_inner().unwrap();

    let repeats = 5;
    let mut lumis_best = f64::INFINITY;
    let mut bare_best = f64::INFINITY;
    let mut dependent_best = f64::INFINITY;
    let mut stats = None;
    for _ in 0..repeats {
        let out = run(&loaded.scene);
        lumis_best = lumis_best.min(out.seconds);
        stats = Some(out.stats);
        let start = Instant::now();
        let hits = bare::trace(loaded.scene.embree(), &rays);
        bare_best = bare_best.min(start.elapsed().as_secs_f64());
        std::hint::black_box(hits);
        let start = Instant::now();
        let hits = bare::trace_dependent(loaded.scene.embree(), &rays);
        dependent_best = dependent_best.min(start.elapsed().as_secs_f64());
        std::hint::black_box(hits);
    }
    let stats = stats.unwrap();
    assert_eq!(
        stats.total_rays(),
        rays.len() as u64,
        "the timed render traced the recorded rays"
    );
    let n = rays.len() as f64;
    let lumis_rate = n / lumis_best;
    let bare_rate = n / bare_best;
    println!("scene {scene_path}, {spp} spp, 1 thread, best of {repeats}");
    println!(
        "rays: {} ({} closest-hit, {} shadow)",
        rays.len(),
        stats.rays,
        stats.shadow_rays
    );
    println!(
        "lumis path tracer: {:.3} s, {:.2} Mrays/s, {:.3} Msamples/s",
        lumis_best,
        lumis_rate * 1e-6,
        stats.samples as f64 / lumis_best * 1e-6
    );
    println!(
        "bare Embree loop:  {:.3} s, {:.2} Mrays/s",
        bare_best,
        bare_rate * 1e-6
    );
    println!(
        "bare Embree loop, each ray waiting for the previous one: {:.3} s, {:.2} Mrays/s",
        dependent_best,
        n / dependent_best * 1e-6
    );
    println!(
        "ratio lumis/bare rays per second: {:.3}",
        lumis_rate / bare_rate
    );
    println!(
        "ratio lumis/dependent bare rays per second: {:.3}",
        lumis_rate / (n / dependent_best)
    );

    // With the `replay` feature: the same render answering every query from
    // a recording of Embree's answers, which times lumis's own work alone
    // (`lumis - bare` above also holds what the two cost each other: caches
    // and branch predictors that traversal and shading evict for each
    // other).
    #[cfg(feature = "replay")]
    {
        loaded.scene.embree_mut().record_queries();
        run(&loaded.scene);
        let mut own_best = f64::INFINITY;
        for _ in 0..repeats {
            let recorded = loaded.scene.embree_mut().replay_queries();
            let out = run(&loaded.scene);
            // Every recorded answer handed out, and no query beyond them
            // (one would have traversed).
            assert_eq!(
                loaded.scene.embree().replayed_queries(),
                recorded,
                "the replaying render asked every recorded query"
            );
            assert_eq!(
                (out.stats.rays, out.stats.shadow_rays),
                (recorded.0 as u64, recorded.1 as u64),
                "the replaying render asked only the recorded queries"
            );
            own_best = own_best.min(out.seconds);
        }
        loaded.scene.embree_mut().stop_replay();
        println!("lumis replaying Embree's answers (its own work): {own_best:.3} s");
        println!(
            "own work / bare traversal: {:.3} (the target ratio 0.5 needs <= 1)",
            own_best / bare_best
        );
        println!(
            "lumis - bare - own work (what traversal and lumis cost each other): {:.3} s",
            lumis_best - bare_best - own_best
        );
    }
}

/// What a ray of a wavefront batch is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    /// From the camera (a pinhole: every one starts at its origin).
    Camera,
    /// From a surface, sampled by a BSDF.
    Bounce,
    Shadow,
}

const KINDS: [Kind; 3] = [Kind::Camera, Kind::Bounce, Kind::Shadow];

/// One batch the integrator handed the scene.
struct Batch {
    shadow: bool,
    rays: Vec<BareRay>,
    /// The rays as the scene saw them, for the renderer's own batch query.
    queries: Vec<Ray>,
    kinds: Vec<Kind>,
}

impl Batch {
    /// The maximal runs of one kind, as `(kind, rays)`.
    fn runs(&self) -> impl Iterator<Item = (Kind, &[BareRay])> {
        let mut start = 0;
        self.kinds.chunk_by(|a, b| a == b).map(move |run| {
            let rays = &self.rays[start..start + run.len()];
            start += run.len();
            (run[0], rays)
        })
    }
}

/// Delegates to the real scene and records every batch (a single query as
/// a batch of one).
struct BatchRecording<'a> {
    inner: &'a dyn Scene,
    camera_origin: [f32; 3],
    batches: Mutex<Vec<Batch>>,
}

impl BatchRecording<'_> {
    fn record(&self, rays: &[Ray], shadow: bool) {
        let bare: Vec<BareRay> = rays
            .iter()
            .map(|ray| BareRay {
                org: ray.o.into(),
                dir: ray.d.into(),
                tfar: ray.t_max,
                shadow,
            })
            .collect();
        let kinds = bare
            .iter()
            .map(|r| match (shadow, r.org == self.camera_origin) {
                (true, _) => Kind::Shadow,
                (false, true) => Kind::Camera,
                (false, false) => Kind::Bounce,
            })
            .collect();
        self.batches.lock().unwrap().push(Batch {
            shadow,
            rays: bare,
            queries: rays.to_vec(),
            kinds,
        });
    }
}

impl Scene for BatchRecording<'_> {
    fn intersect(&self, ray: &Ray) -> Option<SurfaceInteraction<'_>> {
        self.record(std::slice::from_ref(ray), false);
        self.inner.intersect(ray)
    }
    fn occluded(&self, ray: &Ray) -> bool {
        self.record(std::slice::from_ref(ray), true);
        self.inner.occluded(ray)
    }
    fn intersect_batch<'s>(&'s self, rays: &[Ray], out: &mut [Option<SurfaceInteraction<'s>>]) {
        self.record(rays, false);
        self.inner.intersect_batch(rays, out)
    }
    fn occluded_batch(&self, rays: &[Ray], out: &mut [bool]) {
        self.record(rays, true);
        self.inner.occluded_batch(rays, out)
    }
    fn lights(&self) -> &[Box<dyn Light>] {
        self.inner.lights()
    }
    fn infinite_lights(&self) -> &[u32] {
        self.inner.infinite_lights()
    }
    fn light_sampler(&self) -> &dyn LightSampler {
        self.inner.light_sampler()
    }
}

/// The renderer's scene without its batch overrides: the trait's default
/// loops over its single-ray queries, which is what a wavefront render
/// costs without packets.
struct Defaults<'a>(&'a lumis_scene::RenderScene);

impl Scene for Defaults<'_> {
    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<SurfaceInteraction<'_>> {
        self.0.intersect(ray)
    }
    #[inline]
    fn occluded(&self, ray: &Ray) -> bool {
        self.0.occluded(ray)
    }
    fn lights(&self) -> &[Box<dyn Light>] {
        self.0.lights()
    }
    fn infinite_lights(&self) -> &[u32] {
        self.0.infinite_lights()
    }
    fn light_sampler(&self) -> &dyn LightSampler {
        self.0.light_sampler()
    }
}

/// The best of `repeats` timings of each of `fs`, run in turns so that
/// drifts of the machine's speed reach them alike; checks that they all
/// return the same (a count of hits).
fn best_of_each(repeats: usize, fs: &mut [&mut dyn FnMut() -> u64]) -> Vec<f64> {
    let mut best = vec![f64::INFINITY; fs.len()];
    let mut value = None;
    for _ in 0..repeats {
        for (f, best) in fs.iter_mut().zip(&mut best) {
            let start = Instant::now();
            let v = std::hint::black_box(f());
            *best = best.min(start.elapsed().as_secs_f64());
            assert!(value.is_none_or(|w| w == v), "the same answers every way");
            value = Some(v);
        }
    }
    best
}

/// Packets against single rays on the wavefront integrator's batches.
fn packets(scene_path: &str, spp: u32, registry: &Registry) {
    let loaded = lumis_scene::load_file(
        scene_path.as_ref(),
        &[
            format!("sampler.spp={spp}"),
            "integrator.type=\"wavefront\"".to_string(),
        ],
        registry,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let settings = RenderSettings {
        spp,
        seed: loaded.seed,
        threads: 1,
        progress: false,
        clamp: loaded.clamp,
    };
    let camera_ray = loaded.camera.generate_ray(UVec2::ZERO, Vec2::splat(0.5));
    let recording = BatchRecording {
        inner: &loaded.scene,
        camera_origin: camera_ray.o.into(),
        batches: Mutex::new(Vec::new()),
    };
    render(
        &loaded.camera,
        &recording,
        loaded.integrator.as_ref(),
        loaded.sampler.as_ref(),
        &settings,
    )
    .unwrap();
    let batches = recording.batches.into_inner().unwrap();
    let embree = loaded.scene.embree();
    let repeats = 5;

    let count = |shadow: bool| {
        let of_kind = batches.iter().filter(|b| b.shadow == shadow);
        let sizes: Vec<usize> = of_kind.map(|b| b.rays.len()).collect();
        let rays: usize = sizes.iter().sum();
        (sizes.len(), rays as f64 / sizes.len().max(1) as f64)
    };
    let ((hit_batches, hit_mean), (shadow_batches, shadow_mean)) = (count(false), count(true));
    println!();
    println!("scene {scene_path}, {spp} spp, wavefront batches, 1 thread, best of {repeats}");
    println!(
        "{hit_batches} closest-hit batches ({hit_mean:.0} rays on average), {shadow_batches} shadow batches ({shadow_mean:.0})"
    );
    let variants: Vec<Packets> = [false, true]
        .into_iter()
        .flat_map(|coherent| PacketWidth::ALL.map(|width| Packets { width, coherent }))
        .collect();
    let name = |p: &Packets| format!("{}{}", p.width.lanes(), if p.coherent { "c" } else { "" });
    println!(
        "rays per second of packets / of single rays, by kind (n = packets of n, nc = with the coherence hint):"
    );
    print!("{:>7} {:>10} {:>12}", "kind", "rays", "single Mr/s");
    for p in &variants {
        print!(" {:>6}", name(p));
    }
    println!();
    for kind in KINDS {
        let runs: Vec<&[BareRay]> = batches
            .iter()
            .flat_map(|b| b.runs())
            .filter(|&(k, _)| k == kind)
            .map(|(_, rays)| rays)
            .collect();
        let n: usize = runs.iter().map(|r| r.len()).sum();
        if n == 0 {
            continue;
        }
        let runs = &runs;
        let mut single = || runs.iter().map(|r| bare::trace(embree, r)).sum();
        let mut packed: Vec<_> = variants
            .iter()
            .map(|&p| move || runs.iter().map(|r| bare::trace_packets(embree, p, r)).sum())
            .collect();
        let mut fs: Vec<&mut dyn FnMut() -> u64> = vec![&mut single];
        fs.extend(packed.iter_mut().map(|f| f as &mut dyn FnMut() -> u64));
        let times = best_of_each(repeats, &mut fs);
        print!(
            "{:>7} {:>10} {:>12.3}",
            format!("{kind:?}"),
            n,
            n as f64 / times[0] * 1e-6
        );
        for t in &times[1..] {
            print!(" {:>6.3}", times[0] / t);
        }
        println!();
    }

    // How many camera rays the renderer's rule (camera packets of 8) can
    // trace as packets: those in whole packets from a run's start.
    let lanes = PacketWidth::Eight.lanes();
    let (camera, packed): (usize, usize) = batches
        .iter()
        .flat_map(|b| b.runs())
        .filter(|&(k, _)| k == Kind::Camera)
        .map(|(_, rays)| (rays.len(), rays.len() - rays.len() % lanes))
        .fold((0, 0), |(a, b), (c, d)| (a + c, b + d));
    println!(
        "camera rays in whole packets of {lanes} within their run: {:.1}%",
        100.0 * packed as f64 / camera.max(1) as f64
    );

    // Whole batches, camera and bounce rays mixed as the integrator hands
    // them over: ray by ray (the trait's default loop over `intersect`), and
    // through the renderer's own `intersect_batch`, with shading, so that
    // conversions and the choice between packets and single rays count;
    // then the same with `[accel] packets`.
    let hit_batches: Vec<&Batch> = batches.iter().filter(|b| !b.shadow).collect();
    let shadow_batches: Vec<&Batch> = batches.iter().filter(|b| b.shadow).collect();
    let mut loaded = loaded;
    for packets in [false, true] {
        loaded.scene.set_packets(packets);
        let scene = &loaded.scene;
        // The trait's default loop, on a buffer prepared as for the batch.
        let mut by_ray = || {
            let mut out = Vec::new();
            hit_batches
                .iter()
                .map(|b| {
                    out.clear();
                    out.resize(b.queries.len(), None);
                    for (ray, out) in b.queries.iter().zip(&mut out) {
                        *out = scene.intersect(ray);
                    }
                    std::hint::black_box(&mut out);
                    out.iter().filter(|h| h.is_some()).count() as u64
                })
                .sum()
        };
        let mut batched = || {
            let mut out = Vec::new();
            hit_batches
                .iter()
                .map(|b| {
                    out.clear();
                    out.resize(b.queries.len(), None);
                    scene.intersect_batch(&b.queries, &mut out);
                    std::hint::black_box(&mut out);
                    out.iter().filter(|h| h.is_some()).count() as u64
                })
                .sum()
        };
        let mut shadow_by_ray = || {
            let mut out = Vec::new();
            shadow_batches
                .iter()
                .map(|b| {
                    out.clear();
                    out.resize(b.queries.len(), false);
                    for (ray, out) in b.queries.iter().zip(&mut out) {
                        *out = scene.occluded(ray);
                    }
                    std::hint::black_box(&mut out);
                    out.iter().filter(|&&o| o).count() as u64
                })
                .sum()
        };
        let mut shadow_batched = || {
            let mut out = Vec::new();
            shadow_batches
                .iter()
                .map(|b| {
                    out.clear();
                    out.resize(b.queries.len(), false);
                    scene.occluded_batch(&b.queries, &mut out);
                    std::hint::black_box(&mut out);
                    out.iter().filter(|&&o| o).count() as u64
                })
                .sum()
        };
        let t = best_of_each(repeats, &mut [&mut by_ray, &mut batched]);
        let s = best_of_each(repeats, &mut [&mut shadow_by_ray, &mut shadow_batched]);
        println!(
            "RenderScene, [accel] packets = {packets}: intersect_batch {:.3} s, ray by ray {:.3} s, ratio {:.3}; occluded_batch {:.3} s, ray by ray {:.3} s, ratio {:.3} (rays per second, batch / ray by ray)",
            t[1],
            t[0],
            t[0] / t[1],
            s[1],
            s[0],
            s[0] / s[1]
        );
    }

    // Whole wavefront renders (one thread): the renderer's scene with its
    // batch overrides, with `[accel] packets`, and without the overrides.
    let render_with = |scene: &dyn Scene| {
        let out = render(
            &loaded.camera,
            scene,
            loaded.integrator.as_ref(),
            loaded.sampler.as_ref(),
            &settings,
        )
        .unwrap();
        out.stats.total_rays()
    };
    let mut times = Vec::new();
    for packets in [false, true] {
        loaded.scene.set_packets(packets);
        let scene = &loaded.scene;
        let mut defaults = || render_with(&Defaults(scene));
        let mut overrides = || render_with(scene);
        let t = best_of_each(repeats, &mut [&mut defaults, &mut overrides]);
        times.push(t);
    }
    println!(
        "wavefront render: RenderScene overrides {:.3} s, trait defaults (ray by ray) {:.3} s, ratio {:.3}; with [accel] packets {:.3} s, defaults {:.3} s, ratio {:.3} (rays per second, over the defaults of the same round)",
        times[0][1],
        times[0][0],
        times[0][0] / times[0][1],
        times[1][1],
        times[1][0],
        times[1][0] / times[1][1],
    );
}
