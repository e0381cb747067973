//! Vectors and colours as they cross to Python: `(x, y, z)` and
//! `(r, g, b)` tuples.

use lumis_api::{Rgb, Vec3};
use pyo3::prelude::*;

pub fn tuple(v: Vec3) -> (f32, f32, f32) {
    (v.x, v.y, v.z)
}

pub fn vec3(value: &Bound<'_, PyAny>) -> PyResult<Vec3> {
    let (x, y, z) = value.extract::<(f32, f32, f32)>()?;
    Ok(Vec3::new(x, y, z))
}

pub fn rgb(value: &Bound<'_, PyAny>) -> PyResult<Rgb> {
    let (r, g, b) = value.extract::<(f32, f32, f32)>()?;
    Ok(Rgb::new(r, g, b))
}
