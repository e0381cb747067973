//! `lumis render --part K/N` / `--samples A..B` and `lumis merge`: the parts
//! of a render, merged, are the render; parts of different renders, gaps,
//! overlaps and files that are not parts are refused by name.

mod common;

use std::path::Path;

use common::*;
use lumis_core::PluginKind;

const SPP: &str = "6";

/// Every output beside the colour: their sums are split and merged too.
const ALL_AOVS: &str = "film.aovs=[\"albedo\", \"normal\", \"depth\", \"variance\", \"spp\"]";

/// The bits of every channel of an EXR (colour and outputs), by name.
fn all_channels(path: &Path) -> Vec<(String, Vec<u32>)> {
    let mut channels: Vec<(String, Vec<u32>)> = lumis_image::read_exr_channels(path)
        .unwrap()
        .into_iter()
        .map(|(name, values)| (name, values.into_iter().map(f32::to_bits).collect()))
        .collect();
    channels.sort();
    channels
}

/// `lumis render` of the small scene at 16x16 and [`SPP`] with every
/// output and `sampler`, plus `extra` flags, to `out`; panics where it
/// fails.
fn render(sampler: &str, out: &str, extra: &[&str]) {
    render_spp(sampler, out, SPP, extra)
}

/// [`render`] at `spp`.
fn render_spp(sampler: &str, out: &str, spp: &str, extra: &[&str]) {
    let sampler = format!("sampler.type=\"{sampler}\"");
    let mut args = small_render(out, spp);
    args.extend(["--set", "film.resolution=[16, 16]", "--set", ALL_AOVS]);
    args.extend(["--set", &sampler]);
    args.extend(extra);
    let result = lumis(&args);
    assert!(result.status.success(), "{args:?}: {result:?}");
}

fn merge(parts: &[&str], out: &str) -> std::process::Output {
    let mut args = vec!["merge"];
    args.extend(parts);
    args.extend(["-o", out]);
    lumis(&args)
}

fn merged(parts: &[&str], out: &str) {
    let result = merge(parts, out);
    assert!(result.status.success(), "{parts:?}: {result:?}");
}

fn merge_error(parts: &[&str], out: &str) -> String {
    let result = merge(parts, out);
    assert!(!result.status.success(), "{parts:?} merged");
    String::from_utf8_lossy(&result.stderr).into_owned()
}

/// The names of the built-in samplers.
fn builtin_samplers() -> Vec<&'static str> {
    let registry = lumis_app::builtin_registry().unwrap();
    let names = registry.names(PluginKind::Sampler);
    assert!(names.len() >= 7, "{names:?}");
    names
}

