//! Any lumis BSDF as a MERL table: `f` at every node of the format, so that
//! tests and users get measured-style data with a known ground truth.
//!
//! The format holds isotropic, reciprocal reflection without delta lobes;
//! a BSDF that is not checked to be so is refused with the reason, rather
//! than silently averaged into something else.

use indicatif::ProgressBar;
use lumis_api::{Bsdf, BsdfContext, BsdfFlags, Error, Result, Vec3};
use lumis_sampling::halfdiff::spherical_direction;
use lumis_sampling::Pcg32;
use rayon::prelude::*;

use crate::merl::{
    encode, node_directions, sample_index, PHI_D_RES, SAMPLES, THETA_D_RES, THETA_H_RES,
};

/// Pairs of directions the isotropy and reciprocity checks evaluate.
const CHECK_PAIRS: usize = 4096;
/// Relative difference (of the larger value) the checks tolerate: f32
/// rounding of rotated directions, not a modelling difference.
const CHECK_TOLERANCE: f32 = 2e-3;

/// Refuses BSDFs the format cannot represent; `name` is used in messages.
pub fn check_representable(bsdf: &dyn Bsdf, name: &str) -> Result<()> {
    let flags = bsdf.flags();
    if flags.contains(BsdfFlags::TRANSMISSION) {
        return Err(Error::msg(format!(
            "{name} transmits light; a MERL table holds reflection only"
        )));
    }
    if flags.is_specular() {
        return Err(Error::msg(format!(
            "{name} has a delta (specular) lobe, which a table of f cannot hold; give it a roughness"
        )));
    }
    let ctx = BsdfContext::default();
    let mut rng = Pcg32::new(0x7ab, 9);
    let mut any = false;
    for _ in 0..CHECK_PAIRS {
        let mut dir = || {
            let z: f32 = 0.05 + 0.95 * rng.next_f32();
            spherical_direction(z.acos(), std::f32::consts::TAU * rng.next_f32())
        };
        let (wo, wi) = (dir(), dir());
        let f = bsdf.f(&ctx, wo, wi);
        any |= !f.is_black();
        let angle = std::f32::consts::TAU * rng.next_f32();
        let rot = |v: Vec3| {
            let (s, c) = angle.sin_cos();
            Vec3::new(c * v.x - s * v.y, s * v.x + c * v.y, v.z)
        };
        let rotated = bsdf.f(&ctx, rot(wo), rot(wi));
        let swapped = bsdf.f(&ctx, wi, wo);
        let scale = f
            .max_component()
            .max(rotated.max_component())
            .max(swapped.max_component());
        let differs = |g: lumis_api::Rgb| {
            (f - g).map(f32::abs).max_component() > CHECK_TOLERANCE * scale + 1e-6
        };
        if differs(rotated) {
            return Err(Error::msg(format!(
                "{name} is anisotropic (f changes when wo = {wo} and wi = {wi} turn about the normal: {f:?} vs {rotated:?}); the MERL format is isotropic"
            )));
        }
        if differs(swapped) {
            return Err(Error::msg(format!(
                "{name} is not reciprocal (f(wo, wi) = {f:?}, f(wi, wo) = {swapped:?} at wo = {wo}, wi = {wi}); the MERL format folds phi_d by reciprocity"
            )));
        }
    }
    if !any {
        return Err(Error::msg(format!(
            "{name} reflects nothing on this side: f = 0 at every pair tried"
        )));
    }
    Ok(())
}

/// The bytes of the MERL file of `bsdf`, nodes in parallel; ticks
/// `progress` once per `theta_h` row.
pub fn tabulate(bsdf: &dyn Bsdf, name: &str, progress: &ProgressBar) -> Result<Vec<u8>> {
    check_representable(bsdf, name)?;
    let ctx = BsdfContext::default();
    let mut values = vec![None; SAMPLES];
    let per_row = THETA_D_RES * PHI_D_RES;
    let bad: Option<String> = values
        .par_chunks_mut(per_row)
        .enumerate()
        .map(|(i, row)| {
            let mut bad = None;
            for j in 0..THETA_D_RES {
                for k in 0..PHI_D_RES {
                    let (wi, wo) = node_directions(i, j, k);
                    if wi.z <= 0.0 || wo.z <= 0.0 {
                        continue;
                    }
                    let f = bsdf.f(&ctx, wo, wi);
                    if !f.is_finite() || f.min_component() < 0.0 {
                        bad.get_or_insert(format!(
                            "{name} returned f = {f:?} at node theta_h {i}, theta_d {j}, phi_d {k} (wo = {wo}, wi = {wi})"
                        ));
                        continue;
                    }
                    row[sample_index(0, j, k)] = Some([f.r as f64, f.g as f64, f.b as f64]);
                }
            }
            progress.inc(1);
            bad
        })
        .reduce(|| None, |a, b| a.or(b));
    if let Some(bad) = bad {
        return Err(Error::msg(bad));
    }
    debug_assert_eq!(values.len(), THETA_H_RES * per_row);
    Ok(encode(&values))
}
