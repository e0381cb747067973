//! `lumis denoise`: denoises an image that is already on disk, as a render
//! with the same `[denoiser]` would have: its colour, guided by the albedo
//! and normal layers a render writes into its EXR where it has them.

use std::path::{Path, PathBuf};
use std::time::Instant;

use lumis_core::doc::{Table, Value};
use lumis_core::{Error, Location, Registry, Result};
use lumis_image::{Image, ImageError};
use lumis_render::Aov;

use crate::assignments::parameter_table;
use crate::denoise::{
    denoised_paths, header_source, header_table, write_denoised, ConfiguredDenoiser, DENOISED_BY,
};
use crate::metadata::ImageMetadata;
use crate::outputs::{same_file, Outputs};
use crate::render::output_paths;

/// What `lumis denoise` was asked to do; also its command-line flags.
#[derive(Debug, Clone, clap::Args)]
pub struct DenoiseArgs {
    /// The image: an EXR, such as `lumis render` writes (with the albedo
    /// and normal layers a scene with a `[denoiser]` adds).
    pub image: PathBuf,
    /// Output path: writes PATH.exr and PATH.png [default:
    /// IMAGE.denoised.exr and .png beside the image].
    #[arg(long, short)]
    pub output: Option<PathBuf>,
    /// The denoiser plugin [default: the one the image's header records
    /// for its scene (lumis.denoiser), else oidn].
    #[arg(long, value_name = "TYPE")]
    pub denoiser: Option<String>,
    /// A parameter of the denoiser, e.g. `--set quality=fast` (repeatable);
    /// without --denoiser, it changes that of the header's denoiser.
    #[arg(long = "set", value_name = "key=value")]
    pub set: Vec<String>,
    /// Also load this plugin library (repeatable).
    #[arg(long, value_name = "LIB.so")]
    pub load: Vec<PathBuf>,
}

/// The denoiser of an image without `--denoiser` whose header records
/// none.
const DEFAULT_DENOISER: &str = "oidn";

/// What `lumis denoise` wrote.
pub struct DenoiseReport {
    pub exr: PathBuf,
    pub png: PathBuf,
    /// The denoiser as the header records it (`lumis.denoised_by`).
    pub denoised_by: String,
    /// The layers that guided it.
    pub guides: Vec<Aov>,
    pub seconds: f64,
}

impl DenoiseReport {
    /// The line `lumis denoise` prints.
    pub fn summary(&self, image: &Path) -> String {
        let guides = match self.guides.as_slice() {
            [] => "the colour alone".to_string(),
            guides => guides
                .iter()
                .map(|g| g.name())
                .collect::<Vec<_>>()
                .join(" and "),
        };
        format!(
            "{} denoised by {}, guided by {guides}, in {:.2} s -> {} and {}",
            image.display(),
            self.denoised_by,
            self.seconds,
            self.exr.display(),
            self.png.display()
        )
    }
}

/// The image to denoise: its colour, guides and header.
struct Input {
    color: Image,
    albedo: Option<Image>,
    normal: Option<Image>,
    /// Every text attribute of its header, carried over.
    attributes: Vec<(String, String)>,
    metadata: Option<ImageMetadata>,
}

/// Reads the image at `path`; an error naming it where it is not an EXR,
/// has no colour, or is one `lumis denoise` must not take (a part of a
/// render, an image already denoised).
fn read_input(path: &Path) -> Result<Input> {
    let attributes = lumis_image::read_exr_metadata(path).map_err(|e| match e {
        ImageError::Io { .. } | ImageError::Refused { .. } => Error::msg(e.to_string()),
        ImageError::Format { .. } => Error::msg(format!(
            "'{}' is not an EXR image ({e}): lumis denoise reads the EXR a render writes",
            path.display()
        )),
    })?;
    if let Some((_, toml)) = attributes.iter().find(|(name, _)| name == DENOISED_BY) {
        return Err(Error::msg(format!(
            "'{}' is already denoised ({DENOISED_BY} = {toml}): denoise the raw image beside it",
            path.display()
        )));
    }
    let metadata = ImageMetadata::read(path)?;
    if let Some(slice) = metadata.as_ref().and_then(|m| m.slice) {
        return Err(Error::msg(format!(
            "'{}' is a part of a render ({slice}): `lumis merge` its parts, which \
             denoises the merged image when the scene has a [denoiser]",
            path.display()
        )));
    }
    let channels = lumis_image::read_exr_channels(path).map_err(|e| Error::msg(e.to_string()))?;
    let channel = |name: &str| channels.iter().find(|(n, _)| n == name).map(|(_, v)| v);
    if ["R", "G", "B"].iter().any(|c| channel(c).is_none()) {
        let names: Vec<&str> = channels.iter().map(|(n, _)| n.as_str()).collect();
        return Err(Error::msg(format!(
            "'{}' has no colour layer: expected the channels R, G and B, found {}",
            path.display(),
            if names.is_empty() {
                "none".to_string()
            } else {
                names.join(", ")
            }
        )));
    }
    let color = lumis_image::read_exr(path).map_err(|e| Error::msg(e.to_string()))?;
    let layer = |aov: Aov| -> Result<Option<Image>> {
        let found: Vec<Option<&Vec<f32>>> = aov
            .channels()
            .iter()
            .map(|c| channel(&format!("{}.{c}", aov.name())))
            .collect();
        if found.iter().all(Option::is_none) {
            return Ok(None);
        }
        let mut image = Image::new(color.width, color.height);
        for (c, values) in found.iter().enumerate() {
            let name = format!("{}.{}", aov.name(), aov.channels()[c]);
            let values = values.ok_or_else(|| {
                Error::msg(format!(
                    "'{}' has a partial {} layer: no channel {name}",
                    path.display(),
                    aov.name()
                ))
            })?;
            if values.len() != image.pixels.len() {
                return Err(Error::msg(format!(
                    "'{}': channel {name} has {} values, expected {} ({}x{})",
                    path.display(),
                    values.len(),
                    image.pixels.len(),
                    color.width,
                    color.height
                )));
            }
            for (pixel, &v) in image.pixels.iter_mut().zip(values.iter()) {
                pixel[c] = v;
            }
        }
        Ok(Some(image))
    };
    let input = Input {
        albedo: layer(Aov::Albedo)?,
        normal: layer(Aov::Normal)?,
        color,
        attributes,
        metadata,
    };
    // Said first: no denoiser, guided or not, takes a non-finite pixel.
    let layers = [
        ("colour", Some(&input.color)),
        ("albedo", input.albedo.as_ref()),
        ("normal", input.normal.as_ref()),
    ];
    for (name, image) in layers {
        let Some(image) = image else { continue };
        if let Some(i) = image
            .pixels
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            let [r, g, b] = image.pixels[i];
            return Err(Error::msg(format!(
                "'{}': its {name} holds a value that is not finite, [{r}, {g}, {b}] at pixel \
                 ({}, {}); a denoiser needs finite values (`lumis render` leaves out NaN and \
                 infinite samples: this image was made or changed elsewhere)",
                path.display(),
                i % image.width,
                i / image.width
            )));
        }
    }
    Ok(input)
}