/// For every built-in sampler: three parts merged are, bit for bit, the
/// same slices rendered in passes of one sample (each sample index a pass
/// of its own) and merged, and the render of one process with the same
/// slice boundaries (`--parts 3`); they agree with one plain render to
/// within the rounding of the sums; one part of all the samples merged is
/// the plain render, bit for bit.
#[test]
fn merged_parts_are_the_render_for_every_sampler() {
    let tmp = scratch("merge-samplers");
    let file = |name: &str| path_in(tmp.path(), name);
    for sampler in builtin_samplers() {
        let whole = file(&format!("{sampler}-whole.exr"));
        render(sampler, &whole, &[]);
        let mut parts = Vec::new();
        let mut slices = Vec::new();
        for (k, range) in ["0..2", "2..4", "4..6"].into_iter().enumerate() {
            let part = file(&format!("{sampler}-part-{k}.exr"));
            render(sampler, &part, &["--part", &format!("{k}/3")]);
            assert_eq!(header(Path::new(&part), "slice"), range);
            assert_eq!(header(Path::new(&part), "total_spp"), SPP);
            let slice = file(&format!("{sampler}-slice-{k}.exr"));
            render(sampler, &slice, &["--samples", range, "--pass-spp", "1"]);
            parts.push(part);
            slices.push(slice);
        }
        // Given out of order: merge sorts them by their slices.
        parts.swap(0, 2);
        let from_parts = file(&format!("{sampler}-from-parts.exr"));
        let from_slices = file(&format!("{sampler}-from-slices.exr"));
        merged(
            &parts.iter().map(String::as_str).collect::<Vec<_>>(),
            &from_parts,
        );
        merged(
            &slices.iter().map(String::as_str).collect::<Vec<_>>(),
            &from_slices,
        );
        let (merged_channels, whole_channels) = (
            all_channels(Path::new(&from_parts)),
            all_channels(Path::new(&whole)),
        );
        assert_eq!(
            merged_channels,
            all_channels(Path::new(&from_slices)),
            "{sampler}: the merged image depends on how the parts were split into passes"
        );
        let in_one_process = file(&format!("{sampler}-parts.exr"));
        render(
            sampler,
            &in_one_process,
            &["--parts", "3", "--pass-spp", "1"],
        );
        assert_eq!(
            merged_channels,
            all_channels(Path::new(&in_one_process)),
            "{sampler}: the merged parts are not the render with the same slice boundaries"
        );
        assert_eq!(header(Path::new(&from_parts), "spp"), SPP);
        assert_eq!(header(Path::new(&from_parts), "command"), "render");
        // Within rounding: a sampler whose sample i depended on where its
        // range started would differ by the Monte Carlo noise, far more.
        for ((name, merged), (whole_name, whole)) in merged_channels.iter().zip(&whole_channels) {
            assert_eq!(name, whole_name);
            for (&a, &b) in merged.iter().zip(whole) {
                let (a, b) = (f32::from_bits(a), f32::from_bits(b));
                assert!(
                    (a - b).abs() <= 1e-5 * a.abs().max(b.abs()) + 1e-12,
                    "{sampler}: channel {name} of the merged parts is {a}, of one render {b}"
                );
            }
        }
        let single = file(&format!("{sampler}-single.exr"));
        render(sampler, &single, &["--part", "0/1"]);
        let from_single = file(&format!("{sampler}-from-single.exr"));
        merged(&[&single], &from_single);
        assert_eq!(
            all_channels(Path::new(&from_single)),
            whole_channels,
            "{sampler}: the one part of all samples, merged, is not the render"
        );
    }
}

/// Parts that do not make one render are refused, naming the files and
/// what is wrong with them.
#[test]
fn merge_refuses_what_is_not_one_render_by_name() {
    let tmp = scratch("merge-errors");
    let file = |name: &str| path_in(tmp.path(), name);
    let out = file("out.exr");
    let (a, b, c) = (file("a.exr"), file("b.exr"), file("c.exr"));
    render("independent", &a, &["--samples", "0..2"]);
    render("independent", &b, &["--samples", "2..4"]);
    render("independent", &c, &["--samples", "4..6"]);

    let err = merge_error(&[&a, &c], &out);
    assert!(
        err.contains("samples 2..4 of 6 are in no part")
            && err.contains("a.exr")
            && err.contains("c.exr"),
        "{err}"
    );
    let err = merge_error(&[&a, &b], &out);
    assert!(err.contains("samples 4..6 of 6 are in no part"), "{err}");
    let err = merge_error(&[&b, &c], &out);
    assert!(err.contains("samples 0..2 of 6 are in no part"), "{err}");

    let wide = file("wide.exr");
    render("independent", &wide, &["--samples", "1..4"]);
    let err = merge_error(&[&a, &wide, &c], &out);
    assert!(
        err.contains("a.exr")
            && err.contains("wide.exr")
            && err.contains("samples 1..2 are in both"),
        "{err}"
    );

    let seeded = file("seeded.exr");
    render(
        "independent",
        &seeded,
        &["--samples", "2..4", "--seed", "7"],
    );
    let err = merge_error(&[&a, &seeded, &c], &out);
    assert!(
        err.contains("seeded.exr") && err.contains("a.exr") && err.contains("seed 7, not 0"),
        "{err}"
    );

    let other_scene = file("other-scene.exr");
    render(
        "independent",
        &other_scene,
        &["--samples", "2..4", "--set", "integrator.max_depth=2"],
    );
    let err = merge_error(&[&a, &other_scene, &c], &out);
    assert!(
        err.contains("other-scene.exr") && err.contains("a different scene"),
        "{err}"
    );

    let more_spp = file("more-spp.exr");
    render_spp("independent", &more_spp, "8", &["--samples", "2..4"]);
    let err = merge_error(&[&a, &more_spp, &c], &out);
    assert!(
        err.contains("more-spp.exr") && err.contains("8 spp in all, not 6"),
        "{err}"
    );

    let plain = file("plain.exr");
    render("independent", &plain, &[]);
    let err = merge_error(&[&a, &plain], &out);
    assert!(
        err.contains("plain.exr") && err.contains("is not a lumis partial image"),
        "{err}"
    );
    let text = file("text.exr");
    std::fs::write(&text, "not an image").unwrap();
    let err = merge_error(&[&a, &text], &out);
    assert!(err.contains("text.exr"), "{err}");

    let bytes = std::fs::read(&b).unwrap();
    let truncated = file("truncated.exr");
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    let err = merge_error(&[&a, &truncated, &c], &out);
    assert!(err.contains("truncated.exr"), "{err}");
    // One bit of one sum, the file otherwise as written: still a
    // readable EXR, refused by its checksum.
    let damaged = file("damaged.exr");
    let attributes = lumis_image::read_exr_metadata(Path::new(&b)).unwrap();
    let (_, mut channels) = lumis_image::read_exr_uint_channels(Path::new(&b)).unwrap();
    let sum = channels
        .iter_mut()
        .find(|(n, _)| n == "partial.sum.G.lo")
        .unwrap();
    sum.1[17] ^= 1;
    let uints: Vec<lumis_image::ExrUintChannel> = channels
        .iter()
        .map(|(name, values)| lumis_image::ExrUintChannel { name, values })
        .collect();
    let colour = lumis_image::read_exr(Path::new(&b)).unwrap();
    lumis_image::stage_exr_with_channels(Path::new(&damaged), &colour, &[], &uints, &attributes)
        .unwrap()
        .commit()
        .unwrap();
    let err = merge_error(&[&a, &damaged, &c], &out);
    assert!(
        err.contains("damaged.exr") && err.contains("checksum"),
        "{err}"
    );
    let nowhere = path_in(tmp.path(), "missing/merged.exr");
    let err = merge_error(&[&a, &b, &c], &nowhere);
    assert!(err.contains("does not exist"), "{err}");
    assert!(
        !Path::new(&out).exists(),
        "a refused merge wrote its output"
    );
}

