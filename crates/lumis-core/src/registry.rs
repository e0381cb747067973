//! Maps `type = "..."` names to plugin factories.
//!
//! Built-in and dynamically loaded plugins register through the same calls.
//! There is no global registry: the host creates one and hands it to each
//! plugin's `register` function (a loaded library has its own copies of
//! every static, so global state could not be shared anyway).

use std::fmt;
use std::sync::Arc;

use crate::bsdf::Bsdf;
use crate::denoiser::Denoiser;
use crate::entity::PluginEntity;
use crate::error::{Error, Result};
use crate::guard::{FaultSink, Guard, Guarded, PluginGuard};
use crate::integrator::Integrator;
use crate::light::{Light, LightInput, LightShape};
use crate::light_sampler::LightSampler;
use crate::params::{ParamSpec, Params};
use crate::sampler::Sampler;
use crate::texture::{BsdfScope, Texture};

/// The plugin interfaces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum PluginKind {
    Sampler,
    Texture,
    Bsdf,
    Light,
    LightSampler,
    Integrator,
    Denoiser,
}

impl PluginKind {
    pub const ALL: [PluginKind; 7] = [
        PluginKind::Sampler,
        PluginKind::Texture,
        PluginKind::Bsdf,
        PluginKind::Light,
        PluginKind::LightSampler,
        PluginKind::Integrator,
        PluginKind::Denoiser,
    ];

    /// The scene-file table that names plugins of this kind.
    pub fn table_name(self) -> &'static str {
        match self {
            PluginKind::Sampler => "sampler",
            PluginKind::Texture => "texture",
            PluginKind::Bsdf => "bsdf",
            PluginKind::Light => "light",
            PluginKind::LightSampler => "light_sampler",
            PluginKind::Integrator => "integrator",
            PluginKind::Denoiser => "denoiser",
        }
    }
}

impl fmt::Display for PluginKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.table_name())
    }
}

/// What a plugin declares about itself: drives validation and `lumis plugins`.
#[derive(Debug, Clone, Copy)]
pub struct PluginSpec {
    pub kind: PluginKind,
    pub name: &'static str,
    pub doc: &'static str,
    /// `SPECS` of the plugin's struct deriving
    /// [`PluginParams`](crate::params::PluginParams), which its factory reads.
    pub params: &'static [ParamSpec],
}

pub type SamplerFactory = fn(&Params) -> Result<Box<dyn Sampler>>;
pub type TextureFactory = fn(&Params) -> Result<Arc<dyn Texture>>;
/// A BSDF's textured parameters ([`crate::params::Textured`]) refer to the
/// scene's textures through its `Params`.
pub type BsdfFactory = fn(&Params) -> Result<Arc<dyn Bsdf>>;
/// Lights get the geometry they are attached to ([`LightShape::None`] for
/// `[[light]]` tables); a factory refuses shapes it cannot emit from.
pub type LightFactory = fn(&Params, &LightShape) -> Result<Box<dyn Light>>;
pub type LightSamplerFactory = fn(&Params, &[Box<dyn Light>]) -> Result<Box<dyn LightSampler>>;
pub type IntegratorFactory = fn(&Params) -> Result<Box<dyn Integrator>>;
pub type DenoiserFactory = fn(&Params) -> Result<Box<dyn Denoiser>>;

// Factories as registered: the plugin's own function, or that function
// guarded; shared, since registries are cloned per scene.
type MakeSampler = Arc<dyn Fn(&Params) -> Result<Box<dyn Sampler>> + Send + Sync>;
type MakeTexture = Arc<dyn Fn(&Params) -> Result<Arc<dyn Texture>> + Send + Sync>;
type MakeBsdf = Arc<dyn Fn(&Params) -> Result<Arc<dyn Bsdf>> + Send + Sync>;
type MakeLight = Arc<dyn Fn(&Params, &LightShape) -> Result<Box<dyn Light>> + Send + Sync>;
type MakeLightSampler =
    Arc<dyn Fn(&Params, &[Box<dyn Light>]) -> Result<Box<dyn LightSampler>> + Send + Sync>;
type MakeIntegrator = Arc<dyn Fn(&Params) -> Result<Box<dyn Integrator>> + Send + Sync>;
type MakeDenoiser = Arc<dyn Fn(&Params) -> Result<Box<dyn Denoiser>> + Send + Sync>;

/// A factory as the registry keeps it: the plugin's own function for a
/// built-in, or, while a library registers, a closure that calls it under
/// the library's guard and guards what it makes (boxed by `$boxed`).
macro_rules! registered {
    ($registry:ident, $factory:ident, $boxed:path, |$params:ident $(, $input:ident: $ty:ty)?|) => {
        match $registry.guard.clone() {
            None => Arc::new($factory),
            Some(guard) => Arc::new(move |$params: &Params $(, $input: $ty)?| {
                guarded(&guard, $params, || $factory($params $(, $input)?), |made, guard, label| {
                    $boxed(Guarded::new(made, Guard::new(guard, label)))
                })
            }),
        }
    };
}

