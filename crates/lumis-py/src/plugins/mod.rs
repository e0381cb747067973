//! Plugins written in Python: a BSDF, a light or a sampler as a Python
//! class with the methods of the Rust trait, registered by name and then
//! used from a scene by its `type` like any plugin.
//!
//! Each class is registered with the host as a loaded library's plugins
//! are, through [`register_guarded`]: its objects are wrapped in the same
//! guards, so an exception in a method is a fault of that plugin (its
//! answer neutral, the render stopped after the pass) and never a crash.
//! The first exception is kept ([`take_exception`]) and raised by the
//! call that rendered, with lumis's message as a note. The wrappers
//! (`bsdf.rs`, `light.rs`, `sampler.rs`) take the GIL for each call, so a
//! Python plugin runs one call at a time whatever the thread count.

mod bsdf;
mod check;
mod light;
mod object;
mod params;
mod sampler;
mod values;

use std::sync::{Arc, Mutex};

use lumis_api::guard::register_guarded;
use lumis_api::registrar::{Factory, PluginKind, PluginSpec, Registrar, SourceFile};
use lumis_api::{Error, ParamSpec, Params, Result};
use lumis_core::Registry;
use lumis_render::ThreadHost;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyType};

use crate::errors::{lumis_error, OrRaise};

pub use check::check_plugin;
pub use object::take_exception;
use object::PluginObject;

/// A class registered from Python.
struct Declared {
    spec: PluginSpec,
    class: Py<PyAny>,
}

/// The classes registered so far; each registry made afterwards has them.
static DECLARED: Mutex<Vec<Declared>> = Mutex::new(Vec::new());

/// What registries label the Python plugins' source with.
const SOURCE: &str = "python";

/// The built-in plugins, the libraries on `LUMIS_PLUGIN_PATH`, and every
/// class registered from Python: the plugins a scene loaded from Python
/// is made with.
pub fn registry() -> Result<Registry> {
    let mut registry = lumis_app::registry_with_search_path()?;
    registry.begin_library(SOURCE);
    let registered = register_guarded(&mut registry, register_declared);
    registry.end_library();
    registered?;
    Ok(registry)
}

/// Registers every declared class with `registrar` (a guard in front of
/// the host's registry).
fn register_declared(registrar: &mut dyn Registrar) -> Result<()> {
    let declared = DECLARED.lock().unwrap_or_else(|e| e.into_inner());
    for plugin in declared.iter() {
        let class = Python::attach(|py| plugin.class.clone_ref(py));
        let factory = factory(plugin.spec, class);
        registrar.add(plugin.spec, factory)?;
    }
    Ok(())
}

/// The factory of a class: its object made with the scene's parameters as
/// keyword arguments, wrapped for its kind.
fn factory(spec: PluginSpec, class: Py<PyAny>) -> Factory {
    let class = Arc::new(class);
    match spec.kind {
        PluginKind::Bsdf => Factory::Bsdf(Arc::new(move |params: &Params| {
            let object = PluginObject::make(&class, spec, params)?;
            Ok(Arc::new(bsdf::PythonBsdf::new(object)?))
        })),
        PluginKind::Light => Factory::Light(Arc::new(move |params: &Params, shape| {
            if !matches!(shape, lumis_api::LightShape::None) {
                return Err(Error::msg(format!(
                    "light '{}' is written in Python: it is a [[light]] table, not a shape's emission",
                    spec.name
                )));
            }
            let object = PluginObject::make(&class, spec, params)?;
            Ok(Box::new(light::PythonLight::new(object)?))
        })),
        PluginKind::Sampler => Factory::Sampler(Arc::new(move |params: &Params| {
            let object = PluginObject::make(&class, spec, params)?;
            Ok(Box::new(sampler::PythonSampler::new(object)?))
        })),
        kind => unreachable!("no {kind} is registered from Python"),
    }
}

/// Declares `class` as the plugin `name` of `kind`, replacing an earlier
/// class of that name (a notebook's cell run again).
fn declare(
    py: Python<'_>,
    kind: PluginKind,
    name: &str,
    class: &Bound<'_, PyType>,
    params: Option<&Bound<'_, PyDict>>,
    doc: Option<&str>,
) -> PyResult<()> {
    let methods: &[&str] = match kind {
        PluginKind::Bsdf => &["f", "pdf", "sample_f"],
        PluginKind::Light => &["sample_li", "pdf_li", "l", "power"],
        _ => &["start_pixel_sample", "get_1d", "get_2d", "get_pixel_2d"],
    };
    for method in methods {
        if !class.hasattr(*method)? {
            return Err(lumis_error(
                py,
                &Error::msg(format!(
                    "{kind} '{name}': the class {} has no method {method}; a {kind} has {}",
                    class.name()?,
                    methods.join(", ")
                )),
            ));
        }
    }
    let mut specs: Vec<ParamSpec> = Vec::new();
    for (key, declaration) in params.into_iter().flat_map(|p| p.iter()) {
        let key: String = key.extract()?;
        specs.push(params::spec(&key, &declaration).or_raise(py)?);
    }
    let doc = match doc {
        Some(doc) => doc.to_string(),
        None => class
            .getattr("__doc__")?
            .extract::<Option<String>>()?
            .and_then(|d| {
                d.lines()
                    .map(str::trim)
                    .find(|l| !l.is_empty())
                    .map(String::from)
            })
            .unwrap_or_else(|| format!("{kind} written in Python")),
    };
    let module: String = class.getattr("__module__")?.extract()?;
    let spec = PluginSpec {
        kind,
        name: leak(name.to_string()),
        source: SourceFile {
            path: leak(format!("{module} (Python)")),
            notes: "",
        },
        doc: leak(doc),
        params: Box::leak(specs.into_boxed_slice()),
    };
    let mut declared = DECLARED.lock().unwrap_or_else(|e| e.into_inner());
    declared.retain(|d| !(d.spec.kind == kind && d.spec.name == name));
    declared.push(Declared {
        spec,
        class: class.clone().into_any().unbind(),
    });
    Ok(())
}

