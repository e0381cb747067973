//! A partial image: one part of a render split over processes, as the EXR
//! `lumis render --part K/N` (or `--samples A..B`) writes and `lumis merge`
//! reads.
//!
//! Its colour and output layers are the slice's own means, so a viewer
//! shows it like any render. Beside them it holds the film's
//! double-precision sums exactly, which a float channel could not: each
//! `f64` as the high and low 32 bits of its bit pattern in two
//! whole-number channels, `partial.NAME.C.hi` and `partial.NAME.C.lo`,
//! for `NAME.C` in `sum.{R,G,B}`, `square.{R,G,B}` (with the `variance`
//! output), `albedo_sum.{R,G,B}`, `normal_sum.{X,Y,Z}` and `depth_sum.Z`
//! (with `albedo`, `normal` or `depth`), the bits of the splat sums of an
//! integrator that splats, `i64`s in `partial.splat.{R,G,B}.hi` and
//! `.lo`, and each pixel's sample count in `partial.count`. The header
//! holds the [`ImageMetadata`] with its `lumis.slice` and
//! `lumis.total_spp`, the outputs in `lumis.aovs`, and
//! `lumis.checksum`, the FNV-1a hash of the whole-number channels, so a
//! damaged file is refused rather than merged.

use std::path::Path;

use lumis_core::{Error, Result, UVec2};
use lumis_image::ExrUintChannel;
use lumis_render::{Aov, Film};
use lumis_scene::Fnv1a;

use crate::metadata::ImageMetadata;
use crate::outputs::Outputs;

/// The channel of the per-pixel sample counts.
const COUNT_CHANNEL: &str = "partial.count";

/// A partial image read back: the slice's film and its metadata.
#[derive(Debug, Clone, PartialEq)]
pub struct Partial {
    pub film: Film,
    pub metadata: ImageMetadata,
}

/// The film's `f64` sums, one buffer per component, by name (`sum.R`), in
/// a fixed order.
fn sum_components(film: &Film) -> Vec<(String, Vec<f64>)> {
    let mut out = Vec::new();
    let mut rgb = |name: &str, channels: [&str; 3], buffer: &dyn Fn(usize) -> [f64; 3]| {
        for (c, channel) in channels.iter().enumerate() {
            let values = (0..film.sums.len()).map(|i| buffer(i)[c]).collect();
            out.push((format!("{name}.{channel}"), values));
        }
    };
    rgb("sum", ["R", "G", "B"], &|i| film.sums[i]);
    if let Some(squares) = &film.squares {
        rgb("square", ["R", "G", "B"], &|i| squares[i]);
    }
    if let Some(hits) = &film.first_hits {
        rgb("albedo_sum", ["R", "G", "B"], &|i| hits[i].albedo);
        rgb("normal_sum", ["X", "Y", "Z"], &|i| hits[i].normal);
        out.push((
            "depth_sum.Z".to_string(),
            hits.iter().map(|h| h.depth).collect(),
        ));
    }
    out
}

/// The mutable `f64` of component `name` (as [`sum_components`] names it)
/// of pixel `i`.
fn component_mut<'a>(film: &'a mut Film, name: &str, i: usize) -> Option<&'a mut f64> {
    let (buffer, channel) = name.split_once('.')?;
    let c = match channel {
        "R" | "X" => 0,
        "G" | "Y" => 1,
        "B" | "Z" => 2,
        _ => return None,
    };
    match buffer {
        "sum" => Some(&mut film.sums[i][c]),
        "square" => Some(&mut film.squares.as_mut()?[i][c]),
        "albedo_sum" => Some(&mut film.first_hits.as_mut()?[i].albedo[c]),
        "normal_sum" => Some(&mut film.first_hits.as_mut()?[i].normal[c]),
        "depth_sum" => Some(&mut film.first_hits.as_mut()?[i].depth),
        _ => None,
    }
}

/// The splat sums' channels, by colour.
const SPLAT_CHANNELS: [&str; 3] = ["R", "G", "B"];

/// The channels `partial.NAME.hi` and `.lo` of 64-bit values' bits.
fn push_bits(out: &mut Vec<(String, Vec<u32>)>, name: &str, bits: impl Iterator<Item = u64>) {
    let bits: Vec<u64> = bits.collect();
    out.push((
        format!("partial.{name}.hi"),
        bits.iter().map(|b| (b >> 32) as u32).collect(),
    ));
    out.push((
        format!("partial.{name}.lo"),
        bits.iter().map(|&b| b as u32).collect(),
    ));
}

/// FNV-1a of the channels, names and values, in name order.
fn checksum(channels: &[(String, Vec<u32>)]) -> u64 {
    let mut sorted: Vec<&(String, Vec<u32>)> = channels.iter().collect();
    sorted.sort_by(|a, b| a.0.cmp(&b.0));
    let mut hash = Fnv1a::default();
    for (name, values) in sorted {
        hash.write(name.as_bytes());
        for v in values {
            hash.write(&v.to_le_bytes());
        }
    }
    hash.finish()
}

