//! Denoising a finished image, for the `[denoiser]` of `lumis render` and
//! `lumis merge` and for `lumis denoise`: the raw image stays the main
//! output (`NAME.exr`, `NAME.png`, the unbiased estimate); the denoised
//! image, biased, goes beside it as `NAME.denoised.exr` and
//! `NAME.denoised.png`, its header saying in `lumis.denoised_by` which
//! denoiser made it.
//!
//! A denoiser is recorded as its `[denoiser]` table (`type` and
//! parameters) written as one line of TOML, an inline table with its keys
//! sorted: `{ prefilter = false, quality = "fast", type = "oidn" }`. A
//! render writes its scene's in every image's `lumis.denoiser`, so the
//! merge of its parts, and `lumis denoise`, make the same denoiser again.

use std::path::{Path, PathBuf};

use lumis_core::doc::{self, Table, Value};
use lumis_core::entity::TYPE_KEY;
use lumis_core::{
    DenoiseInput, Denoiser, Error, Location, PluginEntity, PluginKind, Registry, Result,
};
use lumis_image::Image;
use lumis_render::{Aov, Film};
use lumis_scene::SceneDenoiser;

use crate::metadata::ImageMetadata;
use crate::outputs::Outputs;

/// The header attribute of a denoised image that records its denoiser.
pub const DENOISED_BY: &str = "lumis.denoised_by";

/// `STEM.denoised.exr` and `STEM.denoised.png` beside the raw `STEM.exr`.
pub fn denoised_paths(raw_exr: &Path) -> (PathBuf, PathBuf) {
    let mut stem = raw_exr.with_extension("").into_os_string();
    stem.push(".denoised.exr");
    let exr = PathBuf::from(stem);
    let png = exr.with_extension("png");
    (exr, png)
}

/// Claims the denoised image's files (`STEM.denoised.exr` and `.png`) before
/// the render starts, so a render never ends unable to write them.
pub fn claim_denoised_outputs(raw_exr: &Path) -> Result<Outputs> {
    let (exr, png) = denoised_paths(raw_exr);
    Outputs::claim(&exr, Some(&png))
}

/// A denoiser, made, and its table as the line of TOML its images record.
pub struct ConfiguredDenoiser {
    pub denoiser: Box<dyn Denoiser>,
    /// `{ quality = "fast", type = "oidn" }`.
    pub toml: String,
}

impl ConfiguredDenoiser {
    /// The denoiser a scene's `[denoiser]` made.
    pub fn of_scene(scene: SceneDenoiser) -> Result<Self> {
        Ok(Self {
            toml: table_toml(&scene.entity.table)?,
            denoiser: scene.denoiser,
        })
    }

    /// Makes the denoiser `table` describes (its `type` and parameters)
    /// through `registry`; `source` says in errors where the table came
    /// from (`--denoiser oidn`, an image's header).
    pub fn create(table: Table, source: &str, registry: &Registry) -> Result<Self> {
        let from_source = |e: Error| Error::msg(format!("{source}: {}", e.message));
        let toml = table_toml(&table).map_err(from_source)?;
        let entity = PluginEntity::from_table(
            PluginKind::Denoiser,
            "denoiser",
            table,
            Location::Builtin,
            TYPE_KEY,
        )
        .map_err(from_source)?;
        let denoiser = registry
            .create::<dyn Denoiser>(&entity, ())
            .map_err(from_source)?;
        Ok(Self { denoiser, toml })
    }

    /// Makes the denoiser an image's `lumis.denoiser` records.
    pub fn of_header(toml: &str, image: &Path, registry: &Registry) -> Result<Self> {
        let source = header_source(toml, image);
        Self::create(header_table(toml, image)?, &source, registry)
    }
}

/// Names the `lumis.denoiser` of `image` in errors.
pub fn header_source(toml: &str, image: &Path) -> String {
    format!("'{}' header lumis.denoiser = {toml}", image.display())
}

