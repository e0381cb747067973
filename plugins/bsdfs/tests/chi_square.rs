//! Every BSDF's `sample_f` draws from exactly its `pdf`: chi-square tests
//! over a sweep that includes grazing angles (cos theta_o = 1e-4).

use lumis_bsdfs::{Diffuse, DiffuseSampling};
use lumis_check::adapters::bsdf_pair;
use lumis_check::{chi_square, corrected_significance, ChiSquareConfig};
use lumis_core::{Bsdf, Rgb, Vec3};

fn wo(cos_theta: f32, phi: f32) -> Vec3 {
    let s = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    Vec3::new(s * phi.cos(), s * phi.sin(), cos_theta)
}

#[test]
fn diffuse_sampling_matches_pdf() {
    let mut cases: Vec<(String, Diffuse, Vec3)> = Vec::new();
    for sampling in [DiffuseSampling::Cosine, DiffuseSampling::Uniform] {
        for two_sided in [false, true] {
            let bsdf = Diffuse::new(Rgb::new(0.9, 0.5, 0.1), two_sided, sampling);
            let mut cos_values = vec![1e-4f32, 0.01, 0.3, 0.7, 1.0];
            if two_sided {
                cos_values.extend([-1e-4f32, -0.5, -1.0]);
            }
            for c in cos_values {
                cases.push((
                    format!("{sampling:?} two_sided={two_sided} cos_o={c}"),
                    bsdf.clone(),
                    wo(c, 0.7),
                ));
            }
        }
    }
    let cfg = ChiSquareConfig {
        significance: corrected_significance(0.01, cases.len()),
        ..Default::default()
    };
    for (name, bsdf, wo) in &cases {
        let (sample, pdf) = bsdf_pair(bsdf as &dyn Bsdf, *wo);
        let report = chi_square(sample, pdf, &cfg);
        assert!(report.passed, "{name}: {report:?}");
        assert!(
            (report.pdf_integral - 1.0).abs() < 2e-3,
            "{name}: pdf integrates to {}",
            report.pdf_integral
        );
    }
}

#[test]
fn one_sided_diffuse_from_behind_samples_nothing() {
    let bsdf = Diffuse::new(Rgb::WHITE, false, DiffuseSampling::Cosine);
    let (sample, pdf) = bsdf_pair(&bsdf as &dyn Bsdf, wo(-0.5, 0.3));
    let report = chi_square(sample, pdf, &ChiSquareConfig::default());
    assert_eq!(report.sampled_fraction, 0.0);
    assert_eq!(report.pdf_integral, 0.0);
    assert!(report.passed, "{report:?}");
}
