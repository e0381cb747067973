//! Helpers shared by the end-to-end tests: render a scene given as TOML
//! text, and compare images with statistics rather than fixed tolerances.

pub mod gltf_writer;

use std::path::{Path, PathBuf};
use std::process::Command;

use lumis_core::{Light, LightSampler, Ray, Registry, Scene, SurfaceInteraction};
use lumis_image::Image;
use lumis_render::{render, RenderOutput, RenderSettings};
use lumis_scene::LoadedScene;

/// Loads `toml` (relative paths resolve against `scenes/`) with overrides
/// and renders it with the scene's own spp and seed.
pub fn render_toml(toml: &str, overrides: &[&str], threads: usize) -> RenderOutput {
    let registry = lumis_app::builtin_registry().expect("built-in plugins register");
    render_toml_with(&registry, toml, overrides, threads)
}

/// [`render_toml`] with a given plugin registry.
pub fn render_toml_with(
    registry: &Registry,
    toml: &str,
    overrides: &[&str],
    threads: usize,
) -> RenderOutput {
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let loaded = lumis_scene::load_str(toml, &scenes_dir().join("test.toml"), &overrides, registry)
        .unwrap_or_else(|e| panic!("scene failed to load: {e}"));
    render_loaded(&loaded, threads)
}

/// Renders a loaded scene with its own spp and seed.
pub fn render_loaded(loaded: &LoadedScene, threads: usize) -> RenderOutput {
    let settings = RenderSettings {
        spp: loaded.sampler.samples_per_pixel(),
        seed: loaded.seed,
        threads,
        progress: false,
        clamp: loaded.clamp,
    };
    render(
        &loaded.camera,
        &loaded.scene,
        loaded.integrator.as_ref(),
        loaded.sampler.as_ref(),
        &settings,
    )
    .expect("render succeeds")
}

/// Delegates every single-ray query to the scene it wraps and keeps the
/// defaults of the rest: integrators run their loop over `dyn Scene`
/// (no `as_any`), and batched queries trace ray by ray (no packets).
pub struct Opaque<'a>(pub &'a dyn Scene);

impl Scene for Opaque<'_> {
    fn intersect(&self, ray: &Ray) -> Option<SurfaceInteraction<'_>> {
        self.0.intersect(ray)
    }
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