/// Calls a loaded plugin's `factory` under `guard`, and guards what it
/// makes. Labels the plugin with its table as written, for messages.
fn guarded<M>(
    guard: &PluginGuard,
    params: &Params,
    factory: impl FnOnce() -> Result<M>,
    wrap: impl FnOnce(M, PluginGuard, Arc<str>) -> M,
) -> Result<M> {
    let label: Arc<str> = Arc::from(format!("{} {{ {} }}", params.owner(), params.written()));
    let made = guard.call(&label, "its factory", factory)??;
    Ok(wrap(made, guard.clone(), label))
}

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
    /// Set while a library registers: its factories and their plugins are
    /// then guarded (see [`crate::guard`]).
    guard: Option<PluginGuard>,
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
            guard: None,
            faults: Arc::default(),
        }
    }

    /// Plugins registered from now on come from the library at `path`:
    /// they are labelled with it, and guarded, until [`Registry::end_library`].
    pub fn begin_library(&mut self, path: &str) {
        self.source = Arc::from(path);
        self.guard = Some(PluginGuard::new(path, self.faults.clone()));
    }

    /// Plugins registered from now on are built-in again.
    pub fn end_library(&mut self) {
        self.source = Arc::from("built-in");
        self.guard = None;
    }

    /// Where a panic of any loaded plugin is recorded; a host checks it
    /// after the calls it made ([`FaultSink::check`]).
    pub fn faults(&self) -> &Arc<FaultSink> {
        &self.faults
    }

    /// Where plugins registered now are said to come from.
    pub fn source(&self) -> &str {
        &self.source
    }

    fn add(&mut self, spec: PluginSpec, factory: Factory) -> Result<()> {
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

    fn check_kind(spec: &PluginSpec, kind: PluginKind) -> Result<()> {
        if spec.kind != kind {
            return Err(Error::msg(format!(
                "plugin '{}' declares kind {} but registers a {kind} factory",
                spec.name, spec.kind
            )));
        }
        Ok(())
    }

    // In a library's registration, each `add_*` below runs in the
    // library's own copy of this code, so the closures `registered!` makes,
    // and their `catch_unwind`, are the library's (see `crate::guard`).

    pub fn add_sampler(&mut self, spec: PluginSpec, factory: SamplerFactory) -> Result<()> {
        Self::check_kind(&spec, PluginKind::Sampler)?;
        let make: MakeSampler = registered!(self, factory, Box::new, |params|);
        self.add(spec, Factory::Sampler(make))
    }

    pub fn add_texture(&mut self, spec: PluginSpec, factory: TextureFactory) -> Result<()> {
        Self::check_kind(&spec, PluginKind::Texture)?;
        let make: MakeTexture = registered!(self, factory, Arc::new, |params|);
        self.add(spec, Factory::Texture(make))
    }

    pub fn add_bsdf(&mut self, spec: PluginSpec, factory: BsdfFactory) -> Result<()> {
        Self::check_kind(&spec, PluginKind::Bsdf)?;
        let make: MakeBsdf = registered!(self, factory, Arc::new, |params|);
        self.add(spec, Factory::Bsdf(make))
    }

    pub fn add_light(&mut self, spec: PluginSpec, factory: LightFactory) -> Result<()> {
        Self::check_kind(&spec, PluginKind::Light)?;
        let make: MakeLight = registered!(self, factory, Box::new, |params, shape: &LightShape|);
        self.add(spec, Factory::Light(make))
    }

    pub fn add_light_sampler(
        &mut self,
        spec: PluginSpec,
        factory: LightSamplerFactory,
    ) -> Result<()> {
        Self::check_kind(&spec, PluginKind::LightSampler)?;
        let make: MakeLightSampler =
            registered!(self, factory, Box::new, |params, lights: &[Box<dyn Light>]|);
        self.add(spec, Factory::LightSampler(make))
    }

    pub fn add_integrator(&mut self, spec: PluginSpec, factory: IntegratorFactory) -> Result<()> {
        Self::check_kind(&spec, PluginKind::Integrator)?;
        let make: MakeIntegrator = registered!(self, factory, Box::new, |params|);
        self.add(spec, Factory::Integrator(make))
    }

    pub fn add_denoiser(&mut self, spec: PluginSpec, factory: DenoiserFactory) -> Result<()> {
        Self::check_kind(&spec, PluginKind::Denoiser)?;
        let make: MakeDenoiser = registered!(self, factory, Box::new, |params|);
        self.add(spec, Factory::Denoiser(make))
    }

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
    fn call(
        factory: &sealed::Factory,
        params: &Params,
        input: Self::Input<'_>,
    ) -> Result<Self::Made>;
}

mod sealed {
    use super::*;

    pub trait Sealed {}

    /// A registered factory, by kind: the plugin's own function, or that
    /// function guarded.
    #[derive(Clone)]
    pub enum Factory {
        Sampler(MakeSampler),
        Texture(MakeTexture),
        Bsdf(MakeBsdf),
        Light(MakeLight),
        LightSampler(MakeLightSampler),
        Integrator(MakeIntegrator),
        Denoiser(MakeDenoiser),
    }

    impl Sealed for dyn Sampler {}
    impl Sealed for dyn Texture {}
    impl Sealed for dyn Bsdf {}
    impl Sealed for dyn Light {}
    impl Sealed for dyn LightSampler {}
    impl Sealed for dyn Integrator {}
    impl Sealed for dyn Denoiser {}
}

use sealed::Factory;

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
    use crate::params::ParamType;
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
