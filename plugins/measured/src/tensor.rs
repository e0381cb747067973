//! The BRDF itself as a sum of rank-1 terms: a tensor approximation in the
//! manner of Bilgili, Ozturk and Kurt 2011 ("A General BRDF Representation
//! Based on Tensor Decomposition", Computer Graphics Forum 30(8)), with the
//! CP (PARAFAC) decomposition of [`crate::cp`] in place of their Tucker
//! decomposition.
//!
//! The table is resampled on a `90 x 90 x 180` grid of nodes over three
//! coordinates of the pair, one tensor per colour channel:
//!
//! - half-diff: `(theta_h, theta_d, phi_d)`, the MERL nodes themselves (no
//!   resampling), `theta_h` with the format's square-root spacing, `phi_d`
//!   periodic over `[0, pi)`;
//! - pdv: `(theta_o, rho, phi)` of the projected deviation vector about
//!   `wo` (`lumis_sampling::pdv`), `theta_o` at cell centres `(a + 1/2) /
//!   90 pi/2`, `rho = 2 (b / 89)^2`, `phi = c / 179 pi` (an isotropic BRDF
//!   is even in `phi`); nodes outside the disk `rho <= 1 + sin theta_o` are
//!   missing;
//! - in-out: `(theta_o, theta_i, |phi_i - phi_o|)`, the elevations at cell
//!   centres, the azimuth difference `c / 179 pi`.
//!
//! Each channel is fitted as
//!
//! ```text
//! y = ln(1 + f) ~ sum_{r < R} lambda_r a_r(x0) b_r(x1) c_r(x2)
//! ```
//!
//! The logarithm tames the dynamic range of the specular peak (Bilgili et
//! al. fit the logarithm of the data for that reason; `ln(1 + f)` is `~f`
//! on the dim diffuse part, `~ln f` in the peak and finite at `f = 0`).
//! The channels are fitted separately rather than with shared factors:
//! the factors are a few KB either way, and a colour that varies with
//! angle (a conductor's Fresnel tint) then costs no extra terms.
//!
//! Between nodes the model is interpolated multilinearly, which for a sum
//! of products is the product of the linearly interpolated factors: `3 R`
//! lerps per channel. `f = max(exp(y) - 1, 0)`. In pdv and in-out the
//! coordinates are about `wo`, so the fitted model need not be reciprocal;
//! [`TensorBrdf::eval`] averages both orders, which is. In half-diff it is
//! reciprocal but for rounding, and the pair is evaluated in a fixed order.

use std::f32::consts::{FRAC_PI_2, PI};

use lumis_api::{Rgb, Vec3};
use lumis_sampling::halfdiff::{spherical_direction, HalfDiff};
use lumis_sampling::pdv::{pdv_from_w, w_from_pdv};
use rayon::prelude::*;

use crate::cp::{AlsReport, AlsSettings, Cp};
use crate::grid::{Grid, Parameterization};
use crate::merl::{
    clamped_axis, node_directions, MerlTable, PHI_D_RES, SAMPLES, THETA_D_RES, THETA_H_RES,
};
use crate::reflectance::Reflectance;

/// Nodes per axis, in every parameterization (the MERL table's).
pub const DIMS: [usize; 3] = [THETA_H_RES, THETA_D_RES, PHI_D_RES];

/// `y = ln(1 + f)`, the value the decomposition fits.
#[inline]
pub fn to_log(f: f32) -> f64 {
    (f as f64).ln_1p()
}

/// `f = max(exp(y) - 1, 0)`.
#[inline]
fn from_log(y: f32) -> f32 {
    y.exp_m1().max(0.0)
}

/// The nodes of `parameterization` as a [`Grid`] (`supersamples` unused):
/// what a cache records of a tensor's layout.
pub fn node_grid(parameterization: Parameterization) -> Grid {
    Grid {
        n_o: DIMS[0],
        n_w: DIMS[1],
        n_phi: DIMS[2],
        supersamples: 0,
        parameterization,
    }
}

/// The position of one coordinate between its two nodes.
type Axis = (usize, usize, f32);

