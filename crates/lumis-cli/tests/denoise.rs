//! `lumis denoise`: an image on disk, denoised as its render would have
//! denoised it; what it cannot denoise is refused by name.

mod common;

use std::path::Path;

use common::*;
use lumis_app::{builtin_registry, denoise_image, DenoiseArgs};
use lumis_core::{
    DenoiseInput, Denoiser, Error, Params, PluginKind, PluginSpec, Registrar, Result,
};

/// The glossy plates' `[denoiser]` in these tests: not the default
/// quality, so an image denoised without reading it differs.
const DENOISER: [&str; 4] = [
    "--set",
    "denoiser.type=\"oidn\"",
    "--set",
    "denoiser.quality=\"fast\"",
];

/// `lumis render` of the small scene at 2 spp to `out`, plus `extra`.
fn render(out: &str, extra: &[&str]) {
    let mut args = small_render(out, "2");
    args.extend(extra);
    let result = lumis(&args);
    assert!(result.status.success(), "{args:?}: {result:?}");
}

/// `lumis denoise` with `args`.
fn denoise(args: &[&str]) -> std::process::Output {
    lumis(&[&["denoise"][..], args].concat())
}

fn denoise_error(args: &[&str]) -> String {
    let result = denoise(args);
    assert!(!result.status.success(), "{args:?} denoised: {result:?}");
    String::from_utf8_lossy(&result.stderr).into_owned()
}

/// The denoiser its render recorded, run on the raw image it wrote, makes
/// the render's denoised image bit for bit; another makes another image;
/// the header is carried over and says what denoised it.
#[test]
fn denoise_reproduces_the_renders_denoised_image() {
    let tmp = scratch("denoise-again");
    let raw = path_in(tmp.path(), "plates.exr");
    render(&raw, &DENOISER);
    let denoised = tmp.path().join("plates.denoised.exr");
    let by_the_render = exr_pixels(&denoised);
    std::fs::remove_file(&denoised).unwrap();

    let result = denoise(&[&raw]);
    assert!(result.status.success(), "{result:?}");
    let stdout = String::from_utf8_lossy(&result.stdout);
    assert!(
        stdout.contains("guided by albedo and normal") && stdout.contains("plates.denoised.exr"),
        "{stdout}"
    );
    assert!(tmp.path().join("plates.denoised.png").is_file());
    assert_eq!(
        exr_pixels(&denoised),
        by_the_render,
        "lumis denoise did not reproduce the render's denoised image"
    );
    let recorded = "{ quality = \"fast\", type = \"oidn\" }";
    assert_eq!(header(Path::new(&raw), "denoiser"), recorded);
    assert_eq!(header(&denoised, "denoised_by"), recorded);
    for key in ["spp", "seed", "scene_hash", "denoiser"] {
        assert_eq!(
            header(&denoised, key),
            header(Path::new(&raw), key),
            "{key}"
        );
    }

    // --set changes the recorded denoiser's parameters.
    let high = path_in(tmp.path(), "high.exr");
    let result = denoise(&[&raw, "-o", &high, "--set", "quality=high"]);
    assert!(result.status.success(), "{result:?}");
    assert_eq!(
        header(Path::new(&high), "denoised_by"),
        "{ quality = \"high\", type = \"oidn\" }"
    );
    assert_ne!(exr_pixels(&high), by_the_render);
    // --denoiser names one afresh, with its defaults.
    let named = path_in(tmp.path(), "named");
    let result = denoise(&[&raw, "-o", &named, "--denoiser", "oidn"]);
    assert!(result.status.success(), "{result:?}");
    assert_eq!(
        header(&tmp.path().join("named.exr"), "denoised_by"),
        "{ type = \"oidn\" }"
    );
    assert!(tmp.path().join("named.png").is_file());
}

/// An image whose scene had no denoiser is denoised by `oidn`, and guided
/// only by the layers it has.
#[test]
fn an_image_without_a_denoiser_gets_oidn_and_its_own_guides() {
    let tmp = scratch("denoise-default");
    let raw = path_in(tmp.path(), "plain.exr");
    render(&raw, &[]);
    let result = denoise(&[&raw]);
    assert!(result.status.success(), "{result:?}");
    let stdout = String::from_utf8_lossy(&result.stdout);
    assert!(stdout.contains("guided by the colour alone"), "{stdout}");
    assert_eq!(
        header(&tmp.path().join("plain.denoised.exr"), "denoised_by"),
        "{ type = \"oidn\" }"
    );
}

/// A denoiser that needs an albedo image, as a plugin may.
struct GuidedOnly;

impl Denoiser for GuidedOnly {
    fn denoise(&self, input: &DenoiseInput<'_>) -> Result<Vec<[f32; 3]>> {
        match input.albedo {
            Some(_) => Ok(input.color.to_vec()),
            None => Err(Error::msg("guided-only needs an albedo image")),
        }
    }
}

const GUIDED_ONLY: PluginSpec = PluginSpec {
    kind: PluginKind::Denoiser,
    name: "guided-only",
    source: lumis_api::source_file!(),
    doc: "returns the colour, but only when given an albedo",
    params: &[],
};

fn guided_only(_: &Params) -> Result<Box<dyn Denoiser>> {
    Ok(Box::new(GuidedOnly))
}

