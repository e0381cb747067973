//! `[film]`: the image's size, where it goes, its pixel filter, the
//! outputs written beside the colour, and the clamp on the samples it adds.

use std::path::PathBuf;

use lumis_core::doc::Table;
use lumis_core::params::LocatedTable;
use lumis_core::{Error, Location, Params, PluginParams, Result, UVec2};
use lumis_render::Aov;

use super::clamp;
use super::document::{type_of, Located};

/// The keys of `[film]`.
#[derive(Debug, Clone, PluginParams)]
pub(crate) struct FilmParams {
    /// image width and height in pixels
    #[param(default = [256, 256])]
    resolution: UVec2,
    /// output EXR path, relative to the scene file
    output: Option<PathBuf>,
    /// pixel filter: { type = "box" } (the default)
    filter: Option<LocatedTable>,
    /// outputs written as layers of the EXR beside the colour: albedo,
    /// normal, depth, variance, spp
    aovs: Option<Vec<String>>,
    /// the largest component a camera sample's radiance may have (as
    /// pbrt-v4's maxcomponentvalue): biased, it trades rare bright samples
    /// for less variance; absent, nothing is clamped
    clamp: Option<f32>,
}

/// What `[film]` asks for.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct FilmDescription {
    pub resolution: UVec2,
    /// `output`, resolved as `Location::resolve` says.
    pub output: Option<PathBuf>,
    /// `aovs`, in the order written, each once.
    pub aovs: Vec<Aov>,
    /// `clamp`, checked positive and finite.
    pub clamp: Option<f32>,
}

/// Reads `[film]` (all defaults when absent; `file` locates its absence).
pub(crate) fn film(table: Option<Located<Table>>, file: &Location) -> Result<FilmDescription> {
    let (table, location) = table.unwrap_or_else(|| (Table::default(), file.clone()));
    let film = Params::new("[film]", &table, location, FilmParams::SPECS, &[])?;
    let p = FilmParams::read(&film)?;
    let keys = FilmParams::KEYS;
    let resolution = p.resolution;
    if resolution.x == 0 || resolution.y == 0 {
        return Err(film.error(keys.resolution, "width and height must be at least 1"));
    }
    if let Some(LocatedTable {
        table: filter,
        location,
    }) = &p.filter
    {
        match type_of(filter, location, "[film] filter")? {
            ("box", _) if filter.entries.len() == 1 => {}
            ("box", _) => {
                return Err(Error::at(
                    location,
                    "the box filter takes no parameters (radius 1/2 pixel)",
                ))
            }
            (other, loc) => {
                return Err(Error::at(
                    &loc,
                    format!("unknown pixel filter \"{other}\"; available: box"),
                ));
            }
        }
    }
    let mut aovs = Vec::new();
    for name in p.aovs.unwrap_or_default() {
        let allowed = || Aov::ALL.map(|a| format!("\"{a}\"")).join(", ");
        let aov = Aov::from_name(&name).ok_or_else(|| {
            film.error(
                keys.aovs,
                format!("unknown output \"{name}\"; allowed: {}", allowed()),
            )
        })?;
        if aovs.contains(&aov) {
            return Err(film.error(keys.aovs, format!("\"{name}\" is listed twice")));
        }
        aovs.push(aov);
    }
    let clamp = p
        .clamp
        .map(|value| clamp::checked(value).map_err(|why| film.error(keys.clamp, why)))
        .transpose()?;
    film.finish()?;
    Ok(FilmDescription {
        resolution,
        output: p.output,
        aovs,
        clamp,
    })
}
