//! What a render reports: its image, where it went, and what it cost.

use std::path::PathBuf;
use std::sync::Arc;

use lumis_core::audit::Defects;
use lumis_core::{Error, RenderStats, Result};
use lumis_image::Image;
use lumis_render::profile::ProfileReport;
use lumis_render::Aov;

use crate::render_args::RenderArgs;

/// The outcome of a render, for the summary line and for tests.
pub struct RenderReport {
    pub image: Image,
    /// The outputs `[film] aovs` asked for, as the EXR holds them.
    pub aovs: Vec<(Aov, Image)>,
    pub exr: PathBuf,
    pub png: PathBuf,
    /// The denoised image, when the scene has a `[denoiser]`.
    pub denoised: Option<DenoisedReport>,
    pub spp: u32,
    /// Stopped by a signal: the image holds the passes finished before it.
    pub interrupted: bool,
    /// `--resume` found the render finished: nothing was rendered, and the
    /// image is the one on disk.
    pub finished_before: bool,
    pub seconds: f64,
    pub stats: RenderStats,
    /// Time by stage, with `--stats`.
    pub profile: Option<ProfileReport>,
    /// The loaded plugins whose answers held defects, each named with its
    /// library ([`lumis_core::audit`]).
    pub defects: Vec<(Arc<str>, Defects)>,
}

impl RenderReport {
    /// One warning line per loaded plugin whose answers held defects.
    pub fn defect_warnings(&self) -> Vec<String> {
        defect_warnings(&self.defects)
    }

    /// With `--strict`, the error that defects are.
    pub fn strict_check(&self, args: &RenderArgs) -> Result<()> {
        if args.strict && !self.defects.is_empty() {
            return Err(Error::msg(format!(
                "--strict: {} loaded plugin(s) answered with defects (warned above); the image was written to {}",
                self.defects.len(),
                self.exr.display()
            )));
        }
        Ok(())
    }
    /// The one-line summary printed at the end of a render.
    pub fn summary(&self) -> String {
        if self.finished_before {
            return format!(
                "{} is finished ({} spp of this scene and seed): nothing to resume",
                self.exr.display(),
                self.spp
            );
        }
        let secs = self.seconds.max(1e-9);
        let interrupted = if self.interrupted {
            "interrupted, "
        } else {
            ""
        };
        format!(
            "{interrupted}{}x{}, {} spp, {:.2} s, {:.3} Msamples/s, {:.2} Mrays/s ({} closest-hit and {} shadow rays), {} NaN/Inf samples, emission found by {} BSDF samples and {} light samples -> {}",
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
        ) + &match &self.denoised {
            Some(denoised) => format!(
                ", denoised in {:.2} s -> {}",
                denoised.seconds,
                denoised.exr.display()
            ),
            None => String::new(),
        }
    }
}

/// The denoised image of a render and what making it cost.
pub struct DenoisedReport {
    pub image: Image,
    pub exr: PathBuf,
    /// Wall time of the denoiser and of writing its image, which a
    /// comparison at equal time adds to the render's.
    pub seconds: f64,
}

/// One warning line per loaded plugin whose answers held defects.
pub(crate) fn defect_warnings(defects: &[(Arc<str>, Defects)]) -> Vec<String> {
    defects
        .iter()
        .map(|(plugin, defects)| format!("warning: {plugin}: {}", defects.describe().join("; ")))
        .collect()
}
