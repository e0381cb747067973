//! The instruction set of the SIMD kernels, as a user chooses it with
//! `LUMIS_SIMD`: reported, checked, and never a change to the image.

mod common;

use std::path::Path;
use std::process::Command;

use common::*;
use lumis_sampling::simd::{Isa, ENV};

/// `lumis` with `LUMIS_SIMD` set to `isa`.
fn lumis_with(isa: &str, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_lumis"))
        .env(ENV, isa)
        .args(args)
        .output()
        .expect("lumis runs")
}

/// The pixels' bits of an EXR.
fn pixel_bits(path: &Path) -> Vec<u32> {
    let image = lumis_image::read_exr(path).expect("the render's EXR reads back");
    image.pixels.iter().flatten().map(|v| v.to_bits()).collect()
}

/// The integrators whose plugins run SIMD kernels (the conductor's
/// batched lobe, the sphere light's cone, the diffuse lane warp) give the
/// same image, bit for bit, under every instruction set the CPU runs.
#[test]
fn every_instruction_set_renders_the_same_image() {
    let tmp = scratch("simd-same-image");
    let supported: Vec<Isa> = Isa::BUILT
        .iter()
        .copied()
        .filter(|isa| isa.is_supported())
        .collect();
    if supported.len() < 2 {
        eprintln!("skipped: this CPU runs only {:?}", supported);
        return;
    }
    for (scene_name, integrator) in [
        ("bench/glossy-beckmann.toml", "wavefront"),
        ("bench/glossy-beckmann.toml", "packet"),
        ("bench/cornell-box.toml", "packet"),
    ] {
        let images: Vec<Vec<u32>> = supported
            .iter()
            .map(|isa| {
                let out = tmp.path().join(format!("{integrator}-{}.exr", isa.name()));
                let out = out.to_str().expect("a UTF-8 scratch path");
                let run = lumis_with(
                    isa.name(),
                    &[
                        "render",
                        &scene(scene_name),
                        "--set",
                        "film.resolution=[48, 32]",
                        "--set",
                        &format!("integrator.type=\"{integrator}\""),
                        "--spp",
                        "4",
                        "--threads",
                        "2",
                        "-o",
                        out,
                    ],
                );
                let stderr = String::from_utf8_lossy(&run.stderr);
                assert!(run.status.success(), "{stderr}");
                assert!(
                    stderr.contains(&format!("SIMD kernels: {isa}")),
                    "the start-up report names {isa}:\n{stderr}"
                );
                pixel_bits(Path::new(out))
            })
            .collect();
        for (isa, image) in supported.iter().zip(&images).skip(1) {
            assert!(
                *image == images[0],
                "{scene_name} under {integrator}: {} and {} differ",
                isa.name(),
                supported[0].name()
            );
        }
    }
}

/// A name that is not an instruction set, or one this CPU does not run,
/// stops every command before it starts, naming the variable and what it
/// may be.
#[test]
fn an_unknown_instruction_set_is_refused_naming_the_variable() {
    let run = lumis_with("mmx", &["plugins"]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success(), "{stderr}");
    assert!(
        stderr.contains(&format!("{ENV}=mmx")) && stderr.contains(Isa::Baseline.name()),
        "{stderr}"
    );
    if let Some(unsupported) = Isa::BUILT.iter().find(|isa| !isa.is_supported()) {
        let run = lumis_with(unsupported.name(), &["plugins"]);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success(), "{stderr}");
        assert!(stderr.contains("this CPU does not run"), "{stderr}");
    }
}

/// `lumis --version` names the instruction sets built and the one chosen.
#[test]
fn version_names_the_instruction_sets() {
    let baseline = Isa::Baseline.name();
    let run = lumis_with(baseline, &["--version"]);
    let stdout = stdout_of_success(&run);
    for isa in Isa::BUILT {
        assert!(stdout.contains(isa.name()), "{stdout}");
    }
    assert!(
        stdout.contains(&format!("runs them with {}", Isa::Baseline)),
        "{stdout}"
    );
}
