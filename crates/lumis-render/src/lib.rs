//! Turning a scene into an image: the camera, the film and the driver that
//! splits the image into tiles and renders them on a thread pool.

mod camera;
mod driver;
pub mod profile;
mod progress;

pub use camera::PerspectiveCamera;
pub use driver::{
    render, worker_threads, RenderOutput, RenderSettings, MAX_THREADS_PER_CORE, TILE_SIZE,
};