/// A rendered, compressed BRDF.
#[derive(Debug, Clone)]
pub struct TensorBrdf {
    parameterization: Parameterization,
    rank: usize,
    /// Per channel, per axis: `DIMS[m] x rank`, row-major; the weights are
    /// folded into the first axis.
    factors: [[Vec<f32>; 3]; 3],
    /// 1, or what brings the largest directional albedo down to 1.
    energy_scale: f32,
}

impl TensorBrdf {
    /// From three fitted channels.
    pub fn new(parameterization: Parameterization, channels: &[Cp; 3]) -> Self {
        let rank = channels[0].rank;
        let factors =
            std::array::from_fn(|c| std::array::from_fn(|m| channels[c].folded_factor(m)));
        Self {
            parameterization,
            rank,
            factors,
            energy_scale: 1.0,
        }
        .conserving_energy()
    }

    /// This model scaled, if need be, so that it reflects no more than it
    /// receives: nothing in the fit keeps a low rank from overshooting the
    /// table (at R = 2 the directional albedo reached 1.35). One factor
    /// for every direction and channel keeps `f` reciprocal and its
    /// colour; the albedo is integrated on the samplers' half-vector grid
    /// ([`Grid::row_at`]), which resolves a lobe of 0.01 rad, at normal
    /// incidence, 32 elevations and grazing.
    fn conserving_energy(mut self) -> Self {
        const ELEVATIONS: usize = 32;
        let grid = Grid {
            n_o: ELEVATIONS,
            n_w: 64,
            n_phi: 32,
            supersamples: 2,
            parameterization: Parameterization::HalfDiff,
        };
        let elevations: Vec<f32> = std::iter::once(0.0)
            .chain((0..ELEVATIONS).map(|k| grid.theta_o(k)))
            .chain(std::iter::once(FRAC_PI_2 - 1e-4))
            .collect();
        let this = &self;
        let albedo = (0..3)
            .flat_map(|c| elevations.iter().map(move |&theta_o| (c, theta_o)))
            .map(|(c, theta_o)| {
                let channel = |wo: Vec3, wi: Vec3| Rgb::splat(this.eval(wi, wo)[c]);
                grid.row_at(theta_o, &channel).iter().sum::<f32>()
            })
            .fold(0.0f32, f32::max);
        if albedo > 1.0 {
            self.energy_scale = 1.0 / albedo;
        }
        self
    }

    /// Numbers in [`Self::payload`] for `rank`.
    pub fn payload_len(rank: usize) -> usize {
        3 * rank * DIMS.iter().sum::<usize>()
    }

    /// The factors as stored in a cache or written by `lumis brdf
    /// compress`: per channel (red, green, blue), the three axes' `n x R`
    /// matrices, row-major, the weights folded into the first.
    pub fn payload(&self) -> Vec<f32> {
        self.factors.iter().flatten().flatten().copied().collect()
    }

    /// The inverse of [`Self::payload`]; `None` if the length is not that
    /// of `rank`.
    pub fn from_payload(
        parameterization: Parameterization,
        rank: usize,
        data: &[f32],
    ) -> Option<Self> {
        if rank == 0 || data.len() != Self::payload_len(rank) {
            return None;
        }
        let mut rest = data;
        let mut take = |n: usize| {
            let (head, tail) = rest.split_at(n);
            rest = tail;
            head.to_vec()
        };
        let factors = std::array::from_fn(|_| std::array::from_fn(|m| take(DIMS[m] * rank)));
        Some(
            Self {
                parameterization,
                rank,
                factors,
                energy_scale: 1.0,
            }
            .conserving_energy(),
        )
    }

    /// The factor [`Self::eval`] scales the model by to conserve energy.
    pub fn energy_scale(&self) -> f32 {
        self.energy_scale
    }

    pub fn rank(&self) -> usize {
        self.rank
    }

    pub fn parameterization(&self) -> Parameterization {
        self.parameterization
    }

    /// Bytes held.
    pub fn memory_bytes(&self) -> usize {
        4 * Self::payload_len(self.rank)
    }

