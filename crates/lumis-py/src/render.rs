//! A render run from Python, and what it returns.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;

use lumis_app::{render_film, FilmRender, FilmRequest, Progress, Session};
use lumis_core::{Error, Registry};
use lumis_image::Image;
use lumis_scene::{LoadedScene, SceneDocument};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

use crate::errors::{Interrupted, OrRaise};
use crate::image::array_of;
use crate::plugins::{self, raise_plugin_exception, take_exception};
use crate::stoppable::run_stoppable;

/// How a render reports how far it is.
pub enum Report {
    Silent,
    /// `progress(done, total)`, in tiles' passes.
    Callback(Py<PyAny>),
    /// A `tqdm` bar.
    Bar(Py<PyAny>),
}

impl Report {
    /// The caller's `progress` argument: a callable, `False` for none, or
    /// `None` (or `True`) for a `tqdm` bar where `tqdm` is installed.
    pub fn of(py: Python<'_>, progress: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        match progress {
            Some(p) if p.is_callable() => Ok(Self::Callback(p.clone().unbind())),
            Some(p) if !p.is_truthy()? => Ok(Self::Silent),
            Some(_) | None => match py.import("tqdm.auto") {
                Ok(tqdm) => {
                    let kwargs = PyDict::new(py);
                    kwargs.set_item("unit", "tile")?;
                    kwargs.set_item("leave", false)?;
                    let bar = tqdm.getattr("tqdm")?.call((), Some(&kwargs))?;
                    Ok(Self::Bar(bar.unbind()))
                }
                Err(_) => Ok(Self::Silent),
            },
        }
    }

    fn show(&self, py: Python<'_>, done: u64, total: u64) -> PyResult<()> {
        match self {
            Self::Silent => Ok(()),
            Self::Callback(f) => f.call1(py, (done, total)).map(drop),
            Self::Bar(bar) => {
                let bar = bar.bind(py);
                bar.setattr("total", total)?;
                bar.setattr("n", done)?;
                bar.call_method0("refresh").map(drop)
            }
        }
    }

    fn close(&self, py: Python<'_>) -> PyResult<()> {
        match self {
            Self::Bar(bar) => bar.call_method0(py, "close").map(drop),
            _ => Ok(()),
        }
    }
}

/// Renders `loaded`, stoppable by Ctrl-C ([`run_stoppable`]), showing
/// `report`; the render's warnings become Python warnings.
/// Returns the render, and the exception that stopped it (a
/// `KeyboardInterrupt`, or one the progress callback raised).
pub fn run(
    py: Python<'_>,
    loaded: &LoadedScene,
    registry: &Registry,
    request: &FilmRequest,
    report: &Report,
) -> PyResult<(FilmRender, Option<PyErr>)> {
    let stop = AtomicBool::new(false);
    let done = Arc::new((AtomicU64::new(0), AtomicU64::new(0)));
    let reported = done.clone();
    // The render's warnings (threads capped), kept for Python's warnings.
    let notes = std::sync::Mutex::new(Vec::new());
    let session = Session {
        registry,
        stop: &stop,
        notes: &|line| notes.lock().unwrap().push(line.to_string()),
        progress: Progress::Reported(Arc::new(move |units, total| {
            reported.0.store(units, Ordering::Relaxed);
            reported.1.store(total, Ordering::Relaxed);
        })),
        thread_host: Some(plugins::thread_host()),
    };
    take_exception();
    let (rendered, stopped_by) = run_stoppable(
        py,
        &stop,
        || render_film(loaded, request, &session),
        |py| {
            let (units, total) = (&done.0, &done.1);
            report.show(
                py,
                units.load(Ordering::Relaxed),
                total.load(Ordering::Relaxed),
            )
        },
    )?;
    report.close(py)?;
    let rendered = raise_plugin_exception(py, rendered)?;
    let warnings = py.import("warnings")?;
    let notes = notes.into_inner().unwrap_or_default();
    for line in notes.iter().chain(&rendered.defect_warnings()) {
        let line = line.strip_prefix("warning: ").unwrap_or(line);
        warnings.call_method1("warn", (line,))?;
    }
    if let Some(Err(e)) = &rendered.denoised {
        let line = format!("denoising failed, the render's `denoised` is None: {e}");
        warnings.call_method1("warn", (line,))?;
    }
    Ok((rendered, stopped_by))
}

/// A finished (or interrupted) render: its image as a NumPy array, its
/// outputs, and what it cost.
#[pyclass(module = "lumis", frozen)]
pub struct Render {
    film: FilmRender,
    document: SceneDocument,
    image: Py<PyAny>,
    aovs: Py<PyDict>,
    denoised: Option<Py<PyAny>>,
}

impl Render {
    pub fn new(py: Python<'_>, film: FilmRender, document: SceneDocument) -> PyResult<Self> {
        let image = array_of(py, film.film.image(), 3)?.unbind();
        let aovs = PyDict::new(py);
        for (aov, image) in film.film.aov_images() {
            aovs.set_item(aov.name(), array_of(py, image, aov.channels().len())?)?;
        }
        let denoised = film
            .denoised_image()
            .map(|image| Ok::<_, PyErr>(array_of(py, image.clone(), 3)?.unbind()))
            .transpose()?;
        Ok(Self {
            film,
            document,
            image,
            aovs: aovs.unbind(),
            denoised,
        })
    }

