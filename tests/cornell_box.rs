//! The Cornell box of `scenes/cornell-box.toml` against an established
//! renderer's converged image, estimator agreement, and determinism.

use lumis_core::{Ray, Scene, Vec3};
use lumis_image::read_exr;
use lumis_render::{render, RenderSettings};
use lumis_tests::{assert_same_mean, bonferroni_z, read_scene, render_toml, scenes_dir, Opaque};

const BLOCK: usize = 32;

/// Pixel means agree with Mitsuba 3's 8192-spp reference of the same scene
/// (`scenes/reference/cornell_box_mitsuba.py`) in every 32x32 block.
#[test]
fn matches_mitsuba_reference() {
    let reference =
        read_exr(&scenes_dir().join("reference/cornell-box-mitsuba.exr")).expect("reference image");
    let out = render_toml(&read_scene("cornell-box.toml"), &["sampler.spp=32"], 0);
    assert_eq!(out.stats.nonfinite, 0);
    let blocks = (256 / BLOCK) * (256 / BLOCK) * 3;
    let worst = assert_same_mean(
        &out.image,
        &reference,
        BLOCK,
        bonferroni_z(1e-3, blocks),
        "lumis vs Mitsuba",
    );
    eprintln!("largest block z-score against Mitsuba: {worst:.2}");
}

/// BSDF-only, light-only and MIS estimators (balance and power) are all
/// unbiased: their images of the same pixels agree in the mean.
#[test]
fn estimators_agree_in_the_mean() {
    let scene = read_scene("cornell-box.toml");
    let render = |overrides: &[&str]| {
        let mut all = vec!["film.resolution=[64, 64]", "sampler.spp=64"];
        all.extend_from_slice(overrides);
        render_toml(&scene, &all, 0).image
    };
    let mis_power = render(&[
        "integrator.strategy=mis",
        "integrator.heuristic=power",
        "seed=1",
    ]);
    let others = [
        ("bsdf", render(&["integrator.strategy=bsdf", "seed=2"])),
        ("light", render(&["integrator.strategy=light", "seed=3"])),
        (
            "mis-balance",
            render(&[
                "integrator.strategy=mis",
                "integrator.heuristic=balance",
                "seed=4",
            ]),
        ),
    ];
    let block = 16;
    let tests = others.len() * (64 / block) * (64 / block) * 3;
    let z = bonferroni_z(1e-3, tests);
    for (name, image) in &others {
        assert_same_mean(image, &mis_power, block, z, &format!("{name} vs mis-power"));
    }
}

/// The same scene, seed and spp give a bit-identical image on 1, 2 and 3
/// threads, with `path` and with the integrators that batch paths.
#[test]
fn bit_identical_for_any_thread_count() {
    let scene = read_scene("cornell-box.toml");
    for integrator in ["path", "wavefront", "packet"] {
        let integrator = format!("integrator.type=\"{integrator}\"");
        let overrides = [
            "film.resolution=[48, 40]",
            "sampler.spp=4",
            "seed=7",
            &integrator,
        ];
        let one = render_toml(&scene, &overrides, 1);
        let two = render_toml(&scene, &overrides, 2);
        let three = render_toml(&scene, &overrides, 3);
        assert!(one.image.pixels.iter().any(|p| p[0] > 0.0));
        assert_eq!(one.image, two.image, "{integrator}");
        assert_eq!(one.image, three.image, "{integrator}");
        assert_eq!(one.stats, two.stats, "{integrator}");
    }
    let overrides = ["film.resolution=[48, 40]", "sampler.spp=4", "seed=7"];
    let one = render_toml(&scene, &overrides, 1);
    let other_seed = render_toml(
        &scene,
        &["film.resolution=[48, 40]", "sampler.spp=4", "seed=8"],
        2,
    );
    assert_ne!(one.image, other_seed.image);
}

/// The integrators compile their loop for lumis's own scene type and for
/// `dyn Scene` (`Specialized` in `plugins/integrators`, which
/// `builtin_registry` registers for `RenderScene`): both give the same
/// image, bit for bit, for every integrator and strategy.
#[test]
fn concrete_and_dyn_scene_loops_agree() {
    let registry = lumis_app::builtin_registry().expect("built-in plugins register");
    let path = read_scene("cornell-box.toml");
    let path_keys = "type = \"path\"\nmax_depth = 8\nrr_depth = 5\n";
    assert!(path.contains(path_keys));
    let direct = path.replace(path_keys, "type = \"direct\"\n");
    for (scene, integrator) in [
        (&path, &["integrator.strategy=\"mis\""][..]),
        (&path, &["integrator.strategy=\"bsdf\""]),
        (
            &path,
            &["integrator.strategy=\"light\"", "integrator.n_g=2"],
        ),
        (&path, &["integrator.estimator=\"one-sample\""]),
        (&direct, &["integrator.n_f=2"]),
    ] {
        let mut overrides = vec![
            "film.resolution=[40, 32]".to_string(),
            "sampler.spp=4".to_string(),
        ];
        overrides.extend(integrator.iter().map(|s| s.to_string()));
        let loaded = lumis_scene::load_str(
            scene,
            &scenes_dir().join("test.toml"),
            &overrides,
            &registry,
        )
        .unwrap_or_else(|e| panic!("{integrator:?}: {e}"));
        let settings = RenderSettings {
            spp: 4,
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
            .expect("render succeeds")
        };
        assert!(
            loaded.scene.as_any().is_some(),
            "the scene offers its concrete type"
        );
        let concrete = run(&loaded.scene);
        let opaque = run(&Opaque(&loaded.scene));
        assert!(concrete.image.pixels.iter().any(|p| p[0] > 0.0));
        assert_eq!(concrete.image, opaque.image, "{integrator:?}");
        assert_eq!(concrete.stats, opaque.stats, "{integrator:?}");
    }
}

