//! Every light's `sample_li` draws directions with exactly the density
//! `pdf_li` reports, from reference points near, far, at grazing angles and
//! behind the emitter.

use lumis_check::adapters::light_pair;
use lumis_check::{chi_square, corrected_significance, ChiSquareConfig, ChiSquareReport};
use lumis_core::{Light, LightSampleContext, Rgb, Vec3};
use lumis_lights::{ConstantLight, Emission, QuadLight, TriangleLight};

fn emission(two_sided: bool) -> Emission {
    Emission {
        radiance: Rgb::WHITE,
        two_sided,
    }
}

/// Facing -y at height 1, 1 x 0.5, not centred on the axis.
fn quad(two_sided: bool) -> QuadLight {
    let (corner, edge_u, edge_v) = (
        Vec3::new(-0.3, 1.0, -0.2),
        Vec3::X,
        Vec3::new(0.0, 0.0, 0.5),
    );
    QuadLight::new(corner, edge_u, edge_v, emission(two_sided)).unwrap()
}

/// Facing -y at height 1.
fn triangle(two_sided: bool) -> TriangleLight {
    let p = [
        Vec3::new(-0.5, 1.0, -0.5),
        Vec3::new(0.8, 1.0, -0.3),
        Vec3::new(0.0, 1.0, 0.7),
    ];
    TriangleLight::new(p, emission(two_sided)).unwrap()
}

/// Reference points: below (front side), close, grazing, beside, above (back side).
fn points() -> Vec<(&'static str, Vec3)> {
    vec![
        ("below", Vec3::new(0.1, 0.0, 0.1)),
        ("close", Vec3::new(0.2, 0.9, 0.0)),
        ("grazing", Vec3::new(2.5, 0.9, 0.3)),
        ("far below", Vec3::new(0.0, -2.0, 0.0)),
        ("behind", Vec3::new(0.0, 1.5, 0.0)),
    ]
}

fn run(name: &str, light: &dyn Light, p: Vec3, cfg: &ChiSquareConfig) -> ChiSquareReport {
    let (sample, pdf) = light_pair(light, LightSampleContext::at(p));
    let report = chi_square(sample, pdf, cfg);
    assert!(report.passed, "{name}: {report:?}");
    report
}

#[test]
fn area_lights_sample_their_pdf() {
    let lights: Vec<(String, Box<dyn Light>, bool)> = vec![
        ("quad one-sided".into(), Box::new(quad(false)), false),
        ("quad two-sided".into(), Box::new(quad(true)), true),
        (
            "triangle one-sided".into(),
            Box::new(triangle(false)),
            false,
        ),
        ("triangle two-sided".into(), Box::new(triangle(true)), true),
    ];
    let tests = lights.len() * points().len();
    let cfg = ChiSquareConfig {
        z_bins: 80,
        phi_bins: 160,
        samples: 400_000,
        // Area-sampling pdfs peak sharply toward grazing directions; the
        // quadrature of such a pdf is only good to a few 1e-3.
        integral_tolerance: 5e-3,
        significance: corrected_significance(0.01, tests),
        ..Default::default()
    };
    for (name, light, two_sided) in &lights {
        for (where_, p) in points() {
            let report = run(&format!("{name} from {where_}"), light.as_ref(), p, &cfg);
            if where_ == "behind" && !two_sided {
                assert_eq!(
                    report.sampled_fraction, 0.0,
                    "{name}: a one-sided light is dark from behind"
                );
            } else {
                assert!(
                    report.sampled_fraction > 0.99,
                    "{name} from {where_}: {report:?}"
                );
            }
        }
    }
}

#[test]
fn constant_light_samples_the_sphere() {
    let light = ConstantLight::new(Rgb::WHITE);
    let report = run(
        "constant",
        &light,
        Vec3::new(3.0, -1.0, 2.0),
        &ChiSquareConfig::default(),
    );
    assert!((report.pdf_integral - 1.0).abs() < 1e-3);
}
