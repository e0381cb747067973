//! The passes of a render: what a render to files and one in memory share.
//! Samples go into the film pass by pass until the last sample index, or
//! until the session's stop flag is set.

use std::sync::atomic::Ordering;

use lumis_core::{Registry, RenderStats, Result, UVec2};
use lumis_render::{render_pass, Aov, Film, PassContext};

use crate::checkpoint::Checkpoint;

/// How long a pass should take when `--pass-spp` does not say: short enough
/// that the first Ctrl-C, which abandons the pass in flight, loses little.
const PASS_SECONDS: f64 = 2.0;

/// What the passes of one run render.
pub(crate) struct PassPlan<'a> {
    pub ctx: &'a PassContext<'a>,
    /// The registry whose loaded plugins' faults end the render.
    pub registry: &'a Registry,
    /// `--pass-spp`: samples per pass, else passes of about
    /// [`PASS_SECONDS`].
    pub pass_spp: Option<u32>,
    /// With `--parts`, where each part's slice of sample indices ends:
    /// each is summed on its own and then added to the film.
    pub part_ends: Option<Vec<u32>>,
    pub resolution: UVec2,
    pub aovs: &'a [Aov],
}

/// What the passes of one run did.
pub(crate) struct PassTotals {
    pub stats: RenderStats,
    pub seconds: f64,
    /// The stop flag ended the run before its last sample.
    pub interrupted: bool,
}

/// Renders `state`'s film up to sample index `end`, pass by pass, calling
/// `after_pass` after each (a checkpoint's save). A pass the stop flag
/// abandons adds nothing; a loaded plugin's panic is the error.
pub(crate) fn run_passes(
    plan: &PassPlan,
    state: &mut Checkpoint,
    end: u32,
    mut after_pass: impl FnMut(&Checkpoint) -> Result<()>,
) -> Result<PassTotals> {
    let mut totals = PassTotals {
        stats: RenderStats::default(),
        seconds: 0.0,
        interrupted: false,
    };
    let mut last_pass = None;
    // With --parts, the slice in flight, summed on its own until it ends.
    let mut in_flight: Option<Film> = None;
    while state.film.samples < end {
        let (film, slice_end) = match &plan.part_ends {
            None => (&mut state.film, end),
            Some(ends) => {
                let from = state.film.samples;
                let slice_end = ends.iter().copied().find(|&e| e > from).unwrap_or(end);
                let film = match &mut in_flight {
                    Some(film) => film,
                    None => in_flight
                        .insert(Film::try_with_aovs(plan.resolution, plan.aovs)?.starting_at(from)),
                };
                (film, slice_end)
            }
        };
        let pass_spp = next_pass_spp(plan.pass_spp, last_pass, slice_end - film.samples);
        let Some(pass) = render_pass(plan.ctx, film, pass_spp)? else {
            totals.interrupted = true;
            break;
        };
        if film.samples == slice_end {
            if let Some(slice) = in_flight.take() {
                state.film.append(&slice)?;
            }
        }
        // A loaded plugin that panicked answered with neutral values: the
        // pass is not the scene's, so nothing is saved, and the panic is the
        // error.
        plan.registry.faults().check()?;
        totals.stats += pass.stats;
        totals.seconds += pass.seconds;
        state.passes += 1;
        state.seconds += pass.seconds;
        last_pass = Some((pass_spp, pass.seconds));
        after_pass(state)?;
        totals.interrupted = plan.ctx.stop.load(Ordering::Relaxed);
        if totals.interrupted {
            break;
        }
    }
    // An interrupted --parts render keeps the samples of its last slice.
    if let Some(slice) = in_flight.take().filter(|s| s.samples > s.start) {
        state.film.append(&slice)?;
    }
    Ok(totals)
}

/// Samples for the next pass: `pass_spp`, else as many as fit in
/// [`PASS_SECONDS`] at the pace so far (starting from one, at most
/// doubling). The image does not depend on the split.
fn next_pass_spp(pass_spp: Option<u32>, last: Option<(u32, f64)>, remaining: u32) -> u32 {
    let spp = match (pass_spp, last) {
        (Some(n), _) => n,
        (None, None) => 1,
        (None, Some((spp, seconds))) => {
            let fit = (PASS_SECONDS * spp as f64 / seconds.max(1e-6)).floor();
            (fit.min(2.0 * spp as f64) as u32).max(1)
        }
    };
    spp.clamp(1, remaining)
}
