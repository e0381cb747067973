//! Batched plugin calls over the lanes of a wave: lanes that hit the same
//! BSDF (or chose the same light) go to one [`Bsdf::sample_f_batch`],
//! [`Bsdf::eval_batch`] or [`Light::sample_li_batch`] call, so that a
//! plugin computing lanes together sees one material at a time.

use lumis_api::{
    Bsdf, BsdfContext, BsdfSample, Light, LightSample, LightSampleContext, Rgb, Vec2, Vec3,
};

/// Reused buffers for grouping lanes and gathering their arguments.
#[derive(Default)]
pub struct Batcher {
    order: Vec<u32>,
    ctx: Vec<BsdfContext>,
    wo: Vec<Vec3>,
    wi: Vec<Vec3>,
    u1: Vec<f32>,
    u2: Vec<Vec2>,
    light_ctx: Vec<LightSampleContext>,
    samples: Vec<Option<BsdfSample>>,
    evals: Vec<(Rgb, f32)>,
    light_samples: Vec<Option<LightSample>>,
}

/// The identity of a plugin object: its data address.
#[inline]
fn identity<T: ?Sized>(object: &T) -> usize {
    (object as *const T).cast::<()>() as usize
}

/// Orders `0..keys.len()` so that equal keys are adjacent, then calls
/// `each` with every run of one key.
fn for_each_run(order: &mut [u32], keys: impl Fn(usize) -> usize, mut each: impl FnMut(&[u32])) {
    order.sort_unstable_by_key(|&i| keys(i as usize));
    let mut start = 0;
    while start < order.len() {
        let key = keys(order[start] as usize);
        let end = start
            + order[start..]
                .iter()
                .position(|&i| keys(i as usize) != key)
                .unwrap_or(order.len() - start);
        each(&order[start..end]);
        start = end;
    }
}

/// What one lane asks of its BSDF.
#[derive(Clone)]
pub struct BsdfLane<'a> {
    pub bsdf: &'a dyn Bsdf,
    pub ctx: BsdfContext,
    pub wo: Vec3,
}

impl Batcher {
    fn reset_order(&mut self, n: usize) -> Vec<u32> {
        let mut order = std::mem::take(&mut self.order);
        order.clear();
        order.extend(0..n as u32);
        order
    }

    /// `out[i] = lanes[i].bsdf.sample_f(ctx, wo, u[i])`, one batched call
    /// per BSDF.
    pub fn sample_f(
        &mut self,
        lanes: &[BsdfLane],
        u: &[(f32, Vec2)],
        out: &mut Vec<Option<BsdfSample>>,
    ) {
        out.clear();
        out.resize(lanes.len(), None);
        let mut order = self.reset_order(lanes.len());
        for_each_run(
            &mut order,
            |i| identity(lanes[i].bsdf),
            |run| {
                self.gather(lanes, run);
                self.u1.clear();
                self.u2.clear();
                for &i in run {
                    self.u1.push(u[i as usize].0);
                    self.u2.push(u[i as usize].1);
                }
                self.samples.clear();
                self.samples.resize(run.len(), None);
                lanes[run[0] as usize].bsdf.sample_f_batch(
                    &self.ctx,
                    &self.wo,
                    &self.u1,
                    &self.u2,
                    &mut self.samples,
                );
                for (&i, s) in run.iter().zip(&self.samples) {
                    out[i as usize] = *s;
                }
            },
        );
        self.order = order;
    }

    /// `out[j] = lanes[of[j]].bsdf.eval(ctx, wo, wi[j])`, one batched call
    /// per BSDF.
    pub fn eval(
        &mut self,
        lanes: &[BsdfLane],
        of: &[usize],
        wi: &[Vec3],
        out: &mut Vec<(Rgb, f32)>,
    ) {
        out.clear();
        out.resize(of.len(), (Rgb::BLACK, 0.0));
        let mut order = self.reset_order(of.len());
        for_each_run(
            &mut order,
            |j| identity(lanes[of[j]].bsdf),
            |run| {
                self.ctx.clear();
                self.wo.clear();
                self.wi.clear();
                for &j in run {
                    let lane = &lanes[of[j as usize]];
                    self.ctx.push(lane.ctx);
                    self.wo.push(lane.wo);
                    self.wi.push(wi[j as usize]);
                }
                self.evals.clear();
                self.evals.resize(run.len(), (Rgb::BLACK, 0.0));
                lanes[of[run[0] as usize]].bsdf.eval_batch(
                    &self.ctx,
                    &self.wo,
                    &self.wi,
                    &mut self.evals,
                );
                for (&i, e) in run.iter().zip(&self.evals) {
                    out[i as usize] = *e;
                }
            },
        );
        self.order = order;
    }

    /// `out[i] = lights[light[i]].sample_li(ctx[i], u[i])`, one batched
    /// call per light.
    pub fn sample_li(
        &mut self,
        lights: &[Box<dyn Light>],
        light: &[u32],
        ctx: &[LightSampleContext],
        u: &[Vec2],
        out: &mut Vec<Option<LightSample>>,
    ) {
        out.clear();
        out.resize(light.len(), None);
        let mut order = self.reset_order(light.len());
        for_each_run(
            &mut order,
            |i| light[i] as usize,
            |run| {
                self.light_ctx.clear();
                self.light_ctx.extend(run.iter().map(|&i| ctx[i as usize]));
                self.u2.clear();
                self.u2.extend(run.iter().map(|&i| u[i as usize]));
                self.light_samples.clear();
                self.light_samples.resize(run.len(), None);
                lights[light[run[0] as usize] as usize].sample_li_batch(
                    &self.light_ctx,
                    &self.u2,
                    &mut self.light_samples,
                );
                for (&i, s) in run.iter().zip(&self.light_samples) {
                    out[i as usize] = *s;
                }
            },
        );
        self.order = order;
    }

    fn gather(&mut self, lanes: &[BsdfLane], run: &[u32]) {
        self.ctx.clear();
        self.wo.clear();
        for &i in run {
            let lane = &lanes[i as usize];
            self.ctx.push(lane.ctx);
            self.wo.push(lane.wo);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_cover_every_lane_once_grouped_by_key() {
        let keys = [3usize, 1, 3, 2, 1, 3, 0];
        let mut order: Vec<u32> = (0..keys.len() as u32).collect();
        let mut seen = vec![0; keys.len()];
        let mut runs = Vec::new();
        for_each_run(
            &mut order,
            |i| keys[i],
            |run| {
                let key = keys[run[0] as usize];
                assert!(run.iter().all(|&i| keys[i as usize] == key));
                for &i in run {
                    seen[i as usize] += 1;
                }
                runs.push(key);
            },
        );
        assert_eq!(seen, vec![1; keys.len()]);
        assert_eq!(runs, vec![0, 1, 2, 3]);
        let mut empty = Vec::new();
        for_each_run(&mut empty, |i| i, |_| panic!("no lanes, no runs"));
    }
}
