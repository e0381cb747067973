//! Runs the Python module's pytest suite (`tests/python/`) against this
//! build: `cargo build` makes the module and the `lumis` command line it
//! is compared with, the module is put in a scratch directory as
//! `lumis.abi3.so`, and pytest, NumPy, pandas (for a study's DataFrame)
//! and tqdm (for the progress bar) are installed from PyPI under the
//! target directory where the interpreter lacks them.
//!
//! Where there is no Python 3 the test says why on stderr and returns
//! (`cargo test -p lumis-py -- --nocapture` shows it); a failure to
//! install them fails it.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The interpreter: `LUMIS_PYTHON`, else `python3` on the path.
fn python() -> Option<String> {
    let python = std::env::var("LUMIS_PYTHON").unwrap_or_else(|_| "python3".into());
    let version = Command::new(&python).arg("--version").output().ok()?;
    version.status.success().then_some(python)
}

/// Whether `python` imports every module of `modules` with `PYTHONPATH`
/// `path`.
fn imports(python: &str, path: &str, modules: &[&str]) -> bool {
    Command::new(python)
        .args(["-c", &format!("import {}", modules.join(", "))])
        .env("PYTHONPATH", path)
        .output()
        .is_ok_and(|o| o.status.success())
}

/// `cargo build -p lumis-py -p lumis-cli`: the module and the binary.
fn build() -> (PathBuf, PathBuf) {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .args(["build", "-p", "lumis-py", "-p", "lumis-cli"])
        .args(["--message-format=json"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cargo runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8(out.stdout).unwrap();
    let built = |suffix: &str| {
        stdout
            .split('"')
            .find(|s| s.ends_with(suffix) && Path::new(s).is_file())
            .map(PathBuf::from)
            .unwrap_or_else(|| panic!("cargo reported no {suffix}"))
    };
    (built("/liblumis_py.so"), built("/lumis"))
}

#[test]
fn the_pytest_suite_passes() {
    let Some(python) = python() else {
        eprintln!("skipped: no Python 3 (python3, or LUMIS_PYTHON) to run the pytest suite");
        return;
    };
    let (module, lumis) = build();
    let scratch = tempfile::tempdir().unwrap();
    std::fs::copy(&module, scratch.path().join("lumis.abi3.so")).unwrap();
    // The test dependencies, installed once per target directory.
    let deps = Path::new(env!("CARGO_TARGET_TMPDIR")).join("python-test-deps");
    let path = format!("{}:{}", scratch.path().display(), deps.display());
    let needed = ["numpy", "pytest", "pandas", "tqdm"];
    if !imports(&python, &path, &needed) {
        let install = Command::new(&python)
            .args([
                "-m",
                "pip",
                "install",
                "--quiet",
                "--disable-pip-version-check",
            ])
            .args(["--target".as_ref(), deps.as_os_str()])
            .args(needed)
            .output()
            .expect("python runs");
        assert!(
            install.status.success(),
            "pip could not install {needed:?}: {}",
            String::from_utf8_lossy(&install.stderr)
        );
    }
    let suite = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python");
    let run = Command::new(&python)
        .args(["-m", "pytest", "-q", "-p", "no:cacheprovider"])
        .arg(&suite)
        .current_dir(scratch.path())
        .env("PYTHONPATH", &path)
        .env("LUMIS_BIN", &lumis)
        .output()
        .expect("python runs");
    let report = format!(
        "{}{}",
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr)
    );
    eprintln!("{report}");
    assert!(run.status.success(), "the pytest suite failed:\n{report}");
}
