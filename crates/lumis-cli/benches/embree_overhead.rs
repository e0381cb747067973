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
//! `cargo bench -p lumis-cli --bench embree_overhead [--features replay] [-- SCENE.toml SPP]`
//!
//! The default is the Cornell box at 64 spp, the setting the throughput
//! target is stated for (25M rays, 0.8 GB of recorded rays); fewer samples
//! per pixel weigh per-pixel set-up (such as the Sobol' sampler's) more.

use std::sync::Mutex;
use std::time::Instant;

use lumis_core::{Light, LightSampler, Ray, Scene, SurfaceInteraction};
use lumis_embree::bare::{self, BareRay};
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
    let registry = lumis_cli::builtin_registry().expect("plugins register");
    #[allow(unused_mut)] // mutated only with the `replay` feature
    let mut loaded = lumis_scene::load_file(
        scene_path.as_ref(),
        &[format!("sampler.spp={spp}")],
        &registry,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let settings = RenderSettings {
        spp,
        seed: loaded.seed,
        threads: 1,
        progress: false,
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
    // Packets against single rays, on the same rays grouped by kind (in
    // the recorded order within each kind: eight consecutive closest-hit
    // rays are mostly one pixel's samples at one depth).
    let mut by_kind = rays.clone();
    by_kind.sort_by_key(|r| r.shadow);
    let (mut single_best, mut packet_best) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..repeats {
        let start = Instant::now();
        let single = bare::trace(loaded.scene.embree(), &by_kind);
        single_best = single_best.min(start.elapsed().as_secs_f64());
        let start = Instant::now();
        let packed = bare::trace_packets(loaded.scene.embree(), &by_kind);
        packet_best = packet_best.min(start.elapsed().as_secs_f64());
        assert_eq!(single, packed, "packets find what single rays find");
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
    println!(
        "bare loop over the rays grouped by kind: single rays {single_best:.3} s, packets of {} {packet_best:.3} s, ratio packets/single rays per second {:.3}",
        lumis_embree::PACKET,
        single_best / packet_best
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
