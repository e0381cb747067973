//! `power`: each light with probability proportional to its emitted power
//! (pbrt-v4 `PowerLightSampler`, section 12.6.2).
//!
//! A light's weight is the luminance of its `power()`; if every weight is
//! zero, the choice is uniform. Bright lights get the shadow rays; a scene
//! of one bright and many dim lights no longer spends most samples on the
//! dim ones. It ignores position: a light far from the shading point still
//! gets its share.

use lumis_api::{Light, LightSampleContext, LightSampler, PluginKind, PluginSpec, SampledLight};

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::LightSampler,
    name: "power",
    source: lumis_api::source_file!(),
    doc: "picks each light with probability proportional to the luminance of its emitted power (uniform if all are zero)",
    params: &[],
};

#[derive(Debug, Clone)]
pub struct PowerLightSampler {
    /// `pmf[i]`, the probability of light `i`.
    pmf: Vec<f32>,
    /// Running sums of `pmf`, `cdf[0] = 0`, `cdf[n] = 1`.
    cdf: Vec<f64>,
}

impl PowerLightSampler {
    pub fn new(lights: &[Box<dyn Light>]) -> Self {
        Self::from_weights(lights.iter().map(|l| l.power().luminance()))
    }

    /// From non-negative weights; non-finite or negative weights count as
    /// zero, all-zero weights as uniform.
    pub fn from_weights(weights: impl IntoIterator<Item = f32>) -> Self {
        let mut w: Vec<f64> = weights
            .into_iter()
            .map(|x| {
                if x.is_finite() && x > 0.0 {
                    f64::from(x)
                } else {
                    0.0
                }
            })
            .collect();
        let mut total: f64 = w.iter().sum();
        if total == 0.0 {
            w.iter_mut().for_each(|x| *x = 1.0);
            total = w.len() as f64;
        }
        let mut cdf = Vec::with_capacity(w.len() + 1);
        let mut acc = 0.0;
        cdf.push(0.0);
        for x in &w {
            acc += x / total;
            cdf.push(acc);
        }
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        Self {
            pmf: w.iter().map(|x| (x / total) as f32).collect(),
            cdf,
        }
    }
}

impl LightSampler for PowerLightSampler {
    #[inline]
    fn sample(&self, _ctx: &LightSampleContext, u: f32) -> Option<SampledLight> {
        if self.pmf.is_empty() {
            return None;
        }
        // The last i with cdf[i] <= u, skipping zero-probability lights.
        let u = f64::from(u);
        let upper = self.cdf.partition_point(|&c| c <= u);
        let mut index = upper.clamp(1, self.pmf.len()) - 1;
        while self.pmf[index] == 0.0 && index > 0 {
            index -= 1;
        }
        (self.pmf[index] > 0.0).then(|| SampledLight {
            index: index as u32,
            pmf: self.pmf[index],
        })
    }

    #[inline]
    fn pmf(&self, _ctx: &LightSampleContext, index: u32) -> f32 {
        self.pmf.get(index as usize).copied().unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lumis_api::Vec3;

    #[test]
    fn frequencies_follow_the_weights() {
        let s = PowerLightSampler::from_weights([1.0, 0.0, 3.0, 4.0]);
        let ctx = LightSampleContext::at(Vec3::ZERO);
        let n = 8000;
        let mut counts = [0; 4];
        for i in 0..n {
            let l = s.sample(&ctx, (i as f32 + 0.5) / n as f32).unwrap();
            assert_eq!(l.pmf, s.pmf(&ctx, l.index));
            counts[l.index as usize] += 1;
        }
        assert_eq!(counts, [1000, 0, 3000, 4000]);
        assert_eq!(s.sample(&ctx, 0.999_999_94).unwrap().index, 3);
        assert_eq!(s.sample(&ctx, 0.0).unwrap().index, 0);
        assert_eq!(s.pmf(&ctx, 9), 0.0);
    }

    #[test]
    fn degenerate_weights() {
        let ctx = LightSampleContext::at(Vec3::ZERO);
        let zero = PowerLightSampler::from_weights([0.0, 0.0]);
        assert_eq!(zero.pmf(&ctx, 1), 0.5);
        assert!(PowerLightSampler::from_weights([])
            .sample(&ctx, 0.5)
            .is_none());
        let odd = PowerLightSampler::from_weights([f32::NAN, 2.0, -1.0]);
        assert_eq!(odd.sample(&ctx, 0.1).unwrap().index, 1);
        assert_eq!(odd.sample(&ctx, 0.99).unwrap().index, 1);
    }
}