fn aov_names(aovs: &[Aov]) -> String {
    aovs.iter().map(|a| a.name()).collect::<Vec<_>>().join(",")
}

impl Partial {
    /// The whole-number channels holding the film: its sums' bits and the
    /// sample counts.
    fn channels(&self) -> Vec<(String, Vec<u32>)> {
        let mut out = Vec::new();
        for (name, values) in sum_components(&self.film) {
            push_bits(&mut out, &name, values.iter().map(|v| v.to_bits()));
        }
        if let Some(splats) = &self.film.splats {
            for (c, channel) in SPLAT_CHANNELS.iter().enumerate() {
                let bits = splats.iter().map(|s| s[c] as u64);
                push_bits(&mut out, &format!("splat.{channel}"), bits);
            }
        }
        let counts = (0..self.film.sums.len()).map(|i| self.film.samples_of(i));
        out.push((COUNT_CHANNEL.to_string(), counts.collect()));
        out
    }

    /// Writes the partial image to `outputs` (its EXR only).
    pub fn write(&self, outputs: &Outputs) -> Result<()> {
        let channels = self.channels();
        let uints: Vec<ExrUintChannel> = channels
            .iter()
            .map(|(name, values)| ExrUintChannel { name, values })
            .collect();
        let mut attributes = self.metadata.attributes();
        attributes.push(("lumis.aovs".into(), aov_names(&self.film.aovs)));
        attributes.push((
            "lumis.checksum".into(),
            format!("{:016x}", checksum(&channels)),
        ));
        outputs.write_with_channels(
            &self.film.image(),
            &self.film.aov_images(),
            &uints,
            &attributes,
        )
    }

    /// Reads the partial image at `path`; an error naming the file where
    /// it is not one lumis wrote, or is truncated or damaged.
    pub fn read(path: &Path) -> Result<Self> {
        let not_partial = |why: &str| {
            Error::msg(format!(
                "'{}' is not a lumis partial image: {why}",
                path.display()
            ))
        };
        let metadata = ImageMetadata::read(path)?
            .ok_or_else(|| not_partial("its EXR header has no lumis metadata"))?;
        let slice = metadata.slice.ok_or_else(|| {
            not_partial("its header has no lumis.slice (`lumis render --part K/N` or `--samples A..B` writes partial images)")
        })?;
        let attributes =
            lumis_image::read_exr_metadata(path).map_err(|e| Error::msg(e.to_string()))?;
        let attribute = |key: &str| {
            attributes
                .iter()
                .find(|(n, _)| n == key)
                .map(|(_, v)| v.as_str())
                .ok_or_else(|| not_partial(&format!("its header lacks {key}")))
        };
        let aovs = attribute("lumis.aovs")?
            .split(',')
            .filter(|name| !name.is_empty())
            .map(|name| {
                Aov::from_name(name).ok_or_else(|| {
                    not_partial(&format!("lumis.aovs names an unknown output '{name}'"))
                })
            })
            .collect::<Result<Vec<Aov>>>()?;
        let expected_checksum = attribute("lumis.checksum")?;
        let ((width, height), channels) =
            lumis_image::read_exr_uint_channels(path).map_err(|e| Error::msg(e.to_string()))?;
        if format!("{:016x}", checksum(&channels)) != expected_checksum {
            return Err(not_partial(
                "its checksum does not match its sums (the file is damaged)",
            ));
        }
        let resolution = UVec2::new(width as u32, height as u32);
        let mut film = Film::try_with_aovs(resolution, &aovs)?.starting_at(slice.start);
        film.samples = slice.end;
        let channel = |name: &str| {
            channels
                .iter()
                .find(|(n, _)| n == name)
                .map(|(_, v)| v)
                .ok_or_else(|| not_partial(&format!("it has no channel {name}")))
        };
        if channel(COUNT_CHANNEL)?.iter().any(|&n| n != slice.spp()) {
            return Err(not_partial(&format!(
                "its sample counts are not all {} ({slice})",
                slice.spp()
            )));
        }
        let bits = |name: &str| -> Result<Vec<u64>> {
            let hi = channel(&format!("partial.{name}.hi"))?;
            let lo = channel(&format!("partial.{name}.lo"))?;
            Ok(hi
                .iter()
                .zip(lo)
                .map(|(&hi, &lo)| (hi as u64) << 32 | lo as u64)
                .collect())
        };
        for (name, _) in sum_components(&film) {
            for (i, bits) in bits(&name)?.into_iter().enumerate() {
                let value = component_mut(&mut film, &name, i)
                    .ok_or_else(|| not_partial(&format!("no buffer for {name}")))?;
                *value = f64::from_bits(bits);
            }
        }
        if channel("partial.splat.R.hi").is_ok() {
            let by_colour = SPLAT_CHANNELS.map(|c| bits(&format!("splat.{c}")));
            let [r, g, b] = by_colour;
            let (r, g, b) = (r?, g?, b?);
            for (i, sum) in film.splat_sums()?.iter_mut().enumerate() {
                *sum = [r[i] as i64, g[i] as i64, b[i] as i64];
            }
        }
        Ok(Self { film, metadata })
    }
}