    /// `f(wi, wo)`, for both directions in the upper hemisphere.
    #[inline]
    pub fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb {
        match self.parameterization {
            // The model is symmetric in the pair, but the f32 rounding of
            // phi_d is not, and near f = 0 the sum of R terms cancels to a
            // few ulps: evaluating the pair in one fixed order makes f
            // reciprocal to the last bit.
            Parameterization::HalfDiff if [wi.z, wi.x, wi.y] < [wo.z, wo.x, wo.y] => {
                self.eval_about(wi, wo)
            }
            Parameterization::HalfDiff => self.eval_about(wo, wi),
            Parameterization::Pdv | Parameterization::InOut => {
                (self.eval_about(wo, wi) + self.eval_about(wi, wo)) * 0.5
            }
        }
    }

    /// The model at the coordinates of `wi` about `wo`.
    #[inline]
    fn eval_about(&self, wo: Vec3, wi: Vec3) -> Rgb {
        let Some(axes) = axes(self.parameterization, wo, wi) else {
            return Rgb::BLACK;
        };
        let r = self.rank;
        let channel = |c: usize| {
            let [a, b, cc] = &self.factors[c];
            let lerp = |f: &[f32], (i0, i1, t): Axis, q: usize| {
                f[i0 * r + q] * (1.0 - t) + f[i1 * r + q] * t
            };
            let y: f32 = (0..r)
                .map(|q| lerp(a, axes[0], q) * lerp(b, axes[1], q) * lerp(cc, axes[2], q))
                .sum();
            from_log(y) * self.energy_scale
        };
        Rgb::new(channel(0), channel(1), channel(2))
    }
}

/// Where `wi` about `wo` falls on the three axes of `parameterization`.
#[inline]
fn axes(parameterization: Parameterization, wo: Vec3, wi: Vec3) -> Option<[Axis; 3]> {
    match parameterization {
        Parameterization::HalfDiff => {
            // As MerlTable::eval: the same nodes, the same lookup.
            let hd = HalfDiff::from_directions(wi, wo)?;
            let th = (hd.theta_h.max(0.0) / FRAC_PI_2).sqrt() * THETA_H_RES as f32;
            let td = hd.theta_d.max(0.0) / FRAC_PI_2 * THETA_D_RES as f32;
            let pd = hd.phi_d.rem_euclid(PI) / PI * PHI_D_RES as f32;
            let k0f = pd.floor();
            let k0 = (k0f as usize) % PHI_D_RES;
            Some([
                clamped_axis(th, THETA_H_RES),
                clamped_axis(td, THETA_D_RES),
                (k0, (k0 + 1) % PHI_D_RES, pd - k0f),
            ])
        }
        Parameterization::Pdv => {
            let (rho, phi, _) = pdv_from_w(wo, wi)?;
            Some([
                clamped_axis(elevation_index(wo), DIMS[0]),
                clamped_axis((rho / 2.0).sqrt() * (DIMS[1] - 1) as f32, DIMS[1]),
                clamped_axis(phi.min(2.0 * PI - phi) / PI * (DIMS[2] - 1) as f32, DIMS[2]),
            ])
        }
        Parameterization::InOut => {
            let (x, y) = (wo.x * wi.x + wo.y * wi.y, wo.x * wi.y - wo.y * wi.x);
            let dphi = y.atan2(x).abs();
            Some([
                clamped_axis(elevation_index(wo), DIMS[0]),
                clamped_axis(elevation_index(wi), DIMS[1]),
                clamped_axis(dphi / PI * (DIMS[2] - 1) as f32, DIMS[2]),
            ])
        }
    }
}

/// The index coordinate of `theta` on an axis of 90 cell-centred nodes.
#[inline]
pub(crate) fn elevation_index(w: Vec3) -> f32 {
    let theta = (w.x * w.x + w.y * w.y).sqrt().atan2(w.z);
    theta / FRAC_PI_2 * DIMS[0] as f32 - 0.5
}

/// The elevation of node `a` of [`elevation_index`].
fn node_elevation(a: usize) -> f32 {
    (a as f32 + 0.5) / DIMS[0] as f32 * FRAC_PI_2
}

