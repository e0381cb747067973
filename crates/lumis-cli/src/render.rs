//! `lumis render`: load, render, write EXR and PNG, report.

use std::path::{Path, PathBuf};

use lumis_core::{Error, RenderStats, Result, Sampler, Scene};
use lumis_image::Image;
use lumis_render::profile::{Profile, ProfileReport, ProfiledSampler, ProfiledScene};
use lumis_render::{render, RenderSettings};
use lumis_scene::LoadedScene;

/// What `lumis render` was asked to do; also its command-line flags.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct RenderArgs {
    /// The scene file.
    pub scene: PathBuf,
    /// Samples per pixel (overrides sampler.spp).
    #[arg(long)]
    pub spp: Option<u32>,
    /// Random seed (overrides the scene's top-level seed).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Worker threads; 0 or absent means one per core.
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// Output path: writes PATH.exr and PATH.png [default: the scene's
    /// film.output, else SCENE-NAME.exr in the current directory].
    #[arg(long, short)]
    pub output: Option<PathBuf>,
    /// Override any scene value, e.g. --set integrator.max_depth=3,
    /// --set bsdf.white.reflectance=[0.5,0.5,0.5], --set sampler.type=independent.
    /// Arrays of tables are addressed by name or index (shape.0.file).
    #[arg(long = "set", value_name = "KEY.PATH=VALUE")]
    pub set: Vec<String>,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
    /// Print what the loader decided the scene needs.
    #[arg(long, short)]
    pub verbose: bool,
    /// Report where the render's time went: traversal, shading, sampling,
    /// light sampling (statistical profile; the render runs a few percent
    /// slower).
    #[arg(long)]
    pub stats: bool,
}

/// The outcome of a render, for the summary line and for tests.
pub struct RenderReport {
    pub image: Image,
    pub exr: PathBuf,
    pub png: PathBuf,
    pub spp: u32,
    pub seconds: f64,
    pub stats: RenderStats,
    /// Time by stage, with `--stats`.
    pub profile: Option<ProfileReport>,
}

impl RenderReport {
    /// The one-line summary printed at the end of a render.
    pub fn summary(&self) -> String {
        let secs = self.seconds.max(1e-9);
        format!(
            "{}x{}, {} spp, {:.2} s, {:.3} Msamples/s, {:.2} Mrays/s ({} closest-hit and {} shadow rays), {} NaN/Inf samples, emission found by {} BSDF samples and {} light samples -> {}",
            self.image.width,
            self.image.height,
            self.spp,
            self.seconds,
            self.stats.samples as f64 / secs * 1e-6,
            self.stats.total_rays() as f64 / secs * 1e-6,
            self.stats.rays,
            self.stats.shadow_rays,
            self.stats.nonfinite,
            self.stats.bsdf_light_hits,
            self.stats.light_samples,
            self.exr.display(),
        )
    }
}

/// `PATH.exr` and `PATH.png` for an output argument given with `.exr`,
/// `.png` or neither; for a directory (one that exists, or a path ending
/// in a separator), `NAME.exr` and `NAME.png` in it.
pub fn output_paths(output: &Path, name: &str) -> (PathBuf, PathBuf) {
    let names_a_directory = output.is_dir()
        || output
            .as_os_str()
            .to_string_lossy()
            .ends_with(std::path::MAIN_SEPARATOR);
    let stem = if names_a_directory {
        output.join(name)
    } else if output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr") || e.eq_ignore_ascii_case("png"))
    {
        output.with_extension("")
    } else {
        output.to_path_buf()
    };
    let with = |ext: &str| {
        let mut s = stem.clone().into_os_string();
        s.push(".");
        s.push(ext);
        PathBuf::from(s)
    };
    (with("exr"), with("png"))
}

/// Loads the scene, applying `--spp`/`--seed` as overrides so they reach the
/// same parameters a scene file sets.
pub fn load(args: &RenderArgs, registry: &lumis_core::Registry) -> Result<LoadedScene> {
    let mut set = args.set.clone();
    if let Some(spp) = args.spp {
        set.push(format!("sampler.spp={spp}"));
    }
    if let Some(seed) = args.seed {
        set.push(format!("seed={seed}"));
    }
    lumis_scene::load_file(&args.scene, &set, registry)
}