/// A denoiser that needs the guides an image lacks fails naming the image
/// and the missing layer; given them, it runs.
#[test]
fn a_denoiser_needing_guides_the_image_lacks_says_so() {
    let tmp = scratch("denoise-guides");
    let mut registry = builtin_registry().unwrap();
    registry.add_denoiser(GUIDED_ONLY, guided_only).unwrap();
    let args = |image: &str| DenoiseArgs {
        image: image.into(),
        output: None,
        denoiser: Some("guided-only".into()),
        set: Vec::new(),
        load: Vec::new(),
    };
    let plain = path_in(tmp.path(), "plain.exr");
    render(&plain, &[]);
    let err = match denoise_image(&args(&plain), &registry) {
        Ok(_) => panic!("denoised without guides"),
        Err(e) => e.to_string(),
    };
    assert!(
        err.contains("the denoiser had no guides")
            && err.contains("plain.exr' has no albedo layer")
            && err.contains("guided-only needs an albedo image"),
        "{err}"
    );
    assert!(!tmp.path().join("plain.denoised.exr").exists());
    let guided = path_in(tmp.path(), "guided.exr");
    render(&guided, &["--set", "film.aovs=[\"albedo\"]"]);
    let report = denoise_image(&args(&guided), &registry).unwrap();
    assert_eq!(exr_pixels(&report.exr), exr_pixels(&guided));
}

/// What `lumis denoise` cannot take is refused, naming the file and what
/// was expected.
#[test]
fn denoise_refuses_what_it_cannot_denoise_by_name() {
    let tmp = scratch("denoise-errors");
    let file = |name: &str| path_in(tmp.path(), name);
    let raw = file("plates.exr");
    render(&raw, &DENOISER);

    let text = file("text.exr");
    std::fs::write(&text, "not an image").unwrap();
    let err = denoise_error(&[&text]);
    assert!(err.contains("text.exr' is not an EXR image"), "{err}");
    let err = denoise_error(&[&file("missing.exr")]);
    assert!(err.contains("missing.exr: No such file"), "{err}");
    let err = denoise_error(&[&file("plates.png")]);
    assert!(err.contains("plates.png' is not an EXR image"), "{err}");

    // A NaN is said first, before the guides the image lacks.
    let nan = file("nan.exr");
    exr::prelude::write_rgb_file(&nan, 2, 2, |x, y| match (x, y) {
        (1, 0) => (f32::NAN, 0.5, 0.5),
        _ => (0.5f32, 0.5f32, 0.5f32),
    })
    .unwrap();
    let err = denoise_error(&[&nan]);
    assert!(
        err.starts_with("error: '") && err.contains("nan.exr': its colour holds a value that is not finite, [NaN, 0.5, 0.5] at pixel (1, 0)")
            && !err.contains("guides"),
        "{err}"
    );

    // An EXR with a luminance channel alone.
    let grey = file("grey.exr");
    let channel = exr::image::AnyChannel::new("Y", exr::image::FlatSamples::F32(vec![0.5; 4]));
    let channels = exr::image::AnyChannels::sort(vec![channel].into());
    exr::prelude::WritableImage::write(&exr::image::Image::from_channels((2, 2), channels))
        .to_file(&grey)
        .unwrap();
    let err = denoise_error(&[&grey]);
    assert!(
        err.contains("grey.exr' has no colour layer: expected the channels R, G and B, found Y"),
        "{err}"
    );

    let err = denoise_error(&[&raw, "--denoiser", "nlm"]);
    assert!(
        err.contains("--denoiser nlm: unknown denoiser type \"nlm\"")
            && err.contains("available: oidn"),
        "{err}"
    );
    let err = denoise_error(&[&raw, "--set", "qualty=fast"]);
    assert!(
        err.contains(
            "header lumis.denoiser = { quality = \"fast\", type = \"oidn\" } --set qualty=fast"
        ) && err.contains("qualty"),
        "{err}"
    );
    // The header's record of a denoiser this lumis does not have.
    let foreign = file("foreign.exr");
    let mut attributes = lumis_image::read_exr_metadata(Path::new(&raw)).unwrap();
    for (name, value) in &mut attributes {
        if name == "lumis.denoiser" {
            *value = "{ type = \"nlm\" }".into();
        }
    }
    let colour = lumis_image::read_exr(Path::new(&raw)).unwrap();
    lumis_image::write_exr_with_metadata(Path::new(&foreign), &colour, &attributes).unwrap();
    let err = denoise_error(&[&foreign]);
    assert!(
        err.contains("foreign.exr' header lumis.denoiser = { type = \"nlm\" }")
            && err.contains("unknown denoiser type \"nlm\"")
            && err.contains("available: oidn"),
        "{err}"
    );

    for output in [raw.as_str(), &file("plates.png"), &file("plates")] {
        let err = denoise_error(&[&raw, "-o", output]);
        assert!(
            err.contains("plates.exr is the image being denoised: give another -o"),
            "{output}: {err}"
        );
    }
    let err = denoise_error(&[&file("plates.denoised.exr")]);
    assert!(
        err.contains("plates.denoised.exr' is already denoised (lumis.denoised_by = {"),
        "{err}"
    );
    let part = file("part.exr");
    render(&part, &["--part", "0/2"]);
    let err = denoise_error(&[&part]);
    assert!(
        err.contains("part.exr' is a part of a render (samples 0..1 of 2)")
            && err.contains("lumis merge"),
        "{err}"
    );
    assert_eq!(
        files_in(tmp.path()),
        [
            "foreign.exr",
            "grey.exr",
            "nan.exr",
            "part.exr",
            "plates.denoised.exr",
            "plates.denoised.png",
            "plates.exr",
            "plates.png",
            "text.exr"
        ],
        "a refused denoise wrote a file"
    );
}
