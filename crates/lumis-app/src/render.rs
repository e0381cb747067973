//! A render: load, render in passes with checkpoints, write the PNG and
//! the EXR (with its metadata in the header), report.

use std::path::{Path, PathBuf};
use std::time::Instant;

use lumis_core::{Error, RenderStats, Result, Sampler, Scene};
use lumis_render::profile::{profiled_sampler, profiled_scene, Profile};
use lumis_render::{progress_units, Aov, Film, PassContext};
use lumis_scene::LoadedScene;

use crate::checkpoint::{checkpoint_path, Checkpoint};
use crate::denoise::{claim_denoised_outputs, denoise_film, ConfiguredDenoiser};
use crate::film_render::empty_film;
use crate::memory::{MemoryBudget, MemoryEstimate};
use crate::metadata::{lumis_version, other_scene_or_seed, ImageMetadata};
use crate::outputs::{partial_path, remove_if_present, Outputs};
use crate::partial::Partial;
use crate::passes::{run_passes, PassPlan, PassTotals};
use crate::render_args::{CheckpointEvery, RenderArgs};
use crate::render_report::{DenoisedReport, RenderReport};
use crate::session::Session;
use crate::slice::SampleSlice;

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

/// The film to render into: the checkpoint's with `--resume` (checked to
/// belong to this render), else an empty one.
fn starting_state(
    args: &RenderArgs,
    session: &Session,
    checkpoint: &Path,
    scene_hash: u64,
    loaded: &LoadedScene,
) -> Result<Checkpoint> {
    let (seed, aovs, adaptive) = (loaded.seed, &loaded.aovs, loaded.adaptive);
    let spp = loaded.sampler.samples_per_pixel();
    let resolution = loaded.camera.resolution();
    let saved = Checkpoint::read(checkpoint)
        .map_err(|e| Error::msg(format!("{e}; remove it to start over")))?;
    let fresh = || -> Result<Checkpoint> {
        Ok(Checkpoint {
            film: empty_film(loaded)?,
            spp,
            passes: 0,
            seed,
            scene_hash,
            seconds: 0.0,
        })
    };
    let Some(saved) = saved else {
        if args.resume {
            eprintln!(
                "no checkpoint '{}' to resume: rendering from the first sample",
                checkpoint.display()
            );
        }
        return fresh();
    };
    let refuse = |why: String| {
        Err(Error::msg(format!(
            "cannot resume '{}': {why}",
            checkpoint.display()
        )))
    };
    if !args.resume {
        return Err(Error::msg(format!(
            "'{}' holds an unfinished render ({} spp): --resume continues it; remove the file to start over",
            checkpoint.display(),
            saved.film.samples
        )));
    }
    if let Some(why) = other_scene_or_seed((saved.scene_hash, saved.seed), scene_hash, seed) {
        return refuse(why);
    }
    if (saved.film.width as u32, saved.film.height as u32) != (resolution.x, resolution.y) {
        return refuse(format!(
            "its film is {}x{}, not {}x{}",
            saved.film.width, saved.film.height, resolution.x, resolution.y
        ));
    }
    let expected = Film::try_with_aovs(lumis_core::UVec2::ONE, aovs)?.aovs;
    if saved.film.aovs != expected {
        let names = |aovs: &[Aov]| format!("{aovs:?}").to_lowercase();
        return refuse(format!(
            "it holds the outputs {}, not {}",
            names(&saved.film.aovs),
            names(&expected)
        ));
    }
    if saved.film.adaptive.as_ref().map(|a| a.settings) != adaptive {
        return refuse(format!(
            "it samples {:?}, not {adaptive:?}",
            saved.film.adaptive.as_ref().map(|a| a.settings)
        ));
    }
    if saved.spp != spp {
        return refuse(format!(
            "it is a render of {} spp, not {spp} (a sampler may place each sample by the total count)",
            saved.spp
        ));
    }
    session.note(&format!(
        "resuming '{}' at {} of {spp} spp",
        checkpoint.display(),
        saved.film.samples
    ));
    Ok(saved)
}