/// `cargo build -p PACKAGE`, returning the path of the file it wrote whose
/// path ends with `suffix`.
pub fn cargo_build(package: &str, suffix: &str) -> PathBuf {
    let out = Command::new(cargo())
        .args(["build", "-p", package, "--message-format=json"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cargo runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8(out.stdout).unwrap();
    stdout
        .split('"')
        .find(|s| s.ends_with(suffix) && Path::new(s).is_file())
        .map(PathBuf::from)
        .unwrap_or_else(|| panic!("cargo reported no {suffix}:\n{stdout}"))
}

/// `cargo build -p PACKAGE`, returning the path of the plugin library
/// (cdylib) `LIB` it wrote.
pub fn build_plugin(package: &str, lib: &str) -> PathBuf {
    let name = format!(
        "{}{lib}.{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_EXTENSION
    );
    cargo_build(package, &format!("/{name}"))
}

/// A scene that loads the plugin `library` and shows the BSDF `subject`,
/// declared by `bsdf` (a `[[bsdf]]` table), on a quad lit by a small
/// emitting quad: `size` x `size` pixels at `spp`, traced by `path`.
pub fn plugin_quad_scene(library: &str, bsdf: &str, size: u32, spp: u32) -> String {
    format!(
        r#"[plugins]
load = ["{library}"]
[film]
resolution = [{size}, {size}]
[camera]
type = "perspective"
origin = [0.0, 0.0, 3.0]
target = [0.0, 0.0, 0.0]
fov = 40.0
[sampler]
type = "independent"
spp = {spp}
[integrator]
type = "path"
max_depth = 3
{bsdf}
[[shape]]
type = "quad"
corner = [-1.0, -1.0, 0.0]
edge_u = [2.0, 0.0, 0.0]
edge_v = [0.0, 2.0, 0.0]
bsdf = "subject"
[[bsdf]]
name = "white"
type = "diffuse"
reflectance = 0.5
[[shape]]
type = "quad"
corner = [1.2, -0.5, 1.5]
edge_u = [0.0, 1.0, 0.0]
edge_v = [1.0, 0.0, 0.0]
bsdf = "white"
emission = {{ radiance = [4.0, 4.0, 4.0] }}
"#
    )
}

/// `cargo build -p lumis-cli`, returning the path of the `lumis` it wrote.
pub fn build_lumis() -> PathBuf {
    cargo_build("lumis-cli", "/lumis")
}

/// The `cargo` running the tests.
pub fn cargo() -> String {
    std::env::var("CARGO").unwrap_or_else(|_| "cargo".into())
}

/// The repository's `scenes/` directory.
pub fn scenes_dir() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join("scenes")
}

/// The error loading `toml` gives, located in a scene file `bad.toml` of
/// the working directory (the scene names no files); panics if it loads.
pub fn load_error(toml: &str) -> String {
    let registry = lumis_app::builtin_registry().unwrap();
    match lumis_scene::load_str(toml, Path::new("bad.toml"), &[], &registry) {
        Ok(_) => panic!("scene unexpectedly loaded:\n{toml}"),
        Err(e) => e.to_string(),
    }
}

pub fn read_scene(name: &str) -> String {
    std::fs::read_to_string(scenes_dir().join(name)).expect("scene file exists")
}

/// Mean and standard error of the mean of `values`.
pub fn mean_and_se(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// Compares two images of the same scene block by block: for each block and
/// channel, the mean of the per-pixel differences must be within `z`
/// standard errors of zero (pixels are independent estimates, so the
/// spread of the differences measures the noise of both images). Returns
/// the largest |z| seen; panics with the block if one exceeds `z`.
pub fn assert_same_mean(a: &Image, b: &Image, block: usize, z: f64, what: &str) -> f64 {
    assert_eq!(
        (a.width, a.height),
        (b.width, b.height),
        "{what}: sizes differ"
    );
    let mut worst = 0.0f64;
    for by in (0..a.height).step_by(block) {
        for bx in (0..a.width).step_by(block) {
            for c in 0..3 {
                let mut diffs = Vec::new();
                for y in by..(by + block).min(a.height) {
                    for x in bx..(bx + block).min(a.width) {
                        diffs.push(a.get(x, y)[c] as f64 - b.get(x, y)[c] as f64);
                    }
                }
                let (mean, se) = mean_and_se(&diffs);
                // Blocks where both images are exactly equal everywhere (e.g.
                // black) have se = 0 and mean = 0: nothing to test.
                if se == 0.0 {
                    assert_eq!(
                        mean, 0.0,
                        "{what}: block ({bx}, {by}) channel {c} differs by a constant"
                    );
                    continue;
                }
                let score = mean / se;
                worst = worst.max(score.abs());
                assert!(
                    score.abs() < z,
                    "{what}: block ({bx}, {by}) channel {c}: mean difference {mean:.5} is {score:.2} standard errors ({se:.5})"
                );
            }
        }
    }
    worst
}

/// A two-sided normal quantile for significance `alpha` shared among
/// `tests` comparisons (Bonferroni), by bisection on the normal tail.
pub fn bonferroni_z(alpha: f64, tests: usize) -> f64 {
    let target = alpha / tests as f64;
    let (mut lo, mut hi) = (0.0f64, 40.0f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if two_sided_tail(mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// P(|Z| > z) for a standard normal Z, via erfc (Numerical Recipes' erfcc,
/// fractional error < 1.2e-7).
fn two_sided_tail(z: f64) -> f64 {
    let x = z / std::f64::consts::SQRT_2;
    let t = 1.0 / (1.0 + 0.5 * x);
    t * (-x * x - 1.26551223
        + t * (1.00002368
            + t * (0.37409196
                + t * (0.09678418
                    + t * (-0.18628806
                        + t * (0.27886807
                            + t * (-1.13520398
                                + t * (1.48851587 + t * (-0.82215223 + t * 0.17087277)))))))))
        .exp()
}

/// The three tables of the measured-results table
/// (docs/src/studies/measured.md): name, the BSDF `lumis brdf tabulate`
/// writes, its parameters.
pub const MEASURED_MATERIALS: [(&str, &str, &[&str]); 3] = [
    (
        "plastic-0.3",
        "plastic",
        &["roughness=0.3", "diffuse_reflectance=[0.6,0.3,0.1]"],
    ),
    (
        "conductor-0.2",
        "conductor",
        &["roughness=0.2", "material=Au"],
    ),
    (
        "conductor-0.05",
        "conductor",
        &["roughness=0.05", "material=Cu"],
    ),
];

/// The check kit on `variants` of the built-in `measured` BSDF: prints
/// the table, removes `dir` (where the tables they name were written) and
/// fails unless every case passed.
pub fn assert_measured_variants_pass(variants: &[lumis_check::bsdf_suite::Variant], dir: &Path) {
    use lumis_check::bsdf_suite::{check_bsdf_variants, format_results, BsdfCheckConfig};
    use lumis_check::outcome::Outcome;
    let registry = lumis_app::builtin_registry().unwrap();
    let results =
        check_bsdf_variants(&registry, "measured", variants, &BsdfCheckConfig::default()).unwrap();
    let report = format_results(&results);
    println!("{report}");
    std::fs::remove_dir_all(dir).unwrap();
    assert!(results.iter().all(|r| r.passed()), "{report}");
}

/// Writes the BSDF plugin `bsdf` with the `set` overrides as the MERL
/// table `dir/name.binary`, as `lumis brdf tabulate` does.
pub fn tabulated(dir: &Path, name: &str, bsdf: &str, set: &[&str]) -> std::path::PathBuf {
    let output = dir.join(format!("{name}.binary"));
    let registry = lumis_app::builtin_registry().unwrap();
    lumis_brdf::tabulate_bsdf(
        &lumis_brdf::TabulateArgs {
            bsdf: bsdf.into(),
            set: set.iter().map(|s| s.to_string()).collect(),
            output: output.clone(),
            quiet: true,
        },
        &registry,
    )
    .unwrap();
    output
}

/// Pixelwise mean of images.
pub fn mean_image(images: &[Image]) -> Image {
    let mut out = Image::new(images[0].width, images[0].height);
    for im in images {
        for (o, p) in out.pixels.iter_mut().zip(&im.pixels) {
            for c in 0..3 {
                o[c] += p[c] / images.len() as f32;
            }
        }
    }
    out
}

/// Which pixels show shape `i` entirely, for a scene rendered by
/// `render(overrides)`: make the shape emit pure blue, look at emitters
/// only, keep the pixels that are fully blue.
pub fn shape_mask(render: impl Fn(&[String]) -> Image, i: usize) -> Vec<bool> {
    let image = render(&[
        "integrator.max_depth=1".into(),
        "sampler.spp=4".into(),
        format!("shape.{i}.emission={{ radiance = [0.0, 0.0, 1.0] }}"),
    ]);
    image
        .pixels
        .iter()
        .map(|p| p[2] >= 0.999 && p[0] == 0.0)
        .collect()
}

/// Per-pixel error of one image of an estimator, from independent `runs`
/// of it: the variance across the runs (an unbiased estimator's MSE),
/// channels averaged; with `Some(epsilon)` over `ref^2 + epsilon`, the
/// relMSE (pbrt-v4 `imgtool`, Mitsuba's `relmse`), `ref` being a converged
/// image used only in that denominator.
pub fn per_pixel_error(runs: &[Image], reference: &Image, epsilon: Option<f64>) -> Vec<f64> {
    let n = runs.len() as f64;
    (0..reference.pixels.len())
        .map(|i| {
            let mut total = 0.0;
            for c in 0..3 {
                let m = runs.iter().map(|im| im.pixels[i][c] as f64).sum::<f64>() / n;
                let var = runs
                    .iter()
                    .map(|im| (im.pixels[i][c] as f64 - m).powi(2))
                    .sum::<f64>()
                    / (n - 1.0);
                total += match epsilon {
                    Some(e) => {
                        let r = reference.pixels[i][c] as f64;
                        var / (r * r + e)
                    }
                    None => var,
                };
            }
            total / 3.0
        })
        .collect()
}

/// The mean [`per_pixel_error`] over the pixels in `mask`, and its standard
/// error by the jackknife over the runs (leave one run out, recompute;
/// Efron and Stein 1981): the noise of the variance estimates themselves,
/// heavy tails included, without pretending that the pixels of a region
/// are a random sample.
pub fn region_error(
    runs: &[Image],
    reference: &Image,
    mask: &[bool],
    epsilon: Option<f64>,
) -> (f64, f64) {
    let pixels = mask.iter().filter(|&&m| m).count();
    assert!(pixels > 200, "region too small: {pixels} pixels");
    let over = |runs: &[Image]| {
        let e = per_pixel_error(runs, reference, epsilon);
        e.iter()
            .zip(mask)
            .filter(|(_, &m)| m)
            .map(|(v, _)| *v)
            .sum::<f64>()
            / pixels as f64
    };
    let full = over(runs);
    let k = runs.len();
    let leave_one_out: Vec<f64> = (0..k)
        .map(|i| {
            let rest: Vec<Image> = runs
                .iter()
                .enumerate()
                .filter(|(j, _)| *j != i)
                .map(|(_, im)| im.clone())
                .collect();
            over(&rest)
        })
        .collect();
    let m = leave_one_out.iter().sum::<f64>() / k as f64;
    let var =
        leave_one_out.iter().map(|x| (x - m).powi(2)).sum::<f64>() * (k as f64 - 1.0) / k as f64;
    (full, var.sqrt())
}

/// The green channel of the BSDF at `hit` seen from world direction `wo`
/// and lit from world direction `wi` (both unit), in the hit's own shading
/// frame and texture lookup: where a normal map's lean shows.
pub fn f_at_hit(hit: &SurfaceInteraction, wo: lumis_core::Vec3, wi: lumis_core::Vec3) -> f32 {
    let ctx = lumis_core::BsdfContext {
        texture: hit.texture,
        ..lumis_core::BsdfContext::default()
    };
    let (wo, wi) = (hit.shading.to_local(wo), hit.shading.to_local(wi));
    hit.bsdf.f(&ctx, wo, wi).g
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bonferroni_quantiles() {
        assert!((bonferroni_z(0.05, 1) - 1.96).abs() < 1e-3);
        assert!((bonferroni_z(0.01, 1) - 2.5758).abs() < 1e-3);
        assert!(bonferroni_z(0.01, 100) > 3.8);
    }
}
