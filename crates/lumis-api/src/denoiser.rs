//! Denoisers: a post-process run on the finished film.
//!
//! A denoiser trades the estimator's unbiasedness for lower variance: its
//! output is a biased estimate of the image, so the host always keeps the
//! raw render next to it.

use crate::error::{Error, Result};
use lumis_derive::plugin_interface;

/// A finished film as a denoiser reads it: the colour and, when the film
/// produced them, the first non-specular hit's albedo and shading normal
/// (the auxiliary images learned denoisers are trained with). Pixels are
/// row-major RGB, `width * height` of them in every buffer.
#[derive(Debug, Clone, Copy)]
pub struct DenoiseInput<'a> {
    pub width: usize,
    pub height: usize,
    pub color: &'a [[f32; 3]],
    pub albedo: Option<&'a [[f32; 3]]>,
    pub normal: Option<&'a [[f32; 3]]>,
}

impl DenoiseInput<'_> {
    /// Refuses buffers of the wrong size and non-finite pixels, naming the
    /// buffer and the first bad pixel: a denoiser may assume neither.
    pub fn validate(&self) -> Result<()> {
        let expected = self.width.checked_mul(self.height).ok_or_else(|| {
            Error::msg(format!(
                "denoiser: a {}x{} image is too large",
                self.width, self.height
            ))
        })?;
        if expected == 0 {
            return Err(Error::msg(format!(
                "denoiser: expected an image of at least 1x1 pixels, got {}x{}",
                self.width, self.height
            )));
        }
        let buffers = [
            ("color", Some(self.color)),
            ("albedo", self.albedo),
            ("normal", self.normal),
        ];
        for (name, buffer) in buffers {
            let Some(pixels) = buffer else { continue };
            if pixels.len() != expected {
                return Err(Error::msg(format!(
                    "denoiser: the {name} image has {} pixels, expected {expected} ({}x{} like the colour)",
                    pixels.len(),
                    self.width,
                    self.height
                )));
            }
            if let Some(i) = pixels.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
                return Err(Error::msg(format!(
                    "denoiser: the {name} image has a non-finite value {:?} at pixel ({}, {}); expected finite values",
                    pixels[i],
                    i % self.width,
                    i / self.width
                )));
            }
        }
        if self.normal.is_some() && self.albedo.is_none() {
            return Err(Error::msg(
                "denoiser: a normal image needs an albedo image too (expected both or neither)",
            ));
        }
        Ok(())
    }
}

/// A post-process that turns a noisy film into a smoother image.
#[plugin_interface]
pub trait Denoiser: Send + Sync {
    /// The denoised colour, `width * height` pixels; an error (never a
    /// panic) when the input is invalid or the denoiser fails.
    #[on_fault(Err(fault.into_error()))]
    fn denoise(&self, input: &DenoiseInput<'_>) -> Result<Vec<[f32; 3]>>;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_names_what_was_expected() {
        let pixels = [[0.5f32; 3]; 6];
        let input = DenoiseInput {
            width: 3,
            height: 2,
            color: &pixels,
            albedo: None,
            normal: None,
        };
        assert!(input.validate().is_ok());
        let err = |input: DenoiseInput<'_>| input.validate().unwrap_err().message;
        assert!(err(DenoiseInput {
            normal: Some(&pixels),
            ..input
        })
        .contains("a normal image needs an albedo image too"));
        assert!(err(DenoiseInput {
            normal: Some(&pixels[..5]),
            albedo: Some(&pixels),
            ..input
        })
        .contains("the normal image has 5 pixels, expected 6 (3x2 like the colour)"));
        let mut infinite = pixels;
        infinite[5][2] = f32::INFINITY;
        assert!(err(DenoiseInput {
            albedo: Some(&infinite),
            ..input
        })
        .contains("the albedo image has a non-finite value [0.5, 0.5, inf] at pixel (2, 1)"));
    }
}
