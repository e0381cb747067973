//! A small safe wrapper over Embree 4 (`embree4-sys`).
//!
//! It covers what lumis needs and nothing more: a device whose errors become
//! Rust errors, a scene built from triangle meshes and spheres whose buffers
//! are shared with Embree (no second copy), and the two queries, closest hit
//! and occlusion, for single rays (`intersect1`, `occluded1`) and for
//! packets of 4, 8 or 16 (`intersect_packets`, `occluded_packets`).
//!
//! The workspace denies `unsafe` code except in the crates that call C or
//! load libraries: this one (Embree), `lumis-denoise`'s `ffi` module
//! (Open Image Denoise), `lumis-loader` (plugin libraries), the plugin
//! declaration of `lumis-api`, and the calls of `lumis-sampling::simd`
//! into code compiled for a CPU feature it has checked. Each block says
//! why it is sound.

#![allow(unsafe_code)]

pub mod bare;
mod buffer;
mod device;
mod packet;
mod ray;
mod record;
mod scene;
mod tape;

pub use buffer::{PaddedBuffer, SpherePoint, Triangle, Vertex};
pub use device::{Device, EmbreeError};
pub use packet::{PacketWidth, Packets, MAX_PACKET};
pub use ray::{Hit, Ray};
pub use scene::{BuildQuality, Scene, SceneBuilder, SceneOptions};

/// The largest vertex coordinate Embree builds with: a triangle with a
/// coordinate of this magnitude or more is invalid and left out of the BVH
/// without a word (`FLT_LARGE`, Embree's `common/math/constants.h`, used
/// by its triangle validity test). Loaders refuse such vertices instead.
pub const MAX_COORDINATE: f32 = 1.844e18;

/// The geometry id Embree reports when nothing was hit.
pub const INVALID_ID: u32 = embree4_sys::RTC_INVALID_GEOMETRY_ID;
