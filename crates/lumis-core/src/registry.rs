//! Maps `type = "..."` names to plugin factories.
//!
//! Built-in and dynamically loaded plugins register through the same calls.
//! There is no global registry: the host creates one and hands it to each
//! plugin's `register` function (a loaded library has its own copies of
//! every static, so global state could not be shared anyway).

use std::sync::Arc;

use lumis_api::registrar::FaultReport;
pub use lumis_api::registrar::{Factory, PluginKind, PluginSpec, Registrar};

use crate::bsdf::Bsdf;
use crate::denoiser::Denoiser;
use crate::entity::PluginEntity;
use crate::error::{Error, Result};
use crate::faults::FaultSink;
use crate::integrator::Integrator;
use crate::light::{Light, LightInput};
use crate::light_sampler::LightSampler;
use crate::params::Params;
use crate::sampler::Sampler;
use crate::texture::{BsdfScope, Texture};

/// A registered plugin and where it came from.
#[derive(Clone)]
pub struct Registered {
    pub spec: PluginSpec,
    /// `built-in`, or the path of the library that registered it.
    pub source: Arc<str>,
    factory: Factory,
}

/// The plugins available to a scene.
#[derive(Clone)]
pub struct Registry {
    plugins: Vec<Registered>,
    source: Arc<str>,
    /// Where guarded plugins report a panic; shared by clones.
    faults: Arc<FaultSink>,
}

impl Default for Registry {
    fn default() -> Self {
        Self::new()
    }
}

impl Registry {
    pub fn new() -> Self {
        Self {
            plugins: Vec::new(),
            source: Arc::from("built-in"),
            faults: Arc::default(),
        }
    }

    /// Plugins registered from now on come from the library at `path`:
    /// they are labelled with it until [`Registry::end_library`]. (The
    /// library guards them itself: `lumis_api::guard::register_guarded`.)
    pub fn begin_library(&mut self, path: &str) {
        self.source = Arc::from(path);
    }

    /// Plugins registered from now on are built-in again.
    pub fn end_library(&mut self) {
        self.source = Arc::from("built-in");
    }

    /// Where a panic of any loaded plugin is recorded; a host checks it
    /// after the calls it made ([`FaultSink::check`]).
    pub fn faults(&self) -> &Arc<FaultSink> {
        &self.faults
    }
}

impl Registrar for Registry {
    fn add(&mut self, spec: PluginSpec, factory: Factory) -> Result<()> {
        if spec.kind != factory.kind() {
            return Err(Error::msg(format!(
                "plugin '{}' declares kind {} but registers a {} factory",
                spec.name,
                spec.kind,
                factory.kind()
            )));
        }
        if let Some(existing) = self.find(spec.kind, spec.name) {
            return Err(Error::msg(format!(
                "{} plugin '{}' from {} clashes with the one from {}; rename one of them",
                spec.kind, spec.name, self.source, existing.source
            )));
        }
        self.plugins.push(Registered {
            spec,
            source: self.source.clone(),
            factory,
        });
        Ok(())
    }

    fn source(&self) -> &str {
        &self.source
    }

    fn faults(&self) -> Arc<dyn FaultReport> {
        self.faults.clone()
    }
}

impl Registry {
    pub fn find(&self, kind: PluginKind, name: &str) -> Option<&Registered> {
        self.plugins
            .iter()
            .find(|p| p.spec.kind == kind && p.spec.name == name)
    }

    /// All plugins, grouped by kind, sorted by name.
    pub fn plugins(&self) -> Vec<&Registered> {
        let mut all: Vec<&Registered> = self.plugins.iter().collect();
        all.sort_by(|a, b| (a.spec.kind, a.spec.name).cmp(&(b.spec.kind, b.spec.name)));
        all
    }

