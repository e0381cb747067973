//! A render's output files, written so that they stay consistent: the EXR
//! (whose header says what the image is) is the one truth, written last.

use std::path::{Path, PathBuf};

use lumis_core::{Error, Result};
use lumis_image::{ExrLayer, ExrUintChannel, Image, OutputLock};
use lumis_render::Aov;

use crate::checkpoint::checkpoint_path;
use crate::metadata::ImageMetadata;

/// The EXR and PNG of one render, locked against other writers for as long
/// as this value lives.
pub struct Outputs {
    pub exr: PathBuf,
    pub png: Option<PathBuf>,
    _lock: OutputLock,
}

fn image_error(e: lumis_image::ImageError) -> Error {
    Error::msg(e.to_string())
}

/// Whether `a` and `b` name one existing file (through links and `..`):
/// a command must not write over what it reads.
pub fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

impl Outputs {
    /// Checks the outputs' directory exists, locks the outputs (the lock is
    /// on the EXR: `PATH.exr.lock`) and removes the temporary files that
    /// killed runs left beside them.
    pub fn claim(exr: &Path, png: Option<&Path>) -> Result<Self> {
        // Callers claim before they render: a missing directory is said
        // now, not after the work.
        if let Some(dir) = exr.parent().filter(|d| !d.as_os_str().is_empty()) {
            if !dir.is_dir() {
                return Err(Error::msg(format!(
                    "output directory '{}' does not exist (for {})",
                    dir.display(),
                    exr.display()
                )));
            }
        }
        let lock = OutputLock::acquire(exr).map_err(image_error)?;
        let checkpoint = checkpoint_path(exr);
        for path in [Some(exr), png, Some(checkpoint.as_path())]
            .into_iter()
            .flatten()
        {
            lumis_image::remove_stale_temporaries(path);
        }
        Ok(Self {
            exr: exr.to_path_buf(),
            png: png.map(Path::to_path_buf),
            _lock: lock,
        })
    }

    /// Writes the image, with `aovs` as named layers of the EXR beside the
    /// colour (the PNG is the colour alone): both files are written in
    /// full under temporary names first, then the PNG renamed into place and the EXR last. A
    /// failure before the renames (a full disk) leaves both old files; a
    /// kill between them leaves a new PNG beside the old EXR, whose header
    /// still tells the truth about itself.
    pub fn write(
        &self,
        image: &Image,
        aovs: &[(Aov, Image)],
        metadata: &ImageMetadata,
    ) -> Result<()> {
        self.write_with_channels(image, aovs, &[], &metadata.attributes())
    }

    /// [`Outputs::write`] with whole-number channels in the EXR too and
    /// the header `attributes` as given (a partial image's).
    pub fn write_with_channels(
        &self,
        image: &Image,
        aovs: &[(Aov, Image)],
        uints: &[ExrUintChannel],
        attributes: &[(String, String)],
    ) -> Result<()> {
        let png = match &self.png {
            Some(path) => Some(lumis_image::stage_png(path, image).map_err(image_error)?),
            None => None,
        };
        let layers: Vec<ExrLayer> = aovs
            .iter()
            .map(|(aov, image)| ExrLayer {
                name: aov.name(),
                channels: aov.channels(),
                image,
            })
            .collect();
        let exr =
            lumis_image::stage_exr_with_channels(&self.exr, image, &layers, uints, attributes)
                .map_err(image_error)?;
        if let Some(png) = png {
            png.commit().map_err(image_error)?;
        }
        exr.commit().map_err(image_error)
    }
}
