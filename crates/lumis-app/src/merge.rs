//! `lumis merge`: puts the parts of a render split over processes back
//! together, after checking that they are the parts of one render and
//! cover each of its sample indices once.

use std::path::PathBuf;

use lumis_core::{Error, Registry, Result};
use lumis_render::Film;

use crate::denoise::{claim_denoised_outputs, denoise_film, ConfiguredDenoiser};
use crate::metadata::ImageMetadata;
use crate::outputs::{same_file, Outputs};
use crate::partial::Partial;
use crate::render::output_paths;

/// What `lumis merge` was asked to do; also its command-line flags.
#[derive(Debug, Clone, clap::Args)]
pub struct MergeArgs {
    /// The partial images (`lumis render --part K/N` or `--samples A..B`),
    /// in any order.
    #[arg(required = true)]
    pub parts: Vec<PathBuf>,
    /// Output path: writes PATH.exr and PATH.png, as `lumis render` does,
    /// and PATH.denoised.exr and .png when the scene has a `[denoiser]`.
    #[arg(long, short)]
    pub output: PathBuf,
}

/// The merged render.
pub struct MergeReport {
    pub exr: PathBuf,
    pub png: PathBuf,
    /// The denoised image's EXR, when the parts' scene has a `[denoiser]`.
    pub denoised: Option<PathBuf>,
    pub metadata: ImageMetadata,
}

/// Why `part` cannot be merged with `first` (the first part given), or
/// `None` where both are parts of one render.
fn differs(first: &Partial, part: &Partial) -> Option<String> {
    let (a, b) = (&first.metadata, &part.metadata);
    let (sa, sb) = (a.slice?, b.slice?);
    // Before the scene hash, which counts the denoiser too: this says what
    // differs.
    if a.denoiser != b.denoiser {
        let named = |d: &Option<String>| match d {
            Some(toml) => format!("the [denoiser] {toml}"),
            None => "no [denoiser]".to_string(),
        };
        return Some(format!(
            "{}, not {}",
            named(&b.denoiser),
            named(&a.denoiser)
        ));
    }
    if a.scene_hash != b.scene_hash || a.scene_file_hash != b.scene_file_hash {
        return Some(format!(
            "a different scene (scene hash {:016x}, not {:016x}: the scene, a file it names or a --set differs)",
            b.scene_hash, a.scene_hash
        ));
    }
    if a.seed != b.seed {
        return Some(format!("seed {}, not {}", b.seed, a.seed));
    }
    if sa.total != sb.total {
        return Some(format!("{} spp in all, not {}", sb.total, sa.total));
    }
    if a.version != b.version {
        return Some(format!("lumis {}, not {}", b.version, a.version));
    }
    let (fa, fb) = (&first.film, &part.film);
    if (fa.width, fa.height) != (fb.width, fb.height) || fa.aovs != fb.aovs {
        return Some(format!(
            "a {}x{} film with outputs {:?}, not {}x{} with {:?}",
            fb.width, fb.height, fb.aovs, fa.width, fa.height, fa.aovs
        ));
    }
    None
}

/// Checks that the slices of `parts`, sorted by their start, cover
/// `0..total` once: a gap or an overlap is an error naming the parts and
/// the sample indices.
fn check_coverage(parts: &[(PathBuf, Partial)]) -> Result<()> {
    let slice = |i: usize| parts[i].1.metadata.slice.expect("a partial has a slice");
    let name = |i: usize| parts[i].0.display();
    let total = slice(0).total;
    let mut covered = 0;
    for i in 0..parts.len() {
        let s = slice(i);
        if s.start > covered {
            let after = match i {
                0 => String::new(),
                _ => format!(" (between '{}' and '{}')", name(i - 1), name(i)),
            };
            return Err(Error::msg(format!(
                "samples {covered}..{} of {total} are in no part{after}",
                s.start
            )));
        }
        if s.start < covered {
            return Err(Error::msg(format!(
                "'{}' ({}) and '{}' ({s}) overlap: samples {}..{} are in both",
                name(i - 1),
                slice(i - 1),
                name(i),
                s.start,
                covered.min(s.end)
            )));
        }
        covered = s.end;
    }
    if covered < total {
        return Err(Error::msg(format!(
            "samples {covered}..{total} of {total} are in no part (the last is '{}', {})",
            name(parts.len() - 1),
            slice(parts.len() - 1)
        )));
    }
    Ok(())
}

/// Reads the parts, checks them, adds their sums in sample-index order and
/// writes the image a plain `lumis render` writes: `PATH.exr` (with the
/// output layers and the metadata in its header) and `PATH.png`, then, for
/// a scene with a `[denoiser]` (made through `registry`), its denoised
/// image `PATH.denoised.exr` and `.png`.
pub fn merge(args: &MergeArgs, registry: &Registry) -> Result<MergeReport> {
    let mut parts = Vec::with_capacity(args.parts.len());
    for path in &args.parts {
        parts.push((path.clone(), Partial::read(path)?));
    }
    let (first_path, first) = &parts[0];
    for (path, part) in &parts[1..] {
        if let Some(why) = differs(first, part) {
            return Err(Error::msg(format!(
                "'{}' is not a part of the render '{}' belongs to: it has {why}",
                path.display(),
                first_path.display()
            )));
        }
    }
    parts.sort_by_key(|(_, part)| part.film.start);
    check_coverage(&parts)?;
    let (exr, png) = output_paths(&args.output, "merged");
    if let Some((part, _)) = parts.iter().find(|(p, _)| same_file(p, &exr)) {
        return Err(Error::msg(format!(
            "the output {} is the part '{}': give another -o",
            exr.display(),
            part.display()
        )));
    }
    let outputs = Outputs::claim(&exr, Some(&png))?;
    // Made and claimed before the merge, as `lumis render` does before it
    // renders: an unknown denoiser stops it before it writes anything.
    let base = &parts[0].1.metadata;
    let denoiser = base
        .denoiser
        .as_ref()
        .map(|toml| ConfiguredDenoiser::of_header(toml, &parts[0].0, registry))
        .transpose()?;
    let denoised_outputs = denoiser
        .as_ref()
        .map(|_| claim_denoised_outputs(&exr))
        .transpose()?;
    let film = append_all(&parts)?;
    let metadata = ImageMetadata {
        command: "render".into(),
        spp: film.samples,
        passes: parts.iter().map(|(_, p)| p.metadata.passes).sum(),
        seconds: parts.iter().map(|(_, p)| p.metadata.seconds).sum(),
        slice: None,
        ..base.clone()
    };
    outputs.write(&film.image(), &film.aov_images(), &metadata)?;
    if let (Some(denoiser), Some(denoised)) = (&denoiser, &denoised_outputs) {
        denoise_film(denoiser, &film, denoised, &metadata, &exr)?;
    }
    Ok(MergeReport {
        exr,
        png,
        denoised: denoised_outputs.map(|o| o.exr.clone()),
        metadata,
    })
}

/// The film of the whole render: the parts' sums added in sample-index
/// order.
fn append_all(parts: &[(PathBuf, Partial)]) -> Result<Film> {
    let first = &parts[0].1.film;
    let resolution = lumis_core::UVec2::new(first.width as u32, first.height as u32);
    let mut film = Film::try_with_aovs(resolution, &first.aovs)?;
    for (path, part) in parts {
        film.append(&part.film)
            .map_err(|e| Error::msg(format!("'{}': {e}", path.display())))?;
    }
    Ok(film)
}