    /// The names of the plugins of `kind`, sorted.
    pub fn names(&self, kind: PluginKind) -> Vec<&'static str> {
        self.plugins()
            .into_iter()
            .filter(|p| p.spec.kind == kind)
            .map(|p| p.spec.name)
            .collect()
    }

    /// Creates the plugin `entity` describes: looks it up by kind and
    /// `type`, checks its table against the plugin's declaration, calls the
    /// factory with `input` and rejects keys the plugin did not read. The
    /// one path by which any plugin is made:
    /// `registry.create::<dyn Bsdf>(&entity, scope)`.
    pub fn create<P: PluginInterface + ?Sized>(
        &self,
        entity: &PluginEntity,
        input: P::Input<'_>,
    ) -> Result<P::Made> {
        if entity.kind != P::KIND {
            return Err(Error::at(
                &entity.location,
                format!(
                    "{}: a {} plugin where a {} plugin is expected",
                    entity.owner,
                    entity.kind,
                    P::KIND
                ),
            ));
        }
        let Some(plugin) = self.find(P::KIND, &entity.type_name) else {
            return Err(self.unknown_type(entity));
        };
        let params = Params::new(
            format!("{} (type = \"{}\")", entity.owner, entity.type_name),
            &entity.table,
            entity.location.clone(),
            plugin.spec.params,
            entity.structural,
        )?;
        let params = match P::scope(&input) {
            Some(scope) => params.with_scope(scope),
            None => params,
        };
        // A factory's own error (a degenerate light shape, a file it could
        // not read) is placed at the entity that asked for it.
        let made = P::call(&plugin.factory, &params, input).map_err(|e| match e.location {
            Some(_) => e,
            None => Error::at(
                &entity.location,
                format!(
                    "{} (type = \"{}\"): {}",
                    entity.owner, entity.type_name, e.message
                ),
            ),
        })?;
        params.finish()?;
        Ok(made)
    }

    fn unknown_type(&self, entity: &PluginEntity) -> Error {
        let mut names: Vec<&str> = self
            .plugins
            .iter()
            .filter(|p| p.spec.kind == entity.kind)
            .map(|p| p.spec.name)
            .collect();
        names.sort_unstable();
        Error::at(
            &entity.type_location,
            format!(
                "unknown {} type \"{}\" for {}; available: {}",
                entity.kind,
                entity.type_name,
                entity.owner,
                if names.is_empty() {
                    "none".into()
                } else {
                    names.join(", ")
                }
            ),
        )
    }
}

/// A plugin interface: its kind, what its factory takes besides the
/// parameters, and what it makes. Implemented for the seven plugin traits
/// (`dyn Sampler`, `dyn Bsdf`, ...), which name the kind in
/// [`Registry::create`].
pub trait PluginInterface: sealed::Sealed {
    const KIND: PluginKind;
    /// What the factory returns.
    type Made;
    /// What the factory takes besides its parameters: the shape an area
    /// light is attached to, the lights a light sampler chooses among.
    type Input<'i>;
    /// What its parameters may refer to by name, if anything.
    fn scope<'i>(_input: &Self::Input<'i>) -> Option<BsdfScope<'i>> {
        None
    }
    #[doc(hidden)]
    fn call(factory: &Factory, params: &Params, input: Self::Input<'_>) -> Result<Self::Made>;
}

mod sealed {
    use super::*;

    pub trait Sealed {}

    impl Sealed for dyn Sampler {}
    impl Sealed for dyn Texture {}
    impl Sealed for dyn Bsdf {}
    impl Sealed for dyn Light {}
    impl Sealed for dyn LightSampler {}
    impl Sealed for dyn Integrator {}
    impl Sealed for dyn Denoiser {}
}

/// Registration checks that a plugin's factory is of its declared kind, and
/// [`Registry::create`] looks plugins up by kind: a factory of another kind
/// never reaches these calls.
const KIND_CHECKED: &str = "factory kind checked at registration and lookup";

impl PluginInterface for dyn Sampler {
    const KIND: PluginKind = PluginKind::Sampler;
    type Made = Box<dyn Sampler>;
    type Input<'i> = ();
    fn call(factory: &Factory, params: &Params, (): ()) -> Result<Self::Made> {
        let Factory::Sampler(f) = factory else {
            unreachable!("{KIND_CHECKED}")
        };
        f(params)
    }
}

