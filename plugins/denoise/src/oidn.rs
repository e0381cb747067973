//! `oidn`: Intel Open Image Denoise's `RT` filter (Áfra 2024, "Intel Open
//! Image Denoise", a U-Net trained on path-traced images with albedo and
//! normal feature buffers).

use lumis_api::{
    DenoiseInput, Denoiser, ParamChoice, Params, PluginKind, PluginParams, PluginSpec, Result,
};

use crate::ffi::{run_rt_filter, Device, RtImages, RtSettings};

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Denoiser,
    name: "oidn",
    source: lumis_api::source_file!(),
    doc: "Intel Open Image Denoise 2 (CPU), its RT filter guided by the film's albedo and normal; biased: the raw render is always kept",
    params: OidnParams::SPECS,
};

#[derive(Debug, Clone, Copy, PluginParams)]
pub struct OidnParams {
    /// high (final frames), balanced or fast (previews)
    #[param(default = High)]
    pub quality: Quality,
    /// denoise the albedo and normal first, then the colour with them marked
    /// clean (OIDN's two-pass mode for noisy auxiliary images)
    #[param(default = true)]
    pub prefilter: bool,
    /// the colour is radiance of any range rather than display values in [0, 1]
    #[param(default = true)]
    pub hdr: bool,
}

/// The `quality` parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
pub enum Quality {
    High,
    Balanced,
    Fast,
}

impl Quality {
    /// Its `OIDNQuality` value.
    fn oidn(self) -> i32 {
        match self {
            Quality::Fast => 4,
            Quality::Balanced => 5,
            Quality::High => 6,
        }
    }
}

/// The `oidn` denoiser. A device is made per call: it holds no state
/// between frames and needs none shared across threads.
#[derive(Debug, Clone, Copy)]
pub struct OidnDenoiser {
    pub params: OidnParams,
}

impl OidnDenoiser {
    pub fn from_params(params: &Params) -> Result<Box<dyn Denoiser>> {
        Ok(Box::new(Self {
            params: OidnParams::read(params)?,
        }))
    }
}

impl Denoiser for OidnDenoiser {
    fn denoise(&self, input: &DenoiseInput<'_>) -> Result<Vec<[f32; 3]>> {
        input.validate()?;
        let device = Device::cpu()?;
        let (width, height) = (input.width, input.height);
        let quality = self.params.quality.oidn();
        let prefilter = self.params.prefilter && input.albedo.is_some();
        // Auxiliary images are prefiltered alone, as LDR images (OIDN
        // manual, "Denoising with prefiltering").
        let aux_settings = RtSettings {
            quality,
            hdr: false,
            clean_aux: false,
        };
        let aux = |image: Option<&[[f32; 3]]>| -> Result<Option<Vec<[f32; 3]>>> {
            let Some(image) = image else { return Ok(None) };
            let mut color = image.to_vec();
            if !prefilter {
                return Ok(Some(color));
            }
            let mut output = vec![[0.0; 3]; color.len()];
            let images = RtImages {
                width,
                height,
                color: &mut color,
                albedo: None,
                normal: None,
                output: &mut output,
            };
            run_rt_filter(&device, images, &aux_settings)?;
            Ok(Some(output))
        };
        let mut albedo = aux(input.albedo)?;
        let mut normal = aux(input.normal)?;

        let mut color = input.color.to_vec();
        let mut output = vec![[0.0; 3]; color.len()];
        let images = RtImages {
            width,
            height,
            color: &mut color,
            albedo: albedo.as_deref_mut(),
            normal: normal.as_deref_mut(),
            output: &mut output,
        };
        let settings = RtSettings {
            quality,
            hdr: self.params.hdr,
            clean_aux: prefilter,
        };
        run_rt_filter(&device, images, &settings)?;
        Ok(output)
    }
}
