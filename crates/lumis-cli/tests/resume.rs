//! `lumis render --resume` continues a killed render to the image an
//! uninterrupted render makes, bit for bit.

mod common;

use common::*;

const SPP: &str = "96";

/// Every output beside the colour: their sums are state that must resume
/// exactly too.
const ALL_AOVS: &str = "film.aovs=[\"albedo\", \"normal\", \"depth\", \"variance\", \"spp\"]";

/// The bits of every channel of an EXR (colour and outputs), by name.
fn all_channels(path: impl AsRef<std::path::Path>) -> Vec<(String, Vec<u32>)> {
    lumis_image::read_exr_channels(path.as_ref())
        .unwrap()
        .into_iter()
        .map(|(name, values)| (name, values.into_iter().map(f32::to_bits).collect()))
        .collect()
}

/// Starts the render (resuming from the second start on), SIGKILLs it at
/// each moment, then lets it finish, and compares with an uninterrupted
/// render, colour and every output.
fn killed_and_resumed_equals_uninterrupted(name: &str, kills: usize, sets: &[&str]) {
    let tmp = scratch(name);
    let whole = path_in(tmp.path(), "whole.exr");
    let mut uninterrupted = small_render(&whole, SPP);
    uninterrupted.extend(["--set", ALL_AOVS]);
    for set in sets {
        uninterrupted.extend(["--set", set]);
    }
    let result = lumis(&uninterrupted);
    assert!(result.status.success(), "{result:?}");

    let out = path_in(tmp.path(), "plates.exr");
    let mut args = small_render(&out, SPP);
    args.extend(["--set", ALL_AOVS]);
    for set in sets {
        args.extend(["--set", set]);
    }
    args.extend(["--checkpoint", "--pass-spp", "1", "--resume"]);
    // One uninterrupted run with the same flags: the kill moments spread
    // over its duration (which only chooses them; nothing is asserted on it).
    let start = std::time::Instant::now();
    let result = lumis(&args);
    let duration_ms = start.elapsed().as_millis() as u64;
    assert!(result.status.success(), "{result:?}");
    let exr = tmp.path().join("plates.exr");
    assert_eq!(
        exr_pixels(&exr),
        exr_pixels(&whole),
        "checkpoints changed the image"
    );
    for name in ["plates.exr", "plates.png"] {
        std::fs::remove_file(tmp.path().join(name)).unwrap();
    }
    let checkpoint = tmp.path().join("plates.checkpoint");
    let killed_mid_render = kill_after_progress(&args, &checkpoint, kills, duration_ms / 2);
    assert!(killed_mid_render > 0, "every run finished before its kill");
    let resumes = checkpoint.exists();
    let result = lumis(&args);
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(result.status.success(), "{stderr}");
    assert!(!resumes || stderr.contains("resuming"), "{stderr}");
    assert_eq!(header(&exr, "spp"), SPP);
    assert_eq!(
        exr_pixels(&exr),
        exr_pixels(&whole),
        "resumed image differs"
    );
    assert_eq!(
        all_channels(&exr),
        all_channels(&whole),
        "resumed outputs differ"
    );
    assert_eq!(
        files_in(tmp.path()),
        ["plates.exr", "plates.png", "whole.exr", "whole.png"],
        "checkpoint, lock and temporary files are gone"
    );
}

#[test]
fn a_render_killed_at_random_moments_resumes_bit_for_bit() {
    killed_and_resumed_equals_uninterrupted("kill", 3, &[]);
}

/// Adaptive sampling's per-pixel counts, half-buffers and stopped pixels
/// resume exactly too.
#[test]
fn an_adaptive_render_killed_at_random_moments_resumes_bit_for_bit() {
    killed_and_resumed_equals_uninterrupted(
        "kill-adaptive",
        2,
        &["adaptive={ min_spp = 8, threshold = 0.05 }"],
    );
}

/// The same with many more kills (a few minutes):
/// `cargo test -p lumis-cli --test resume -- --ignored`.
#[test]
#[ignore]
fn a_render_killed_many_times_resumes_bit_for_bit() {
    killed_and_resumed_equals_uninterrupted("kill-many", 40, &[]);
}

/// A checkpoint is continued only with `--resume`, and only by the render
/// it belongs to.
#[test]
fn a_checkpoint_is_resumed_only_on_request_and_by_its_own_scene() {
    let tmp = scratch("resume-refuses");
    let out = path_in(tmp.path(), "plates.exr");
    let mut args = small_render(&out, "1000000");
    args.extend(["--checkpoint", "--pass-spp", "2"]);
    let mut child = spawn(&args);
    wait_for(&mut child, &tmp.path().join("plates.checkpoint"));
    signal(child.id(), "KILL");
    child.wait().unwrap();

    let plain = lumis(&small_render(&out, "8"));
    let stderr = String::from_utf8(plain.stderr).unwrap();
    assert!(
        !plain.status.success()
            && stderr.contains("plates.checkpoint")
            && stderr.contains("--resume continues it"),
        "{stderr}"
    );

    let mut other = small_render(&out, "8");
    other.extend(["--resume", "--set", "integrator.max_depth=2"]);
    let result = lumis(&other);
    let stderr = String::from_utf8(result.stderr).unwrap();
    assert!(
        !result.status.success() && stderr.contains("different scene"),
        "{stderr}"
    );

    let mut reseeded = small_render(&out, "8");
    reseeded.extend(["--resume", "--seed", "5"]);
    let stderr = String::from_utf8(lumis(&reseeded).stderr).unwrap();
    assert!(stderr.contains("seed 0, not 5"), "{stderr}");

    let mut fewer = small_render(&out, "1");
    fewer.push("--resume");
    let stderr = String::from_utf8(lumis(&fewer).stderr).unwrap();
    assert!(
        stderr.contains("a render of 1000000 spp, not 1"),
        "{stderr}"
    );

    let mut damaged = std::fs::read(tmp.path().join("plates.checkpoint")).unwrap();
    damaged[60] ^= 0xff;
    std::fs::write(tmp.path().join("plates.checkpoint"), damaged).unwrap();
    let mut resume = small_render(&out, "1000000");
    resume.push("--resume");
    let stderr = String::from_utf8(lumis(&resume).stderr).unwrap();
    assert!(
        stderr.contains("plates.checkpoint: not a lumis checkpoint")
            && stderr.contains("checksum")
            && stderr.contains("remove it to start over"),
        "{stderr}"
    );
}