/// The `[denoiser]` table an image's `lumis.denoiser` holds.
pub fn header_table(toml: &str, image: &Path) -> Result<Table> {
    let source = header_source(toml, image);
    let not_a_table = |why: String| {
        Error::msg(format!(
            "{source}: expected an inline TOML table {{ type = \"...\", ... }}: {why}"
        ))
    };
    let root =
        doc::parse(&format!("denoiser = {toml}\n"), &source).map_err(|e| not_a_table(e.message))?;
    match root.get("denoiser").map(|node| &node.value) {
        Some(Value::Table(table)) => Ok(table.clone()),
        Some(other) => Err(not_a_table(format!("found {}", other.type_name()))),
        None => Err(not_a_table("found nothing".into())),
    }
}

/// `table` as one line of TOML: an inline table, keys sorted, so one
/// configuration has one spelling.
pub fn table_toml(table: &Table) -> Result<String> {
    Ok(toml::Value::Table(toml_table(table)?).to_string())
}

fn toml_table(table: &Table) -> Result<toml::Table> {
    let mut entries: Vec<&doc::Entry> = table.entries.iter().collect();
    entries.sort_by(|a, b| a.key.cmp(&b.key));
    entries
        .into_iter()
        .map(|e| Ok((e.key.clone(), toml_value(&e.node.value)?)))
        .collect()
}

fn toml_value(value: &Value) -> Result<toml::Value> {
    Ok(match value {
        Value::Bool(b) => toml::Value::Boolean(*b),
        Value::Int(i) => toml::Value::Integer(*i),
        Value::Float(x) => toml::Value::Float(*x),
        Value::String(s) => toml::Value::String(s.clone()),
        Value::Array(items) => toml::Value::Array(
            items
                .iter()
                .map(|item| toml_value(&item.value))
                .collect::<Result<_>>()?,
        ),
        Value::Table(table) => toml::Value::Table(toml_table(table)?),
        Value::Datetime(text) => toml::Value::Datetime(
            text.parse()
                .map_err(|e| Error::msg(format!("the date {text}: {e}")))?,
        ),
        Value::Image(image) => return Err(Error::msg(format!("{image:?} has no TOML spelling"))),
    })
}

/// Denoises `color`, guided by `albedo` and `normal` where given.
pub fn denoise_colour(
    denoiser: &dyn Denoiser,
    color: &Image,
    albedo: Option<&Image>,
    normal: Option<&Image>,
) -> Result<Image> {
    let input = DenoiseInput {
        width: color.width,
        height: color.height,
        color: &color.pixels,
        albedo: albedo.map(|a| a.pixels.as_slice()),
        normal: normal.map(|n| n.pixels.as_slice()),
    };
    let pixels = denoiser.denoise(&input)?;
    if pixels.len() != color.pixels.len() {
        return Err(Error::msg(format!(
            "the denoiser returned {} pixels, expected {}",
            pixels.len(),
            color.pixels.len()
        )));
    }
    Ok(Image {
        width: color.width,
        height: color.height,
        pixels,
    })
}

/// Denoises a film's image, guided by its albedo and normal, which a
/// scene with a denoiser always makes.
pub fn denoise_film_image(denoiser: &dyn Denoiser, film: &Film) -> Result<Image> {
    let aovs = film.aov_images();
    let guide = |wanted: Aov| aovs.iter().find(|(aov, _)| *aov == wanted).map(|(_, i)| i);
    denoise_colour(
        denoiser,
        &film.image(),
        guide(Aov::Albedo),
        guide(Aov::Normal),
    )
}

/// Writes `denoised` to `outputs` with the header `attributes` and
/// [`DENOISED_BY`] `denoiser_toml`.
pub fn write_denoised_image(
    denoised: &Image,
    denoiser_toml: &str,
    outputs: &Outputs,
    mut attributes: Vec<(String, String)>,
) -> Result<()> {
    attributes.retain(|(name, _)| name != DENOISED_BY);
    attributes.push((DENOISED_BY.into(), denoiser_toml.to_string()));
    outputs.write_with_channels(denoised, &[], &[], &attributes)
}

/// The error of a denoise that failed after the raw image at `raw_exr`
/// was written: it names where the raw render is.
fn failed_beside(raw_exr: &Path) -> impl Fn(Error) -> Error + '_ {
    move |e| {
        Error::msg(format!(
            "denoising failed; the raw render is in {}: {}",
            raw_exr.display(),
            e
        ))
    }
}