/// Writes the film's colour and outputs.
fn write_film(outputs: &Outputs, film: &Film, metadata: &ImageMetadata) -> Result<()> {
    outputs.write(&film.image(), &film.aov_images(), metadata)
}

/// Renders a scene file and writes `PATH.exr` and `PATH.png`, in passes,
/// saving a checkpoint as [`RenderArgs::checkpoint`] asks; with
/// [`RenderArgs::part`] or [`RenderArgs::samples`], renders that slice of
/// the sample indices to a partial EXR ([`Partial`](crate::Partial))
/// instead. Once the session's `stop` is set (by the first Ctrl-C) the
/// pass in flight is abandoned and the passes done are written, with their
/// true sample count (a part writes nothing).
pub fn render(args: &RenderArgs, session: &Session) -> Result<RenderReport> {
    let (registry, stop) = (session.registry, session.stop);
    let mut loaded = load(args, registry)?;
    if !args.quiet {
        for line in loaded.scene.load_report().lines(loaded.scene.counts()) {
            session.note(&line);
        }
        session.note(&format!("SIMD kernels: {}", lumis_sampling::simd::chosen()));
    }
    if args.verbose {
        session.note(&describe(&loaded));
    }
    if args.pass_spp == Some(0) {
        return Err(Error::msg("--pass-spp must be at least 1"));
    }
    let spp = loaded.sampler.samples_per_pixel();
    if spp == 0 {
        return Err(Error::msg("spp must be at least 1"));
    }
    let slice = args.sample_slice(spp)?;
    let memory = MemoryEstimate::of(&loaded);
    let budget = MemoryBudget::of(args.max_memory);
    if !args.quiet {
        session.note(&memory.line(&budget));
    }
    memory.check(&budget)?;
    if (slice.is_some() || args.parts.is_some()) && loaded.adaptive.is_some() {
        return Err(Error::msg(
            "--part, --samples and --parts cannot split a render with [adaptive] sampling: \
             which pixels still sample depends on all their earlier samples; remove the \
             scene's [adaptive] table to render it in parts",
        ));
    }
    // With --parts, where each part's slice ends.
    let part_ends = args
        .parts
        .map(|n| {
            (0..n)
                .map(|k| SampleSlice::part(k, n as u64, spp).map(|s| s.end))
                .collect::<std::result::Result<Vec<u32>, String>>()
                .map_err(|why| Error::msg(format!("--parts {n}: {why}")))
        })
        .transpose()?;
    // A part is short and cheap to redo: it never checkpoints.
    let every = match slice {
        Some(_) => CheckpointEvery::Never,
        None => CheckpointEvery::of(args)?,
    };
    let output = match (&args.output, &loaded.output, slice) {
        (Some(o), _, _) => o.clone(),
        (None, _, Some(s)) => {
            PathBuf::from(format!("{}.samples-{}-{}.exr", loaded.name, s.start, s.end))
        }
        (None, Some(o), None) => o.clone(),
        (None, None, None) => PathBuf::from(format!("{}.exr", loaded.name)),
    };
    let (exr, png) = output_paths(&output, &loaded.name);
    // A part writes its partial EXR only, and is not denoised (the merged
    // image is the render).
    let outputs = Outputs::claim(&exr, slice.is_none().then_some(png.as_path()))?;
    let denoiser = loaded
        .denoiser
        .take()
        .map(ConfiguredDenoiser::of_scene)
        .transpose()?;
    let denoised_outputs = denoiser
        .as_ref()
        .filter(|_| slice.is_none())
        .map(|_| claim_denoised_outputs(&exr))
        .transpose()?;
    if let Some(warning) = threads_capped(args.threads) {
        session.note(&warning);
    }
    let scene_hash = lumis_scene::scene_hash(&args.scene, &args.set)?;
    let checkpoint_file = checkpoint_path(&exr);
    let resolution = loaded.camera.resolution();
    if slice.is_none() {
        let this = (scene_hash, loaded.seed, spp);
        if let Some(existing) = finished_or_kept(args, &exr, &checkpoint_file, this)? {
            return finished_before(exr, png, &existing);
        }
    }
    let mut state = match slice {
        Some(slice) => Checkpoint {
            film: Film::try_with_aovs(resolution, &loaded.aovs)?.starting_at(slice.start),
            spp,
            passes: 0,
            seed: loaded.seed,
            scene_hash,
            seconds: 0.0,
        },
        None => starting_state(args, session, &checkpoint_file, scene_hash, &loaded)?,
    };
    // The last sample index (exclusive) this run renders.
    let end = slice.map_or(spp, |s| s.end);
    // With --stats the scene, its plugins and the sampler run inside the
    // profiling wrappers; the render itself is the same call.
    if args.stats {
        loaded.scene = loaded.scene.into_profiled();
    }
    let profiled_scene = profiled_scene(&loaded.scene);
    let profiled_sampler = args
        .stats
        .then(|| profiled_sampler(loaded.sampler.clone_sampler()));
    let (scene, sampler): (&dyn Scene, &dyn Sampler) = match &profiled_sampler {
        Some(sampler) => (&profiled_scene, sampler),
        None => (&loaded.scene, loaded.sampler.as_ref()),
    };
    let pool = session.pool(args.threads)?;
    let units = progress_units(resolution, end - state.film.samples);
    let progress = match args.quiet {
        true => crate::Progress::Hidden.over(units),
        false => session.progress.over(units),
    };
    let ctx = PassContext {
        camera: &loaded.camera,
        scene,
        integrator: loaded.integrator.as_ref(),
        sampler,
        seed: loaded.seed,
        clamp: loaded.clamp,
        pool: &pool,
        progress: &progress,
        stop,
    };
    let scene_file_hash = lumis_scene::scene_file_hash(&args.scene)?;
    let metadata = |state: &Checkpoint| ImageMetadata {
        command: "render".into(),
        spp: state.film.samples - state.film.start,
        passes: state.passes,
        seed: state.seed,
        scene_hash,
        scene_file_hash,
        seconds: state.seconds,
        version: lumis_version(),
        slice,
        denoiser: denoiser.as_ref().map(|d| d.toml.clone()),
    };
    // An unfinished render's image goes beside the outputs, never over a
    // finished image, which stays until this render finishes.
    let save = |state: &Checkpoint| -> Result<()> {
        state.write(&checkpoint_file)?;
        outputs.write_unfinished(
            &state.film.image(),
            &state.film.aov_images(),
            &metadata(state),
        )
    };
    let profile = args.stats.then(Profile::start);
    let plan = PassPlan {
        ctx: &ctx,
        registry,
        pass_spp: args.pass_spp,
        part_ends,
        resolution,
        aovs: &loaded.aovs,
    };
    let mut last_save = Instant::now();
    let passes = run_passes(&plan, &mut state, end, |state| {
        let due = match every {
            CheckpointEvery::Pass => true,
            CheckpointEvery::Seconds(s) => last_save.elapsed().as_secs_f64() >= s,
            CheckpointEvery::Never => false,
        };
        if due && state.film.samples < spp {
            save(state)?;
            last_save = Instant::now();
        }
        Ok(())
    })?;
    let PassTotals {
        stats,
        seconds,
        mut interrupted,
    } = passes;
    progress.finish();
    let profile = profile.map(Profile::finish);
    if interrupted && slice.is_some() {
        return Err(Error::msg(format!(
            "interrupted: a part is written only when finished, nothing written to {} (rerun the part)",
            exr.display()
        )));
    }
    if slice.is_some() {
        Partial {
            film: state.film.clone(),
            metadata: metadata(&state),
        }
        .write(&outputs)?;
    } else if interrupted && state.film.samples == 0 {
        return Err(Error::msg(format!(
            "interrupted before the first pass ended: nothing written to {}",
            exr.display()
        )));
    } else if interrupted && state.film.samples < spp {
        save(&state)?;
        session.note(&format!(
            "interrupted at {} of {spp} spp: {} holds the image so far; --resume continues it",
            state.film.samples,
            partial_path(&exr).display()
        ));
    } else {
        write_film(&outputs, &state.film, &metadata(&state))?;
        // Last: a kill before this line leaves a checkpoint that resumes
        // to the same, finished image.
        remove_if_present(&checkpoint_file, "the finished render's checkpoint")?;
        outputs.remove_unfinished()?;
        interrupted = false;
    }
    // Only a finished render is denoised, after its raw image is on disk.
    let denoised = match (&denoiser, &denoised_outputs) {
        (Some(denoiser), Some(denoised)) if !interrupted => {
            let start = Instant::now();
            let image = denoise_film(denoiser, &state.film, denoised, &metadata(&state), &exr)?;
            Some(DenoisedReport {
                image,
                exr: denoised.exr.clone(),
                seconds: start.elapsed().as_secs_f64(),
            })
        }
        _ => None,
    };
    Ok(RenderReport {
        image: state.film.image(),
        aovs: state.film.aov_images(),
        exr,
        png,
        denoised,
        spp: state.film.samples - state.film.start,
        interrupted,
        finished_before: false,
        seconds,
        stats,
        profile,
        defects: registry.faults().defects(),
    })
}

