//! Pearson's chi-square goodness-of-fit test for direction samplers.
//!
//! Directions are binned on the sphere in (z = cos theta, phi), which are
//! equal-area coordinates: d(omega) = dz dphi. Expected counts integrate the
//! pdf over each bin with Gauss-Legendre quadrature; bins expecting fewer
//! than `min_expected` samples are pooled (Cochran's rule), and a sample in
//! a bin where the pdf integrates to zero fails the test outright.

use std::f64::consts::PI;

use lumis_core::{Vec2, Vec3};
use lumis_sampling::Pcg32;
use statrs::distribution::{ChiSquared, ContinuousCDF};

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChiSquareConfig {
    pub z_bins: usize,
    pub phi_bins: usize,
    pub samples: usize,
    /// How many times a bin may be split in four by the adaptive quadrature.
    pub max_refinement: u32,
    pub min_expected: f64,
    /// Reject when the p-value falls below this.
    pub significance: f64,
    /// How far above 1 the quadrature of the pdf may come before the pdf is
    /// declared over-normalised (quadrature converges slowly across the
    /// edges of discontinuous pdfs, e.g. the silhouette of an area light).
    pub integral_tolerance: f64,
    pub seed: u64,
}

impl Default for ChiSquareConfig {
    fn default() -> Self {
        Self {
            z_bins: 20,
            phi_bins: 40,
            samples: 200_000,
            max_refinement: 6,
            min_expected: 5.0,
            significance: 0.01,
            integral_tolerance: 1e-3,
            seed: 1,
        }
    }
}

/// The outcome of one test, with what is needed to explain a failure.
#[derive(Debug, Clone, PartialEq)]
pub struct ChiSquareReport {
    pub statistic: f64,
    /// The statistic that the quadrature's own error estimate (the last
    /// refinement's change in each bin) could account for, with no defect
    /// in the sampler: expected counts are only as good as the quadrature.
    pub quadrature_statistic: f64,
    /// The quadrature's error estimate of the pdf's whole integral.
    pub quadrature_error: f64,
    pub degrees_of_freedom: usize,
    pub p_value: f64,
    /// Integral of the pdf over the sphere (must not exceed 1).
    pub pdf_integral: f64,
    /// Fraction of attempts that produced a sample.
    pub sampled_fraction: f64,
    /// Why the test failed outright, if it did (non-finite or
    /// out-of-support samples, a pdf that integrates above 1).
    pub defect: Option<String>,
    pub passed: bool,
    /// Samples per bin, row-major over (z, phi), for failure pictures.
    pub observed: Vec<f64>,
    /// Expected samples per bin.
    pub expected: Vec<f64>,
}

impl ChiSquareReport {
    /// Why this test cannot decide, if it cannot: the expected counts are
    /// less certain than the counts themselves. The quadrature's error
    /// estimate alone accounts for a statistic of `quadrature_statistic`;
    /// above one standard deviation of the statistic under the null
    /// hypothesis, `sqrt(2 dof)`, a failure may be the quadrature's, not
    /// the sampler's. That happens where the pdf does not converge under
    /// refinement even on the lobe zoom's magnified image: a lobe a few f32
    /// ulps wide, whose pdf jumps between neighbouring representable
    /// directions. A wrong sampler at any resolvable setting leaves the
    /// quadrature converged and still fails.
    pub fn unresolved(&self) -> Option<String> {
        let noise = (2.0 * self.degrees_of_freedom as f64).sqrt();
        (self.quadrature_statistic > noise).then(|| {
            format!(
                "the pdf's quadrature does not converge (its error alone accounts for a statistic of {:.1}, above the noise {noise:.1} of {} degrees of freedom): the lobe is narrower than the bins and f32 directions resolve",
                self.quadrature_statistic, self.degrees_of_freedom
            )
        })
    }
}

fn bin_of(d: Vec3, cfg: &ChiSquareConfig) -> usize {
    let z = d.z.clamp(-1.0, 1.0) as f64;
    let zi = (((z + 1.0) * 0.5 * cfg.z_bins as f64) as usize).min(cfg.z_bins - 1);
    let mut phi = (d.y as f64).atan2(d.x as f64);
    if phi < 0.0 {
        phi += 2.0 * PI;
    }
    let pi = ((phi / (2.0 * PI) * cfg.phi_bins as f64) as usize).min(cfg.phi_bins - 1);
    zi * cfg.phi_bins + pi
}

fn direction(z: f64, phi: f64) -> Vec3 {
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32)
}