/// A declaration lives as long as the process: registries hold `'static`
/// specs.
fn leak(text: String) -> &'static str {
    Box::leak(text.into_boxed_str())
}

/// A `register_*` function of the module: one per kind a Python class
/// can be, each taking the plugin's name, its class, its parameters'
/// declarations and a line of documentation (else the class's docstring).
macro_rules! registration {
    ($(#[$doc:meta])* $function:ident => $kind:expr) => {
        $(#[$doc])*
        #[pyfunction]
        #[pyo3(signature = (name, cls, params = None, doc = None))]
        pub fn $function(
            py: Python<'_>,
            name: &str,
            cls: &Bound<'_, PyType>,
            params: Option<&Bound<'_, PyDict>>,
            doc: Option<&str>,
        ) -> PyResult<()> {
            declare(py, $kind, name, cls, params, doc)
        }
    };
}

registration! {
    /// Registers a BSDF written in Python. `cls(**params)` makes it; its
    /// methods, in the local shading frame (`z` the normal, directions as
    /// `(x, y, z)` tuples pointing away from the surface), are
    /// `f(wo, wi) -> (r, g, b)` (no cosine), `pdf(wo, wi) -> float` (solid
    /// angle) and `sample_f(wo, u1, (u2x, u2y))` returning `None` or
    /// `(f, wi, pdf)` (optionally `flags` and `eta` after them), and its
    /// `flags` attribute names its lobes (`"diffuse|reflection"`). `params`
    /// declares its parameters: `{"name": default}` or `{"name": {"type":
    /// "float", "default": 0.5, "range": [0, 1], "doc": "..."}}` (types
    /// `bool`, `int`, `float`, `string`, `rgb`, `vec3`).
    register_bsdf => PluginKind::Bsdf
}

registration! {
    /// Registers a light written in Python, used as a `[[light]]` table. Its
    /// `kind` attribute is `"delta_position"` (a point: never hit) or
    /// `"infinite"` (an environment: seen by escaping rays, with an optional
    /// `preprocess(center, radius)` given the scene's bounding sphere). With
    /// `p` and `n` the shaded point and its normal (zero off surfaces), its
    /// methods are `sample_li(p, n, (u1, u2))` returning `None` or
    /// `(radiance, wi, pdf, point)`, `pdf_li(p, n, wi) -> float`,
    /// `l(p, n, uv, w) -> (r, g, b)` (for an infinite light, the radiance
    /// arriving along `-w`) and `power() -> (r, g, b)`. `params` as for
    /// `register_bsdf`.
    register_light => PluginKind::Light
}

registration! {
    /// Registers a sampler written in Python. `cls(**params)` makes it; its
    /// `spp` attribute is its samples per pixel (declare an `spp` parameter,
    /// as the built-ins do, for a scene to set it), and its methods are `start_pixel_sample((x, y), index, seed)`, `get_1d() ->
    /// float`, `get_2d() -> (u, v)` and `get_pixel_2d() -> (u, v)`, numbers in
    /// [0, 1). Each render thread works on a copy (`copy.deepcopy`).
    register_sampler => PluginKind::Sampler
}

/// What runs each worker thread of a render or a check: the thread joins
/// the interpreter once, for its whole life, and leaves the GIL free
/// until a plugin written in Python is called. Each call then only takes
/// the GIL; without this, each made and freed an interpreter thread state
/// (its frame stack mapped and unmapped), which cost more than the call.
pub fn thread_host() -> ThreadHost {
    Arc::new(|work: Box<dyn FnOnce() + Send>| Python::attach(|py| py.detach(work)))
}

/// A lumis result whose error, where a Python plugin raised, is that
/// exception, with lumis's message as a note.
pub fn raise_plugin_exception<T>(py: Python<'_>, result: Result<T>) -> PyResult<T> {
    match result {
        Ok(v) => Ok(v),
        Err(e) => match take_exception() {
            Some(raised) => {
                let note = format!("lumis: {e}");
                // `add_note` is Python 3.11's; earlier, the message alone.
                let _ = raised.value(py).call_method1("add_note", (note,));
                Err(raised)
            }
            None => Err(lumis_error(py, &e)),
        },
    }
}
