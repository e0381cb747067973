//! `lumis reference`: a high-spp render of a scene with its own settings,
//! written pass by pass with its metadata in the EXR header, so that an
//! interrupted run resumes and a rerun never silently replaces a more
//! converged or a different reference.

use std::path::{Path, PathBuf};

use lumis_core::{Error, Result};
use lumis_image::{read_exr, Image};
use lumis_render::{progress_units, render_pass, Film, PassContext};

use crate::metadata::{lumis_version, other_scene_or_seed, ImageMetadata};
use crate::outputs::Outputs;
use crate::render::{load, output_paths, threads_capped};
use crate::render_args::RenderArgs;
use crate::session::Session;

#[derive(clap::Args, Debug, Clone)]
pub struct ReferenceArgs {
    /// The scene file.
    pub scene: PathBuf,
    /// Total samples per pixel.
    #[arg(long)]
    pub spp: u32,
    /// Samples per pixel per pass; the image and its metadata are saved
    /// after every pass, so at most one pass is lost to an interruption.
    #[arg(long, default_value_t = 256)]
    pub pass_spp: u32,
    /// Output EXR [default: SCENE-NAME-reference.exr]; its header holds
    /// the metadata (spp, passes, seed, scene hash, lumis version).
    #[arg(long, short)]
    pub output: Option<PathBuf>,
    /// Replace an existing reference that is more converged, of another
    /// scene or seed, or not a reference at all, instead of refusing.
    #[arg(long)]
    pub force: bool,
    /// Scene overrides, as for `lumis render`.
    #[arg(long = "set", value_name = "KEY.PATH=VALUE")]
    pub set: Vec<String>,
    /// Worker threads; 0 means one per core.
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
}

/// Why an existing file at the reference's path may not be continued, or
/// `None` where it may. Replacing it needs `--force`.
fn reason_to_keep(
    existing: &ImageMetadata,
    args: &ReferenceArgs,
    scene_hash: u64,
    seed: u64,
) -> Option<String> {
    if existing.command != "reference" {
        return Some(format!(
            "it was written by `lumis {}`, not `lumis reference`",
            existing.command
        ));
    }
    if let Some(why) = other_scene_or_seed((existing.scene_hash, existing.seed), scene_hash, seed) {
        return Some(why);
    }
    if existing.spp > args.spp {
        return Some(format!(
            "it has {} spp, more than the {} asked for: it is the more converged one",
            existing.spp, args.spp
        ));
    }
    None
}

/// The reference to continue: the existing file's image and metadata, or
/// `None` to start over (no file, or `--force`). Refuses, saying why, to
/// replace a file that is not this reference or is more converged.
fn existing_reference(
    exr: &Path,
    args: &ReferenceArgs,
    session: &Session,
    scene_hash: u64,
    seed: u64,
) -> Result<Option<(ImageMetadata, Image)>> {
    if !exr.exists() {
        return Ok(None);
    }
    let refuse = |why: String| {
        Err(Error::msg(format!(
            "{}: refusing to replace it: {why}; --force replaces it",
            exr.display()
        )))
    };
    if args.force {
        session.note(&format!("replacing {} (--force)", exr.display()));
        return Ok(None);
    }
    let meta = match ImageMetadata::read(exr) {
        Ok(Some(meta)) => meta,
        Ok(None) => return refuse("its header holds no lumis metadata".into()),
        Err(e) => return refuse(format!("it cannot be read ({e})")),
    };
    if let Some(why) = reason_to_keep(&meta, args, scene_hash, seed) {
        return refuse(why);
    }
    let image = read_exr(exr).map_err(|e| Error::msg(e.to_string()))?;
    Ok(Some((meta, image)))
}

/// Renders (or continues) the reference; returns its path and metadata.
/// Pass `k` uses seed `base_seed + k`, so a resumed run never reuses the
/// samples of an earlier pass, and the image is the sample-weighted mean of
/// independent passes. The EXR's header is the resume state: written in the
/// same atomic rename as the image, it always describes it.
pub fn render_reference(
    args: &ReferenceArgs,
    session: &Session,
) -> Result<(PathBuf, ImageMetadata)> {
    let (registry, stop) = (session.registry, session.stop);
    if let Some(warning) = threads_capped(args.threads) {
        session.note(&warning);
    }
    if args.spp == 0 || args.pass_spp == 0 {
        return Err(Error::msg("--spp and --pass-spp must be at least 1"));
    }
    let probe = load(
        &RenderArgs {
            scene: args.scene.clone(),
            set: args.set.clone(),
            spp: Some(1),
            ..Default::default()
        },
        registry,
    )?;
    let base_seed = probe.seed;
    let resolution = probe.camera.resolution();
    let name = format!("{}-reference", probe.name);
    drop(probe);
    let scene_hash = lumis_scene::scene_hash(&args.scene, &args.set)?;
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{name}.exr")));
    let (exr, _) = output_paths(&output, &name);
    let outputs = Outputs::claim(&exr, None)?;
    let (mut meta, mut mean) = match existing_reference(&exr, args, session, scene_hash, base_seed)?
    {
        Some((meta, image)) => {
            session.note(&format!(
                "resuming {} at {} of {} spp",
                exr.display(),
                meta.spp,
                args.spp
            ));
            (meta, Some(image))
        }
        None => (
            ImageMetadata {
                command: "reference".into(),
                spp: 0,
                passes: 0,
                seed: base_seed,
                scene_hash,
                scene_file_hash: lumis_scene::scene_file_hash(&args.scene)?,
                seconds: 0.0,
                version: lumis_version(),
                slice: None,
                // A reference is never denoised.
                denoiser: None,
            },
            None,
        ),
    };
    let pool = session.pool(args.threads)?;
    while meta.spp < args.spp {
        let pass = args.pass_spp.min(args.spp - meta.spp);
        let seed = base_seed.wrapping_add(meta.passes);
        let loaded = load(
            &RenderArgs {
                scene: args.scene.clone(),
                set: args.set.clone(),
                spp: Some(pass),
                seed: Some(seed),
                ..Default::default()
            },
            registry,
        )?;
        let progress = session.progress.over(progress_units(resolution, pass));
        let ctx = PassContext {
            camera: &loaded.camera,
            scene: &loaded.scene,
            integrator: loaded.integrator.as_ref(),
            sampler: loaded.sampler.as_ref(),
            seed,
            clamp: loaded.clamp,
            pool: &pool,
            progress: &progress,
            stop,
        };
        let mut film = Film::try_new(resolution)?;
        let out = render_pass(&ctx, &mut film, pass)?;
        progress.finish();
        let Some(out) = out else {
            return Err(Error::msg(format!(
                "interrupted at {} of {} spp: {} holds the passes done; run again to resume",
                meta.spp,
                args.spp,
                exr.display()
            )));
        };
        // A loaded plugin that panicked answered with neutral values: the
        // pass is not the scene's, and the panic is the error.
        registry.faults().check()?;
        // Running mean weighted by samples.
        let done = meta.spp as f32;
        let image = film.image();
        mean = Some(match mean.take() {
            None => image,
            Some(mut acc) => {
                let total = done + pass as f32;
                for (a, p) in acc.pixels.iter_mut().zip(&image.pixels) {
                    for c in 0..3 {
                        a[c] = (a[c] * done + p[c] * pass as f32) / total;
                    }
                }
                acc
            }
        });
        meta.spp += pass;
        meta.passes += 1;
        meta.seconds += out.seconds;
        meta.version = lumis_version();
        if let Some(image) = &mean {
            outputs.write(image, &[], &meta)?;
        }
    }
    Ok((exr, meta))
}
