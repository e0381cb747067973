//! The render loop: passes of samples over tiles on a rayon pool, added to
//! a box-filtered film, with a progress bar and counters.

use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

use lumis_core::{
    Error, Integrator, Pinhole, Ray, RenderStats, Result, Rgb, Sampler, SamplerLanes, Scene, UVec2,
    Vec3,
};
use lumis_image::Image;
use rayon::prelude::*;

use crate::camera::PerspectiveCamera;
use crate::film::Film;
use crate::first_hit::{first_hit, first_hit_rng};
use crate::profile::{self, Stage};
use crate::progress::RenderProgress;
use crate::splat::SplatBuffer;

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
    /// The cap on each sample's largest component ([`Rgb::clamp_max_component`]).
    pub clamp: Option<f32>,
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
    index_of_lane: Vec<u32>,
    radiance: Vec<Rgb>,
    /// Lanes holding a ray.
    filled: usize,
}

impl Batch {
    /// Traces the filled lanes and adds their radiance (clamped, where the
    /// scene asks) to their pixels in `film`, in lane order; an integrator
    /// that splats adds its splats to `splats`, clamped the same way.
    #[allow(clippy::too_many_arguments)]
    fn trace(
        &mut self,
        scene: &dyn Scene,
        integrator: &dyn Integrator,
        lanes: &mut dyn SamplerLanes,
        stats: &mut RenderStats,
        film: &mut Film,
        clamp: Option<f32>,
        splats: Option<&Splats>,
    ) {
        let n = std::mem::take(&mut self.filled);
        if n == 0 {
            return;
        }
        let clamped = |l: Rgb| clamp.map_or(l, |max| l.clamp_max_component(max));
        profile::in_stage(Stage::Integrator, || match splats {
            None => integrator.li_batch(
                &self.rays[..n],
                scene,
                lanes,
                stats,
                &mut self.radiance[..n],
            ),
            Some(splats) => {
                let mut splat = |raster, l| splats.buffer.add(raster, clamped(l));
                for (lane, (ray, out)) in self.rays[..n].iter().zip(&mut self.radiance).enumerate()
                {
                    *out = lanes.with_lane(lane, |sampler| {
                        integrator.li_splat(ray, scene, &splats.camera, sampler, &mut splat, stats)
                    });
                }
            }
        });
        let lanes = self.pixel_of_lane[..n].iter().zip(&self.index_of_lane);
        for ((&i, &index), l) in lanes.zip(&self.radiance) {
            stats.samples += 1;
            film.count_sample(i);
            if !l.is_finite() {
                stats.nonfinite += 1;
                continue;
            }
            film.add_sample(i, index, clamped(*l));
        }
    }
}

/// Where the paths of an integrator that splats add their light: the
/// run's sums, and the camera they are seen through.
struct Splats {
    buffer: SplatBuffer,
    camera: Pinhole,
}