/// `(wo, wi)` of node `(a, b, c)` of `parameterization`; `None` where no
/// pair of the upper hemisphere has those coordinates.
pub fn node_pair(
    parameterization: Parameterization,
    a: usize,
    b: usize,
    c: usize,
) -> Option<(Vec3, Vec3)> {
    let azimuth = c as f32 / (DIMS[2] - 1) as f32 * PI;
    let (wo, wi) = match parameterization {
        Parameterization::HalfDiff => {
            let (wi, wo) = node_directions(a, b, c);
            (wo, wi)
        }
        Parameterization::Pdv => {
            let wo = spherical_direction(node_elevation(a), 0.0);
            let t = b as f32 / (DIMS[1] - 1) as f32;
            let (wi, _) = w_from_pdv(wo, 2.0 * t * t, azimuth)?;
            (wo, wi)
        }
        Parameterization::InOut => (
            spherical_direction(node_elevation(a), 0.0),
            spherical_direction(node_elevation(b), azimuth),
        ),
    };
    (wo.z > 0.0 && wi.z > 0.0).then_some((wo, wi))
}

/// `f` of `source` at the nodes of `parameterization`, `(a, b, c)` at
/// `(a * DIMS[1] + b) * DIMS[2] + c`, per channel; `None` where unknown. A
/// table in half-diff gives its own MERL nodes (an invalid sample is
/// unknown); otherwise each node's pair is evaluated (a node with no pair
/// is unknown): a table through its interpolation, an analytic BSDF
/// exactly, at the parameterization's own nodes.
pub fn node_reflectance(
    source: &Reflectance,
    parameterization: Parameterization,
) -> Vec<[Option<f32>; 3]> {
    (0..SAMPLES)
        .into_par_iter()
        .map(|n| {
            let (a, b, c) = (
                n / (DIMS[1] * DIMS[2]),
                (n / DIMS[2]) % DIMS[1],
                n % DIMS[2],
            );
            match (source, parameterization) {
                (Reflectance::Table(table), Parameterization::HalfDiff) => table.node(a, b, c),
                _ => match node_pair(parameterization, a, b, c) {
                    Some((wo, wi)) => {
                        let f = source.eval(wi, wo);
                        [Some(f.r), Some(f.g), Some(f.b)]
                    }
                    None => [None; 3],
                },
            }
        })
        .collect()
}

/// `ln(1 + f)` of `source` at the nodes of `parameterization`
/// ([`node_reflectance`]), per channel, and which nodes are known.
pub fn log_samples(
    source: &Reflectance,
    parameterization: Parameterization,
) -> ([Vec<f64>; 3], [Vec<bool>; 3]) {
    let nodes = node_reflectance(source, parameterization);
    let values = std::array::from_fn(|c| nodes.iter().map(|v| v[c].map_or(0.0, to_log)).collect());
    let known = std::array::from_fn(|c| nodes.iter().map(|v| v[c].is_some()).collect());
    (values, known)
}

/// Fits `rank` terms per channel to `source` in `parameterization`; calls
/// `tick` after each channel.
pub fn fit(
    source: &Reflectance,
    parameterization: Parameterization,
    rank: usize,
    settings: AlsSettings,
    tick: &(dyn Fn() + Sync),
) -> (TensorBrdf, [AlsReport; 3]) {
    let (values, known) = log_samples(source, parameterization);
    let fits: Vec<(Cp, AlsReport)> = (0..3)
        .map(|c| {
            let fit = Cp::fit(&values[c], Some(&known[c]), DIMS, rank, settings);
            tick();
            fit
        })
        .collect();
    let channels: [Cp; 3] = std::array::from_fn(|c| fits[c].0.clone());
    let reports = std::array::from_fn(|c| fits[c].1);
    (TensorBrdf::new(parameterization, &channels), reports)
}

/// The error of an approximation of `table`, at the MERL nodes where the
/// table is valid in every channel and both directions are above the
/// horizon.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompressionError {
    pub nodes: usize,
    /// `sqrt(sum (f' - f)^2 / sum f^2)` over the nodes and channels.
    pub relative_rmse: f64,
    /// `20 log10(max y / rms(y' - y))` of `y = ln(1 + f)`.
    pub log_psnr_db: f64,
}

