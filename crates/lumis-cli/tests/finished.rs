//! A finished image is never replaced by a less converged one unless the
//! user says so: an unfinished render writes beside it
//! (`NAME.partial.exr`), a render with fewer samples of the same scene is
//! refused without `--force`, and `--resume` of a finished render does
//! nothing.

mod common;

use common::*;

/// A render under way, checkpointing and then killed, leaves the finished
/// image it would replace as it was; its own image so far is beside it.
#[test]
fn an_unfinished_render_writes_beside_the_finished_image() {
    let tmp = scratch("finished-kept");
    let out = path_in(tmp.path(), "plates.exr");
    assert!(lumis(&small_render(&out, "8")).status.success());
    let exr = tmp.path().join("plates.exr");
    let finished = std::fs::read(&exr).unwrap();

    let mut args = small_render(&out, "1000000");
    args.extend(["--checkpoint", "--pass-spp", "2"]);
    let mut child = spawn(&args);
    wait_for(&mut child, &tmp.path().join("plates.partial.exr"));
    signal(child.id(), "KILL");
    child.wait().unwrap();
    assert_eq!(
        std::fs::read(&exr).unwrap(),
        finished,
        "the finished image was replaced"
    );
    let partial = tmp.path().join("plates.partial.exr");
    assert!(header(&partial, "spp").parse::<u32>().unwrap() < 1_000_000);

    // Resumed to its end, the render replaces the image and clears up.
    let mut finish = small_render(&out, "12");
    finish.extend(["--checkpoint", "--pass-spp", "2"]);
    std::fs::remove_file(tmp.path().join("plates.checkpoint")).unwrap();
    let result = lumis(&finish);
    assert!(result.status.success(), "{result:?}");
    assert_eq!(header(&exr, "spp"), "12");
    assert_eq!(files_in(tmp.path()), ["plates.exr", "plates.png"]);
}

/// An image of the same scene with more samples (a render's or a
/// reference's) is refused without `--force`.
#[test]
fn a_more_converged_image_is_kept_without_force() {
    let tmp = scratch("finished-force");
    let out = path_in(tmp.path(), "plates.exr");
    assert!(lumis(&small_render(&out, "16")).status.success());
    let exr = tmp.path().join("plates.exr");
    let finished = std::fs::read(&exr).unwrap();
    let fewer = lumis(&small_render(&out, "4"));
    let stderr = String::from_utf8_lossy(&fewer.stderr);
    assert!(!fewer.status.success(), "{stderr}");
    assert!(
        stderr.contains("refusing to replace it")
            && stderr.contains("16 spp of this scene")
            && stderr.contains("--force"),
        "{stderr}"
    );
    assert_eq!(std::fs::read(&exr).unwrap(), finished);

    // Another scene's image, or one with fewer samples, is replaced.
    let mut other = small_render(&out, "4");
    other.extend(["--set", "integrator.max_depth=2"]);
    assert!(lumis(&other).status.success());
    assert_eq!(header(&exr, "spp"), "4");
    assert!(lumis(&small_render(&out, "8")).status.success());
    let mut forced = small_render(&out, "2");
    forced.push("--force");
    assert!(lumis(&forced).status.success());
    assert_eq!(header(&exr, "spp"), "2");

    // A reference of the scene is kept too.
    let reference = path_in(tmp.path(), "ref.exr");
    let made = lumis(&[
        "reference",
        &scene("glossy-plates.toml"),
        "--set",
        "film.resolution=[32, 32]",
        "--spp",
        "8",
        "--pass-spp",
        "8",
        "--threads",
        "2",
        "-o",
        &reference,
    ]);
    assert!(made.status.success(), "{made:?}");
    let over = lumis(&small_render(&reference, "2"));
    let stderr = String::from_utf8_lossy(&over.stderr);
    assert!(
        !over.status.success() && stderr.contains("`lumis reference`"),
        "{stderr}"
    );
}

/// `--resume` where the render finished (no checkpoint beside it) says so
/// and renders nothing.
#[test]
fn resuming_a_finished_render_does_nothing() {
    let tmp = scratch("finished-resume");
    let out = path_in(tmp.path(), "plates.exr");
    assert!(lumis(&small_render(&out, "8")).status.success());
    let exr = tmp.path().join("plates.exr");
    let finished = std::fs::read(&exr).unwrap();
    let mut resume = small_render(&out, "8");
    resume.push("--resume");
    let result = lumis(&resume);
    let stdout = String::from_utf8_lossy(&result.stdout);
    assert!(result.status.success(), "{result:?}");
    assert!(
        stdout.contains("is finished (8 spp") && stdout.contains("nothing to resume"),
        "{stdout}"
    );
    assert_eq!(std::fs::read(&exr).unwrap(), finished);
    // With more samples asked for, it renders them from the start.
    let mut more = small_render(&out, "9");
    more.push("--resume");
    let result = lumis(&more);
    assert!(result.status.success(), "{result:?}");
    assert_eq!(header(&exr, "spp"), "9");
}
