//! The `[denoiser]` post-process of `lumis render`: the finished raw image
//! stays the main output (`NAME.exr`, `NAME.png`, the unbiased estimate);
//! the denoised image, biased, goes beside it as `NAME.denoised.exr` and
//! `NAME.denoised.png`.

use std::path::{Path, PathBuf};

use lumis_core::{DenoiseInput, Denoiser, Error, Result};
use lumis_image::Image;

use crate::metadata::ImageMetadata;
use crate::outputs::Outputs;

/// `STEM.denoised.exr` beside the raw `STEM.exr`.
pub fn denoised_exr_path(raw_exr: &Path) -> PathBuf {
    let mut stem = raw_exr.with_extension("").into_os_string();
    stem.push(".denoised.exr");
    PathBuf::from(stem)
}

/// Claims the denoised image's files (`STEM.denoised.exr` and `.png`) before
/// the render starts, so a render never ends unable to write them.
pub fn claim_denoised_outputs(raw_exr: &Path) -> Result<Outputs> {
    let exr = denoised_exr_path(raw_exr);
    let png = exr.with_extension("png");
    Outputs::claim(&exr, Some(&png))
}

/// Denoises `color` (guided by the film's `albedo` and `normal`, when it
/// made them), writes the result to `outputs` and returns it. Called once the raw image
/// is on disk: an error here leaves it in place and says so.
pub fn write_denoised(
    denoiser: &dyn Denoiser,
    color: &Image,
    albedo: Option<&Image>,
    normal: Option<&Image>,
    outputs: &Outputs,
    metadata: &ImageMetadata,
    raw_exr: &Path,
) -> Result<Image> {
    let input = DenoiseInput {
        width: color.width,
        height: color.height,
        color: &color.pixels,
        albedo: albedo.map(|a| a.pixels.as_slice()),
        normal: normal.map(|n| n.pixels.as_slice()),
    };
    let failed = |e: Error| {
        Error::msg(format!(
            "denoising failed; the raw render is in {}: {}",
            raw_exr.display(),
            e
        ))
    };
    let pixels = denoiser.denoise(&input).map_err(failed)?;
    if pixels.len() != color.pixels.len() {
        return Err(failed(Error::msg(format!(
            "the denoiser returned {} pixels, expected {}",
            pixels.len(),
            color.pixels.len()
        ))));
    }
    let denoised = Image {
        width: color.width,
        height: color.height,
        pixels,
    };
    outputs.write(&denoised, &[], metadata).map_err(failed)?;
    Ok(denoised)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_denoised_image_sits_beside_the_raw_one() {
        assert_eq!(
            denoised_exr_path(Path::new("out/cornell-box.exr")),
            Path::new("out/cornell-box.denoised.exr")
        );
    }
}