impl PluginInterface for dyn Texture {
    const KIND: PluginKind = PluginKind::Texture;
    type Made = Arc<dyn Texture>;
    type Input<'i> = ();
    fn call(factory: &Factory, params: &Params, (): ()) -> Result<Self::Made> {
        let Factory::Texture(f) = factory else {
            unreachable!("{KIND_CHECKED}")
        };
        f(params)
    }
}

/// A BSDF is made with the textures and BSDFs its parameters may name
/// ([`BsdfScope::EMPTY`] outside a scene).
impl PluginInterface for dyn Bsdf {
    const KIND: PluginKind = PluginKind::Bsdf;
    type Made = Arc<dyn Bsdf>;
    type Input<'i> = BsdfScope<'i>;
    fn scope<'i>(input: &Self::Input<'i>) -> Option<BsdfScope<'i>> {
        Some(*input)
    }
    fn call(factory: &Factory, params: &Params, _: BsdfScope<'_>) -> Result<Self::Made> {
        let Factory::Bsdf(f) = factory else {
            unreachable!("{KIND_CHECKED}")
        };
        f(params)
    }
}

/// A light is made with its shape and the textures its parameters may
/// name.
impl PluginInterface for dyn Light {
    const KIND: PluginKind = PluginKind::Light;
    type Made = Box<dyn Light>;
    type Input<'i> = LightInput<'i>;
    fn scope<'i>(input: &Self::Input<'i>) -> Option<BsdfScope<'i>> {
        Some(BsdfScope::textures(input.textures))
    }
    fn call(factory: &Factory, params: &Params, input: LightInput<'_>) -> Result<Self::Made> {
        let Factory::Light(f) = factory else {
            unreachable!("{KIND_CHECKED}")
        };
        f(params, input.shape)
    }
}

impl PluginInterface for dyn LightSampler {
    const KIND: PluginKind = PluginKind::LightSampler;
    type Made = Box<dyn LightSampler>;
    type Input<'i> = &'i [Box<dyn Light>];
    fn call(factory: &Factory, params: &Params, lights: &[Box<dyn Light>]) -> Result<Self::Made> {
        let Factory::LightSampler(f) = factory else {
            unreachable!("{KIND_CHECKED}")
        };
        f(params, lights)
    }
}

impl PluginInterface for dyn Integrator {
    const KIND: PluginKind = PluginKind::Integrator;
    type Made = Box<dyn Integrator>;
    type Input<'i> = ();
    fn call(factory: &Factory, params: &Params, (): ()) -> Result<Self::Made> {
        let Factory::Integrator(f) = factory else {
            unreachable!("{KIND_CHECKED}")
        };
        f(params)
    }
}

impl PluginInterface for dyn Denoiser {
    const KIND: PluginKind = PluginKind::Denoiser;
    type Made = Box<dyn Denoiser>;
    type Input<'i> = ();
    fn call(factory: &Factory, params: &Params, (): ()) -> Result<Self::Made> {
        let Factory::Denoiser(f) = factory else {
            unreachable!("{KIND_CHECKED}")
        };
        f(params)
    }
}

#[cfg(test)]
mod tests {
    use glam::{Vec2, Vec3};

    use super::*;
    use crate::bsdf::{BsdfContext, BsdfFlags, BsdfSample};
    use crate::doc::{self, Table, Value};
    use crate::entity::TYPE_KEY;
    use crate::error::Location;
    use crate::params::{ParamSpec, ParamType};
    use crate::spectrum::Rgb;

    /// A BSDF of one parameter, `albedo`, returned by `f`.
    struct Grey(Rgb);

    impl Bsdf for Grey {
        fn flags(&self) -> BsdfFlags {
            BsdfFlags::DIFFUSE_REFLECTION
        }
        fn f(&self, _: &BsdfContext, _: Vec3, _: Vec3) -> Rgb {
            self.0
        }
        fn sample_f(&self, _: &BsdfContext, _: Vec3, _: f32, _: Vec2) -> Option<BsdfSample> {
            None
        }
        fn pdf(&self, _: &BsdfContext, _: Vec3, _: Vec3) -> f32 {
            0.0
        }
    }

