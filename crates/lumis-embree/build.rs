//! Finds Embree 4 for `embree4-sys` (which only says `-l embree4`).
//!
//! Routes, in order:
//! 1. `pkg-config embree4` (a system or package-manager install);
//! 2. `EMBREE_DIR` (an extracted Embree release: `$EMBREE_DIR/lib/libembree4.so`);
//! 3. the Embree 4 runtime shipped inside the `embreex` 4.4.0.post1 wheel on
//!    PyPI, fetched once with `python3 -m pip download` into a cache directory
//!    outside the source tree (`$LUMIS_EMBREE_CACHE`, else
//!    `$XDG_CACHE_HOME/lumis/embree-4.4.0`, else `~/.cache/lumis/embree-4.4.0`).
//!
//! The library directory is added to the link search path and to the rpath of
//! this crate's own test binaries; it is also exported as
//! `DEP_LUMIS_EMBREE_LIBDIR` so that binary crates can put it in their rpath
//! (see `crates/lumis-cli/build.rs`).

use std::env;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

const WHEEL: &str = "embreex==4.4.0.post1";

fn main() {
    println!("cargo:rerun-if-env-changed=EMBREE_DIR");
    println!("cargo:rerun-if-env-changed=LUMIS_EMBREE_CACHE");
    println!("cargo:rerun-if-env-changed=PKG_CONFIG_PATH");

    let mut tried = Vec::new();
    let lib_dir = match find_pkg_config(&mut tried)
        .or_else(|| find_embree_dir(&mut tried))
        .or_else(|| fetch_wheel(&mut tried))
    {
        Some(dir) => dir,
        None => {
            panic!(
                "\n\nlumis-embree: Embree 4 was not found. Routes tried:\n{}\n\n\
                 Install one of:\n  \
                 - Embree 4 with its pkg-config file (e.g. Debian/Ubuntu `libembree-dev` >= 4),\n  \
                 - an Embree 4 release, then `export EMBREE_DIR=/path/to/embree` (containing lib/libembree4.so),\n  \
                 - Python 3 with pip and access to PyPI, so the `{WHEEL}` wheel can be fetched.\n\
                 Building the bindings also needs libclang (Debian: `apt-get install libclang-dev`).\n",
                tried
                    .iter()
                    .map(|t| format!("  - {t}"))
                    .collect::<Vec<_>>()
                    .join("\n")
            );
        }
    };
    let lib_dir = lib_dir.display();
    println!("cargo:rustc-link-search=native={lib_dir}");
    println!("cargo:rustc-link-arg=-Wl,-rpath,{lib_dir}");
    println!("cargo:libdir={lib_dir}");
}

fn find_pkg_config(tried: &mut Vec<String>) -> Option<PathBuf> {
    match pkg_config::Config::new()
        .cargo_metadata(false)
        .probe("embree4")
    {
        Ok(lib) => {
            let dir = lib.link_paths.first().cloned();
            match dir {
                Some(dir) => Some(dir),
                None => {
                    tried.push(
                        "pkg-config embree4: found, but it names no library directory".into(),
                    );
                    None
                }
            }
        }
        Err(e) => {
            let first_line = e.to_string().lines().next().unwrap_or("").to_string();
            tried.push(format!("pkg-config embree4: {first_line}"));
            None
        }
    }
}

fn find_embree_dir(tried: &mut Vec<String>) -> Option<PathBuf> {
    let Some(root) = env::var_os("EMBREE_DIR") else {
        tried.push("EMBREE_DIR: not set".into());
        return None;
    };
    let root = PathBuf::from(root);
    for sub in ["lib", "lib64", "."] {
        let dir = root.join(sub);
        if dir.join("libembree4.so").exists() {
            return Some(dir);
        }
    }
    tried.push(format!(
        "EMBREE_DIR={}: no libembree4.so in lib/, lib64/ or the directory itself",
        root.display()
    ));
    None
}

fn cache_dir() -> Option<PathBuf> {
    if let Some(dir) = env::var_os("LUMIS_EMBREE_CACHE") {
        return Some(PathBuf::from(dir));
    }
    let base = env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))?;
    Some(base.join("lumis").join("embree-4.4.0"))
}