/// Denoises `color` (guided by `albedo` and `normal`, where given), writes
/// the result to `outputs` with the header `attributes` and
/// [`DENOISED_BY`], and returns it. Called once the raw image is on disk
/// at `raw_exr`: an error here leaves it in place and says so.
pub fn write_denoised(
    denoiser: &ConfiguredDenoiser,
    color: &Image,
    albedo: Option<&Image>,
    normal: Option<&Image>,
    outputs: &Outputs,
    attributes: Vec<(String, String)>,
    raw_exr: &Path,
) -> Result<Image> {
    let failed = failed_beside(raw_exr);
    let denoised =
        denoise_colour(denoiser.denoiser.as_ref(), color, albedo, normal).map_err(&failed)?;
    write_denoised_image(&denoised, &denoiser.toml, outputs, attributes).map_err(&failed)?;
    Ok(denoised)
}

/// Denoises a finished film (`lumis render`, `lumis merge`), writes the
/// result beside the raw image at `raw_exr`, and returns it.
pub fn denoise_film(
    denoiser: &ConfiguredDenoiser,
    film: &Film,
    outputs: &Outputs,
    metadata: &ImageMetadata,
    raw_exr: &Path,
) -> Result<Image> {
    let failed = failed_beside(raw_exr);
    let denoised = denoise_film_image(denoiser.denoiser.as_ref(), film).map_err(&failed)?;
    write_denoised_image(&denoised, &denoiser.toml, outputs, metadata.attributes())
        .map_err(&failed)?;
    Ok(denoised)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_denoised_image_sits_beside_the_raw_one() {
        assert_eq!(
            denoised_paths(Path::new("out/cornell-box.exr")),
            (
                PathBuf::from("out/cornell-box.denoised.exr"),
                PathBuf::from("out/cornell-box.denoised.png")
            )
        );
    }

    /// The recorded line has one spelling per configuration, and reads
    /// back as the same table.
    #[test]
    fn a_table_round_trips_through_its_line_of_toml() {
        let written = doc::parse(
            "type = \"oidn\"\nquality = \"fast\" # a comment\nprefilter = false\nscale = 1e-3\nsize = [1, 2]\n",
            "scene.toml",
        )
        .unwrap();
        let toml = table_toml(&written).unwrap();
        assert_eq!(
            toml,
            "{ prefilter = false, quality = \"fast\", scale = 0.001, size = [1, 2], type = \"oidn\" }"
        );
        let image = Path::new("x.exr");
        assert_eq!(
            table_toml(&header_table(&toml, image).unwrap()).unwrap(),
            toml
        );
        let err = header_table("oidn", image).unwrap_err().to_string();
        assert!(
            err.contains("'x.exr' header lumis.denoiser = oidn: expected an inline TOML table"),
            "{err}"
        );
        let err = header_table("\"oidn\"", image).unwrap_err().to_string();
        assert!(err.contains("found a string"), "{err}");
    }

    /// A denoiser that fails leaves the raw render where it is, and the
    /// error says so; nothing is written for the denoised image.
    #[test]
    fn a_failed_denoise_names_the_raw_render_it_leaves() {
        struct Failing;
        impl Denoiser for Failing {
            fn denoise(&self, _: &DenoiseInput<'_>) -> Result<Vec<[f32; 3]>> {
                Err(Error::msg("no device"))
            }
        }
        let dir = tempfile::tempdir().unwrap();
        let raw = dir.path().join("plates.exr");
        let (exr, png) = denoised_paths(&raw);
        let outputs = Outputs::claim(&exr, Some(&png)).unwrap();
        let denoiser = ConfiguredDenoiser {
            denoiser: Box::new(Failing),
            toml: "{ type = \"failing\" }".into(),
        };
        let err = write_denoised(
            &denoiser,
            &Image::new(2, 2),
            None,
            None,
            &outputs,
            Vec::new(),
            &raw,
        )
        .unwrap_err()
        .to_string();
        assert!(
            err.contains(&format!(
                "denoising failed; the raw render is in {}: no device",
                raw.display()
            )),
            "{err}"
        );
        drop(outputs);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}
