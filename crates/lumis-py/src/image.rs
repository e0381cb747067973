//! Images between lumis and NumPy, and `lumis.diff`.

use std::path::PathBuf;

use lumis_analysis::image_error::{check_same_size, error_metrics};
use lumis_core::Error;
use lumis_image::Image;
use numpy::{AllowTypeChange, IntoPyArray, PyArrayLike3, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{lumis_error, OrRaise};
use crate::render::Render;

/// `image` as a NumPy `float32` array of shape (height, width, channels),
/// its pixels moved, not copied; one channel gives shape (height, width).
pub fn array_of(py: Python<'_>, image: Image, channels: usize) -> PyResult<Bound<'_, PyAny>> {
    let (height, width) = (image.height, image.width);
    if channels == 1 {
        let values: Vec<f32> = image.pixels.iter().map(|p| p[0]).collect();
        return Ok(values.into_pyarray(py).reshape([height, width])?.into_any());
    }
    let values = image.pixels.into_flattened();
    Ok(values
        .into_pyarray(py)
        .reshape([height, width, 3])?
        .into_any())
}

/// The colour of the EXR at `path` (a render's, a reference's) as a
/// `float32` array of shape (height, width, 3).
#[pyfunction]
pub fn read_image(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyAny>> {
    let image = py
        .detach(|| lumis_image::read_exr(&path))
        .map_err(|e| lumis_error(py, &Error::msg(e.to_string())))?;
    array_of(py, image, 3)
}

/// An image given to `lumis.diff`: a [`Render`], the path of an EXR, or
/// an array of shape (height, width, 3).
pub fn image_from(value: &Bound<'_, PyAny>) -> PyResult<Image> {
    let py = value.py();
    if let Ok(render) = value.cast::<Render>() {
        return Ok(render.get().image());
    }
    if let Ok(path) = value.extract::<PathBuf>() {
        return lumis_image::read_exr(&path)
            .map_err(|e| lumis_error(py, &Error::msg(e.to_string())));
    }
    let array: PyArrayLike3<f32, AllowTypeChange> = value.extract()?;
    let shape = array.shape();
    if shape[2] != 3 {
        return Err(lumis_error(
            py,
            &Error::msg(format!(
                "an image of shape {shape:?}: expected (height, width, 3)"
            )),
        ));
    }
    let pixels = array
        .as_array()
        .as_standard_layout()
        .as_slice()
        .expect("a standard-layout array is contiguous")
        .as_chunks::<3>()
        .0
        .to_vec();
    Ok(Image {
        width: shape[1],
        height: shape[0],
        pixels,
    })
}

/// The error metrics of `image` against `reference`, as `lumis diff`
/// prints them for the whole image: `mse`, `rmse`, `rel_mse`,
/// `mean_abs_rel_error`, `mean_signed_rel_error`, `psnr_db` and `count`
/// (the channel values compared). Each image is a Render, an EXR's path,
/// or an array of shape (height, width, 3).
#[pyfunction]
pub fn diff<'py>(
    image: &Bound<'py, PyAny>,
    reference: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    let py = image.py();
    let (a, b) = (image_from(image)?, image_from(reference)?);
    check_same_size(&a, &b).map_err(Error::msg).or_raise(py)?;
    let m = error_metrics(&a, &b, None);
    let metrics = PyDict::new(py);
    metrics.set_item("mse", m.mse)?;
    metrics.set_item("rmse", m.rmse)?;
    metrics.set_item("rel_mse", m.rel_mse)?;
    metrics.set_item("mean_abs_rel_error", m.mean_abs_rel_error)?;
    metrics.set_item("mean_signed_rel_error", m.mean_signed_rel_error)?;
    metrics.set_item("psnr_db", m.psnr_db)?;
    metrics.set_item("count", m.count)?;
    Ok(metrics)
}
