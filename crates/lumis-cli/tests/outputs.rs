//! A render's files stay consistent: metadata in the EXR header, the EXR
//! written last, no temporary files left by killed runs, one writer at a
//! time.

mod common;

use common::*;

#[test]
fn the_exr_header_says_what_the_image_is() {
    let tmp = scratch("header");
    let out = path_in(tmp.path(), "plates.exr");
    let result = lumis(&small_render(&out, "3"));
    assert!(result.status.success(), "{result:?}");
    let exr = tmp.path().join("plates.exr");
    assert_eq!(header(&exr, "command"), "render");
    assert_eq!(header(&exr, "spp"), "3");
    assert_eq!(header(&exr, "seed"), "0");
    assert_eq!(header(&exr, "version"), env!("CARGO_PKG_VERSION"));
    assert_eq!(header(&exr, "scene_hash").len(), 16);
    assert!(header(&exr, "passes").parse::<u64>().unwrap() >= 1);
    // No lock, checkpoint or temporary file stays behind.
    assert_eq!(files_in(tmp.path()), ["plates.exr", "plates.png"]);
}

/// The PNG is renamed into place before the EXR: where it cannot be (its
/// path is a directory here, as a full disk would fail it), the EXR is
/// the previous one, and no temporary file is left.
#[test]
fn a_failed_png_leaves_the_previous_exr() {
    let tmp = scratch("png-fails");
    let out = path_in(tmp.path(), "plates.exr");
    assert!(lumis(&small_render(&out, "1")).status.success());
    let exr = tmp.path().join("plates.exr");
    let before = std::fs::read(&exr).unwrap();
    std::fs::remove_file(tmp.path().join("plates.png")).unwrap();
    std::fs::create_dir_all(tmp.path().join("plates.png/in-the-way")).unwrap();
    let result = lumis(&small_render(&out, "2"));
    assert!(!result.status.success(), "{result:?}");
    let stderr = String::from_utf8(result.stderr).unwrap();
    assert!(stderr.contains("plates.png"), "{stderr}");
    assert_eq!(std::fs::read(&exr).unwrap(), before, "the EXR was replaced");
    assert_eq!(files_in(tmp.path()), ["plates.exr", "plates.png"]);
}

#[test]
fn temporary_files_of_dead_processes_are_removed() {
    let tmp = scratch("stale-tmp");
    let dead = dead_pid();
    for name in [
        "plates.exr",
        "plates.png",
        "plates.checkpoint",
        "plates.exr.lock",
    ] {
        std::fs::write(tmp.path().join(format!(".{name}.tmp-{dead}")), b"partial").unwrap();
    }
    let out = path_in(tmp.path(), "plates.exr");
    assert!(lumis(&small_render(&out, "1")).status.success());
    assert_eq!(files_in(tmp.path()), ["plates.exr", "plates.png"]);
}

/// A second render to the same output while the first runs is refused,
/// naming the first; the lock of a killed render is taken over.
#[test]
fn a_second_writer_is_refused_and_a_dead_ones_lock_taken_over() {
    let tmp = scratch("lock");
    let out = path_in(tmp.path(), "plates.exr");
    let lock = tmp.path().join("plates.exr.lock");
    let mut first = spawn(&small_render(&out, "1000000"));
    wait_for(&mut first, &lock);
    let second = lumis(&small_render(&out, "1"));
    assert!(!second.status.success());
    let stderr = String::from_utf8(second.stderr).unwrap();
    assert!(
        stderr.contains(&format!("another lumis (process {})", first.id()))
            && stderr.contains("plates.exr.lock"),
        "{stderr}"
    );
    signal(first.id(), "KILL");
    first.wait().unwrap();
    assert!(lock.exists(), "a killed process cannot remove its lock");
    let third = lumis(&small_render(&out, "1"));
    assert!(third.status.success(), "{third:?}");
    assert!(!lock.exists());
    assert_eq!(header(&tmp.path().join("plates.exr"), "spp"), "1");
}

/// With a `[denoiser]`, the raw render stays the main output, the same
/// image a render without one makes (with the denoiser's albedo and
/// normal guides as layers), and the denoised one sits beside it.
#[test]
fn a_denoiser_writes_its_image_beside_the_raw_one() {
    let tmp = scratch("denoised");
    let plain = path_in(tmp.path(), "plain.exr");
    assert!(lumis(&small_render(&plain, "2")).status.success());
    let out = path_in(tmp.path(), "plates.exr");
    let mut args = small_render(&out, "2");
    args.extend(["--set", "denoiser.type=\"oidn\""]);
    let result = lumis(&args);
    assert!(result.status.success(), "{result:?}");
    assert_eq!(
        files_in(tmp.path()),
        [
            "plain.exr",
            "plain.png",
            "plates.denoised.exr",
            "plates.denoised.png",
            "plates.exr",
            "plates.png"
        ]
    );
    let read = |name: &str| lumis_image::read_exr(&tmp.path().join(name)).unwrap();
    assert_eq!(
        read("plates.exr"),
        read("plain.exr"),
        "the raw image changed"
    );
    // The albedo and normal that guided the denoiser are layers of the raw
    // EXR, though the scene lists no outputs.
    let channels: Vec<String> = lumis_image::read_exr_channels(&tmp.path().join("plates.exr"))
        .unwrap()
        .into_iter()
        .map(|(name, _)| name)
        .collect();
    for layer in [
        "albedo.R", "albedo.G", "albedo.B", "normal.X", "normal.Y", "normal.Z",
    ] {
        assert!(
            channels.iter().any(|c| c == layer),
            "{layer} in {channels:?}"
        );
    }
    let denoised = read("plates.denoised.exr");
    assert_eq!((denoised.width, denoised.height), (32, 32));
    assert!(denoised.pixels.iter().flatten().all(|v| v.is_finite()));
    assert_eq!(header(&tmp.path().join("plates.denoised.exr"), "spp"), "2");
}

/// An output that cannot be replaced (the denoised PNG's path is a
/// directory here) is refused before anything is rendered or written.
#[test]
fn an_output_in_the_way_is_refused_before_rendering() {
    let tmp = scratch("denoise-in-the-way");
    std::fs::create_dir_all(tmp.path().join("plates.denoised.png/in-the-way")).unwrap();
    let out = path_in(tmp.path(), "plates.exr");
    let mut args = small_render(&out, "1");
    args.extend(["--set", "denoiser.type=\"oidn\""]);
    let result = lumis(&args);
    assert!(!result.status.success(), "{result:?}");
    let stderr = String::from_utf8(result.stderr).unwrap();
    assert!(
        stderr.contains("plates.denoised.png' is a directory; an output must be a file"),
        "{stderr}"
    );
    assert_eq!(files_in(tmp.path()), ["plates.denoised.png"]);
}
