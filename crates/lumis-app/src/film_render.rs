//! A render in memory: a loaded scene's samples into a film that the
//! caller keeps (Python's `Scene.render`), with no file written until it
//! asks. Its passes are those of a render to files ([`crate::render`]),
//! so the two give the same image, bit for bit, for the same scene, seed
//! and samples.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use lumis_core::audit::Defects;
use lumis_core::{Error, RenderStats, Result};
use lumis_image::Image;
use lumis_render::{progress_units, Film, PassContext};
use lumis_scene::{LoadedScene, SceneDocument};

use crate::checkpoint::Checkpoint;
use crate::denoise::{
    claim_denoised_outputs, denoise_film_image, table_toml, write_denoised_image,
};
use crate::memory::{MemoryBudget, MemoryEstimate};
use crate::metadata::{lumis_version, ImageMetadata};
use crate::outputs::Outputs;
use crate::partial::Partial;
use crate::passes::{run_passes, PassPlan};
use crate::render::{output_paths, refuse_fewer_samples, threads_capped};
use crate::render_report::defect_warnings;
use crate::session::Session;
use crate::slice::SampleSlice;

/// What a render in memory is asked for, beyond the loaded scene (whose
/// sampler holds the samples per pixel, and whose `seed` seeds it).
#[derive(Debug, Clone, Default)]
pub struct FilmRequest {
    /// Worker threads; 0 means one per core.
    pub threads: usize,
    /// The sample indices to render, a part of the scene's samples per
    /// pixel; `None` renders them all.
    pub samples: Option<SampleSlice>,
    /// Samples per pixel per pass; `None`, passes of about two seconds.
    /// The image does not depend on it.
    pub pass_spp: Option<u32>,
    /// The memory the render may use, scene included; `None`, the film
    /// must fit in what the system has available.
    pub max_memory: Option<u64>,
}

/// A render held in memory.
pub struct FilmRender {
    /// The samples' sums: [`Film::image`] is the image, and
    /// [`Film::aov_images`] the outputs the scene asks for.
    pub film: Film,
    pub seed: u64,
    /// The slice rendered, for a part.
    pub slice: Option<SampleSlice>,
    pub passes: u64,
    pub seconds: f64,
    pub stats: RenderStats,
    /// Stopped by the session's stop flag: the film holds the passes
    /// finished before it.
    pub interrupted: bool,
    /// The loaded plugins whose answers held defects.
    pub defects: Vec<(Arc<str>, Defects)>,
    /// The scene's `[denoiser]` as one line of TOML, recorded in the
    /// images written ([`ImageMetadata::denoiser`]).
    pub denoiser: Option<String>,
    /// The image the scene's `[denoiser]` made of a finished render of all
    /// the samples, as `lumis render` denoises it; an error where
    /// denoising failed (the render stands); `None` without a denoiser,
    /// for a part, or for an interrupted render.
    pub denoised: Option<Result<Image>>,
}

/// Renders `loaded` into a film, in passes, until its samples are done or
/// the session's stop flag is set.
pub fn render_film(
    loaded: &LoadedScene,
    request: &FilmRequest,
    session: &Session,
) -> Result<FilmRender> {
    if request.pass_spp == Some(0) {
        return Err(Error::msg("pass_spp must be at least 1"));
    }
    let spp = loaded.sampler.samples_per_pixel();
    if spp == 0 {
        return Err(Error::msg("spp must be at least 1"));
    }
    if let Some(slice) = request.samples {
        if slice.total != spp || slice.start >= slice.end || slice.end > spp {
            return Err(Error::msg(format!(
                "samples {}..{}: expected sample indices A..B with A < B <= {spp}, the scene's spp",
                slice.start, slice.end
            )));
        }
        if loaded.adaptive.is_some() {
            return Err(Error::msg(
                "a slice of the samples cannot be rendered with [adaptive] sampling: which \
                 pixels still sample depends on all their earlier samples",
            ));
        }
    }
    let resolution = loaded.camera.resolution();
    let memory = MemoryEstimate::of(loaded);
    memory.check(&MemoryBudget::of(request.max_memory))?;
    let mut state = Checkpoint {
        film: empty_film(loaded)?.starting_at(request.samples.map_or(0, |s| s.start)),
        spp,
        passes: 0,
        seed: loaded.seed,
        scene_hash: 0,
        seconds: 0.0,
    };
    let end = request.samples.map_or(spp, |s| s.end);
    if let Some(warning) = threads_capped(request.threads) {
        session.note(&warning);
    }
    let pool = session.pool(request.threads)?;
    let progress = session
        .progress
        .over(progress_units(resolution, end - state.film.samples));
    let ctx = PassContext {
        camera: &loaded.camera,
        scene: &loaded.scene,
        integrator: loaded.integrator.as_ref(),
        sampler: loaded.sampler.as_ref(),
        seed: loaded.seed,
        clamp: loaded.clamp,
        pool: &pool,
        progress: &progress,
        stop: session.stop,
    };
    let plan = PassPlan {
        ctx: &ctx,
        registry: session.registry,
        pass_spp: request.pass_spp,
        part_ends: None,
        resolution,
        aovs: &loaded.aovs,
    };
    let totals = run_passes(&plan, &mut state, end, |_| Ok(()))?;
    progress.finish();
    let finished = !totals.interrupted && state.film.samples > state.film.start;
    let denoised = match &loaded.denoiser {
        Some(scene) if finished && request.samples.is_none() => {
            Some(denoise_film_image(scene.denoiser.as_ref(), &state.film))
        }
        _ => None,
    };
    Ok(FilmRender {
        film: state.film,
        seed: loaded.seed,
        slice: request.samples,
        passes: state.passes,
        seconds: totals.seconds,
        stats: totals.stats,
        interrupted: totals.interrupted,
        defects: session.registry.faults().defects(),
        denoiser: loaded
            .denoiser
            .as_ref()
            .map(|d| table_toml(&d.entity.table))
            .transpose()?,
        denoised,
    })
}

