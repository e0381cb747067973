//! The render loop: tiles on a rayon pool, a box-filtered film, a progress
//! bar, and counters.

use std::time::Instant;

use lumis_core::{
    Error, Integrator, Ray, RenderStats, Result, Rgb, Sampler, SamplerLanes, Scene, UVec2, Vec3,
};
use lumis_image::Image;
use rayon::prelude::*;

use crate::camera::PerspectiveCamera;
use crate::profile::{self, Stage};
use crate::progress::Progress;

/// Tile edge in pixels: small enough to balance load, large enough that
/// per-tile overhead (sampler clone, progress update) does not show.
pub const TILE_SIZE: u32 = 16;

#[derive(Debug, Clone, PartialEq)]
pub struct RenderSettings {
    pub spp: u32,
    pub seed: u64,
    /// Worker threads; 0 means one per core.
    pub threads: usize,
    /// Draw a progress bar on stderr (hidden when stderr is not a terminal).
    pub progress: bool,
}

pub struct RenderOutput {
    pub image: Image,
    pub stats: RenderStats,
    pub seconds: f64,
}

struct Tile {
    min: UVec2,
    max: UVec2,
}

fn tiles(resolution: UVec2) -> Vec<Tile> {
    let mut out = Vec::new();
    for y in (0..resolution.y).step_by(TILE_SIZE as usize) {
        for x in (0..resolution.x).step_by(TILE_SIZE as usize) {
            out.push(Tile {
                min: UVec2::new(x, y),
                max: UVec2::new(
                    (x + TILE_SIZE).min(resolution.x),
                    (y + TILE_SIZE).min(resolution.y),
                ),
            });
        }
    }
    out
}

/// More worker threads than this per core only cost start-up time and
/// memory: a request beyond it is capped.
pub const MAX_THREADS_PER_CORE: usize = 4;

/// The worker threads a render runs for `requested` (0: one per core),
/// capped at [`MAX_THREADS_PER_CORE`] per core.
pub fn worker_threads(requested: usize) -> usize {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    match requested {
        0 => cores,
        n => n.min(MAX_THREADS_PER_CORE * cores),
    }
}

/// The camera rays of a tile waiting for the integrator, one per lane.
struct Batch {
    rays: Vec<Ray>,
    pixel_of_lane: Vec<usize>,
    radiance: Vec<Rgb>,
    /// Lanes holding a ray.
    filled: usize,
}

impl Batch {
    /// Traces the filled lanes and adds their radiance to their pixels'
    /// sums, in lane order.
    fn trace(
        &mut self,
        scene: &dyn Scene,
        integrator: &dyn Integrator,
        lanes: &mut dyn SamplerLanes,
        stats: &mut RenderStats,
        sums: &mut [[f64; 3]],
    ) {
        let n = std::mem::take(&mut self.filled);
        if n == 0 {
            return;
        }
        profile::in_stage(Stage::Integrator, || {
            integrator.li_batch(
                &self.rays[..n],
                scene,
                lanes,
                stats,
                &mut self.radiance[..n],
            )
        });
        for (&i, l) in self.pixel_of_lane[..n].iter().zip(&self.radiance) {
            stats.samples += 1;
            if !l.is_finite() {
                stats.nonfinite += 1;
                continue;
            }
            let sum = &mut sums[i];
            sum[0] += l.r as f64;
            sum[1] += l.g as f64;
            sum[2] += l.b as f64;
        }
    }
}