/// Describes what the loader decided the scene needs (`-v`).
fn describe(loaded: &LoadedScene) -> String {
    let c = loaded.scene.counts();
    let lights = c.area_lights + c.delta_lights + c.infinite_lights;
    format!(
        "scene '{}': {} meshes ({} triangles, {} instances), {} spheres; {} lights ({} area, {} delta, {} infinite); \
         shading normals: {}; MIS: {}",
        loaded.name,
        c.meshes,
        c.triangles,
        c.instances,
        c.spheres,
        lights,
        c.area_lights,
        c.delta_lights,
        c.infinite_lights,
        if c.shading_normals { "interpolated" } else { "flat (none stored)" },
        if c.area_lights + c.infinite_lights > 0 {
            "can matter (lights that BSDF rays can hit)"
        } else {
            "cannot matter (only delta lights: light sampling gets weight 1)"
        },
    )
}

/// Renders a scene file and writes `PATH.exr` and `PATH.png`.
pub fn render_scene_file(
    args: &RenderArgs,
    registry: &lumis_core::Registry,
) -> Result<RenderReport> {
    let mut loaded = load(args, registry)?;
    if !args.quiet {
        for line in loaded.scene.load_report().lines(loaded.scene.counts()) {
            eprintln!("{line}");
        }
    }
    if args.verbose {
        eprintln!("{}", describe(&loaded));
    }
    let output = match (&args.output, &loaded.output) {
        (Some(o), _) => o.clone(),
        (None, Some(o)) => o.clone(),
        (None, None) => PathBuf::from(format!("{}.exr", loaded.name)),
    };
    let (exr, png) = output_paths(&output, &loaded.name);
    // Fail before rendering, not after, when the output cannot be written.
    if let Some(dir) = exr.parent().filter(|d| !d.as_os_str().is_empty()) {
        if !dir.is_dir() {
            return Err(Error::msg(format!(
                "output directory '{}' does not exist (for {})",
                dir.display(),
                exr.display()
            )));
        }
    }
    crate::warn_if_threads_capped(args.threads);
    let settings = RenderSettings {
        spp: loaded.sampler.samples_per_pixel(),
        seed: loaded.seed,
        threads: args.threads,
        progress: !args.quiet,
    };
    // With --stats the scene, its plugins and the sampler run inside the
    // profiling wrappers; the render itself is the same call.
    if args.stats {
        loaded.scene = loaded.scene.into_profiled();
    }
    let profiled_scene = ProfiledScene(&loaded.scene);
    let profiled_sampler = args
        .stats
        .then(|| ProfiledSampler(loaded.sampler.clone_sampler()));
    let (scene, sampler): (&dyn Scene, &dyn Sampler) = match &profiled_sampler {
        Some(sampler) => (&profiled_scene, sampler),
        None => (&loaded.scene, loaded.sampler.as_ref()),
    };
    let profile = args.stats.then(Profile::start);
    let out = render(
        &loaded.camera,
        scene,
        loaded.integrator.as_ref(),
        sampler,
        &settings,
    );
    let profile = profile.map(Profile::finish);
    let out = out?;
    // A loaded plugin that panicked answered with neutral values: the image
    // is not the scene's, and the panic is the error.
    registry.faults().check()?;
    lumis_image::write_exr(&exr, &out.image).map_err(|e| Error::msg(e.to_string()))?;
    lumis_image::write_png(&png, &out.image).map_err(|e| Error::msg(e.to_string()))?;
    Ok(RenderReport {
        image: out.image,
        exr,
        png,
        spp: settings.spp,
        seconds: out.seconds,
        stats: out.stats,
        profile,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn output_paths_add_both_extensions() {
        let paths = |o: &str| {
            let (e, p) = output_paths(Path::new(o), "scene");
            (e.display().to_string(), p.display().to_string())
        };
        let both = |stem: &str| (format!("{stem}.exr"), format!("{stem}.png"));
        assert_eq!(paths("out/box.exr"), both("out/box"));
        assert_eq!(paths("out/box.PNG"), both("out/box"));
        assert_eq!(paths("box.v2"), both("box.v2"));
        assert_eq!(paths("renders/"), both("renders/scene"));
        let dir = std::env::temp_dir();
        assert_eq!(
            paths(&dir.display().to_string()),
            both(&dir.join("scene").display().to_string())
        );
    }
}
