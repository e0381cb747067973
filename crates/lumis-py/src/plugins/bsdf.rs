//! A BSDF written in Python.

use lumis_api::{Bsdf, BsdfContext, BsdfFlags, BsdfSample, Error, Result, Rgb, Vec2, Vec3};
use pyo3::prelude::*;

use super::object::PluginObject;
use super::values::{rgb, tuple};

/// A Python object with `flags`, `f`, `pdf` and `sample_f`, as a [`Bsdf`]:
/// directions cross as `(x, y, z)` tuples of the local shading frame.
pub struct PythonBsdf {
    object: PluginObject,
    flags: BsdfFlags,
}

impl PythonBsdf {
    pub fn new(object: PluginObject) -> Result<Self> {
        let flags = object.attribute("flags", |f| f.extract::<String>())?;
        let flags = flags_named(&flags)
            .map_err(|why| Error::msg(format!("{}: flags: {why}", object.label)))?;
        Ok(Self { object, flags })
    }
}

/// `"diffuse|reflection"`: lobe names joined by `|`.
pub fn flags_named(text: &str) -> std::result::Result<BsdfFlags, String> {
    text.split('|').map(str::trim).try_fold(BsdfFlags::NONE, |flags, name| {
        let flag = match name {
            "reflection" => BsdfFlags::REFLECTION,
            "transmission" => BsdfFlags::TRANSMISSION,
            "diffuse" => BsdfFlags::DIFFUSE,
            "glossy" => BsdfFlags::GLOSSY,
            "specular" => BsdfFlags::SPECULAR,
            other => {
                return Err(format!(
                    "unknown lobe \"{other}\" in \"{text}\": expected reflection, transmission, diffuse, glossy or specular joined by |"
                ))
            }
        };
        Ok(flags | flag)
    })
}

impl Bsdf for PythonBsdf {
    fn flags(&self) -> BsdfFlags {
        self.flags
    }

    fn f(&self, _ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> Rgb {
        self.object.call("f", (tuple(wo), tuple(wi)), rgb)
    }

    fn pdf(&self, _ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> f32 {
        self.object
            .call("pdf", (tuple(wo), tuple(wi)), |p| p.extract::<f32>())
    }

    fn sample_f(&self, _ctx: &BsdfContext, wo: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample> {
        self.object
            .call("sample_f", (tuple(wo), u1, (u2.x, u2.y)), |answer| {
                if answer.is_none() {
                    return Ok(None);
                }
                let items: Vec<Bound<'_, PyAny>> = answer.extract()?;
                if !(3..=5).contains(&items.len()) {
                    return Err(pyo3::exceptions::PyValueError::new_err(format!(
                        "sample_f returned {} values: expected None or (f, wi, pdf[, flags[, eta]])",
                        items.len()
                    )));
                }
                let (x, y, z) = items[1].extract::<(f32, f32, f32)>()?;
                let flags = match items.get(3) {
                    Some(f) => flags_named(&f.extract::<String>()?)
                        .map_err(pyo3::exceptions::PyValueError::new_err)?,
                    None => self.flags,
                };
                Ok(Some(BsdfSample {
                    f: rgb(&items[0])?,
                    wi: Vec3::new(x, y, z),
                    pdf: items[2].extract()?,
                    flags,
                    eta: items.get(4).map(|e| e.extract()).transpose()?.unwrap_or(1.0),
                }))
            })
    }
}