/// Renders one tile. The tile's samples go to the integrator in batches of
/// at most its [`Integrator::batch_size`], one sampler per batch lane: a
/// run of the tile's pixels, several samples of each. Lane `l` holds pixel
/// `l % run` of the run throughout, so that a lane keeps one pixel for all
/// its samples and its sampler reuses per-pixel work (the Sobol' sampler's
/// scramble seeds), as `path`'s single sampler does. Each pixel's samples
/// are summed in index order, so the result does not depend on the thread
/// count or the batch size.
fn render_tile(
    tile: &Tile,
    camera: &PerspectiveCamera,
    scene: &dyn Scene,
    integrator: &dyn Integrator,
    lanes: &mut dyn SamplerLanes,
    settings: &RenderSettings,
) -> (Vec<[f32; 3]>, RenderStats) {
    profile::enter_worker();
    let mut stats = RenderStats::default();
    let width = tile.max.x - tile.min.x;
    let count = (width * (tile.max.y - tile.min.y)) as usize;
    let mut sums = vec![[0.0f64; 3]; count];
    let mut batch = Batch {
        rays: vec![Ray::new(Vec3::ZERO, Vec3::Z); lanes.len()],
        pixel_of_lane: vec![0; lanes.len()],
        radiance: vec![Rgb::BLACK; lanes.len()],
        filled: 0,
    };
    let run = lanes.len().min(count);
    let samples_per_batch = (lanes.len() / run) as u32;
    for first in (0..count).step_by(run) {
        let pixels = first..(first + run).min(count);
        for base in (0..settings.spp).step_by(samples_per_batch as usize) {
            for index in base..(base + samples_per_batch).min(settings.spp) {
                for i in pixels.clone() {
                    let pixel =
                        UVec2::new(tile.min.x + i as u32 % width, tile.min.y + i as u32 / width);
                    let lane = lanes.lane(batch.filled);
                    lane.start_pixel_sample(pixel, index, settings.seed);
                    // Box filter of radius 1/2: uniform over the pixel, weight 1.
                    batch.rays[batch.filled] = profile::in_stage(Stage::CameraAndFilm, || {
                        camera.generate_ray(pixel, lane.get_pixel_2d())
                    });
                    batch.pixel_of_lane[batch.filled] = i;
                    batch.filled += 1;
                }
            }
            batch.trace(scene, integrator, lanes, &mut stats, &mut sums);
        }
    }
    let inv = 1.0 / settings.spp as f64;
    let pixels = sums
        .into_iter()
        .map(|sum| sum.map(|s| (s * inv) as f32))
        .collect();
    (pixels, stats)
}

/// Renders the image seen by `camera`. Samples whose radiance is NaN or
/// infinite are counted in the stats and contribute zero.
pub fn render(
    camera: &PerspectiveCamera,
    scene: &dyn Scene,
    integrator: &dyn Integrator,
    sampler: &dyn Sampler,
    settings: &RenderSettings,
) -> Result<RenderOutput> {
    if settings.spp == 0 {
        return Err(Error::msg("spp must be at least 1"));
    }
    let resolution = camera.resolution();
    // The film first: a resolution beyond memory fails now, with a message,
    // not after the render with an aborted allocation.
    let mut image = Image::try_new(resolution.x as usize, resolution.y as usize).map_err(|e| {
        Error::msg(format!(
            "film resolution {}x{}: {e}",
            resolution.x, resolution.y
        ))
    })?;
    let tiles = tiles(resolution);
    let threads = worker_threads(settings.threads);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::msg(format!("cannot start {threads} render threads: {e}")))?;

    let progress = Progress::new(settings.progress, tiles.len() as u64);

    let start = Instant::now();
    let rendered: Vec<(Vec<[f32; 3]>, RenderStats)> = pool.install(|| {
        tiles
            .par_iter()
            .map_init(
                || sampler.lanes(integrator.batch_size().max(1)),
                |lanes, tile| {
                    let out =
                        render_tile(tile, camera, scene, integrator, lanes.as_mut(), settings);
                    progress.tile_done();
                    out
                },
            )
            .collect()
    });
    let seconds = start.elapsed().as_secs_f64();
    progress.finish();

    let mut stats = RenderStats::default();
    for (tile, (pixels, tile_stats)) in tiles.iter().zip(rendered) {
        stats += tile_stats;
        let width = (tile.max.x - tile.min.x) as usize;
        for (i, p) in pixels.into_iter().enumerate() {
            image.set(
                tile.min.x as usize + i % width,
                tile.min.y as usize + i / width,
                p,
            );
        }
    }
    Ok(RenderOutput {
        image,
        stats,
        seconds,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_the_image_once() {
        let res = UVec2::new(37, 20);
        let mut covered = vec![0u8; (res.x * res.y) as usize];
        for t in tiles(res) {
            for y in t.min.y..t.max.y {
                for x in t.min.x..t.max.x {
                    covered[(y * res.x + x) as usize] += 1;
                }
            }
        }
        assert!(covered.iter().all(|&c| c == 1));
    }
}