/// Renders sample indices `samples` of one tile, adding them to `film`
/// (the tile's pixels, a [`Film::crop`]). Where the film has first-hit
/// buffers, each camera ray is also traced by [`first_hit`]. The tile's samples go to the integrator
/// in batches of at most its [`Integrator::batch_size`], one sampler per
/// batch lane: a run of the tile's pixels, several samples of each. Lane
/// `l` holds pixel `l % run` of the run throughout, so that a lane keeps
/// one pixel for all its samples and its sampler reuses per-pixel work (the
/// Sobol' sampler's scramble seeds), as `path`'s single sampler does. Each
/// pixel's samples are added in index order, so the result depends neither
/// on the thread count, the batch size nor how the samples were split into
/// passes. Returns `None`, abandoning the tile, once `stop` is set.
#[allow(clippy::too_many_arguments)]
fn render_tile(
    tile: &Tile,
    camera: &PerspectiveCamera,
    scene: &dyn Scene,
    integrator: &dyn Integrator,
    lanes: &mut dyn SamplerLanes,
    seed: u64,
    clamp: Option<f32>,
    samples: Range<u32>,
    mut film: Film,
    splats: Option<&Splats>,
    stop: &AtomicBool,
) -> Option<(Film, RenderStats)> {
    profile::enter_worker();
    let mut stats = RenderStats::default();
    let width = tile.max.x - tile.min.x;
    let count = film.sums.len();
    let first_hits = film.first_hits.is_some();
    // At least one lane, even from a plugin's lanes that faulted (whose
    // answers are then neutral until the host stops at the fault).
    let n = lanes.len().max(1);
    let mut batch = Batch {
        rays: vec![Ray::new(Vec3::ZERO, Vec3::Z); n],
        pixel_of_lane: vec![0; n],
        index_of_lane: vec![0; n],
        radiance: vec![Rgb::BLACK; n],
        filled: 0,
    };
    let run = n.min(count);
    let samples_per_batch = (n / run) as u32;
    for first in (0..count).step_by(run) {
        let pixels = first..(first + run).min(count);
        for base in samples.clone().step_by(samples_per_batch as usize) {
            if stop.load(Ordering::Relaxed) {
                return None;
            }
            for index in base..(base + samples_per_batch).min(samples.end) {
                for i in pixels.clone() {
                    if !film.is_active(i) {
                        continue;
                    }
                    let pixel =
                        UVec2::new(tile.min.x + i as u32 % width, tile.min.y + i as u32 / width);
                    batch.rays[batch.filled] = lanes.with_lane(batch.filled, |lane| {
                        lane.start_pixel_sample(pixel, index, seed);
                        // Box filter of radius 1/2: uniform over the pixel, weight 1.
                        profile::in_stage(Stage::CameraAndFilm, || {
                            camera.generate_ray(pixel, lane.get_pixel_2d())
                        })
                    });
                    if first_hits {
                        let mut rng = first_hit_rng(pixel, index, seed);
                        let seen = first_hit(scene, &batch.rays[batch.filled], &mut rng);
                        film.add_first_hit(i, &seen);
                    }
                    batch.pixel_of_lane[batch.filled] = i;
                    batch.index_of_lane[batch.filled] = index;
                    batch.filled += 1;
                }
            }
            batch.trace(
                scene, integrator, lanes, &mut stats, &mut film, clamp, splats,
            );
        }
    }
    Some((film, stats))
}

/// What one pass of a render did.
pub struct PassOutput {
    pub stats: RenderStats,
    pub seconds: f64,
}

/// A render's worker threads, started once for all its passes.
pub struct RenderPool {
    pool: rayon::ThreadPool,
}

/// What runs each worker thread's whole life, given the thread's work: a
/// host embedding lumis prepares its threads once this way rather than on
/// every call into it (Python keeps one interpreter thread state per
/// worker instead of making one for each call of a plugin written in
/// Python).
pub type ThreadHost = Arc<dyn Fn(Box<dyn FnOnce() + Send>) + Send + Sync>;

impl RenderPool {
    /// Starts [`worker_threads`]`(requested)` threads.
    pub fn new(requested: usize) -> Result<Self> {
        Self::hosted(requested, None)
    }

    /// [`Self::new`], each thread run inside `host` where one is given.
    pub fn hosted(requested: usize, host: Option<ThreadHost>) -> Result<Self> {
        let threads = worker_threads(requested);
        let builder = rayon::ThreadPoolBuilder::new().num_threads(threads);
        let pool = match host {
            None => builder.build(),
            Some(host) => builder
                .spawn_handler(move |thread| {
                    let host = host.clone();
                    std::thread::Builder::new()
                        .spawn(move || host(Box::new(move || thread.run())))
                        .map(drop)
                })
                .build(),
        };
        let pool =
            pool.map_err(|e| Error::msg(format!("cannot start {threads} render threads: {e}")))?;
        Ok(Self { pool })
    }

    /// Runs `work` in the pool: its parallel iterators use these threads.
    pub fn install<R: Send>(&self, work: impl FnOnce() -> R + Send) -> R {
        self.pool.install(work)
    }
}

/// Everything a pass renders with, beside the film it adds to.
pub struct PassContext<'a> {
    pub camera: &'a PerspectiveCamera,
    pub scene: &'a dyn Scene,
    pub integrator: &'a dyn Integrator,
    pub sampler: &'a dyn Sampler,
    pub seed: u64,
    /// The cap on each sample's largest component ([`Rgb::clamp_max_component`]).
    pub clamp: Option<f32>,
    pub pool: &'a RenderPool,
    pub progress: &'a RenderProgress,
    /// Set (by a signal handler) to abandon the pass in flight.
    pub stop: &'a AtomicBool,
}