/// Adaptive sampling cannot be split; bad slices say what was expected;
/// a part cannot be resumed.
#[test]
fn render_refuses_slices_it_cannot_render() {
    let tmp = scratch("merge-refusals");
    let out = path_in(tmp.path(), "part.exr");
    let refusal = |extra: &[&str]| {
        let mut args = small_render(&out, SPP);
        args.extend(extra);
        let result = lumis(&args);
        assert!(!result.status.success(), "{extra:?} rendered");
        String::from_utf8_lossy(&result.stderr).into_owned()
    };
    let err = refusal(&[
        "--part",
        "0/2",
        "--set",
        "adaptive={min_spp = 2, threshold = 0.1}",
    ]);
    assert!(err.contains("[adaptive]"), "{err}");
    assert!(refusal(&["--part", "2/2"]).contains("expected K/N"));
    assert!(refusal(&["--part", "0/7"]).contains("at most 6 parts"));
    assert!(refusal(&["--samples", "4..7"]).contains("expected A..B"));
    assert!(refusal(&["--part", "0/2", "--resume"]).contains("--resume"));
    assert!(refusal(&["--part", "0/2", "--samples", "0..3"]).contains("--samples"));
    assert!(refusal(&["--parts", "7"]).contains("at most 6 parts"));
    assert!(refusal(&["--parts", "2", "--part", "0/2"]).contains("--part"));
    assert!(!Path::new(&out).exists());
}

/// A `[denoiser]` of the glossy plates, and another.
const BALANCED: [&str; 4] = [
    "--set",
    "denoiser.type=\"oidn\"",
    "--set",
    "denoiser.quality=\"balanced\"",
];
const FAST: [&str; 4] = [
    "--set",
    "denoiser.type=\"oidn\"",
    "--set",
    "denoiser.quality=\"fast\"",
];