/// How far `approximation(wi, wo)` is from `table` at its nodes.
pub fn compression_error(
    table: &MerlTable,
    approximation: &(dyn Fn(Vec3, Vec3) -> Rgb + Sync),
) -> CompressionError {
    // (nodes, sum df^2, sum f^2, sum dy^2, max y)
    let zero = || (0usize, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let (nodes, df2, f2, dy2, max_y) = (0..SAMPLES)
        .into_par_iter()
        .fold(zero, |acc, n| {
            let (a, b, c) = (
                n / (DIMS[1] * DIMS[2]),
                (n / DIMS[2]) % DIMS[1],
                n % DIMS[2],
            );
            let [Some(r), Some(g), Some(bl)] = table.node(a, b, c) else {
                return acc;
            };
            let (wi, wo) = node_directions(a, b, c);
            if wi.z <= 0.0 || wo.z <= 0.0 {
                return acc;
            }
            let got = approximation(wi, wo);
            let mut acc = acc;
            acc.0 += 1;
            for (want, got) in [(r, got.r), (g, got.g), (bl, got.b)] {
                let (want_y, got_y) = (to_log(want), to_log(got.max(0.0)));
                acc.1 += ((got - want) as f64).powi(2);
                acc.2 += (want as f64).powi(2);
                acc.3 += (got_y - want_y).powi(2);
                acc.4 = acc.4.max(want_y);
            }
            acc
        })
        .reduce(zero, |a, b| {
            (a.0 + b.0, a.1 + b.1, a.2 + b.2, a.3 + b.3, a.4.max(b.4))
        });
    let rms_y = (dy2 / (3 * nodes.max(1)) as f64).sqrt();
    CompressionError {
        nodes,
        relative_rmse: (df2 / f2.max(f64::MIN_POSITIVE)).sqrt(),
        log_psnr_db: 20.0 * (max_y / rms_y.max(f64::MIN_POSITIVE)).log10(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rank-1 model of the constant `f` in every parameterization.
    fn constant(parameterization: Parameterization, f: f32) -> TensorBrdf {
        let mut payload = Vec::new();
        for _ in 0..3 {
            payload.extend(std::iter::repeat_n(to_log(f) as f32, DIMS[0]));
            payload.extend(std::iter::repeat_n(1.0, DIMS[1] + DIMS[2]));
        }
        TensorBrdf::from_payload(parameterization, 1, &payload).unwrap()
    }

    #[test]
    fn a_model_that_reflects_more_than_it_receives_is_scaled_to_albedo_one() {
        // A constant f has the albedo pi f from every direction (up to the
        // grid's cells across the horizon, within 2%).
        for parameterization in [
            Parameterization::HalfDiff,
            Parameterization::Pdv,
            Parameterization::InOut,
        ] {
            let bright = constant(parameterization, 2.0 / PI);
            assert!(
                (bright.energy_scale() - 0.5).abs() < 0.01,
                "{parameterization:?}: {}",
                bright.energy_scale()
            );
            let f = bright.eval(Vec3::Z, spherical_direction(0.7, 1.0));
            assert!((f.r * PI - 1.0).abs() < 0.02, "{parameterization:?}: {f:?}");
            assert_eq!(constant(parameterization, 0.9 / PI).energy_scale(), 1.0);
        }
    }

    #[test]
    fn node_pairs_have_their_node_coordinates() {
        for p in [
            Parameterization::HalfDiff,
            Parameterization::Pdv,
            Parameterization::InOut,
        ] {
            let mut checked = 0;
            for (a, b, c) in [
                (3, 5, 7),
                (40, 30, 100),
                (10, 60, 179),
                (80, 2, 0),
                (45, 45, 90),
            ] {
                let Some((wo, wi)) = node_pair(p, a, b, c) else {
                    continue;
                };
                let [x, y, z] = axes(p, wo, wi).unwrap();
                for ((i0, i1, t), want) in [(x, a), (y, b), (z, c)] {
                    let at = i0 as f32 * (1.0 - t) + i1 as f32 * t;
                    assert!(
                        (at - want as f32).abs() < 2e-2,
                        "{p:?} node {a},{b},{c}: {x:?} {y:?} {z:?}"
                    );
                }
                checked += 1;
            }
            assert!(checked >= 3, "{p:?}: {checked}");
        }
    }
}
