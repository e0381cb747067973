//! What a plugin registers, and the host it registers with.
//!
//! A plugin's `register` function is handed a `&mut dyn Registrar`: the
//! host's registry behind a trait object, so a library calls the host's own
//! code (its vtable) and never assumes the layout of the host's registry.
//! What crosses is declared here: the [`PluginSpec`] a plugin describes
//! itself with and the [`Factory`] that makes it.

use std::fmt;
use std::sync::Arc;

use crate::audit::Tally;
use crate::bsdf::Bsdf;
use crate::denoiser::Denoiser;
use crate::error::{Error, Result};
use crate::integrator::Integrator;
use crate::light::{Light, LightShape};
use crate::light_sampler::LightSampler;
use crate::params::{ParamSpec, Params};
use crate::sampler::Sampler;
use crate::texture::Texture;

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
    /// Where the plugin is written: `lumis_api::source_file!()` in the
    /// file that declares it. The plugin reference links to the file and
    /// renders its module documentation.
    pub source: SourceFile,
    /// One line: what the plugin is.
    pub doc: &'static str,
    /// `SPECS` of the plugin's struct deriving
    /// [`PluginParams`](crate::params::PluginParams), which its factory reads.
    pub params: &'static [ParamSpec],
}

/// A plugin's source file and its module documentation, written
/// `lumis_api::source_file!()`.
#[derive(Debug, Clone, Copy)]
pub struct SourceFile {
    /// The path as `file!()` gives it: from the workspace root for a
    /// workspace member.
    pub path: &'static str,
    /// The file's leading `//!` lines: how the plugin works, in Markdown.
    pub notes: &'static str,
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

// Factories as registered: a plugin's own function, or that function
// guarded (a closure); shared, since registries are cloned per scene.
pub type MakeSampler = Arc<dyn Fn(&Params) -> Result<Box<dyn Sampler>> + Send + Sync>;
pub type MakeTexture = Arc<dyn Fn(&Params) -> Result<Arc<dyn Texture>> + Send + Sync>;
pub type MakeBsdf = Arc<dyn Fn(&Params) -> Result<Arc<dyn Bsdf>> + Send + Sync>;
pub type MakeLight = Arc<dyn Fn(&Params, &LightShape) -> Result<Box<dyn Light>> + Send + Sync>;
pub type MakeLightSampler =
    Arc<dyn Fn(&Params, &[Box<dyn Light>]) -> Result<Box<dyn LightSampler>> + Send + Sync>;
pub type MakeIntegrator = Arc<dyn Fn(&Params) -> Result<Box<dyn Integrator>> + Send + Sync>;
pub type MakeDenoiser = Arc<dyn Fn(&Params) -> Result<Box<dyn Denoiser>> + Send + Sync>;

/// A factory as registered, by kind.
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

impl Factory {
    /// The kind of plugin this factory makes.
    pub fn kind(&self) -> PluginKind {
        match self {
            Factory::Sampler(_) => PluginKind::Sampler,
            Factory::Texture(_) => PluginKind::Texture,
            Factory::Bsdf(_) => PluginKind::Bsdf,
            Factory::Light(_) => PluginKind::Light,
            Factory::LightSampler(_) => PluginKind::LightSampler,
            Factory::Integrator(_) => PluginKind::Integrator,
            Factory::Denoiser(_) => PluginKind::Denoiser,
        }
    }
}

/// Where guarded plugins report, implemented by the host: a library's
/// guards call it through this trait object, so they never assume the
/// layout of the host's records.
pub trait FaultReport: Send + Sync {
    /// Keeps `error`, the panic of the plugin labelled `plugin`, if it is
    /// that plugin's first.
    fn record(&self, plugin: &str, error: Error);

    /// The tally of the plugin named `name` (its label and library),
    /// shared by every object made under that name.
    fn tally(&self, name: &str) -> Arc<Tally>;
}

/// Where plugins register: the host's registry, or, while a library
/// registers, the library's guard in front of it
/// ([`register_guarded`](crate::guard::register_guarded)).
///
/// Object-safe, so that it crosses the library boundary as a vtable. Every
/// provided method registers through [`Registrar::add`], so a wrapper that
/// implements `add` sees every registration.
pub trait Registrar {
    /// Adds the plugin `spec` describes, made by `factory`; refused when
    /// the factory's kind is not `spec.kind` or the name is taken.
    fn add(&mut self, spec: PluginSpec, factory: Factory) -> Result<()>;

    /// Where plugins registered now come from: `built-in`, or the path of
    /// the library registering.
    fn source(&self) -> &str;

    /// Where the guards of a library's plugins report their faults and
    /// defects.
    fn faults(&self) -> Arc<dyn FaultReport>;

    fn add_sampler(&mut self, spec: PluginSpec, factory: SamplerFactory) -> Result<()> {
        self.add(spec, Factory::Sampler(Arc::new(factory)))
    }

    fn add_texture(&mut self, spec: PluginSpec, factory: TextureFactory) -> Result<()> {
        self.add(spec, Factory::Texture(Arc::new(factory)))
    }

    fn add_bsdf(&mut self, spec: PluginSpec, factory: BsdfFactory) -> Result<()> {
        self.add(spec, Factory::Bsdf(Arc::new(factory)))
    }

    fn add_light(&mut self, spec: PluginSpec, factory: LightFactory) -> Result<()> {
        self.add(spec, Factory::Light(Arc::new(factory)))
    }

    fn add_light_sampler(&mut self, spec: PluginSpec, factory: LightSamplerFactory) -> Result<()> {
        self.add(spec, Factory::LightSampler(Arc::new(factory)))
    }

    fn add_integrator(&mut self, spec: PluginSpec, factory: IntegratorFactory) -> Result<()> {
        self.add(spec, Factory::Integrator(Arc::new(factory)))
    }

    fn add_denoiser(&mut self, spec: PluginSpec, factory: DenoiserFactory) -> Result<()> {
        self.add(spec, Factory::Denoiser(Arc::new(factory)))
    }
}