/// Adds sample indices `film.samples..film.samples + spp` of every pixel to
/// `film` (of every pixel still sampling, with adaptive sampling, which
/// checks the pixels at its fixed sample counts on the way). Returns
/// `None` where `stop` was set before the pass finished, with `film`
/// holding the runs of samples up to the last check passed, if any: a film
/// holds whole runs only, so every pixel still sampling has taken the same
/// samples.
pub fn render_pass(ctx: &PassContext, film: &mut Film, spp: u32) -> Result<Option<PassOutput>> {
    let end = film
        .samples
        .checked_add(spp)
        .ok_or_else(|| Error::msg("more than 2^32 samples per pixel"))?;
    let mut pass = PassOutput {
        stats: RenderStats::default(),
        seconds: 0.0,
    };
    while film.samples < end {
        let run_end = match &film.adaptive {
            Some(adaptive) => adaptive.settings.next_check(film.samples).min(end),
            None => end,
        };
        let Some(run) = render_run(ctx, film, run_end)? else {
            return Ok(None);
        };
        pass.stats += run.stats;
        pass.seconds += run.seconds;
        film.check_convergence();
    }
    Ok(Some(pass))
}

/// Adds sample indices `film.samples..end` of every pixel still sampling
/// to `film`; `None`, with `film` as it was, once `stop` is set.
fn render_run(ctx: &PassContext, film: &mut Film, end: u32) -> Result<Option<PassOutput>> {
    let spp = end - film.samples;
    let samples = film.samples..end;
    let resolution = UVec2::new(film.width as u32, film.height as u32);
    let tiles = tiles(resolution);
    let splats = match ctx.integrator.splats() {
        true if film.adaptive.is_some() => {
            return Err(Error::msg(
                "adaptive sampling cannot be used with an integrator that splats: its paths \
                 add light to pixels that may have stopped sampling",
            ))
        }
        // The film's sums are made first: memory that is lacking fails
        // before the render, not after it.
        true => film.splat_sums().map(|_| {
            Some(Splats {
                buffer: SplatBuffer::new(resolution),
                camera: ctx.camera.pinhole(),
            })
        })?,
        false => None,
    };
    let start = Instant::now();
    let rendered: Vec<Option<(Film, RenderStats)>> = ctx.pool.pool.install(|| {
        tiles
            .par_iter()
            .map_init(
                || ctx.sampler.lanes(ctx.integrator.batch_size().max(1)),
                |lanes, tile| {
                    let out = render_tile(
                        tile,
                        ctx.camera,
                        ctx.scene,
                        ctx.integrator,
                        lanes.as_mut(),
                        ctx.seed,
                        ctx.clamp,
                        samples.clone(),
                        film.crop(tile.min, tile.max),
                        splats.as_ref(),
                        ctx.stop,
                    );
                    if out.is_some() {
                        ctx.progress.advance(spp as u64);
                    }
                    out
                },
            )
            .collect()
    });
    let seconds = start.elapsed().as_secs_f64();
    if rendered.iter().any(Option::is_none) {
        return Ok(None);
    }
    let mut stats = RenderStats::default();
    for (tile, (tile_film, tile_stats)) in tiles.iter().zip(rendered.into_iter().flatten()) {
        stats += tile_stats;
        film.paste(tile.min, tile_film);
    }
    if let Some(splats) = &splats {
        splats.buffer.add_to(film.splat_sums()?)?;
        stats.nonfinite += splats.buffer.dropped();
    }
    film.samples = end;
    Ok(Some(PassOutput { stats, seconds }))
}

/// The progress units of a render of `spp` samples per pixel at
/// `resolution`, for [`RenderProgress::new`]: one per tile and sample.
pub fn progress_units(resolution: UVec2, spp: u32) -> u64 {
    tiles(resolution).len() as u64 * spp as u64
}

/// Renders the image seen by `camera` in one pass. Samples whose radiance
/// is NaN or infinite are counted in the stats and contribute zero.
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
    let mut film = Film::try_new(resolution)?;
    let pool = RenderPool::new(settings.threads)?;
    let progress = RenderProgress::new(settings.progress, progress_units(resolution, settings.spp));
    let never = AtomicBool::new(false);
    let ctx = PassContext {
        camera,
        scene,
        integrator,
        sampler,
        seed: settings.seed,
        clamp: settings.clamp,
        pool: &pool,
        progress: &progress,
        stop: &never,
    };
    let pass = render_pass(&ctx, &mut film, settings.spp)?;
    progress.finish();
    let pass = pass.ok_or_else(|| Error::msg("render stopped"))?;
    Ok(RenderOutput {
        image: film.image(),
        stats: pass.stats,
        seconds: pass.seconds,
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