/// The warning where `--threads` asks for more workers than a render runs
/// (`lumis_render::worker_threads`).
pub fn threads_capped(requested: usize) -> Option<String> {
    let used = lumis_render::worker_threads(requested);
    (requested != 0 && used < requested).then(|| {
        format!(
            "warning: --threads {requested} capped at {used} ({} per core)",
            lumis_render::MAX_THREADS_PER_CORE
        )
    })
}

/// What the image already at `exr` means for a render of `(scene hash,
/// seed, spp)`: its metadata where `--resume` finds that render finished
/// (no checkpoint beside it: nothing to do); an error where it holds more
/// samples of the same scene and `--force` is not given. Any other file is
/// replaced when the render finishes.
fn finished_or_kept(
    args: &RenderArgs,
    exr: &Path,
    checkpoint: &Path,
    (scene_hash, seed, spp): (u64, u64, u32),
) -> Result<Option<ImageMetadata>> {
    let existing = ImageMetadata::read(exr).ok().flatten();
    let Some(existing) = existing.filter(|m| m.scene_hash == scene_hash) else {
        return Ok(None);
    };
    let finished = existing.command == "render"
        && existing.slice.is_none()
        && existing.seed == seed
        && existing.spp == spp;
    if args.resume && finished && !checkpoint.exists() {
        return Ok(Some(existing));
    }
    refuse_fewer_samples(exr, scene_hash, spp, args.force)?;
    Ok(None)
}

