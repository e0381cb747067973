//! A render's output files, written so that they stay consistent: the EXR
//! (whose header says what the image is) is the one truth, written last.

use std::path::{Path, PathBuf};

use lumis_core::{Error, Result};
use lumis_image::{ExrLayer, ExrUintChannel, Image, OutputLock};
use lumis_render::Aov;

use crate::checkpoint::checkpoint_path;
use crate::metadata::ImageMetadata;

/// `NAME.partial.EXT` for `NAME.EXT`: where an unfinished render's image
/// goes, so that it never replaces a finished one.
pub fn partial_path(path: &Path) -> PathBuf {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    match path.extension() {
        Some(ext) => path.with_file_name(format!("{stem}.partial.{}", ext.to_string_lossy())),
        None => path.with_file_name(format!("{stem}.partial")),
    }
}

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

/// Removes `what` at `path`, if it is there.
pub fn remove_if_present(path: &Path, what: &str) -> Result<()> {
    match std::fs::remove_file(path) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(Error::msg(format!(
            "{}: cannot remove {what}: {e}",
            path.display()
        ))),
    }
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
        for path in [Some(exr), png].into_iter().flatten() {
            lumis_files::check_replaceable(path).map_err(Error::msg)?;
        }
        let lock = OutputLock::acquire(exr).map_err(image_error)?;
        let checkpoint = checkpoint_path(exr);
        let partials = [Some(partial_path(exr)), png.map(partial_path)];
        for path in [Some(exr), png, Some(checkpoint.as_path())]
            .into_iter()
            .chain(partials.iter().map(Option::as_deref))
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

    /// The image of an unfinished render, beside the outputs
    /// ([`partial_path`]): a finished image there stays until the render
    /// that replaces it finishes.
    pub fn write_unfinished(
        &self,
        image: &Image,
        aovs: &[(Aov, Image)],
        metadata: &ImageMetadata,
    ) -> Result<()> {
        let png = self.png.as_deref().map(partial_path);
        write_pair(
            &partial_path(&self.exr),
            png.as_deref(),
            image,
            aovs,
            &[],
            &metadata.attributes(),
        )
    }

    /// Removes the unfinished render's image, once the finished one is
    /// written.
    pub fn remove_unfinished(&self) -> Result<()> {
        let png = self.png.as_deref().map(partial_path);
        for path in [Some(partial_path(&self.exr)), png].into_iter().flatten() {
            remove_if_present(&path, "the unfinished image")?;
        }
        Ok(())
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
        write_pair(
            &self.exr,
            self.png.as_deref(),
            image,
            aovs,
            uints,
            attributes,
        )
    }
}

/// Writes `exr` (with `aovs` as layers, `uints` as channels and
/// `attributes` in its header) and `png`: both staged in full, then the
/// PNG renamed into place and the EXR last.
fn write_pair(
    exr: &Path,
    png: Option<&Path>,
    image: &Image,
    aovs: &[(Aov, Image)],
    uints: &[ExrUintChannel],
    attributes: &[(String, String)],
) -> Result<()> {
    let png = match png {
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
    let exr = lumis_image::stage_exr_with_channels(exr, image, &layers, uints, attributes)
        .map_err(image_error)?;
    if let Some(png) = png {
        png.commit().map_err(image_error)?;
    }
    exr.commit().map_err(image_error)
}
