//! Finds Intel Open Image Denoise 2 (`libOpenImageDenoise.so.2`), like
//! `crates/lumis-embree/build.rs` finds Embree.
//!
//! Routes, in order:
//! 1. `pkg-config OpenImageDenoise` (a system or package-manager install),
//!    else the library on the linker's default search path;
//! 2. `OIDN_DIR` (an extracted OIDN release: `$OIDN_DIR/lib/libOpenImageDenoise.so`);
//! 3. Intel's official OIDN 2.5.1 runtime shipped inside the `pyoidn`
//!    2.5.1.0 wheel on PyPI (the library, its core, the CPU device module and
//!    TBB), fetched once with `python3 -m pip download` into a cache
//!    directory outside the source tree (`$LUMIS_OIDN_CACHE`, else
//!    `$XDG_CACHE_HOME/lumis/oidn-2.5.1`, else `~/.cache/lumis/oidn-2.5.1`).
//!
//! The library directory is added to the link search path and to the rpath
//! of this crate's own test binaries; it is also exported as
//! `DEP_LUMIS_OIDN_LIBDIR` so that binary crates can put it in their rpath
//! (see `crates/lumis-cli/build.rs`).

use std::env;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

const WHEEL: &str = "pyoidn==2.5.1.0";
const LIBRARY: &str = "libOpenImageDenoise.so";
/// What the wheel's `pyoidn/oidn/lib/` holds that the CPU device needs. The
/// wheel stores copies, not symlinks, so only the sonames are unpacked; the
/// libraries find each other through their `$ORIGIN/../lib` rpath, which is
/// why the cache keeps them in a `lib/` directory.
const WHEEL_FILES: [&str; 4] = [
    "libOpenImageDenoise.so.2",
    "libOpenImageDenoise_core.so.2.5.1",
    "libOpenImageDenoise_device_cpu.so.2.5.1",
    "libtbb.so.12",
];

fn main() {
    println!("cargo:rerun-if-env-changed=OIDN_DIR");
    println!("cargo:rerun-if-env-changed=LUMIS_OIDN_CACHE");
    println!("cargo:rerun-if-env-changed=PKG_CONFIG_PATH");

    let mut tried = Vec::new();
    let lib_dir = match find_system(&mut tried)
        .or_else(|| find_oidn_dir(&mut tried))
        .or_else(|| fetch_wheel(&mut tried))
    {
        Some(dir) => dir,
        None => {
            panic!(
                "\n\nlumis-denoise: Open Image Denoise 2 was not found. Routes tried:\n{}\n\n\
                 Install one of:\n  \
                 - Open Image Denoise 2 with its pkg-config file, or its library on the default search path,\n  \
                 - an OIDN 2 release, then `export OIDN_DIR=/path/to/oidn` (containing lib/{LIBRARY}),\n  \
                 - Python 3 with pip and access to PyPI, so the `{WHEEL}` wheel can be fetched.\n",
                tried
                    .iter()
                    .map(|t| format!("  - {t}"))
                    .collect::<Vec<_>>()
                    .join("\n")
            );
        }
    };
    // `src/ffi.rs` links `-l OpenImageDenoise`; a library on the default
    // search path needs no directory.
    if let Some(dir) = lib_dir {
        let dir = dir.display();
        println!("cargo:rustc-link-search=native={dir}");
        println!("cargo:rustc-link-arg=-Wl,-rpath,{dir}");
        println!("cargo:libdir={dir}");
    }
}

/// `Some(None)`: found on the default search path (no directory to add).
fn find_system(tried: &mut Vec<String>) -> Option<Option<PathBuf>> {
    match pkg_config::Config::new()
        .cargo_metadata(false)
        .atleast_version("2.0")
        .probe("OpenImageDenoise")
    {
        Ok(lib) => return Some(lib.link_paths.first().cloned()),
        Err(e) => {
            let first_line = e.to_string().lines().next().unwrap_or("").to_string();
            tried.push(format!("pkg-config OpenImageDenoise: {first_line}"));
        }
    }
    let listed = Command::new("ldconfig")
        .arg("-p")
        .output()
        .map(|out| String::from_utf8_lossy(&out.stdout).into_owned())
        .unwrap_or_default();
    if listed.contains("libOpenImageDenoise.so.2 ") && listed.contains(&format!("{LIBRARY} ")) {
        return Some(None);
    }
    tried.push(format!(
        "default search path: `ldconfig -p` lists no {LIBRARY} (with libOpenImageDenoise.so.2)"
    ));
    None
}

