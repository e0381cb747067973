//! Every scene of the bench suite (`scenes/bench/`) loads and renders, at a
//! tiny size, to a finite image that is not black, so that the suite the
//! performance numbers come from cannot rot between benchmark runs. Scenes
//! whose assets are fetched or made on demand (the dragon scan, the
//! measured table) are rendered when those files exist and skipped with
//! the reason printed otherwise (`python3 scripts/peer-bench/fetch_assets.py`
//! and `peer_bench.py` make them; docs/src/bench-suite.md).

use std::path::Path;

use lumis_tests::{render_loaded, scenes_dir};

#[test]
fn every_bench_scene_renders() {
    let dir = scenes_dir().join("bench");
    let registry = lumis_app::builtin_registry().unwrap();
    let mut scenes: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 9, "{scenes:?}");
    let mut rendered = 0;
    for scene in &scenes {
        let text = std::fs::read_to_string(scene).unwrap();
        if let Some(missing) = missing_asset(&text, &dir) {
            println!(
                "skipped {}: {missing} is made on demand (docs/src/bench-suite.md)",
                scene.display()
            );
            continue;
        }
        let set = [
            "film.resolution=[24, 16]".to_string(),
            "sampler.spp=4".to_string(),
        ];
        let loaded = lumis_scene::load_file(scene, &set, &registry)
            .unwrap_or_else(|e| panic!("{}: {e}", scene.display()));
        let out = render_loaded(&loaded, 0);
        assert_eq!(out.stats.nonfinite, 0, "{}", scene.display());
        let sum: f64 = out
            .image
            .pixels
            .iter()
            .flat_map(|p| p.iter().map(|&c| c as f64))
            .sum();
        assert!(
            sum.is_finite() && sum > 0.0,
            "{}: black image",
            scene.display()
        );
        rendered += 1;
    }
    assert!(rendered >= 6, "only {rendered} bench scenes rendered");
}

/// The first `assets/...` file the scene names that does not exist.
fn missing_asset(text: &str, dir: &Path) -> Option<String> {
    text.lines()
        .filter(|l| !l.trim_start().starts_with('#'))
        .filter_map(|l| l.split('"').nth(1))
        .filter(|f| f.starts_with("assets/"))
        .find(|f| !dir.join(f).exists())
        .map(str::to_string)
}
