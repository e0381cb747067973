//! A sampler written in Python.

use lumis_api::{Error, Result, Sampler, UVec2, Vec2};
use pyo3::prelude::*;

use super::object::PluginObject;

/// A Python object with `start_pixel_sample`, `get_1d`, `get_2d` and
/// `get_pixel_2d`, as a [`Sampler`]; its samples per pixel are its `spp`
/// attribute, read once.
pub struct PythonSampler {
    object: PluginObject,
    spp: u32,
}

impl PythonSampler {
    pub fn new(object: PluginObject) -> Result<Self> {
        let spp = object.attribute("spp", |s| s.extract::<u32>())?;
        if spp == 0 {
            return Err(Error::msg(format!(
                "{}: spp must be at least 1",
                object.label
            )));
        }
        Ok(Self { object, spp })
    }
}

fn pair(value: &Bound<'_, PyAny>) -> PyResult<Vec2> {
    let (u, v) = value.extract::<(f32, f32)>()?;
    Ok(Vec2::new(u, v))
}

impl Sampler for PythonSampler {
    fn samples_per_pixel(&self) -> u32 {
        self.spp
    }

    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32, seed: u64) {
        self.object.call(
            "start_pixel_sample",
            ((pixel.x, pixel.y), index, seed),
            |_| Ok(()),
        )
    }

    fn get_1d(&mut self) -> f32 {
        self.object.call("get_1d", (), |u| u.extract::<f32>())
    }

    fn get_2d(&mut self) -> Vec2 {
        self.object.call("get_2d", (), pair)
    }

    fn get_pixel_2d(&mut self) -> Vec2 {
        self.object.call("get_pixel_2d", (), pair)
    }

    fn clone_sampler(&self) -> Box<dyn Sampler> {
        Box::new(Self {
            object: self.object.deep_copy(),
            spp: self.spp,
        })
    }
}
