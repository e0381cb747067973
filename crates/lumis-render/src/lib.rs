//! Turning a scene into an image: the camera, the film and the driver that
//! splits the image into tiles and renders them on a thread pool.

mod camera;
mod driver;
mod film;
pub mod profile;
mod progress;

pub use camera::PerspectiveCamera;
pub use driver::{
    progress_units, render, render_pass, worker_threads, PassContext, PassOutput, RenderOutput,
    RenderPool, RenderSettings, MAX_THREADS_PER_CORE, TILE_SIZE,
};
pub use film::Film;
pub use progress::RenderProgress;