    /// The image, computed again from the film's sums (the array may have
    /// been changed by its holder).
    pub fn image(&self) -> Image {
        self.film.film.image()
    }

    /// The exception a stopped render raises, carrying this render.
    pub fn interrupted_error(py: Python<'_>, render: Option<Render>) -> PyResult<PyErr> {
        let message = match &render {
            Some(r) => format!(
                "interrupted at {} spp: the exception's `render` holds the passes finished",
                r.film.spp()
            ),
            None => "interrupted before the first pass ended".to_string(),
        };
        let error = Interrupted::new_err(message);
        let render = render.map(|r| Py::new(py, r)).transpose()?;
        error.value(py).setattr("render", render)?;
        Ok(error)
    }
}

#[pymethods]
impl Render {
    /// The image: a `float32` array of shape (height, width, 3), linear RGB.
    #[getter(image)]
    fn image_array(&self, py: Python<'_>) -> Py<PyAny> {
        self.image.clone_ref(py)
    }

    /// The outputs the scene's `[film] aovs` asks for, by name
    /// (`albedo`, `normal`, `variance`: (height, width, 3); `depth`,
    /// `spp`: (height, width)).
    #[getter]
    fn aovs(&self, py: Python<'_>) -> Py<PyDict> {
        self.aovs.clone_ref(py)
    }

    /// The image the scene's `[denoiser]` made of the finished render,
    /// as `lumis render` denoises it (shape and type as `image`); `None`
    /// without a denoiser, for a part of the samples, or when interrupted.
    #[getter]
    fn denoised(&self, py: Python<'_>) -> Option<Py<PyAny>> {
        self.denoised.as_ref().map(|d| d.clone_ref(py))
    }

    /// Samples per pixel in the image.
    #[getter]
    fn spp(&self) -> u32 {
        self.film.spp()
    }

    #[getter]
    fn seed(&self) -> u64 {
        self.film.seed
    }

    /// Rendering time in seconds.
    #[getter]
    fn seconds(&self) -> f64 {
        self.film.seconds
    }

    /// Whether Ctrl-C stopped the render before its last sample.
    #[getter]
    fn interrupted(&self) -> bool {
        self.film.interrupted
    }

    /// What the render did: rays, shadow rays, samples, non-finite samples
    /// dropped, emission found by BSDF and by light sampling, passes,
    /// seconds and spp.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = &self.film.stats;
        let stats = PyDict::new(py);
        stats.set_item("rays", s.rays)?;
        stats.set_item("shadow_rays", s.shadow_rays)?;
        stats.set_item("samples", s.samples)?;
        stats.set_item("nonfinite", s.nonfinite)?;
        stats.set_item("bsdf_light_hits", s.bsdf_light_hits)?;
        stats.set_item("light_samples", s.light_samples)?;
        stats.set_item("passes", self.film.passes)?;
        stats.set_item("seconds", self.film.seconds)?;
        stats.set_item("spp", self.film.spp())?;
        Ok(stats)
    }

    /// NumPy's view of a render is its image: `np.asarray(render)`.
    #[pyo3(signature = (dtype=None, copy=None))]
    fn __array__<'py>(
        &self,
        py: Python<'py>,
        dtype: Option<&Bound<'py, PyAny>>,
        copy: Option<bool>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let image = self.image.bind(py).clone();
        let numpy = py.import("numpy")?;
        let kwargs = PyDict::new(py);
        kwargs.set_item("dtype", dtype)?;
        kwargs.set_item("copy", copy.unwrap_or(false))?;
        numpy.getattr("array")?.call((image,), Some(&kwargs))
    }

    /// The image as the PNG `lumis render` writes (clamped, sRGB), which a
    /// notebook shows.
    fn _repr_png_<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let png = lumis_image::encode_png(&self.image())
            .map_err(Error::msg)
            .or_raise(py)?;
        Ok(PyBytes::new(py, &png))
    }

    /// Writes `PATH.exr` and `PATH.png` as `lumis render -o PATH` would,
    /// with the same metadata in the EXR's header, and the denoised image
    /// as `PATH.denoised.exr` and `.png` where there is one (a render of a
    /// slice of the samples writes its partial EXR, for `lumis merge`). An
    /// image of this scene with more samples is kept unless `force`.
    /// Returns the raw image's paths.
    #[pyo3(signature = (path, force=false))]
    fn write(
        &self,
        py: Python<'_>,
        path: PathBuf,
        force: bool,
    ) -> PyResult<(PathBuf, Option<PathBuf>)> {
        py.detach(|| self.film.write(&path, &self.document, force))
            .or_raise(py)
    }

    fn __repr__(&self) -> String {
        let film = &self.film.film;
        format!(
            "<lumis.Render {}x{}, {} spp, seed {}, {:.2} s{}>",
            film.width,
            film.height,
            self.film.spp(),
            self.film.seed,
            self.film.seconds,
            if self.film.interrupted {
                ", interrupted"
            } else {
                ""
            }
        )
    }
}
