//! Ctrl-C and SIGTERM stop a render and keep its work; a second one quits
//! at once.

mod common;

use common::*;

/// The first SIGINT, SIGTERM or SIGHUP abandons the pass in flight, writes the
/// passes done with their true sample count (`NAME.partial.exr`) and exits
/// 130; the image is the one a render of that many samples makes, bit for
/// bit.
#[test]
fn an_interrupt_writes_the_passes_done_and_exits_130() {
    for sig in ["INT", "TERM", "HUP"] {
        let tmp = scratch(&format!("sig{sig}"));
        let out = path_in(tmp.path(), "plates.exr");
        let mut args = small_render(&out, "1000000");
        args.extend(["--checkpoint", "--pass-spp", "2"]);
        let mut child = spawn(&args);
        wait_for(&mut child, &tmp.path().join("plates.checkpoint"));
        signal(child.id(), sig);
        let result = child.wait_with_output().unwrap();
        let stderr = String::from_utf8(result.stderr).unwrap();
        assert_eq!(result.status.code(), Some(130), "SIG{sig}: {stderr}");
        assert!(stderr.contains("interrupted at"), "{stderr}");
        // Beside the output, which an unfinished render never replaces.
        let exr = tmp.path().join("plates.partial.exr");
        let spp = header(&exr, "spp");
        let n: u32 = spp.parse().unwrap();
        assert!(n > 0 && n < 1_000_000 && n.is_multiple_of(2), "{n} spp");
        let whole = path_in(tmp.path(), "whole.exr");
        assert!(lumis(&small_render(&whole, &spp)).status.success());
        assert_eq!(exr_pixels(&exr), exr_pixels(&whole), "SIG{sig}");
        // The lock is released; the checkpoint stays for --resume.
        assert_eq!(
            files_in(tmp.path()),
            [
                "plates.checkpoint",
                "plates.partial.exr",
                "plates.partial.png",
                "whole.exr",
                "whole.png"
            ]
        );
    }
}

/// A second Ctrl-C while the first is saving a large image exits at once
/// (with the status of an interrupted program), leaving the lock behind
/// for the next run to take over.
#[test]
fn a_second_interrupt_quits_at_once() {
    let tmp = scratch("sigint-twice");
    let out = path_in(tmp.path(), "big.exr");
    let mut child = spawn(&[
        "render",
        &scene("glossy-plates.toml"),
        "--set",
        "film.resolution=[1536, 1536]",
        "--set",
        "integrator.max_depth=1",
        "--threads",
        "2",
        "--spp",
        "1000000",
        "--pass-spp",
        "1",
        "--checkpoint",
        "-o",
        &out,
        "-q",
    ]);
    wait_for(&mut child, &tmp.path().join("big.checkpoint"));
    // The first stops the render, which then saves a 1536x1536 film and
    // image (tens of megabytes, synced to disk); the second comes once the
    // first has been handled (its message is on stderr), while it saves.
    signal(child.id(), "INT");
    let mut stderr = std::io::BufReader::new(child.stderr.take().unwrap());
    let mut text = String::new();
    while !text.contains("interrupted:") {
        let read = std::io::BufRead::read_line(&mut stderr, &mut text).unwrap();
        assert!(read > 0, "lumis ended without a message: {text}");
    }
    signal(child.id(), "INT");
    std::io::Read::read_to_string(&mut stderr, &mut text).unwrap();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "{text}");
    assert!(text.contains("interrupted again: quitting"), "{text}");
    assert!(tmp.path().join("big.exr.lock").exists());
}