/// A scene that keeps the fast BVH stores each flat-shaded triangle's
/// shading frame (`MeshData::flat_frames`); a hit that loads it must see
/// the surface a hit computing it from Embree's normal sees: the same
/// point and error bound, and the same frame up to rounding. The compact
/// build stores none, so it is the computed side. A flipped quad in the
/// middle of the box checks that the stored frames face the same way.
#[test]
fn stored_flat_frames_match_frames_computed_at_the_hit() {
    let registry = lumis_app::builtin_registry().expect("built-in plugins register");
    let scene = read_scene("cornell-box.toml")
        + "\n[[shape]]\ntype = \"quad\"\ncorner = [-0.3, -0.2, 0.2]\n\
           edge_u = [0.5, 0.1, 0.0]\nedge_v = [0.1, 0.4, 0.3]\n\
           bsdf = \"white\"\nflip_normals = true\n";
    let load = |overrides: &[String]| {
        lumis_scene::load_str(
            &scene,
            &scenes_dir().join("test.toml"),
            overrides,
            &registry,
        )
        .expect("the Cornell box loads")
    };
    let stored = load(&[]);
    let computed = load(&["accel.compact=true".to_string()]);
    let (stored_report, computed_report) =
        (stored.scene.load_report(), computed.scene.load_report());
    assert!(!stored_report.compact && computed_report.compact);
    // 38 flat triangles, one 48-byte frame each.
    assert_eq!(
        stored_report.geometry_bytes - computed_report.geometry_bytes,
        38 * std::mem::size_of::<lumis_core::math::Frame>()
    );

    let origins = [
        Vec3::new(0.0, 0.0, 3.9),
        Vec3::new(0.1, 0.2, 0.3),
        Vec3::new(-0.7, -0.9, 0.8),
        Vec3::new(0.6, 0.9, -0.6),
    ];
    // The quad's edges cross to +z and its front is flipped.
    let quad_normal = Vec3::new(0.5, 0.1, 0.0)
        .cross(Vec3::new(0.1, 0.4, 0.3))
        .normalize();
    let close = |u: lumis_core::glam::Vec3A, v: lumis_core::glam::Vec3A| (u - v).length() < 1e-6;
    let (mut hits, mut light_hits, mut flipped_hits) = (0, 0, 0);
    for o in origins {
        // Directions on a Fibonacci sphere, so every wall, both boxes and
        // the light are hit from inside the box.
        let n = 4000;
        for i in 0..n {
            let z = 1.0 - (2 * i + 1) as f32 / n as f32;
            let phi = i as f32 * 2.399_963;
            let r = (1.0 - z * z).sqrt();
            let ray = Ray::new(o, Vec3::new(r * phi.cos(), r * phi.sin(), z));
            let (a, b) = (stored.scene.intersect(&ray), computed.scene.intersect(&ray));
            let (Some(a), Some(b)) = (a, b) else {
                assert!(
                    a.is_none() && b.is_none(),
                    "one build hit and the other did not: {ray:?}"
                );
                continue;
            };
            hits += 1;
            light_hits += usize::from(a.light.is_some());
            flipped_hits += usize::from((a.n() + quad_normal).length() < 1e-5);
            assert_eq!(a.point.p, b.point.p);
            assert_eq!(a.point.p_error, b.point.p_error);
            assert_eq!((a.light, a.texture), (b.light, b.texture));
            assert!((a.n() - b.n()).length() < 1e-6, "{ray:?}");
            assert!(
                close(a.shading.x, b.shading.x)
                    && close(a.shading.y, b.shading.y)
                    && close(a.shading.z, b.shading.z),
                "{ray:?}: {:?} against {:?}",
                a.shading,
                b.shading
            );
        }
    }
    assert!(
        hits > 9_000 && light_hits > 50 && flipped_hits > 50,
        "only {hits} rays hit, {light_hits} of them the light, {flipped_hits} the flipped quad"
    );
}