/// With a `[denoiser]`, the merge denoises the merged film as `lumis
/// render --parts N` denoises its own: the same image, bit for bit, which
/// records the same denoiser; parts of other denoisers are refused.
#[test]
fn merge_denoises_as_the_render_in_parts_does() {
    let tmp = scratch("merge-denoised");
    let file = |name: &str| path_in(tmp.path(), name);
    let (part_0, part_1) = (file("part-0.exr"), file("part-1.exr"));
    render(
        "sobol",
        &part_0,
        &[&["--part", "0/2"][..], &BALANCED].concat(),
    );
    render(
        "sobol",
        &part_1,
        &[&["--part", "1/2"][..], &BALANCED].concat(),
    );
    // A part is not denoised: the merged image is the render.
    assert!(!tmp.path().join("part-0.denoised.exr").exists());
    let merged_exr = file("merged.exr");
    merged(&[&part_1, &part_0], &merged_exr);
    let in_one_process = file("parts.exr");
    render(
        "sobol",
        &in_one_process,
        &[&["--parts", "2"][..], &BALANCED].concat(),
    );
    assert_eq!(
        all_channels(Path::new(&merged_exr)),
        all_channels(Path::new(&in_one_process)),
        "the merged raw image is not the render in parts"
    );
    let (merged_denoised, render_denoised) = (
        tmp.path().join("merged.denoised.exr"),
        tmp.path().join("parts.denoised.exr"),
    );
    assert!(tmp.path().join("merged.denoised.png").is_file());
    assert_eq!(
        exr_pixels(&merged_denoised),
        exr_pixels(&render_denoised),
        "the merge's denoised image is not the render's"
    );
    let recorded = "{ quality = \"balanced\", type = \"oidn\" }";
    for (path, key) in [
        (Path::new(&part_0), "denoiser"),
        (Path::new(&merged_exr), "denoiser"),
        (merged_denoised.as_path(), "denoiser"),
        (merged_denoised.as_path(), "denoised_by"),
        (render_denoised.as_path(), "denoised_by"),
    ] {
        assert_eq!(header(path, key), recorded, "{} {key}", path.display());
    }
    assert_eq!(header(&merged_denoised, "spp"), SPP);

    let fast = file("fast-1.exr");
    render("sobol", &fast, &[&["--part", "1/2"][..], &FAST].concat());
    let err = merge_error(&[&part_0, &fast], &file("refused.exr"));
    assert!(
        err.contains("fast-1.exr")
            && err.contains(
                "the [denoiser] { quality = \"fast\", type = \"oidn\" }, \
                 not the [denoiser] { quality = \"balanced\", type = \"oidn\" }"
            ),
        "{err}"
    );
    // A part whose denoiser this lumis does not have: refused before the
    // merge writes anything.
    let whole_part = file("whole-part.exr");
    render(
        "sobol",
        &whole_part,
        &[&["--part", "0/1"][..], &BALANCED].concat(),
    );
    let foreign = file("foreign.exr");
    let mut attributes = lumis_image::read_exr_metadata(Path::new(&whole_part)).unwrap();
    for (name, value) in &mut attributes {
        if name == "lumis.denoiser" {
            *value = "{ type = \"nlm\" }".into();
        }
    }
    let (_, channels) = lumis_image::read_exr_uint_channels(Path::new(&whole_part)).unwrap();
    let uints: Vec<lumis_image::ExrUintChannel> = channels
        .iter()
        .map(|(name, values)| lumis_image::ExrUintChannel { name, values })
        .collect();
    let colour = lumis_image::read_exr(Path::new(&whole_part)).unwrap();
    lumis_image::stage_exr_with_channels(Path::new(&foreign), &colour, &[], &uints, &attributes)
        .unwrap()
        .commit()
        .unwrap();
    let err = merge_error(&[&foreign], &file("refused.exr"));
    assert!(
        err.contains("foreign.exr' header lumis.denoiser = { type = \"nlm\" }: unknown denoiser type \"nlm\"")
            && err.contains("available: oidn"),
        "{err}"
    );
    assert!(!tmp.path().join("refused.exr").exists());
    let plain = file("plain-1.exr");
    render("sobol", &plain, &["--part", "1/2"]);
    let err = merge_error(&[&part_0, &plain], &file("refused.exr"));
    assert!(
        err.contains("plain-1.exr") && err.contains("no [denoiser], not the [denoiser] { quality"),
        "{err}"
    );
}
