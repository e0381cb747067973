//! The environment map the light suite hands a light's required `path`
//! parameter (a sweep cannot invent the file a light reads): an
//! equirectangular EXR with what makes sampling one hard, a smooth sky,
//! a sun a few texels wide, and a black band of rows.

use std::path::{Path, PathBuf};

use lumis_core::{Error, Result};
use lumis_image::Image;

/// The map's file, removed when dropped.
pub struct TestMap {
    _dir: tempfile::TempDir,
    path: PathBuf,
}

impl TestMap {
    pub const WIDTH: usize = 64;
    pub const HEIGHT: usize = 32;

    /// Writes the map in a fresh temporary directory.
    pub fn write() -> Result<Self> {
        let dir = tempfile::tempdir()
            .map_err(|e| Error::msg(format!("cannot make the test map's directory: {e}")))?;
        let path = dir.path().join("test-sky.exr");
        lumis_image::write_exr(&path, &Self::image())
            .map_err(|e| Error::msg(format!("cannot write the test map: {e}")))?;
        Ok(Self { _dir: dir, path })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Sky blue brightening toward the zenith, a sun at 30 degrees of
    /// elevation 4000 times brighter, black below 22.5 degrees under the
    /// horizon.
    pub fn image() -> Image {
        let mut image = Image::new(Self::WIDTH, Self::HEIGHT);
        for y in 0..Self::HEIGHT {
            let v = (y as f32 + 0.5) / Self::HEIGHT as f32;
            for x in 0..Self::WIDTH {
                let sky = if v > 0.625 {
                    [0.0; 3]
                } else {
                    let t = 1.0 - v;
                    [0.3 * t, 0.5 * t, 1.0 * t]
                };
                let sun = (x / 2 == 5 && y / 2 == 5) as u8 as f32 * 4000.0;
                image.set(x, y, sky.map(|c| c + sun));
            }
        }
        image
    }
}
