//! `uniform`: every light with the same probability.

use lumis_api::{LightSampleContext, LightSampler, PluginKind, PluginSpec, SampledLight};

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::LightSampler,
    name: "uniform",
    source: lumis_api::source_file!(),
    doc: "picks each of the N lights with probability 1/N",
    params: &[],
};

#[derive(Debug, Clone)]
pub struct UniformLightSampler {
    count: u32,
    /// `1 / count`, divided once rather than at every light sample.
    pmf: f32,
}

impl UniformLightSampler {
    pub fn new(count: usize) -> Self {
        Self {
            count: count as u32,
            pmf: 1.0 / count as f32,
        }
    }
}

impl LightSampler for UniformLightSampler {
    #[inline]
    fn sample(&self, _ctx: &LightSampleContext, u: f32) -> Option<SampledLight> {
        if self.count == 0 {
            return None;
        }
        let index = ((u * self.count as f32) as u32).min(self.count - 1);
        Some(SampledLight {
            index,
            pmf: self.pmf,
        })
    }

    #[inline]
    fn pmf(&self, _ctx: &LightSampleContext, index: u32) -> f32 {
        if index < self.count {
            self.pmf
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lumis_api::Vec3;

    #[test]
    fn picks_every_light_equally() {
        let s = UniformLightSampler::new(3);
        let ctx = LightSampleContext::at(Vec3::ZERO);
        let mut counts = [0; 3];
        for i in 0..3000 {
            let l = s.sample(&ctx, (i as f32 + 0.5) / 3000.0).unwrap();
            assert_eq!(l.pmf, s.pmf(&ctx, l.index));
            counts[l.index as usize] += 1;
        }
        assert_eq!(counts, [1000, 1000, 1000]);
        assert!(s.sample(&ctx, 0.999_999_94).unwrap().index == 2);
        assert!(UniformLightSampler::new(0).sample(&ctx, 0.5).is_none());
    }
}