/// An error where the image at `exr` holds more samples of this scene than
/// the `spp` to be written over it, unless `force`: a finished image is
/// never replaced by a worse one by mistake.
pub(crate) fn refuse_fewer_samples(
    exr: &Path,
    scene_hash: u64,
    spp: u32,
    force: bool,
) -> Result<()> {
    let existing = ImageMetadata::read(exr).ok().flatten();
    match existing.filter(|m| m.scene_hash == scene_hash) {
        Some(existing) if existing.spp > spp && !force => Err(Error::msg(format!(
            "{}: refusing to replace it: it holds {} spp of this scene (`lumis {}`), more \
             than the {spp} this render makes; --force replaces it",
            exr.display(),
            existing.spp,
            existing.command
        ))),
        _ => Ok(()),
    }
}

/// The report of a `--resume` that finds its render finished: the image on
/// disk, nothing rendered.
fn finished_before(exr: PathBuf, png: PathBuf, existing: &ImageMetadata) -> Result<RenderReport> {
    let image = lumis_image::read_exr(&exr).map_err(|e| Error::msg(e.to_string()))?;
    Ok(RenderReport {
        image,
        aovs: Vec::new(),
        exr,
        png,
        denoised: None,
        spp: existing.spp,
        interrupted: false,
        finished_before: true,
        seconds: existing.seconds,
        stats: RenderStats::default(),
        profile: None,
        defects: Vec::new(),
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
