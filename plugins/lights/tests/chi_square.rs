//! Every light's `sample_li` draws directions with exactly the density
//! `pdf_li` reports, for every sampling mode, from reference points near,
//! far, at grazing angles, behind the emitter and (spheres) inside and on it.

use lumis_check::adapters::light_pair;
use lumis_check::{chi_square, corrected_significance, ChiSquareConfig, ChiSquareReport};
use lumis_core::{Light, LightSampleContext, Rgb, Vec3};
use lumis_lights::{ConstantLight, Emission, QuadLight, Sampling, SphereLight, TriangleLight};

fn emission(two_sided: bool) -> Emission {
    Emission {
        radiance: Rgb::WHITE,
        two_sided,
    }
}

/// Facing -y at height 1, 1 x 0.5, not centred on the axis.
fn quad(two_sided: bool, sampling: Sampling) -> QuadLight {
    let (corner, edge_u, edge_v) = (
        Vec3::new(-0.3, 1.0, -0.2),
        Vec3::X,
        Vec3::new(0.0, 0.0, 0.5),
    );
    QuadLight::new(corner, edge_u, edge_v, emission(two_sided))
        .unwrap()
        .with_sampling(sampling)
}

/// Facing -y at height 1.
fn triangle(two_sided: bool, sampling: Sampling) -> TriangleLight {
    let p = [
        Vec3::new(-0.5, 1.0, -0.5),
        Vec3::new(0.8, 1.0, -0.3),
        Vec3::new(0.0, 1.0, 0.7),
    ];
    TriangleLight::new(p, emission(two_sided))
        .unwrap()
        .with_sampling(sampling)
}

/// Reference points: below (front side), close, grazing, beside, above (back side).
fn points() -> Vec<(&'static str, Vec3)> {
    vec![
        ("below", Vec3::new(0.1, 0.0, 0.1)),
        ("close", Vec3::new(0.2, 0.9, 0.0)),
        // 9.5 degrees above the plane: grazing, yet wide enough (0.03 sr)
        // for the bins' quadrature to resolve the outline of a uniform
        // solid-angle pdf to the 1e-4 that 400k samples see.
        ("grazing", Vec3::new(1.5, 0.8, 0.3)),
        ("far below", Vec3::new(0.0, -2.0, 0.0)),
        ("behind", Vec3::new(0.0, 1.5, 0.0)),
    ]
}

fn run(name: &str, light: &dyn Light, p: Vec3, cfg: &ChiSquareConfig) -> ChiSquareReport {
    let (sample, pdf) = light_pair(light, LightSampleContext::at(p));
    let report = chi_square(sample, pdf, cfg);
    assert!(report.passed, "{name}: {}", summary(&report));
    report
}

/// The report without its histograms.
fn summary(r: &ChiSquareReport) -> String {
    format!(
        "p = {:.3e}, chi2 = {:.1} ({} dof), pdf integral {:.4}, sampled fraction {:.4}, {:?}",
        r.p_value, r.statistic, r.degrees_of_freedom, r.pdf_integral, r.sampled_fraction, r.defect
    )
}

#[test]
fn area_lights_sample_their_pdf() {
    use Sampling::{Area, SolidAngle};
    let mut lights: Vec<(String, Box<dyn Light>, bool)> = Vec::new();
    for (mode, sampling) in [("area", Area), ("solid-angle", SolidAngle)] {
        for two_sided in [false, true] {
            let sides = if two_sided { "two-sided" } else { "one-sided" };
            lights.push((
                format!("quad {sides} {mode}"),
                Box::new(quad(two_sided, sampling)),
                two_sided,
            ));
            lights.push((
                format!("triangle {sides} {mode}"),
                Box::new(triangle(two_sided, sampling)),
                two_sided,
            ));
        }
    }
    // Every solid-angle case above really samples the solid angle (the
    // fallback would make the solid-angle rows repeat the area rows).
    for (_, p) in points() {
        assert!(quad(false, SolidAngle).samples_solid_angle_from(p));
        assert!(triangle(false, SolidAngle).samples_solid_angle_from(p));
    }
    let tests = lights.len() * points().len() + sphere_cases().len();
    let cfg = config(tests);
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
                    "{name} from {where_}: {}",
                    summary(&report)
                );
            }
        }
    }
}

/// The shared chi-square configuration, Sidak-corrected for `tests` cases.
fn config(tests: usize) -> ChiSquareConfig {
    ChiSquareConfig {
        z_bins: 80,
        phi_bins: 160,
        samples: 400_000,
        // Area-sampling pdfs peak sharply toward grazing directions; the
        // quadrature of such a pdf is only good to a few 1e-3.
        integral_tolerance: 5e-3,
        // A uniform solid-angle pdf is an indicator of the light's outline;
        // a small light has few bins and many of them are cut by the
        // outline, where the quadrature needs more splits to get the bin's
        // mass to the 1e-4 that 400k samples resolve.
        max_refinement: 8,
        significance: corrected_significance(0.01, tests * 2),
        ..Default::default()
    }
}

