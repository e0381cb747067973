//! The sample-generator plugin interface.

use glam::{UVec2, Vec2};

/// Hands out the random numbers of one pixel sample, dimension by dimension.
///
/// Deterministic: the same pixel, sample index and seed give the same numbers
/// on any thread, so renders do not depend on the thread count.
pub trait Sampler: Send + Sync {
    fn samples_per_pixel(&self) -> u32;

    /// Starts sample `index` of `pixel`; dimensions restart at zero.
    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32, seed: u64);

    fn get_1d(&mut self) -> f32;

    fn get_2d(&mut self) -> Vec2;

    /// `get_1d()` then `get_2d()`, the same three numbers: what a light
    /// sample (which light, which point) and a BSDF sample (which lobe,
    /// which direction) each draw. One call instead of two, so a sampler
    /// can share the work of the three dimensions (a Sobol' sampler walks
    /// the sample index's bits once for all three).
    fn get_1d_2d(&mut self) -> (f32, Vec2) {
        let u = self.get_1d();
        (u, self.get_2d())
    }

    /// The film position within the pixel (the first two dimensions of a
    /// sample, so samplers can stratify them best).
    fn get_pixel_2d(&mut self) -> Vec2;

    /// An independent copy for another thread.
    fn clone_sampler(&self) -> Box<dyn Sampler>;
}
