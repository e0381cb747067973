//! Turning a scene into an image: the camera, the film and the driver that
//! splits the image into tiles and renders them on a thread pool.

mod adaptive;
mod aov;
mod camera;
mod driver;
mod film;
mod first_hit;
pub mod profile;
mod progress;
mod splat;

pub use adaptive::{pixel_error, AdaptiveSampling};
pub use aov::Aov;
pub use camera::PerspectiveCamera;
pub use driver::{
    progress_units, render, render_pass, worker_threads, PassContext, PassOutput, RenderOutput,
    RenderPool, RenderSettings, ThreadHost, MAX_THREADS_PER_CORE, TILE_SIZE,
};
pub use film::{AdaptiveState, Film, FirstHitSums};
pub use first_hit::{first_hit, first_hit_rng, FirstHit, MAX_SPECULAR_BOUNCES};
pub use progress::{ProgressFn, RenderProgress};
pub use splat::{SplatBuffer, SPLAT_QUANTUM};