/// Nodes and weights of 5-point Gauss-Legendre quadrature on [-1, 1].
const GAUSS_LEGENDRE_5: [(f64, f64); 5] = [
    (0.0, 0.568_888_888_888_888_9),
    (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
    (0.906_179_845_938_664, 0.236_926_885_056_189_1),
];

/// 5x5-point Gauss-Legendre over the cell `[z0, z0+hz] x [phi0, phi0+hphi]`,
/// and whether the cell holds an edge of the support (some nodes zero,
/// some not).
fn cell_integral(pdf: &dyn Fn(Vec3) -> f32, z0: f64, hz: f64, phi0: f64, hphi: f64) -> (f64, bool) {
    let mut sum = 0.0;
    let (mut zero, mut positive) = (false, false);
    for (xa, wa) in GAUSS_LEGENDRE_5 {
        for (xb, wb) in GAUSS_LEGENDRE_5 {
            let d = direction(z0 + 0.5 * hz * (1.0 + xa), phi0 + 0.5 * hphi * (1.0 + xb));
            let p = pdf(d) as f64;
            zero |= p == 0.0;
            positive |= p > 0.0;
            sum += wa * wb * p;
        }
    }
    (sum * 0.25 * hz * hphi, zero && positive)
}

/// Absolute tolerances (in probability) of [`adaptive_integral`]: one for
/// smooth cells, a stricter one for cells that an edge of the support
/// crosses.
#[derive(Debug, Clone, Copy)]
struct Tolerance {
    smooth: f64,
    edge: f64,
}

/// Adaptive quadrature: a cell is split in four until the four quarters
/// agree with the whole to the tolerance, so peaked pdfs (area lights seen
/// at grazing angles) are integrated accurately where they need it and
/// cheaply elsewhere. Each quarter gets half the tolerance: what keeps
/// refining is a jump along a curve (a horizon seen through the lobe
/// zoom), whose error sits in about two of the four quarters and halves
/// with each level, so a quarter of the tolerance would never be met and
/// every such cell would go to the maximum depth. Cells crossed by an edge
/// of the support use the strict tolerance: their errors share a sign
/// along the whole edge, and their sum decides the expected count of the
/// "no sample" cell. The nodes are interior, so pdfs that jump at a cell
/// edge (a hemisphere's rim) are handled too.
fn adaptive_integral(
    pdf: &dyn Fn(Vec3) -> f32,
    (z0, hz, phi0, hphi): (f64, f64, f64, f64),
    whole: f64,
    tolerance: Tolerance,
    depth: u32,
    forced: u32,
) -> (f64, f64) {
    let (qz, qphi) = (0.5 * hz, 0.5 * hphi);
    let quarters = [
        (z0, phi0),
        (z0 + qz, phi0),
        (z0, phi0 + qphi),
        (z0 + qz, phi0 + qphi),
    ]
    .map(|(z, phi)| (z, phi, cell_integral(pdf, z, qz, phi, qphi)));
    let refined: f64 = quarters.iter().map(|q| q.2 .0).sum();
    let edge = quarters.iter().any(|q| q.2 .1);
    let allowed = if edge {
        tolerance.edge
    } else {
        tolerance.smooth
    };
    if depth == 0 || (forced == 0 && (refined - whole).abs() <= allowed) {
        return (refined, (refined - whole).abs());
    }
    let half = Tolerance {
        smooth: 0.5 * tolerance.smooth,
        edge: 0.5 * tolerance.edge,
    };
    quarters
        .iter()
        .map(|&(z, phi, (part, _))| {
            adaptive_integral(
                pdf,
                (z, qz, phi, qphi),
                part,
                half,
                depth - 1,
                forced.saturating_sub(1),
            )
        })
        .fold((0.0, 0.0), |(v, e), (part, error)| (v + part, e + error))
}

/// Bins whose first-pass mass is below this many expected samples, but
/// where samples landed, are integrated again with full refinement. (A
/// sample in a bin expecting 0.5 is ordinary in the tails; one in a bin
/// expecting 1e-2 says the first pass missed something.)
const MISSED_FEATURE: f64 = 1e-2;

/// The probability mass of every bin. Bins where samples landed but the
/// quadrature found (almost) no mass are integrated again with full
/// refinement: a feature as thin as the corner of an area light seen at a
/// grazing angle can fall between the nodes of the first pass.
fn expected_mass(
    pdf: &dyn Fn(Vec3) -> f32,
    observed: &[u64],
    cfg: &ChiSquareConfig,
) -> (Vec<f64>, Vec<f64>) {
    let dz = 2.0 / cfg.z_bins as f64;
    let dphi = 2.0 * PI / cfg.phi_bins as f64;
    // Each bin's quadrature error must be small against its Poisson noise:
    // an error delta in a bin of mass m adds N delta^2 / m to the
    // statistic, so delta <= 0.05 sqrt(m / N) adds at most 0.0025 a bin.
    // Bins of (almost) no mass keep an absolute floor, a total well below
    // one expected sample over the whole grid.
    let floor = 0.01 / (cfg.samples as f64 * (cfg.z_bins * cfg.phi_bins) as f64).sqrt();
    let tolerance = |whole: f64| Tolerance {
        smooth: floor.max(0.05 * (whole.max(0.0) / cfg.samples as f64).sqrt()),
        edge: floor,
    };
    let strict = Tolerance {
        smooth: floor,
        edge: floor,
    };
    let mut mass = vec![0.0; cfg.z_bins * cfg.phi_bins];
    let mut error = vec![0.0; cfg.z_bins * cfg.phi_bins];
    for zi in 0..cfg.z_bins {
        for pi in 0..cfg.phi_bins {
            let cell = (-1.0 + zi as f64 * dz, dz, pi as f64 * dphi, dphi);
            let (whole, _) = cell_integral(pdf, cell.0, cell.1, cell.2, cell.3);
            let i = zi * cfg.phi_bins + pi;
            // The first levels are always refined: a feature narrower than
            // the coarse nodes' spacing would otherwise go unseen.
            (mass[i], error[i]) =
                adaptive_integral(pdf, cell, whole, tolerance(whole), cfg.max_refinement, 2);
            if observed[i] > 0 && mass[i] * (cfg.samples as f64) < MISSED_FEATURE {
                (mass[i], error[i]) = adaptive_integral(
                    pdf,
                    cell,
                    whole,
                    strict,
                    cfg.max_refinement,
                    cfg.max_refinement,
                );
            }
        }
    }
    (mass, error)
}

/// Tests that `sample(u)` draws unit directions with density `pdf` (w.r.t.
/// solid angle). `sample` may return `None` (no sample); the pdf then need
/// only integrate to the fraction of attempts that produce one.
pub fn chi_square(
    mut sample: impl FnMut(f32, Vec2) -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f32,
    cfg: &ChiSquareConfig,
) -> ChiSquareReport {
    let mut rng = Pcg32::new(cfg.seed, 0x5eed);
    let mut observed = vec![0u64; cfg.z_bins * cfg.phi_bins];
    let mut produced = 0usize;
    let mut defect = None;
    for _ in 0..cfg.samples {
        let u1 = rng.next_f32();
        let u2 = Vec2::new(rng.next_f32(), rng.next_f32());
        let Some(d) = sample(u1, u2) else { continue };
        if !d.is_finite() || (d.length() - 1.0).abs() > 1e-3 {
            defect.get_or_insert(format!("sample {d:?} is not a finite unit vector"));
            continue;
        }
        produced += 1;
        observed[bin_of(d, cfg)] += 1;
    }
    let (mass, error) = expected_mass(&pdf, &observed, cfg);
    let pdf_integral: f64 = mass.iter().sum();
    let quadrature_error: f64 = error.iter().sum();
    let sampled_fraction = produced as f64 / cfg.samples as f64;
    // Over 1 by more than the tolerance and than the quadrature's own
    // error estimate: an integral the quadrature cannot pin down is left
    // to `unresolved`.
    if pdf_integral - quadrature_error > 1.0 + cfg.integral_tolerance {
        defect.get_or_insert(format!("the pdf integrates to {pdf_integral:.5} > 1"));
    }

    // Pool the bins with small expected counts (smallest first).
    let expected: Vec<f64> = mass.iter().map(|m| m * cfg.samples as f64).collect();
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut pool_obs, mut pool_exp, mut statistic, mut dof) = (0.0, 0.0, 0.0, 0usize);
    let n = cfg.samples as f64;
    let (mut quadrature_statistic, mut pool_error) = (0.0, 0.0);
    for &i in order.iter() {
        let (o, e) = (observed[i] as f64, expected[i]);
        if e <= 0.0 && o > 0.0 {
            defect.get_or_insert(format!(
                "{o} samples in bin {i} where the pdf integrates to zero"
            ));
        }
        if e < cfg.min_expected {
            pool_obs += o;
            pool_exp += e;
            pool_error += n * error[i];
        } else {
            statistic += (o - e).powi(2) / e;
            quadrature_statistic += (n * error[i]).powi(2) / e;
            dof += 1;
        }
    }
    // Samples that the pdf's mass does not account for (None samples are
    // missing mass) form the last cell together with the pooled bins.
    let missing_obs = (cfg.samples - produced) as f64;
    let missing_exp = (1.0 - pdf_integral).max(0.0) * cfg.samples as f64;
    pool_obs += missing_obs;
    pool_exp += missing_exp;
    if pool_exp >= cfg.min_expected {
        statistic += (pool_obs - pool_exp).powi(2) / pool_exp;
        quadrature_statistic += pool_error.powi(2) / pool_exp;
        dof += 1;
    } else if pool_obs > pool_exp + 5.0 * pool_exp.max(1.0).sqrt() + 5.0 {
        defect.get_or_insert(format!(
            "{pool_obs} samples where only {pool_exp:.2} are expected"
        ));
    }
    let dof = dof.saturating_sub(1).max(1);
    let p_value = 1.0
        - ChiSquared::new(dof as f64)
            .map(|c| c.cdf(statistic))
            .unwrap_or(0.0);
    ChiSquareReport {
        statistic,
        quadrature_statistic,
        quadrature_error,
        degrees_of_freedom: dof,
        p_value,
        pdf_integral,
        sampled_fraction,
        passed: defect.is_none() && p_value >= cfg.significance,
        defect,
        observed: observed.iter().map(|&o| o as f64).collect(),
        expected,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lumis_sampling::warp;

    #[test]
    fn accepts_correct_warps() {
        let cfg = ChiSquareConfig::default();
        let cos = chi_square(
            |_, u| Some(warp::square_to_cosine_hemisphere(u)),
            |d| warp::cosine_hemisphere_pdf(d.z),
            &cfg,
        );
        assert!(cos.passed, "{cos:?}");
        assert!((cos.pdf_integral - 1.0).abs() < 1e-3);
        let sphere = chi_square(
            |_, u| Some(warp::square_to_uniform_sphere(u)),
            |_| warp::UNIFORM_SPHERE_PDF,
            &cfg,
        );
        assert!(sphere.passed, "{sphere:?}");
        let hemi = chi_square(
            |_, u| Some(warp::square_to_uniform_hemisphere(u)),
            |d| warp::uniform_hemisphere_pdf(d.z),
            &cfg,
        );
        assert!(hemi.passed, "{hemi:?}");
    }

    #[test]
    fn rejects_a_wrong_pdf() {
        // Cosine samples tested against the uniform hemisphere pdf.
        let r = chi_square(
            |_, u| Some(warp::square_to_cosine_hemisphere(u)),
            |d| warp::uniform_hemisphere_pdf(d.z),
            &ChiSquareConfig::default(),
        );
        assert!(!r.passed && r.p_value < 1e-10, "{r:?}");
    }

    #[test]
    fn rejects_a_subtly_wrong_sampler() {
        // cos^1.1 instead of cos: a 10% change in the exponent.
        let r = chi_square(
            |_, u| {
                let z = u.x.powf(1.0 / 2.1);
                let r = (1.0 - z * z).max(0.0).sqrt();
                let phi = 2.0 * std::f32::consts::PI * u.y;
                Some(Vec3::new(r * phi.cos(), r * phi.sin(), z))
            },
            |d| warp::cosine_hemisphere_pdf(d.z),
            &ChiSquareConfig::default(),
        );
        assert!(!r.passed, "{r:?}");
        // A smooth pdf's quadrature converges: the failure is the sampler's.
        assert_eq!(r.unresolved(), None);
    }

    #[test]
    fn rejects_samples_outside_the_support_and_excess_mass() {
        let below = chi_square(
            |_, u| Some(-warp::square_to_cosine_hemisphere(u)),
            |d| warp::cosine_hemisphere_pdf(d.z),
            &ChiSquareConfig::default(),
        );
        assert!(!below.passed && below.defect.is_some(), "{below:?}");
        let double = chi_square(
            |_, u| Some(warp::square_to_uniform_sphere(u)),
            |_| 2.0 * warp::UNIFORM_SPHERE_PDF,
            &ChiSquareConfig::default(),
        );
        assert!(
            double
                .defect
                .as_deref()
                .unwrap_or("")
                .contains("integrates"),
            "{double:?}"
        );
    }

    #[test]
    fn missing_mass_must_match_none_samples() {
        // Half the samples are dropped, and the pdf says so: passes.
        let half = chi_square(
            |u1, u| (u1 < 0.5).then(|| warp::square_to_uniform_sphere(u)),
            |_| 0.5 * warp::UNIFORM_SPHERE_PDF,
            &ChiSquareConfig::default(),
        );
        assert!(half.passed, "{half:?}");
        // Half are dropped but the pdf claims all are returned: fails.
        let lying = chi_square(
            |u1, u| (u1 < 0.5).then(|| warp::square_to_uniform_sphere(u)),
            |_| warp::UNIFORM_SPHERE_PDF,
            &ChiSquareConfig::default(),
        );
        assert!(!lying.passed, "{lying:?}");
    }
}
