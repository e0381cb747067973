//! What an image was rendered from, kept in its EXR header: one file holds
//! both the pixels and their description, so they cannot disagree.

use std::path::Path;

use lumis_core::{Error, Result};

use crate::slice::SampleSlice;

/// The `lumis.*` text attributes of a rendered EXR.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageMetadata {
    /// The command that wrote it: `render` or `reference`.
    pub command: String,
    /// Samples per pixel in the image.
    pub spp: u32,
    /// Passes rendered. A `reference`'s pass `k` used seed `seed + k`; a
    /// `render`'s passes continue one sequence of sample indices.
    pub passes: u64,
    pub seed: u64,
    /// [`lumis_scene::scene_hash`] of the scene with its `--set` overrides.
    pub scene_hash: u64,
    /// [`lumis_scene::scene_hash`] of the scene file alone, for `converge`
    /// to tell whether it measures the scene a reference came from.
    pub scene_file_hash: u64,
    /// Rendering time over all runs that made the image.
    pub seconds: f64,
    /// The lumis version that wrote it.
    pub version: String,
    /// For a part of a render split over processes (a partial image), the
    /// sample indices it holds of how many; `None` for a whole image.
    pub slice: Option<SampleSlice>,
    /// The scene's `[denoiser]` as one line of TOML
    /// (`{ quality = "fast", type = "oidn" }`), from which a merge of the
    /// parts or `lumis denoise` makes the same denoiser; `None` where the
    /// scene has none.
    pub denoiser: Option<String>,
}

const PREFIX: &str = "lumis.";

/// Why saved work (a reference, a checkpoint) rendered from `saved_hash`
/// and `saved_seed` cannot be continued with this scene and seed, or
/// `None` when it can.
pub fn other_scene_or_seed(
    (saved_hash, saved_seed): (u64, u64),
    scene_hash: u64,
    seed: u64,
) -> Option<String> {
    if saved_hash != scene_hash {
        return Some(format!(
            "it was rendered from a different scene (scene hash {saved_hash:016x}, this scene {scene_hash:016x}: the scene, a file it names or a --set differs)"
        ));
    }
    (saved_seed != seed).then(|| format!("it was rendered from seed {saved_seed}, not {seed}"))
}

impl ImageMetadata {
    /// The header attributes, `(name, value)`.
    pub fn attributes(&self) -> Vec<(String, String)> {
        [
            ("command", self.command.clone()),
            ("spp", self.spp.to_string()),
            ("passes", self.passes.to_string()),
            ("seed", self.seed.to_string()),
            ("scene_hash", format!("{:016x}", self.scene_hash)),
            ("scene_file_hash", format!("{:016x}", self.scene_file_hash)),
            ("seconds", format!("{:.3}", self.seconds)),
            ("version", self.version.clone()),
        ]
        .into_iter()
        .chain(self.slice.iter().flat_map(|slice| {
            [
                ("slice", format!("{}..{}", slice.start, slice.end)),
                ("total_spp", slice.total.to_string()),
            ]
        }))
        .chain(self.denoiser.iter().map(|toml| ("denoiser", toml.clone())))
        .map(|(k, v)| (format!("{PREFIX}{k}"), v))
        .collect()
    }

    /// The metadata in the header of the EXR at `path`; `None` where it
    /// has none (an image lumis did not write).
    pub fn read(path: &Path) -> Result<Option<Self>> {
        let attributes =
            lumis_image::read_exr_metadata(path).map_err(|e| Error::msg(e.to_string()))?;
        let get = |key: &str| -> Option<&str> {
            let name = format!("{PREFIX}{key}");
            attributes
                .iter()
                .find(|(n, _)| *n == name)
                .map(|(_, v)| v.as_str())
        };
        if get("command").is_none() {
            return Ok(None);
        }
        let field = |key: &str| {
            get(key).ok_or_else(|| {
                Error::msg(format!(
                    "{}: the EXR header lacks the attribute {PREFIX}{key}",
                    path.display()
                ))
            })
        };
        let invalid = |key: &str, expected: &str| {
            Error::msg(format!(
                "{}: the EXR header attribute {PREFIX}{key} is not {expected}",
                path.display()
            ))
        };
        let number = |key: &str| -> Result<u64> {
            field(key)?
                .parse()
                .map_err(|_| invalid(key, "a whole number"))
        };
        let hash = |key: &str| -> Result<u64> {
            u64::from_str_radix(field(key)?, 16).map_err(|_| invalid(key, "a hexadecimal hash"))
        };
        let slice = match get("slice") {
            None => None,
            Some(text) => {
                let total = u32::try_from(number("total_spp")?)
                    .map_err(|_| invalid("total_spp", "below 2^32"))?;
                Some(
                    SampleSlice::parse_range(text, total)
                        .map_err(|why| invalid("slice", &format!("a slice A..B ({why})")))?,
                )
            }
        };
        Ok(Some(Self {
            command: field("command")?.to_string(),
            spp: u32::try_from(number("spp")?).map_err(|_| invalid("spp", "below 2^32"))?,
            passes: number("passes")?,
            seed: number("seed")?,
            scene_hash: hash("scene_hash")?,
            scene_file_hash: hash("scene_file_hash")?,
            seconds: field("seconds")?
                .parse()
                .map_err(|_| invalid("seconds", "a number"))?,
            version: field("version")?.to_string(),
            slice,
            denoiser: get("denoiser").map(str::to_string),
        }))
    }
}

/// This build's version, as `lumis --version` prints it first.
pub fn lumis_version() -> String {
    env!("CARGO_PKG_VERSION").to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_through_an_exr_header() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.exr");
        let meta = ImageMetadata {
            command: "reference".into(),
            spp: 512,
            passes: 2,
            seed: u64::MAX,
            scene_hash: 0x0123_4567_89ab_cdef,
            scene_file_hash: 7,
            seconds: 1.5,
            version: lumis_version(),
            slice: None,
            denoiser: None,
        };
        let image = lumis_image::Image::new(1, 1);
        lumis_image::write_exr_with_metadata(&path, &image, &meta.attributes()).unwrap();
        assert_eq!(ImageMetadata::read(&path).unwrap(), Some(meta.clone()));
        let part = ImageMetadata {
            slice: Some(SampleSlice {
                start: 16,
                end: 48,
                total: 512,
            }),
            denoiser: Some("{ quality = \"fast\", type = \"oidn\" }".into()),
            ..meta
        };
        lumis_image::write_exr_with_metadata(&path, &image, &part.attributes()).unwrap();
        assert_eq!(ImageMetadata::read(&path).unwrap(), Some(part));
        lumis_image::write_exr(&path, &image).unwrap();
        assert_eq!(ImageMetadata::read(&path).unwrap(), None);
    }
}
