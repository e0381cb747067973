//! lumis core: the types every other crate speaks.
//!
//! Math (a glam re-export plus frames and floating-point helpers), RGB
//! radiance, rays and surface interactions with pbrt-v4 style error bounds,
//! the plugin traits ([`Sampler`], [`Bsdf`], [`Texture`], [`Light`],
//! [`LightSampler`], [`Integrator`], [`Denoiser`]) with the [`Scene`] they query, and the plugin machinery:
//! the scene document model, [`Params`] and the [`Registry`].

// The derives name `::lumis_core`, which this lets them do here too.
extern crate self as lumis_core;

pub mod audit;
pub mod bsdf;
pub mod denoiser;
pub mod doc;
pub mod entity;
pub mod error;
pub mod files;
pub mod footprint;
pub mod guard;
pub mod integrator;
pub mod interaction;
pub mod light;
pub mod light_bounds;
pub mod light_sampler;
pub mod math;
pub mod params;
pub mod plugin;
pub mod ray;
pub mod registry;
pub mod sampler;
pub mod scene;
pub mod spectrum;
pub mod stats;
pub mod texture;
pub mod wrap;

pub use bsdf::{Bsdf, BsdfContext, BsdfFlags, BsdfSample, TransportMode};
pub use denoiser::{DenoiseInput, Denoiser};
pub use entity::PluginEntity;
pub use error::{Error, Location, Result};
pub use footprint::{PackedFootprint, PixelFootprint};
pub use integrator::Integrator;
pub use interaction::{LightIndex, LightSampleContext, SurfaceInteraction};
pub use light::{Light, LightInput, LightKind, LightSample, LightShape};
pub use light_bounds::{Aabb, DirectionCone, LightBounds};
pub use light_sampler::{LightSampler, SampledLight};
pub use math::Frame;
pub use params::{
    ParamChoice, ParamSpec, ParamType, ParamValue, Params, PluginParams, TexturedFloat, TexturedRgb,
};
pub use ray::Ray;
pub use registry::{PluginInterface, PluginKind, PluginSpec, Registry};
pub use sampler::{ConcreteLanes, PixelPattern, Sampler, SamplerLanes};
pub use scene::Scene;
pub use spectrum::Rgb;
pub use stats::RenderStats;
pub use texture::{BsdfScope, Texture, TextureQuery, Textures, UvTransform};

/// `#[plugin_interface]`: a plugin trait and its wrappers, declared once
/// (see [`wrap`]).
pub use lumis_derive::plugin_interface;
/// `#[derive(PluginParams)]` and `#[derive(ParamChoice)]`: a plugin's
/// parameters declared once, as a struct (see [`PluginParams`](trait@PluginParams)).
pub use lumis_derive::{ParamChoice, PluginParams};

/// glam, re-exported so plugins use the exact same math types.
pub use glam;
pub use glam::{UVec2, Vec2, Vec3};