/// The scene's film with no samples: its outputs, and adaptive sampling's
/// state where the scene asks for it.
pub(crate) fn empty_film(loaded: &LoadedScene) -> Result<Film> {
    let film = Film::try_with_aovs(loaded.camera.resolution(), &loaded.aovs)?;
    match loaded.adaptive {
        Some(settings) => film.with_adaptive(settings),
        None => Ok(film),
    }
}

impl FilmRender {
    /// Samples per pixel in the film.
    pub fn spp(&self) -> u32 {
        self.film.samples - self.film.start
    }

    /// One warning line per loaded plugin whose answers held defects.
    pub fn defect_warnings(&self) -> Vec<String> {
        defect_warnings(&self.defects)
    }

    /// The denoised image, where the render has one ([`Self::denoised`]).
    pub fn denoised_image(&self) -> Option<&Image> {
        self.denoised.as_ref()?.as_ref().ok()
    }

    /// Writes the render as `lumis render` would have: `PATH.exr` and
    /// `PATH.png` for `output` (a directory gets `NAME.exr`), the EXR's
    /// header saying what `document` rendered, and its denoised image as
    /// `PATH.denoised.exr` and `.png` where it has one; a slice writes its
    /// partial EXR for `lumis merge`. An image of this scene with more
    /// samples is not replaced unless `force`. Returns the raw image's
    /// files.
    pub fn write(
        &self,
        output: &Path,
        document: &SceneDocument,
        force: bool,
    ) -> Result<(PathBuf, Option<PathBuf>)> {
        if self.interrupted && self.slice.is_some() {
            return Err(Error::msg(
                "an interrupted part is not written: rerun the part (lumis merge needs it whole)",
            ));
        }
        if self.spp() == 0 {
            return Err(Error::msg("the render has no samples to write"));
        }
        let (exr, png) = output_paths(output, &document.name);
        let png = self.slice.is_none().then_some(png);
        let outputs = Outputs::claim(&exr, png.as_deref())?;
        let denoised = match (self.denoised_image(), &self.denoiser) {
            (Some(image), Some(toml)) => Some((image, toml, claim_denoised_outputs(&exr)?)),
            _ => None,
        };
        let scene_hash = document.hash()?;
        if self.slice.is_none() {
            refuse_fewer_samples(&exr, scene_hash, self.spp(), force)?;
        }
        let metadata = ImageMetadata {
            command: "render".into(),
            spp: self.spp(),
            passes: self.passes,
            seed: self.seed,
            scene_hash,
            scene_file_hash: document.file_hash()?,
            seconds: self.seconds,
            version: lumis_version(),
            slice: self.slice,
            denoiser: self.denoiser.clone(),
        };
        let attributes = metadata.attributes();
        match self.slice {
            Some(_) => Partial {
                film: self.film.clone(),
                metadata,
            }
            .write(&outputs)?,
            None => outputs.write(&self.film.image(), &self.film.aov_images(), &metadata)?,
        }
        if let Some((image, toml, outputs)) = denoised {
            write_denoised_image(image, toml, &outputs, attributes)?;
        }
        Ok((exr, png))
    }
}
