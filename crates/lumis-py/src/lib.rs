//! `import lumis`: the render session library ([`lumis_app`]) from Python.
//!
//! A scene is loaded from a file with `--set` overrides (`load_file`) or
//! from nested dicts (`load_dict`), rendered in memory to a NumPy array
//! (`Scene.render`, with the GIL released, Ctrl-C stopping it with the
//! samples done, and a progress bar), written as the command line writes
//! it, and compared with a reference (`diff`). A lumis error is a
//! `lumis.Error` exception carrying the message and where in the scene it
//! was found. The book's Python chapter (`docs/src/python.md`) shows each.

mod errors;
mod image;
mod mapping;
mod plugins;
mod render;
mod scene;
mod stoppable;
mod study;

use pyo3::prelude::*;

/// lumis: a Monte Carlo path tracer whose subject is variance reduction.
///
/// `lumis.load_file(path, **overrides)` and `lumis.load_dict(scene)` load
/// a scene; `scene.render(spp=..., seed=...)` renders it to a `Render`,
/// whose `image` is a NumPy array of shape (height, width, 3);
/// `lumis.diff(image, reference)` gives the error metrics of `lumis diff`.
#[pymodule]
mod lumis {
    #[pymodule_export]
    use crate::errors::{Error, Interrupted};
    #[pymodule_export]
    use crate::image::{diff, read_image};
    #[pymodule_export]
    use crate::plugins::{check_plugin, register_bsdf, register_light, register_sampler};
    #[pymodule_export]
    use crate::render::Render;
    #[pymodule_export]
    use crate::scene::{load_dict, load_file, Scene};
    #[pymodule_export]
    use crate::study::{bias_variance, converge, Study};

    #[pymodule_init]
    fn init(m: &pyo3::Bound<'_, pyo3::types::PyModule>) -> pyo3::PyResult<()> {
        use pyo3::types::PyModuleMethods;
        m.add("__version__", env!("CARGO_PKG_VERSION"))
    }
}