fn fetch_wheel(tried: &mut Vec<String>) -> Option<PathBuf> {
    let target = env::var("TARGET").unwrap_or_default();
    if target != "x86_64-unknown-linux-gnu" {
        tried.push(format!(
            "PyPI wheel {WHEEL}: only built for x86_64 Linux, not {target}"
        ));
        return None;
    }
    let Some(cache) = cache_dir() else {
        tried.push("PyPI wheel: no cache directory (set LUMIS_EMBREE_CACHE or HOME)".into());
        return None;
    };
    if cache.join("libembree4.so").exists() {
        return Some(cache);
    }
    match download_and_unpack(&cache) {
        Ok(()) => Some(cache),
        Err(e) => {
            tried.push(format!("PyPI wheel {WHEEL} into {}: {e}", cache.display()));
            None
        }
    }
}

/// Downloads the wheel with pip and unpacks `embreex.libs/` into `cache`.
/// Unpacks into a sibling temporary directory first and renames it, so an
/// interrupted build never leaves a half-filled cache behind.
fn download_and_unpack(cache: &Path) -> Result<(), String> {
    let parent = cache.parent().ok_or("cache directory has no parent")?;
    fs::create_dir_all(parent).map_err(|e| format!("cannot create {}: {e}", parent.display()))?;
    let staging = parent.join(format!(".embree-staging-{}", std::process::id()));
    let _ = fs::remove_dir_all(&staging);
    fs::create_dir_all(&staging).map_err(|e| e.to_string())?;

    let python = env::var("PYTHON").unwrap_or_else(|_| "python3".into());
    // The wheel is tagged cp311; pinning interpreter and platform tags lets any
    // Python 3 with pip download it (we only want the shared libraries inside).
    let status = Command::new(&python)
        .args([
            "-m",
            "pip",
            "download",
            "--quiet",
            "--no-deps",
            "--only-binary=:all:",
        ])
        .args([
            "--python-version",
            "3.11",
            "--platform",
            "manylinux_2_28_x86_64",
        ])
        .arg("--dest")
        .arg(&staging)
        .arg(WHEEL)
        .status()
        .map_err(|e| format!("cannot run `{python} -m pip`: {e}"))?;
    if !status.success() {
        return Err(format!(
            "`{python} -m pip download {WHEEL}` failed ({status})"
        ));
    }
    let wheel = fs::read_dir(&staging)
        .map_err(|e| e.to_string())?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| p.extension().is_some_and(|x| x == "whl"))
        .ok_or("pip reported success but no .whl file was written")?;

    let unpack = "import sys, zipfile, os\n\
        z = zipfile.ZipFile(sys.argv[1])\n\
        for n in z.namelist():\n\
        \x20   if n.startswith('embreex.libs/') and not n.endswith('/'):\n\
        \x20       open(os.path.join(sys.argv[2], os.path.basename(n)), 'wb').write(z.read(n))\n";
    let libs = staging.join("lib");
    fs::create_dir_all(&libs).map_err(|e| e.to_string())?;
    let status = Command::new(&python)
        .args(["-c", unpack])
        .arg(&wheel)
        .arg(&libs)
        .status()
        .map_err(|e| e.to_string())?;
    if !status.success() {
        return Err(format!("unpacking {} failed", wheel.display()));
    }
    let embree = fs::read_dir(&libs)
        .map_err(|e| e.to_string())?
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .find(|n| n.starts_with("libembree4"))
        .ok_or("the wheel holds no libembree4 shared library")?;
    // embree4-sys links `-l embree4`: give the linker the plain name.
    std::os::unix::fs::symlink(&embree, libs.join("libembree4.so")).map_err(|e| e.to_string())?;

    let _ = fs::remove_dir_all(cache);
    fs::rename(&libs, cache).map_err(|e| format!("cannot move into {}: {e}", cache.display()))?;
    let _ = fs::remove_dir_all(&staging);
    Ok(())
}