    const GREY: PluginSpec = PluginSpec {
        kind: PluginKind::Bsdf,
        name: "grey",
        source: lumis_api::source_file!(),
        doc: "test",
        params: &[ParamSpec::required("albedo", ParamType::Rgb, "albedo")],
    };

    fn registry() -> Registry {
        let mut registry = Registry::new();
        registry
            .add_bsdf(GREY, |p| Ok(Arc::new(Grey(p.get("albedo")?))))
            .unwrap();
        registry
    }

    fn entity(text: &str, kind: PluginKind) -> PluginEntity {
        let table = doc::parse(text, "s.toml").unwrap();
        PluginEntity::from_table(kind, "bsdf \"a\"", table, Location::Builtin, TYPE_KEY).unwrap()
    }

    #[test]
    fn creates_from_a_document_table_and_from_a_built_one() {
        let registry = registry();
        let read = entity("type = \"grey\"\nalbedo = 0.25\n", PluginKind::Bsdf);
        let bsdf = registry
            .create::<dyn Bsdf>(&read, BsdfScope::EMPTY)
            .unwrap();
        let ctx = BsdfContext::default();
        assert_eq!(bsdf.f(&ctx, Vec3::Z, Vec3::Z), Rgb::splat(0.25));

        let table = Table::built(&Location::Builtin, [("albedo", Value::from([0.5f32; 3]))]);
        let built = PluginEntity::new(PluginKind::Bsdf, "x", "grey", table, Location::Builtin);
        let bsdf = registry
            .create::<dyn Bsdf>(&built, BsdfScope::EMPTY)
            .unwrap();
        assert_eq!(bsdf.f(&ctx, Vec3::Z, Vec3::Z), Rgb::splat(0.5));
    }

    #[test]
    fn errors_name_the_type_key_and_kind() {
        let registry = registry();
        let unknown = entity("type = \"gray\"\n", PluginKind::Bsdf);
        let err = registry
            .create::<dyn Bsdf>(&unknown, BsdfScope::EMPTY)
            .err()
            .unwrap();
        let text = err.to_string();
        assert!(
            text.starts_with("s.toml:1:8")
                && text.contains("unknown bsdf type \"gray\" for bsdf \"a\"; available: grey"),
            "{text}"
        );

        let typo = entity(
            "type = \"grey\"\nalbedo = 0.5\nalbedoo = 1\n",
            PluginKind::Bsdf,
        );
        let err = registry
            .create::<dyn Bsdf>(&typo, BsdfScope::EMPTY)
            .err()
            .unwrap();
        assert!(
            err.to_string().starts_with("s.toml:3:1") && err.message.contains("'albedoo'"),
            "{err}"
        );

        let light = entity("type = \"grey\"\nalbedo = 0.5\n", PluginKind::Light);
        let err = registry
            .create::<dyn Bsdf>(&light, BsdfScope::EMPTY)
            .err()
            .unwrap();
        assert!(
            err.message
                .contains("a light plugin where a bsdf plugin is expected"),
            "{err}"
        );
    }

    #[test]
    fn a_table_without_a_type_is_refused_or_defaulted() {
        let table = doc::parse("albedo = 0.5\n", "s.toml").unwrap();
        let err = PluginEntity::from_table(
            PluginKind::Bsdf,
            "bsdf \"a\"",
            table.clone(),
            Location::Builtin,
            TYPE_KEY,
        )
        .err()
        .unwrap();
        assert!(err.message.contains("bsdf \"a\" needs a type"), "{err}");
        let defaulted =
            PluginEntity::from_table_or(PluginKind::Bsdf, "b", table, Location::Builtin, "grey")
                .unwrap();
        assert_eq!(defaulted.type_name, "grey");
        assert!(registry()
            .create::<dyn Bsdf>(&defaulted, BsdfScope::EMPTY)
            .is_ok());
    }
}