/// The denoiser `args` name (`--denoiser`, else the header's, else
/// [`DEFAULT_DENOISER`]) with `--set` over its parameters.
fn choose_denoiser(
    args: &DenoiseArgs,
    recorded: Option<&str>,
    registry: &Registry,
) -> Result<ConfiguredDenoiser> {
    let flag_table = |type_name: &str| {
        Table::built(
            &Location::Builtin,
            [("type", Value::String(type_name.to_string()))],
        )
    };
    let (mut table, mut source) = match (&args.denoiser, recorded) {
        (Some(type_name), _) => (flag_table(type_name), format!("--denoiser {type_name}")),
        (None, Some(toml)) => (
            header_table(toml, &args.image)?,
            header_source(toml, &args.image),
        ),
        (None, None) => (
            flag_table(DEFAULT_DENOISER),
            format!("the default denoiser {DEFAULT_DENOISER}"),
        ),
    };
    for entry in parameter_table(&args.set)?.entries {
        table.insert(&entry.key, entry.node);
    }
    for set in &args.set {
        source += &format!(" --set {set}");
    }
    ConfiguredDenoiser::create(table, &source, registry)
}

/// Denoises `args.image` and writes `IMAGE.denoised.exr` and `.png` (or
/// the `-o` path), with the image's header and `lumis.denoised_by`.
pub fn denoise_image(args: &DenoiseArgs, registry: &Registry) -> Result<DenoiseReport> {
    let mut extended;
    let registry = if args.load.is_empty() {
        registry
    } else {
        extended = registry.clone();
        for library in &args.load {
            lumis_loader::load_library(library, &mut extended)?;
        }
        &extended
    };
    let input = read_input(&args.image)?;
    let recorded = input.metadata.as_ref().and_then(|m| m.denoiser.as_deref());
    let denoiser = choose_denoiser(args, recorded, registry)?;
    let (exr, png) = match &args.output {
        Some(output) => {
            let stem = args.image.file_stem().unwrap_or_default().to_string_lossy();
            output_paths(output, &format!("{stem}.denoised"))
        }
        None => denoised_paths(&args.image),
    };
    for output in [&exr, &png] {
        if same_file(output, &args.image) {
            return Err(Error::msg(format!(
                "the output {} is the image being denoised: give another -o",
                output.display()
            )));
        }
    }
    let outputs = Outputs::claim(&exr, Some(&png))?;
    // The albedo guides alone; the normal only with it (OIDN's rule).
    let albedo = input.albedo.as_ref();
    let normal = albedo.and(input.normal.as_ref());
    let guides: Vec<Aov> = [(Aov::Albedo, albedo), (Aov::Normal, normal)]
        .into_iter()
        .filter_map(|(aov, image)| image.map(|_| aov))
        .collect();
    let start = Instant::now();
    write_denoised(
        &denoiser,
        &input.color,
        albedo,
        normal,
        &outputs,
        input.attributes,
        &args.image,
    )
    .map_err(|e| match guides.is_empty() {
        true => e.context(format!(
            "the denoiser had no guides: '{}' has no albedo layer (a render of a scene with a \
             [denoiser], or with [film] aovs = [\"albedo\", \"normal\"], writes the albedo \
             and normal)",
            args.image.display()
        )),
        false => e,
    })?;
    Ok(DenoiseReport {
        exr,
        png,
        denoised_by: denoiser.toml,
        guides,
        seconds: start.elapsed().as_secs_f64(),
    })
}
