//! What a render is asked to do: the settings of `lumis render`, declared
//! once for the command line and for library callers.

use std::path::PathBuf;

use lumis_core::{Error, Result};

use crate::slice::SampleSlice;

/// What `lumis render` was asked to do; also its command-line flags.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct RenderArgs {
    /// The scene file.
    pub scene: PathBuf,
    /// Samples per pixel (overrides sampler.spp).
    #[arg(long)]
    pub spp: Option<u32>,
    /// Random seed (overrides the scene's top-level seed), at most
    /// 2^63 - 1 as a scene's is.
    #[arg(long, value_parser = clap::value_parser!(u64).range(..=i64::MAX as u64))]
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
    /// No start-up report and no progress bar.
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
    /// Fail (exit 1, after the image is written) where a loaded plugin
    /// answered with NaN or infinite values, negative ones, or BSDF samples
    /// that create energy; without it, each is a warning.
    #[arg(long)]
    pub strict: bool,
    /// Save the render's state (NAME.checkpoint beside the EXR, and the
    /// image so far) every SECONDS, or after every pass without a value.
    /// Without this flag a render checkpoints every 60 s.
    #[arg(long, value_name = "SECONDS", num_args = 0..=1, conflicts_with = "no_checkpoint")]
    pub checkpoint: Option<Option<f64>>,
    /// Never write a checkpoint while rendering (Ctrl-C still saves the
    /// passes done).
    #[arg(long)]
    pub no_checkpoint: bool,
    /// Continue the render its checkpoint saved (same scene, overrides and
    /// seed); the image is the one an uninterrupted render makes.
    #[arg(long)]
    pub resume: bool,
    /// The memory the render may use, scene included (8G, 512M) [default:
    /// the film must fit in what the system has available].
    #[arg(long, value_name = "SIZE", value_parser = crate::memory::parse_bytes)]
    pub max_memory: Option<u64>,
    /// Replace an image of this scene with more samples than this render
    /// makes, instead of refusing.
    #[arg(long)]
    pub force: bool,
    /// Samples per pixel per pass [default: passes of about two seconds].
    /// The image does not depend on it.
    #[arg(long, value_name = "N")]
    pub pass_spp: Option<u32>,
    /// Render part K (0-based) of N of the scene's samples per pixel: the
    /// sample indices [K spp / N, (K + 1) spp / N), written as a partial
    /// EXR that `lumis merge` adds to the other parts.
    #[arg(long, value_name = "K/N", conflicts_with_all = ["samples", "resume", "checkpoint"])]
    pub part: Option<String>,
    /// Render sample indices A..B (half-open, B <= spp) of the scene's
    /// samples per pixel, written as a partial EXR for `lumis merge`.
    #[arg(long, value_name = "A..B", conflicts_with_all = ["resume", "checkpoint"])]
    pub samples: Option<String>,
    /// Render the whole image in this process, summed as N parts: each
    /// slice `--part K/N` renders is summed on its own and added to the
    /// slices before it, so the image is, bit for bit, what `lumis merge`
    /// makes of the N parts (one plain run sums every sample in turn,
    /// which rounds the sums differently in their last bits). It
    /// checkpoints and resumes like any render; a part interrupted midway
    /// is then summed in two pieces, equal to `merge`'s to rounding.
    #[arg(
        long,
        value_name = "N",
        value_parser = clap::value_parser!(u32).range(1..),
        conflicts_with_all = ["part", "samples"]
    )]
    pub parts: Option<u32>,
}

/// Seconds between checkpoints when `--checkpoint` does not say.
pub const DEFAULT_CHECKPOINT_SECONDS: f64 = 60.0;

/// When a render saves its state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum CheckpointEvery {
    Pass,
    Seconds(f64),
    Never,
}

impl CheckpointEvery {
    pub(crate) fn of(args: &RenderArgs) -> Result<Self> {
        match args.checkpoint {
            _ if args.no_checkpoint => Ok(Self::Never),
            None => Ok(Self::Seconds(DEFAULT_CHECKPOINT_SECONDS)),
            Some(None) => Ok(Self::Pass),
            Some(Some(s)) if s.is_finite() && s >= 0.0 => Ok(Self::Seconds(s)),
            Some(Some(s)) => Err(Error::msg(format!(
                "--checkpoint {s}: expected a number of seconds, 0 or more"
            ))),
        }
    }
}

impl RenderArgs {
    /// The slice of sample indices `--part` or `--samples` asks for, of a
    /// render of `spp` samples per pixel; `None` for a whole render.
    pub(crate) fn sample_slice(&self, spp: u32) -> Result<Option<SampleSlice>> {
        let slice = match (&self.part, &self.samples) {
            (Some(part), _) => SampleSlice::parse_part(part, spp)
                .map_err(|why| Error::msg(format!("--part {why}")))?,
            (None, Some(range)) => SampleSlice::parse_range(range, spp)
                .map_err(|why| Error::msg(format!("--samples {why}")))?,
            (None, None) => return Ok(None),
        };
        Ok(Some(slice))
    }
}
