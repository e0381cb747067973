//! Only regular files are read or replaced. A FIFO opened for reading
//! blocks until a writer comes, and a device such as `/dev/zero` never
//! ends: every input lumis is named is refused before it is opened, with
//! the message the scene loader gives ("is not a regular file"). An output
//! that is a FIFO, a device or a socket is refused before rendering and
//! left as it was.

mod common;

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use common::{path_in, scratch};

/// How long a refusal may take: a blocked open would take forever.
const DEADLINE: Duration = Duration::from_secs(60);

/// Runs `lumis` with `args`, failing the test if it does not end within
/// [`DEADLINE`] (it is killed then).
fn lumis_in_time(args: &[&str]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_lumis"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("lumis starts");
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > DEADLINE {
            child.kill().unwrap();
            panic!("lumis {args:?} blocked for {DEADLINE:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// Makes a FIFO at `path`; false where `mkfifo` is missing (the test then
/// says so and checks nothing).
fn fifo(path: &Path) -> bool {
    let made = Command::new("mkfifo").arg(path).status();
    let made = made.is_ok_and(|s| s.success());
    if !made {
        eprintln!("skipped: mkfifo could not make {}", path.display());
    }
    made
}

fn assert_not_regular(run: &Output, name: &str) {
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains(name) && stderr.contains("not a regular file"),
        "expected '{name}' refused as not a regular file:\n{stderr}"
    );
}

#[test]
fn fifo_inputs_are_refused_not_waited_on() {
    let tmp = scratch("fifo-inputs");
    let dir = tmp.path();
    let pipe = dir.join("pipe.exr");
    if !fifo(&pipe) {
        return;
    }
    let pipe_arg = pipe.display().to_string();
    let fine = dir.join("fine.exr");
    exr::prelude::write_rgb_file(&fine, 1, 1, |_, _| (0.5f32, 0.5f32, 0.5f32)).unwrap();
    let fine_arg = fine.display().to_string();
    assert_not_regular(&lumis_in_time(&["diff", &pipe_arg, &fine_arg]), "pipe.exr");
    assert_not_regular(
        &lumis_in_time(&["denoise", &pipe_arg, "-o", &path_in(dir, "d.exr")]),
        "pipe.exr",
    );
    assert_not_regular(
        &lumis_in_time(&["merge", &pipe_arg, &pipe_arg, "-o", &path_in(dir, "m.exr")]),
        "pipe.exr",
    );
    assert_not_regular(
        &lumis_in_time(&["plugins", "--load", &pipe_arg]),
        "pipe.exr",
    );

    // An environment map.
    let scene_file = dir.join("sky.toml");
    std::fs::write(
        &scene_file,
        "[film]\nresolution = [4, 4]\n\n[camera]\ntype = \"perspective\"\norigin = [0.0, 0.0, 3.0]\n\
         target = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\nfov = 40.0\n\n[sampler]\n\
         type = \"independent\"\nspp = 1\n\n[integrator]\ntype = \"path\"\n\n\
         [[light]]\ntype = \"envmap\"\nfilename = \"pipe.exr\"\n",
    )
    .unwrap();
    let run = lumis_in_time(&[
        "render",
        &scene_file.display().to_string(),
        "-o",
        &path_in(dir, "sky.exr"),
        "-q",
    ]);
    assert_not_regular(&run, "pipe.exr");
}

/// `--resume` reads the checkpoint beside the output; a FIFO or a device
/// there is refused.
#[test]
fn a_checkpoint_that_is_not_a_file_is_refused() {
    let tmp = scratch("fifo-checkpoint");
    let dir = tmp.path();
    let out = path_in(dir, "plates.exr");
    let args = |out: &str| {
        let mut args = common::small_render(out, "4");
        args.push("--resume");
        args.into_iter().map(str::to_owned).collect::<Vec<_>>()
    };
    if fifo(&dir.join("plates.checkpoint")) {
        let run = lumis_in_time(&args(&out).iter().map(String::as_str).collect::<Vec<_>>());
        assert_not_regular(&run, "plates.checkpoint");
    }
    let zero = path_in(dir, "zero.exr");
    std::os::unix::fs::symlink("/dev/zero", dir.join("zero.checkpoint")).unwrap();
    let run = lumis_in_time(&args(&zero).iter().map(String::as_str).collect::<Vec<_>>());
    assert_not_regular(&run, "zero.checkpoint");
}

/// An output that is a FIFO or a device is refused before rendering, and
/// stays what it was.
#[test]
fn special_outputs_are_never_replaced() {
    let tmp = scratch("special-outputs");
    let dir = tmp.path();
    if fifo(&dir.join("out.png")) {
        let run = lumis_in_time(&common::small_render(&path_in(dir, "out.exr"), "1"));
        assert_not_regular(&run, "out.png");
        assert!(!std::fs::metadata(dir.join("out.png")).unwrap().is_file());
        assert!(!dir.join("out.exr").exists());
    }
    let image = path_in(dir, "image.exr");
    exr::prelude::write_rgb_file(&image, 1, 1, |_, _| (0.5f32, 0.5f32, 0.5f32)).unwrap();
    let run = lumis_in_time(&["diff", &image, &image, "--error-image", "/dev/full"]);
    assert_not_regular(&run, "/dev/full");
    assert!(!std::fs::metadata("/dev/full").unwrap().is_file());
    assert!(!Path::new("/dev/full.lock").exists());
    // A scene path too: the scene loader's own message.
    let run = lumis_in_time(&["render", "/dev/null", "-q"]);
    assert_not_regular(&run, "/dev/null");
}
