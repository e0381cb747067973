//! Records what a dynamically loaded plugin must share with its host (Rust
//! has no stable ABI): the compiler version, and the fingerprint of the
//! plugin interface (the `lumis-fingerprint` crate).
use std::path::{Path, PathBuf};
use std::process::Command;

/// The crates whose types appear in the plugin traits, pinned to one
/// version in the workspace manifest.
const BOUNDARY_CRATES: &[&str] = &["glam"];

fn main() {
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let version = Command::new(&rustc)
        .arg("--version")
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_else(|| "unknown rustc".into());
    println!("cargo:rustc-env=LUMIS_RUSTC_VERSION={version}");
    println!("cargo:rerun-if-env-changed=RUSTC");

    let crate_dir = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let mut sources = Vec::new();
    collect_sources(&crate_dir.join("src"), &crate_dir, &mut sources);
    sources.sort();
    let manifest = crate_dir.join("../../Cargo.toml");
    let workspace = std::fs::read_to_string(&manifest).unwrap_or_else(|e| {
        panic!(
            "lumis-api is built inside the lumis workspace, whose {} cannot be read: {e}",
            manifest.display()
        )
    });
    let boundary: Vec<String> = BOUNDARY_CRATES
        .iter()
        .map(|name| pinned_requirement(&workspace, name))
        .collect();
    let hash = lumis_fingerprint::fingerprint(&sources, &boundary);
    println!("cargo:rustc-env=LUMIS_INTERFACE_FINGERPRINT={hash:016x}");
    println!("cargo:rerun-if-changed=src");
    println!("cargo:rerun-if-changed={}", manifest.display());
}

/// Every `.rs` file under `dir`, as (path relative to `root`, text).
fn collect_sources(dir: &Path, root: &Path, out: &mut Vec<(String, String)>) {
    let entries =
        std::fs::read_dir(dir).unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()));
    for entry in entries {
        let path = entry.expect("a directory entry").path();
        if path.is_dir() {
            collect_sources(&path, root, out);
        } else if path.extension().is_some_and(|x| x == "rs") {
            let text = std::fs::read_to_string(&path)
                .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
            let relative = path.strip_prefix(root).expect("under the crate");
            out.push((relative.to_string_lossy().replace('\\', "/"), text));
        }
    }
}

/// The workspace's requirement line for `name`, which must pin one
/// version (`name = "=x.y.z"`): with a range, a plugin's lockfile could
/// pick another version than the host's and the fingerprint would not
/// see it.
fn pinned_requirement(workspace: &str, name: &str) -> String {
    let line = workspace
        .lines()
        .map(str::trim)
        .find(|l| {
            l.strip_prefix(name)
                .is_some_and(|rest| rest.trim_start().starts_with('='))
        })
        .unwrap_or_else(|| panic!("the workspace manifest declares no `{name}` dependency"));
    let requirement = line.split_once('=').map(|(_, r)| r.trim()).unwrap_or("");
    assert!(
        requirement.contains("\"="),
        "the workspace's `{line}` must pin one version (\"=x.y.z\"): {name}'s types cross the plugin boundary"
    );
    line.to_string()
}