fn find_oidn_dir(tried: &mut Vec<String>) -> Option<Option<PathBuf>> {
    let Some(root) = env::var_os("OIDN_DIR") else {
        tried.push("OIDN_DIR: not set".into());
        return None;
    };
    let root = PathBuf::from(root);
    for sub in ["lib", "lib64", "."] {
        let dir = root.join(sub);
        if dir.join(LIBRARY).exists() {
            return Some(Some(dir));
        }
    }
    tried.push(format!(
        "OIDN_DIR={}: no {LIBRARY} in lib/, lib64/ or the directory itself",
        root.display()
    ));
    None
}

fn cache_dir() -> Option<PathBuf> {
    if let Some(dir) = env::var_os("LUMIS_OIDN_CACHE") {
        return Some(PathBuf::from(dir));
    }
    let base = env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))?;
    Some(base.join("lumis").join("oidn-2.5.1"))
}

fn fetch_wheel(tried: &mut Vec<String>) -> Option<Option<PathBuf>> {
    let target = env::var("TARGET").unwrap_or_default();
    if target != "x86_64-unknown-linux-gnu" {
        tried.push(format!(
            "PyPI wheel {WHEEL}: only built for x86_64 Linux, not {target}"
        ));
        return None;
    }
    let Some(cache) = cache_dir() else {
        tried.push("PyPI wheel: no cache directory (set LUMIS_OIDN_CACHE or HOME)".into());
        return None;
    };
    let lib = cache.join("lib");
    if lib.join(LIBRARY).exists() {
        return Some(Some(lib));
    }
    match download_and_unpack(&cache) {
        Ok(()) => Some(Some(lib)),
        Err(e) => {
            tried.push(format!("PyPI wheel {WHEEL} into {}: {e}", cache.display()));
            None
        }
    }
}

/// Downloads the wheel with pip and unpacks [`WHEEL_FILES`] into
/// `cache/lib`. Unpacks into a sibling temporary directory first and renames
/// it, so an interrupted build never leaves a half-filled cache behind.
fn download_and_unpack(cache: &Path) -> Result<(), String> {
    let parent = cache.parent().ok_or("cache directory has no parent")?;
    fs::create_dir_all(parent).map_err(|e| format!("cannot create {}: {e}", parent.display()))?;
    let staging = parent.join(format!(".oidn-staging-{}", std::process::id()));
    let _ = fs::remove_dir_all(&staging);
    fs::create_dir_all(&staging).map_err(|e| e.to_string())?;
    let result = download_into(&staging).and_then(|()| {
        let _ = fs::remove_dir_all(cache);
        fs::rename(staging.join("oidn"), cache)
            .map_err(|e| format!("cannot move into {}: {e}", cache.display()))
    });
    // The wheel (~90 MB) is not kept: only the few libraries are.
    let _ = fs::remove_dir_all(&staging);
    result
}

fn download_into(staging: &Path) -> Result<(), String> {
    let python = env::var("PYTHON").unwrap_or_else(|_| "python3".into());
    // The wheel is tagged py3-none-manylinux2014_x86_64: pinning the platform
    // lets any Python 3 with pip download it (we only want the libraries).
    let status = Command::new(&python)
        .args([
            "-m",
            "pip",
            "download",
            "--quiet",
            "--no-deps",
            "--only-binary=:all:",
        ])
        .args(["--platform", "manylinux2014_x86_64"])
        .arg("--dest")
        .arg(staging)
        .arg(WHEEL)
        .status()
        .map_err(|e| format!("cannot run `{python} -m pip`: {e}"))?;
    if !status.success() {
        return Err(format!(
            "`{python} -m pip download {WHEEL}` failed ({status})"
        ));
    }
    let wheel = fs::read_dir(staging)
        .map_err(|e| e.to_string())?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| p.extension().is_some_and(|x| x == "whl"))
        .ok_or("pip reported success but no .whl file was written")?;

    let unpack = "import sys, zipfile, os\n\
        z = zipfile.ZipFile(sys.argv[1])\n\
        for name in sys.argv[3:]:\n\
        \x20   open(os.path.join(sys.argv[2], name), 'wb').write(z.read('pyoidn/oidn/lib/' + name))\n";
    let lib = staging.join("oidn").join("lib");
    fs::create_dir_all(&lib).map_err(|e| e.to_string())?;
    let status = Command::new(&python)
        .args(["-c", unpack])
        .arg(&wheel)
        .arg(&lib)
        .args(WHEEL_FILES)
        .status()
        .map_err(|e| e.to_string())?;
    if !status.success() {
        return Err(format!(
            "unpacking {} failed (expected {})",
            wheel.display(),
            WHEEL_FILES.join(", ")
        ));
    }
    // `-l OpenImageDenoise` needs the plain name.
    std::os::unix::fs::symlink(WHEEL_FILES[0], lib.join(LIBRARY)).map_err(|e| e.to_string())
}
