//! `lumis reference` never silently replaces a more converged or a
//! different reference, keeps its resume state in the EXR header, and
//! stops on Ctrl-C with a nonzero status.

mod common;

use std::path::Path;

use common::*;

/// `lumis reference` of `scene` to `out` with extra arguments.
fn reference(scene: &Path, out: &str, spp: &str, extra: &[&str]) -> std::process::Output {
    let scene = scene.display().to_string();
    let mut args = vec![
        "reference",
        &scene,
        "--set",
        "film.resolution=[16, 16]",
        "--threads",
        "2",
        "--spp",
        spp,
        "--pass-spp",
        "4",
        "-o",
        out,
    ];
    args.extend(extra);
    lumis(&args)
}

fn stderr_of(output: &std::process::Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

#[test]
fn a_rerun_refuses_to_replace_a_more_converged_or_different_reference() {
    let tmp = scratch("reference");
    // A copy of a scene that names no files, to edit.
    let text = std::fs::read_to_string(scene("glossy-plates.toml")).unwrap();
    let scene_file = tmp.path().join("plates.toml");
    std::fs::write(&scene_file, &text).unwrap();
    let out = path_in(tmp.path(), "ref.exr");
    let exr = tmp.path().join("ref.exr");

    let first = reference(&scene_file, &out, "8", &[]);
    assert!(first.status.success(), "{}", stderr_of(&first));
    assert_eq!(header(&exr, "command"), "reference");
    assert_eq!(header(&exr, "spp"), "8");
    assert_eq!(header(&exr, "passes"), "2");
    // The header is the only metadata: no JSON beside it.
    assert_eq!(files_in(tmp.path()), ["plates.toml", "ref.exr"]);
    let eight = std::fs::read(&exr).unwrap();

    // Fewer spp: refused, the reference kept.
    let fewer = reference(&scene_file, &out, "4", &[]);
    let stderr = stderr_of(&fewer);
    assert!(!fewer.status.success(), "{stderr}");
    assert!(
        stderr.contains("refusing to replace") && stderr.contains("has 8 spp, more than the 4"),
        "{stderr}"
    );
    assert_eq!(std::fs::read(&exr).unwrap(), eight);

    // Another scene: refused.
    let other = reference(
        &scene_file,
        &out,
        "12",
        &["--set", "integrator.max_depth=2"],
    );
    let stderr = stderr_of(&other);
    assert!(
        !other.status.success() && stderr.contains("different scene"),
        "{stderr}"
    );
    assert_eq!(std::fs::read(&exr).unwrap(), eight);

    // An edited comment is the same scene: resumed, not restarted.
    std::fs::write(&scene_file, format!("# edited\n{text}")).unwrap();
    let more = reference(&scene_file, &out, "12", &[]);
    let stderr = stderr_of(&more);
    assert!(
        more.status.success() && stderr.contains("resuming") && stderr.contains("at 8 of 12"),
        "{stderr}"
    );
    assert_eq!(header(&exr, "spp"), "12");
    assert_eq!(header(&exr, "passes"), "3");

    // A render's image is not a reference to continue.
    let render_out = path_in(tmp.path(), "render.exr");
    let render = lumis(&[
        "render",
        &scene_file.display().to_string(),
        "--set",
        "film.resolution=[16, 16]",
        "--spp",
        "1",
        "-q",
        "-o",
        &render_out,
    ]);
    assert!(render.status.success());
    let stderr = stderr_of(&reference(&scene_file, &render_out, "8", &[]));
    assert!(stderr.contains("written by `lumis render`"), "{stderr}");

    // --force replaces.
    let forced = reference(&scene_file, &out, "4", &["--force"]);
    assert!(forced.status.success(), "{}", stderr_of(&forced));
    assert_eq!(header(&exr, "spp"), "4");
}

/// Ctrl-C abandons the pass in flight and exits 130; the EXR holds the
/// passes done and a rerun resumes from them.
#[test]
fn an_interrupted_reference_exits_nonzero_and_resumes() {
    let tmp = scratch("reference-int");
    let out = path_in(tmp.path(), "ref.exr");
    let exr = tmp.path().join("ref.exr");
    let mut child = spawn(&[
        "reference",
        &scene("glossy-plates.toml"),
        "--set",
        "film.resolution=[16, 16]",
        "--threads",
        "2",
        "--spp",
        "100000000",
        "--pass-spp",
        "2",
        "-o",
        &out,
    ]);
    wait_for(&mut child, &exr);
    signal(child.id(), "INT");
    let result = child.wait_with_output().unwrap();
    let stderr = stderr_of(&result);
    assert_eq!(result.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("interrupted at"), "{stderr}");
    let spp: u32 = header(&exr, "spp").parse().unwrap();
    let passes: u32 = header(&exr, "passes").parse().unwrap();
    assert!(spp > 0 && spp == 2 * passes, "{spp} spp in {passes} passes");
    let more = (spp + 2).to_string();
    let resumed = lumis(&[
        "reference",
        &scene("glossy-plates.toml"),
        "--set",
        "film.resolution=[16, 16]",
        "--spp",
        &more,
        "--pass-spp",
        "2",
        "-o",
        &out,
    ]);
    assert!(resumed.status.success(), "{}", stderr_of(&resumed));
    assert!(stderr_of(&resumed).contains(&format!("at {spp} of {more}")));
    assert_eq!(header(&exr, "passes"), (passes + 1).to_string());
}

/// SIGKILLed at random moments and rerun, a reference reaches the image
/// and the header of an uninterrupted one, bit for bit: its resume state is
/// the EXR it renames into place whole, so no kill can leave a pass counted
/// twice or an image and a count that disagree.
#[test]
fn a_reference_killed_at_random_moments_resumes_bit_for_bit() {
    let tmp = scratch("reference-kill");
    let plates = scene("glossy-plates.toml");
    let args = |out: &str| {
        [
            "reference",
            &plates,
            "--set",
            "film.resolution=[48, 48]",
            "--threads",
            "2",
            "--spp",
            "240",
            "--pass-spp",
            "2",
            "-o",
            out,
        ]
        .map(str::to_string)
    };
    let run = |out: &str| {
        let args = args(out);
        lumis(&args.iter().map(String::as_str).collect::<Vec<_>>())
    };
    let whole = path_in(tmp.path(), "whole.exr");
    let start = std::time::Instant::now();
    assert!(run(&whole).status.success());
    let duration_ms = start.elapsed().as_millis() as u64;

    let out = path_in(tmp.path(), "ref.exr");
    let exr = tmp.path().join("ref.exr");
    let argv = args(&out);
    let argv: Vec<&str> = argv.iter().map(String::as_str).collect();
    let killed = kill_after_progress(&argv, &exr, 3, duration_ms);
    assert!(killed > 0, "every run finished before its kill");
    let last = run(&out);
    assert!(last.status.success(), "{}", stderr_of(&last));
    let whole = tmp.path().join("whole.exr");
    assert_eq!(
        exr_pixels(&exr),
        exr_pixels(&whole),
        "resumed reference differs"
    );
    for key in ["spp", "passes", "seed", "scene_hash"] {
        assert_eq!(header(&exr, key), header(&whole, key), "{key}");
    }
}
