//! `lumis.load_file`, `lumis.load_dict` and the scene they return.

use std::path::PathBuf;
use std::sync::Arc;

use lumis_app::{FilmRequest, SampleSlice};
use lumis_core::{Error, Location, Registry};
use lumis_scene::{LoadedScene, SceneDocument};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyRange, PyRangeMethods};

use crate::errors::{lumis_error, OrRaise};
use crate::mapping::{assignment, document_of, toml_of};
use crate::plugins;
use crate::render::{run, Render, Report};

/// A loaded scene, ready to render.
///
/// Rendering at another `spp` than the scene's loads it again with
/// `sampler.spp` set, as `lumis render --spp` does: a sampler may place
/// each sample by the total count.
#[pyclass(module = "lumis")]
pub struct Scene {
    document: SceneDocument,
    registry: Registry,
    loaded: LoadedScene,
    /// The seed the document sets: a render's default.
    seed: u64,
}

impl Scene {
    fn load(py: Python<'_>, document: SceneDocument) -> PyResult<Self> {
        py.detach(|| {
            let registry = plugins::registry()?;
            let loaded = document.load(&[], &registry)?;
            Ok(Self {
                document,
                registry,
                seed: loaded.seed,
                loaded,
            })
        })
        .or_raise(py)
    }
}

/// Loads the scene file at `path`. Each keyword is a `--set` override,
/// its name the key's path and its value a Python value:
/// `lumis.load_file("scene.toml", **{"integrator.max_depth": 3})`; a
/// top-level key is a plain keyword (`seed=7`).
#[pyfunction]
#[pyo3(signature = (path, **overrides))]
pub fn load_file(
    py: Python<'_>,
    path: PathBuf,
    overrides: Option<&Bound<'_, PyDict>>,
) -> PyResult<Scene> {
    let mut sets = Vec::new();
    for (key, value) in overrides.into_iter().flat_map(|o| o.iter()) {
        sets.push(assignment(&key.extract::<String>()?, &value)?);
    }
    let document = SceneDocument::read(&path)
        .or_raise(py)?
        .with_overrides(sets);
    Scene::load(py, document)
}

/// Loads a scene given as nested dicts: the TOML document's tables as
/// dicts, its arrays of tables as lists of dicts
/// (`{"bsdf": [{"name": "white", "type": "diffuse"}], ...}`). Relative
/// paths are relative to the working directory; `name` names the files a
/// render writes. An error names the value by its subscripts
/// (`scene["bsdf"][0]["reflectance"]`).
#[pyfunction]
#[pyo3(signature = (scene, name = "scene"))]
pub fn load_dict(py: Python<'_>, scene: &Bound<'_, PyDict>, name: &str) -> PyResult<Scene> {
    let root = "scene";
    let toml::Value::Table(table) = toml_of(scene.as_any(), root)? else {
        unreachable!("a dict is a table");
    };
    let document = SceneDocument::from_table(
        name,
        document_of(&table, root),
        Location::Key(Arc::from(root)),
    );
    Scene::load(py, document)
}

/// `samples=range(a, b)`: sample indices `a..b` of a render of `spp`.
fn slice_of(py: Python<'_>, samples: &Bound<'_, PyRange>, spp: u32) -> PyResult<SampleSlice> {
    let text = format!("{}..{}", samples.start()?, samples.stop()?);
    if samples.step()? != 1 {
        return Err(lumis_error(
            py,
            &Error::msg(format!("samples={samples}: expected a range with step 1")),
        ));
    }
    SampleSlice::parse_range(&text, spp)
        .map_err(|why| Error::msg(format!("samples={samples}: {why}")))
        .or_raise(py)
}

#[pymethods]
impl Scene {
    /// Renders the scene to a `Render`, whose `image` is a `float32` array
    /// of shape (height, width, 3): the image `lumis render` makes with the
    /// same `--spp`, `--seed` and samples, bit for bit.
    ///
    /// `spp` and `seed` default to the scene's; `threads=0` uses one per
    /// core; `samples=range(a, b)` renders only those sample indices (a
    /// part, as `--samples a..b`); `pass_spp` sets the samples per pass
    /// (the image does not depend on it). `progress` is a callable taking
    /// `(done, total)`, `False` for none, or by default a `tqdm` bar where
    /// `tqdm` is installed. The GIL is released while rendering; Ctrl-C
    /// stops the render after the pass in flight and raises
    /// `lumis.Interrupted`, whose `render` holds the passes finished.
    #[pyo3(signature = (spp=None, seed=None, threads=0, samples=None, pass_spp=None, progress=None))]
    #[allow(clippy::too_many_arguments)]
    fn render(
        &mut self,
        py: Python<'_>,
        spp: Option<u32>,
        seed: Option<u64>,
        threads: usize,
        samples: Option<&Bound<'_, PyRange>>,
        pass_spp: Option<u32>,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Render> {
        if let Some(spp) = spp.filter(|&n| n != self.loaded.sampler.samples_per_pixel()) {
            let set = [format!("sampler.spp={spp}")];
            let (document, registry) = (&self.document, &self.registry);
            self.loaded = py.detach(|| document.load(&set, registry)).or_raise(py)?;
        }
        let seed = match seed {
            Some(s) if s > i64::MAX as u64 => {
                return Err(lumis_error(
                    py,
                    &Error::msg(format!("seed={s}: at most 2^63 - 1, as a scene's seed")),
                ))
            }
            Some(s) => s,
            None => self.seed,
        };
        self.loaded.seed = seed;
        let spp = self.loaded.sampler.samples_per_pixel();
        let request = FilmRequest {
            threads,
            samples: samples.map(|s| slice_of(py, s, spp)).transpose()?,
            pass_spp,
            max_memory: None,
        };
        let report = Report::of(py, progress)?;
        let (film, stopped_by) = run(py, &self.loaded, &self.registry, &request, &report)?;
        let document = self.document.clone();
        match stopped_by {
            None => Render::new(py, film, document),
            Some(e) if e.is_instance_of::<pyo3::exceptions::PyKeyboardInterrupt>(py) => {
                let render = (film.spp() > 0)
                    .then(|| Render::new(py, film, document))
                    .transpose()?;
                Err(Render::interrupted_error(py, render)?)
            }
            Some(e) => Err(e),
        }
    }

    /// The scene's name, which names the files a render writes.
    #[getter]
    fn name(&self) -> &str {
        &self.document.name
    }

    /// (width, height) of the film.
    #[getter]
    fn resolution(&self) -> (u32, u32) {
        let r = self.loaded.camera.resolution();
        (r.x, r.y)
    }

    /// The scene's samples per pixel.
    #[getter]
    fn spp(&self) -> u32 {
        self.loaded.sampler.samples_per_pixel()
    }

    fn __repr__(&self) -> String {
        let (w, h) = self.resolution();
        format!(
            "<lumis.Scene '{}' {w}x{h}, {} spp>",
            self.document.name,
            self.spp()
        )
    }
}
