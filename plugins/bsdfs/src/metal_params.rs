//! The parameters that choose a metal's reflectance, shared by `conductor`
//! and `mirror`: a named metal, or its complex index of refraction.

use lumis_api::params::Textured;
use lumis_api::{ParamChoice, Params, PluginParams, Result, Rgb, TexturedRgb};

use crate::fresnel;
use crate::metal_fresnel::{ConductorFresnel, MetalFresnel};

/// The `material` choice: a metal of [`fresnel::METALS`], or none.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
pub enum MetalName {
    /// A perfect reflector, Fresnel = 1.
    None,
    #[choice("Ag")]
    Ag,
    #[choice("Al")]
    Al,
    #[choice("Au")]
    Au,
    #[choice("Cr")]
    Cr,
    #[choice("Cu")]
    Cu,
    #[choice("Fe")]
    Fe,
    #[choice("Pt")]
    Pt,
}

#[derive(Debug, Clone, PluginParams)]
pub struct MetalParams {
    /// named metal (complex IOR at 650/550/450 nm) or none: a perfect
    /// reflector, Fresnel = 1
    #[param(default = None)]
    pub material: MetalName,
    /// real part of the IOR per channel, with k, or a texture; replaces
    /// material
    pub eta: Option<TexturedRgb>,
    /// imaginary part (absorption) of the IOR per channel, with eta, or a
    /// texture
    pub k: Option<TexturedRgb>,
    /// multiplies the Fresnel term (not physical; for artistic tints), each
    /// channel in [0, 1], or a texture
    #[param(default = 1.0)]
    pub specular_reflectance: TexturedRgb,
}

impl MetalParams {
    /// The metal's Fresnel term: named, or given as `eta` and `k`
    /// (constants or textures).
    pub fn fresnel(&self, params: &Params) -> Result<MetalFresnel> {
        let keys = Self::KEYS;
        match (&self.eta, &self.k) {
            (None, None) => Ok(MetalFresnel::Fixed(match self.material {
                MetalName::None => ConductorFresnel::Perfect,
                named => {
                    let metal = fresnel::metal(named.name())
                        .expect("every MetalName is tabulated in fresnel::METALS (tested)");
                    ConductorFresnel::Complex {
                        eta: metal.eta.into(),
                        k: metal.k.into(),
                    }
                }
            })),
            (Some(eta), Some(k)) => {
                if params.is_given(keys.material) {
                    return Err(
                        params.error(keys.material, "give either material or eta and k, not both")
                    );
                }
                let (Some(eta), Some(k)) = (eta.constant(), k.constant()) else {
                    return Ok(MetalFresnel::Textured {
                        eta: eta.clone(),
                        k: k.clone(),
                    });
                };
                if eta.min_component() <= 0.0 || k.min_component() < 0.0 {
                    return Err(params.error(
                        keys.eta,
                        format!("eta must be > 0 and k >= 0 per channel, got eta {eta}, k {k}"),
                    ));
                }
                Ok(MetalFresnel::Fixed(ConductorFresnel::Complex { eta, k }))
            }
            (Some(_), None) => Err(params.error(keys.eta, "needs k too (the absorption)")),
            (None, Some(_)) => Err(params.error(keys.k, "needs eta too (the real part)")),
        }
    }

    /// `specular_reflectance`, each channel in [0, 1].
    pub fn scale(&self, params: &Params) -> Result<Rgb> {
        let Some(scale) = self.specular_reflectance.constant() else {
            return Ok(Rgb::WHITE);
        };
        if !(scale.min_component() >= 0.0 && scale.max_component() <= 1.0) {
            return Err(params.error(
                Self::KEYS.specular_reflectance,
                format!("each channel must be in [0, 1], got {scale}"),
            ));
        }
        Ok(scale)
    }

    /// The texture that gives `specular_reflectance`, if one does: it
    /// multiplies the BSDF's value at each hit ([`Self::scale`] is then
    /// white), exact since the value is linear in it and sampling ignores
    /// it.
    pub fn tint(&self) -> Option<TexturedRgb> {
        match &self.specular_reflectance {
            Textured::Constant(_) => None,
            textured => Some(textured.clone()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metal_names_are_the_choices() {
        let names: Vec<&str> = fresnel::METALS.iter().map(|m| m.name).collect();
        assert_eq!(&MetalName::NAMES[1..], names.as_slice());
    }
}
