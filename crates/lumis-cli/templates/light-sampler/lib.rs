//! `{{plugin}}`: picks each light with probability proportional to its
//! power (pbrt-v4 `PowerLightSampler`), by inverting the cumulative
//! distribution of the powers; every light equally when none has power.
//!
//! A light sampler only chooses *which* light a shading point samples; the
//! estimator divides by the probability `pmf` returns, so `sample` and
//! `pmf` must agree, and every light that can contribute needs a
//! probability above zero.

use lumis_api::{
    Light, LightSampleContext, LightSampler, PluginKind, PluginSpec, Registrar, Result, SampledLight,
};

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::LightSampler,
    name: "{{plugin}}",
    source: lumis_api::source_file!(),
    doc: "picks each light with probability proportional to the luminance of its power",
    params: &[],
};

/// Registers the plugin; exported through [`lumis_api::lumis_plugin!`].
pub fn register(registry: &mut dyn Registrar) -> Result<()> {
    registry.add_light_sampler(SPEC, |_params, lights| {
        Ok(Box::new(PowerSampler::new(lights)))
    })
}

lumis_api::lumis_plugin!(register);

#[derive(Debug, Clone)]
pub struct PowerSampler {
    /// `pmf[i]`: the probability of light `i`.
    pmf: Vec<f32>,
    /// `cdf[i]`: the probability of lights `0..i`; `cdf[0] = 0`, and one
    /// more entry than lights, the last 1.
    cdf: Vec<f32>,
}

impl PowerSampler {
    pub fn new(lights: &[Box<dyn Light>]) -> Self {
        let mut weights: Vec<f64> = lights
            .iter()
            .map(|l| f64::from(l.power().luminance()))
            .map(|w| if w.is_finite() && w > 0.0 { w } else { 0.0 })
            .collect();
        let mut total: f64 = weights.iter().sum();
        if total == 0.0 {
            weights.iter_mut().for_each(|w| *w = 1.0);
            total = weights.len() as f64;
        }
        let pmf: Vec<f32> = weights.iter().map(|w| (w / total) as f32).collect();
        let mut cdf = Vec::with_capacity(weights.len() + 1);
        let mut sum = 0.0f64;
        cdf.push(0.0);
        for w in &weights {
            sum += w / total;
            cdf.push(sum as f32);
        }
        // Rounding must not leave a sliver of [0, 1) without a light.
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        Self { pmf, cdf }
    }
}

impl LightSampler for PowerSampler {
    fn sample(&self, _ctx: &LightSampleContext, u: f32) -> Option<SampledLight> {
        if self.pmf.is_empty() {
            return None;
        }
        // The light `i` with `cdf[i] <= u < cdf[i + 1]`; lights of zero
        // probability have an empty interval and are never chosen.
        let index = self
            .cdf
            .partition_point(|&c| c <= u)
            .clamp(1, self.pmf.len())
            - 1;
        Some(SampledLight {
            index: index as u32,
            pmf: self.pmf[index],
        })
    }

    fn pmf(&self, _ctx: &LightSampleContext, index: u32) -> f32 {
        self.pmf.get(index as usize).copied().unwrap_or(0.0)
    }
}
