//! Maps `type = "..."` names to plugin factories.
//!
//! Built-in and dynamically loaded plugins register through the same calls.
//! There is no global registry: the host creates one and hands it to each
//! plugin's `register` function (a loaded library has its own copies of
//! every static, so global state could not be shared anyway).

use std::fmt;
use std::sync::Arc;

use crate::bsdf::Bsdf;
use crate::doc::Table;
use crate::error::{Error, Location, Result};
use crate::integrator::Integrator;
use crate::light::{Light, LightShape};
use crate::light_sampler::LightSampler;
use crate::params::{ParamSpec, Params};
use crate::sampler::Sampler;

/// The plugin interfaces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum PluginKind {
    Sampler,
    Bsdf,
    Light,
    LightSampler,
    Integrator,
}

impl PluginKind {
    pub const ALL: [PluginKind; 5] = [
        PluginKind::Sampler,
        PluginKind::Bsdf,
        PluginKind::Light,
        PluginKind::LightSampler,
        PluginKind::Integrator,
    ];

    /// The scene-file table that names plugins of this kind.
    pub fn table_name(self) -> &'static str {
        match self {
            PluginKind::Sampler => "sampler",
            PluginKind::Bsdf => "bsdf",
            PluginKind::Light => "light",
            PluginKind::LightSampler => "light_sampler",
            PluginKind::Integrator => "integrator",
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
pub type BsdfFactory = fn(&Params) -> Result<Arc<dyn Bsdf>>;
/// Lights get the geometry they are attached to ([`LightShape::None`] for
/// `[[light]]` tables); a factory refuses shapes it cannot emit from.
pub type LightFactory = fn(&Params, &LightShape) -> Result<Box<dyn Light>>;
pub type LightSamplerFactory = fn(&Params, &[Box<dyn Light>]) -> Result<Box<dyn LightSampler>>;
pub type IntegratorFactory = fn(&Params) -> Result<Box<dyn Integrator>>;

#[derive(Clone, Copy)]
enum Factory {
    Sampler(SamplerFactory),
    Bsdf(BsdfFactory),
    Light(LightFactory),
    LightSampler(LightSamplerFactory),
    Integrator(IntegratorFactory),
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
}

impl Default for Registry {
    fn default() -> Self {
        Self::new()
    }
}

/// Where a plugin table sits in the scene, for error messages.
pub struct TableRef<'a> {
    /// E.g. `bsdf "white"` or `integrator`.
    pub owner: &'a str,
    pub table: &'a Table,
    pub location: &'a Location,
    /// The `type = "..."` value and where it was written.
    pub type_name: &'a str,
    pub type_location: &'a Location,
    /// Keys the scene loader reads itself (`type`, `name`, ...).
    pub structural: &'a [&'a str],
}

impl Registry {
    pub fn new() -> Self {
        Self {
            plugins: Vec::new(),
            source: Arc::from("built-in"),
        }
    }

    /// Labels the plugins registered from now on (e.g. a library's path).
    pub fn set_source(&mut self, source: &str) {
        self.source = Arc::from(source);
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

    pub fn add_sampler(&mut self, spec: PluginSpec, factory: SamplerFactory) -> Result<()> {
        Self::check_kind(&spec, PluginKind::Sampler)?;
        self.add(spec, Factory::Sampler(factory))
    }

    pub fn add_bsdf(&mut self, spec: PluginSpec, factory: BsdfFactory) -> Result<()> {
        Self::check_kind(&spec, PluginKind::Bsdf)?;
        self.add(spec, Factory::Bsdf(factory))
    }

    pub fn add_light(&mut self, spec: PluginSpec, factory: LightFactory) -> Result<()> {
        Self::check_kind(&spec, PluginKind::Light)?;
        self.add(spec, Factory::Light(factory))
    }

    pub fn add_light_sampler(
        &mut self,
        spec: PluginSpec,
        factory: LightSamplerFactory,
    ) -> Result<()> {
        Self::check_kind(&spec, PluginKind::LightSampler)?;
        self.add(spec, Factory::LightSampler(factory))
    }

    pub fn add_integrator(&mut self, spec: PluginSpec, factory: IntegratorFactory) -> Result<()> {
        Self::check_kind(&spec, PluginKind::Integrator)?;
        self.add(spec, Factory::Integrator(factory))
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

    /// Looks up the plugin named by `table.type_name` and checks the table
    /// against its declaration.
    fn lookup<'t>(&self, kind: PluginKind, table: &TableRef<'t>) -> Result<(Factory, Params<'t>)> {
        let Some(plugin) = self.find(kind, table.type_name) else {
            let mut names: Vec<&str> = self
                .plugins
                .iter()
                .filter(|p| p.spec.kind == kind)
                .map(|p| p.spec.name)
                .collect();
            names.sort_unstable();
            return Err(Error::at(
                table.type_location,
                format!(
                    "unknown {kind} type \"{}\" for {}; available: {}",
                    table.type_name,
                    table.owner,
                    if names.is_empty() {
                        "none".into()
                    } else {
                        names.join(", ")
                    }
                ),
            ));
        };
        let owner = format!("{} (type = \"{}\")", table.owner, table.type_name);
        let params = Params::new(
            owner,
            table.table,
            table.location.clone(),
            plugin.spec.params,
            table.structural,
        )?;
        Ok((plugin.factory, params))
    }

    pub fn create_sampler(&self, table: &TableRef) -> Result<Box<dyn Sampler>> {
        let (Factory::Sampler(f), params) = self.lookup(PluginKind::Sampler, table)? else {
            unreachable!("kind checked at registration")
        };
        let made = f(&params)?;
        params.finish()?;
        Ok(made)
    }

    pub fn create_bsdf(&self, table: &TableRef) -> Result<Arc<dyn Bsdf>> {
        let (Factory::Bsdf(f), params) = self.lookup(PluginKind::Bsdf, table)? else {
            unreachable!("kind checked at registration")
        };
        let made = f(&params)?;
        params.finish()?;
        Ok(made)
    }

    pub fn create_light(&self, table: &TableRef, shape: &LightShape) -> Result<Box<dyn Light>> {
        let (Factory::Light(f), params) = self.lookup(PluginKind::Light, table)? else {
            unreachable!("kind checked at registration")
        };
        let made = f(&params, shape)?;
        params.finish()?;
        Ok(made)
    }

    pub fn create_light_sampler(
        &self,
        table: &TableRef,
        lights: &[Box<dyn Light>],
    ) -> Result<Box<dyn LightSampler>> {
        let (Factory::LightSampler(f), params) = self.lookup(PluginKind::LightSampler, table)?
        else {
            unreachable!("kind checked at registration")
        };
        let made = f(&params, lights)?;
        params.finish()?;
        Ok(made)
    }

    pub fn create_integrator(&self, table: &TableRef) -> Result<Box<dyn Integrator>> {
        let (Factory::Integrator(f), params) = self.lookup(PluginKind::Integrator, table)? else {
            unreachable!("kind checked at registration")
        };
        let made = f(&params)?;
        params.finish()?;
        Ok(made)
    }
}