/// A sphere of radius 0.3 at (0, 1, 0): name, light, reference point, the
/// fraction of samples expected to be valid (1 or 0), and whether the point
/// samples the cone.
fn sphere_cases() -> Vec<(&'static str, SphereLight, Vec3, f64, bool)> {
    let c = Vec3::new(0.0, 1.0, 0.0);
    let make = |inward: bool, two_sided: bool, sampling: Sampling| {
        SphereLight::new(c, 0.3, inward, emission(two_sided))
            .unwrap()
            .with_sampling(sampling)
    };
    use Sampling::{Area, SolidAngle};
    vec![
        (
            "cone, near",
            make(false, false, SolidAngle),
            Vec3::new(0.2, 0.5, 0.1),
            1.0,
            true,
        ),
        (
            "cone, far",
            make(false, false, SolidAngle),
            Vec3::new(0.0, -3.0, 1.0),
            1.0,
            true,
        ),
        (
            "cone, just outside",
            make(false, false, SolidAngle),
            Vec3::new(0.0, 0.69, 0.0),
            1.0,
            true,
        ),
        // Area sampling from outside has a 1/cos singularity all along the
        // silhouette that the bin quadrature cannot integrate; it is
        // checked by `sphere_area_sampling_from_outside_covers_the_cone`.
        (
            "area, inside",
            make(true, false, Area),
            Vec3::new(0.1, 1.1, 0.0),
            1.0,
            false,
        ),
        (
            "inward, inside",
            make(true, false, SolidAngle),
            Vec3::new(0.1, 1.1, 0.0),
            1.0,
            false,
        ),
        (
            "inward, on it",
            make(true, false, SolidAngle),
            Vec3::new(0.0, 0.7, 0.0),
            1.0,
            false,
        ),
        (
            "two-sided, inside",
            make(false, true, SolidAngle),
            Vec3::new(0.0, 1.2, 0.05),
            1.0,
            false,
        ),
        (
            "outward, inside: dark",
            make(false, false, SolidAngle),
            Vec3::new(0.0, 1.2, 0.05),
            0.0,
            false,
        ),
        (
            "inward, outside: dark",
            make(true, false, SolidAngle),
            Vec3::new(0.2, 0.5, 0.1),
            0.0,
            true,
        ),
    ]
}

#[test]
fn sphere_light_samples_its_pdf() {
    let cases = sphere_cases();
    let tests = cases.len() + 40;
    let cfg = config(tests);
    for (name, light, p, fraction, cone) in &cases {
        assert_eq!(light.samples_cone_from(*p), *cone, "{name}");
        let report = run(&format!("sphere {name}"), light, *p, &cfg);
        if *fraction == 1.0 {
            assert!(
                report.sampled_fraction > 0.99,
                "{name}: {}",
                summary(&report)
            );
            assert!(
                (report.pdf_integral - 1.0).abs() < 5e-3,
                "{name}: {}",
                summary(&report)
            );
        } else {
            assert_eq!(report.sampled_fraction, 0.0, "{name}: {}", summary(&report));
        }
    }
}

/// Area sampling from outside: only the visible cap is returned, and the
/// estimate `E[1/pdf]` (0 for rejected samples) of the solid angle matches
/// the cone's `2 pi (1 - cos theta_max)`; a wrong density or a wrong
/// visibility rule would bias it. The spread of 1/pdf is estimated too, so
/// the bound is 5 standard errors, not a guess.
#[test]
fn sphere_area_sampling_from_outside_covers_the_cone() {
    let c = Vec3::new(0.0, 1.0, 0.0);
    let light = SphereLight::new(c, 0.3, false, emission(false))
        .unwrap()
        .with_sampling(Sampling::Area);
    for p in [Vec3::new(0.2, 0.5, 0.1), Vec3::new(0.0, -3.0, 1.0)] {
        let ctx = LightSampleContext::at(p);
        let d = (c - p).length() as f64;
        let sin2 = (0.3 / d) * (0.3 / d);
        let omega = 2.0 * std::f64::consts::PI * sin2 / (1.0 + (1.0 - sin2).sqrt());
        let n = 1_000_000;
        let mut rng = lumis_sampling::Pcg32::new(11, 12);
        let (mut sum, mut sum2, mut valid) = (0.0f64, 0.0f64, 0usize);
        for _ in 0..n {
            let u = lumis_core::Vec2::new(rng.next_f32(), rng.next_f32());
            if let Some(s) = light.sample_li(&ctx, u) {
                assert!(s.pdf.is_finite() && s.pdf > 0.0);
                let w = 1.0 / s.pdf as f64;
                sum += w;
                sum2 += w * w;
                valid += 1;
            }
        }
        let mean = sum / n as f64;
        let se = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
        assert!(
            (mean - omega).abs() < 5.0 * se + 1e-6 * omega,
            "from {p}: {mean} +- {se} vs {omega}"
        );
        // The visible cap's share of the area: (1 - r/d) / 2.
        let cap = (1.0 - 0.3 / d) / 2.0;
        let fraction = valid as f64 / n as f64;
        assert!((fraction - cap).abs() < 3e-3, "{fraction} vs {cap}");
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
