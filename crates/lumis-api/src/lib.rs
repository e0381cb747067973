//! The lumis plugin interface: everything a plugin and its host share, and
//! nothing else.
//!
//! Math (a glam re-export plus frames and floating-point helpers), RGB
//! radiance, rays and surface interactions with pbrt-v4 style error bounds,
//! the plugin traits ([`Sampler`], [`Bsdf`], [`Texture`], [`Light`],
//! [`LightSampler`], [`Integrator`], [`Denoiser`]) with the [`Scene`] they
//! query, the located parameter values ([`doc`]) a plugin reads through
//! [`Params`], the [`Registrar`] it registers with, the guards a library
//! runs itself ([`guard`]), and the [`lumis_plugin!`] macro.
//!
//! A plugin library is checked against this crate's fingerprint
//! ([`plugin`]): its public declarations and the layouts of its types.
//! The host's side (parsing scene files, the registry, fault records) is
//! lumis-core, which a plugin does not depend on.

// The derives name `::lumis_api`, which this lets them do here too.
extern crate self as lumis_api;

pub mod audit;
pub mod bsdf;
pub mod camera;
pub mod denoiser;
pub mod doc;
pub mod error;
pub mod footprint;
pub mod guard;
pub mod image;
pub mod integrator;
pub mod interaction;
pub mod lanes;
pub mod light;
pub mod light_bounds;
pub mod light_sampler;
pub mod math;
pub mod params;
pub mod plugin;
pub mod ray;
pub mod registrar;
pub mod sampler;
pub mod scene;
pub mod spectrum;
pub mod stats;
pub mod texture;
pub mod wrap;

pub use bsdf::{Bsdf, BsdfContext, BsdfFlags, BsdfSample, TransportMode};
pub use camera::{CameraSample, Pinhole};
pub use denoiser::{DenoiseInput, Denoiser};
pub use error::{Error, Location, Result};
pub use footprint::{PackedFootprint, PixelFootprint};
pub use image::{DecodedImage, ImageValues};
pub use integrator::Integrator;
pub use interaction::{LightIndex, LightSampleContext, SurfaceInteraction};
pub use lanes::{LaneMask, LANES};
pub use light::{EmissionSample, Light, LightInput, LightKind, LightSample, LightShape};
pub use light_bounds::{Aabb, DirectionCone, LightBounds};
pub use light_sampler::{LightSampler, SampledLight};
pub use math::Frame;
pub use params::{
    ParamChoice, ParamSpec, ParamType, ParamValue, Params, PluginParams, TexturedFloat, TexturedRgb,
};
pub use ray::Ray;
pub use registrar::{PluginKind, PluginSpec, Registrar, SourceFile};
pub use sampler::{ConcreteLanes, PixelPattern, Sampler, SamplerLanes};
pub use scene::Scene;
pub use spectrum::Rgb;
pub use stats::RenderStats;
pub use texture::{BsdfScope, Texture, TextureQuery, Textures, UvTransform};

/// `#[plugin_interface]`: a plugin trait and its wrappers, declared once
/// (see [`wrap`]).
pub use lumis_derive::plugin_interface;
/// `source_file!()`: the [`SourceFile`] of the file it is written in, for
/// [`PluginSpec::source`].
pub use lumis_derive::source_file;
/// `#[derive(PluginParams)]` and `#[derive(ParamChoice)]`: a plugin's
/// parameters declared once, as a struct (see [`PluginParams`](trait@PluginParams)).
pub use lumis_derive::{ParamChoice, PluginParams};

/// glam, re-exported so plugins use the exact same math types.
pub use glam;
pub use glam::{UVec2, Vec2, Vec3};
