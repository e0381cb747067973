//! Loading plugin libraries at run time.
//!
//! The rules that keep this sound:
//! - the file is checked before it is mapped (`elf.rs`), and found by its
//!   absolute path, never through the system's library search path;
//! - the library's declaration is checked first: ABI version, rustc
//!   version, lumis-api version and plugin interface fingerprint must
//!   equal the host's, or nothing else in the library is touched;
//! - a library already loaded is not loaded again;
//! - the registry is passed in, never shared through globals;
//! - a `cdylib` carries its own panic runtime, whose panics the host
//!   cannot catch: `lumis_plugin!` runs `register` under the library's own
//!   `catch_unwind`, and guards the library's factories and plugins the
//!   same way (`lumis_api::guard`), so a panic in a plugin is an error in
//!   the registry's fault sink;
//! - a library is never unloaded (thread-local destructors and vtables of
//!   objects it created must outlive every use), so it is leaked on purpose.

#![allow(unsafe_code)]

mod elf;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use libloading::{Library, Symbol};
use lumis_core::plugin::{
    entry_point, PluginDeclaration, API_VERSION, INTERFACE_FINGERPRINT, PLUGIN_ABI_VERSION,
    RUSTC_VERSION,
};
use lumis_core::{Error, Registry, Result};

/// A plugin library, as the files a user names are bounded
/// (`lumis_files`).
const PLUGIN_LIBRARY: lumis_files::FileKind =
    lumis_files::FileKind::new("plugin library", 4 * lumis_files::GIB);

/// The environment variable listing directories whose plugin libraries are
/// loaded at start-up, separated by `:`.
pub const PLUGIN_PATH_VAR: &str = "LUMIS_PLUGIN_PATH";

type Entry = extern "C" fn() -> *const PluginDeclaration;

fn describe_panic(payload: Box<dyn std::any::Any + Send>) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}

/// `e` and the errors under it, which hold the system loader's own words.
fn describe_error(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        text += &format!(": {s}");
        source = s.source();
    }
    text
}

/// The crate a library at `path` was built from, by cargo's naming of a
/// `cdylib` (`libmy_bsdf.so` is `my_bsdf`).
fn crate_name(path: &Path) -> String {
    let name = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let name = name
        .strip_prefix(std::env::consts::DLL_PREFIX)
        .unwrap_or(&name);
    // `libm.so.6`: the name ends at its first dot.
    name.split('.').next().unwrap_or(name).replace('-', "_")
}

/// Loads the plugin library at `path` (relative to the current directory)
/// and registers its plugins, labelled with its absolute path so clashes
/// name both sources. A library already loaded into `registry` is not
/// loaded again.
pub fn load_library(path: &Path, registry: &mut Registry) -> Result<()> {
    if !path.exists() {
        return Err(Error::msg(format!(
            "plugin library '{}' does not exist",
            path.display()
        )));
    }
    // Absolute, so that `dlopen` opens this file and does not search the
    // system's library path for a bare name.
    let path = std::fs::canonicalize(path).map_err(|e| {
        Error::msg(format!(
            "plugin library '{}' cannot be opened: {e}",
            path.display()
        ))
    })?;
    let shown = path.display();
    if registry
        .plugins()
        .iter()
        .any(|p| *p.source == *shown.to_string())
    {
        return Ok(());
    }
    // A FIFO would block `dlopen`, and a device is no library.
    lumis_files::open_regular(&path, PLUGIN_LIBRARY).map_err(Error::msg)?;
    if cfg!(target_os = "linux") {
        elf::check(&path).map_err(|why| {
            Error::msg(format!("'{shown}' is not a loadable shared library: {why}"))
        })?;
    }
    // SAFETY: loading runs the library's initialisers. This is the point
    // of a plugin system: the user asked for this library. Everything after
    // is guarded by the declaration check.
    let library = unsafe { Library::new(&path) }.map_err(|e| {
        Error::msg(format!(
            "'{shown}' is not a loadable shared library: {}",
            describe_error(&e)
        ))
    })?;
    // SAFETY: the symbol, if present, was exported by `lumis_plugin!` with
    // exactly this signature; a library that exports the name with another
    // signature is not a lumis plugin and breaks the contract it claims.
    let symbol = entry_point(&crate_name(&path));
    let entry: Symbol<Entry> = unsafe { library.get(symbol.as_bytes()) }.map_err(|_| {
        Error::msg(format!(
            "'{shown}' has no {symbol} entry point: it is not a lumis plugin \
             (a plugin crate calls lumis_api::lumis_plugin!(register)), or it was renamed \
             (a plugin library keeps the file name cargo gives it, lib<crate>.so)"
        ))
    })?;
    let declaration = catch_unwind(|| entry()).map_err(|p| {
        Error::msg(format!(
            "'{shown}': entry point panicked: {}",
            describe_panic(p)
        ))
    })?;
    if declaration.is_null() {
        return Err(Error::msg(format!(
            "'{shown}': entry point returned no declaration"
        )));
    }
    // SAFETY: non-null, points at the plugin's static declaration, which
    // lives as long as the library (forever: it is never unloaded). Only the
    // leading u32 is read before the ABI version is known to match.
    let abi = unsafe { std::ptr::addr_of!((*declaration).abi_version).read() };
    if abi != PLUGIN_ABI_VERSION {
        return Err(Error::msg(format!(
            "'{shown}' uses plugin ABI version {abi}, this lumis uses {PLUGIN_ABI_VERSION}: \
             rebuild the plugin against this lumis-api"
        )));
    }
    // SAFETY: same ABI version, so the layout of the declaration is ours.
    let declaration = unsafe { &*declaration };
    let rustc = declaration.rustc_version();
    if rustc != RUSTC_VERSION {
        return Err(Error::msg(format!(
            "'{shown}' was built by {rustc}, lumis by {RUSTC_VERSION}: rebuild the plugin with \
             the same toolchain (e.g. `rustup run <version> cargo build --release`)"
        )));
    }
    let api = declaration.api_version();
    if api != API_VERSION {
        return Err(Error::msg(format!(
            "'{shown}' was built against lumis-api {api}, lumis has {API_VERSION}: point the \
             plugin's lumis-api dependency at this lumis and rebuild"
        )));
    }
    let interface = declaration.interface_fingerprint();
    if interface != INTERFACE_FINGERPRINT {
        return Err(Error::msg(format!(
            "'{shown}' was built against a lumis-api {api} whose plugin interface differs from \
             this lumis's (interface fingerprint {interface}, this lumis {INTERFACE_FINGERPRINT}): \
             point the plugin's lumis-api dependency at this lumis and rebuild"
        )));
    }
    registry.begin_library(&shown.to_string());
    let registered = catch_unwind(AssertUnwindSafe(|| (declaration.register)(registry)));
    registry.end_library();
    match registered {
        Ok(Ok(())) => {}
        Ok(Err(e)) => return Err(e.context(format!("'{shown}' failed to register"))),
        Err(p) => {
            return Err(Error::msg(format!(
                "'{shown}' panicked while registering: {}",
                describe_panic(p)
            )))
        }
    }
    // Never unloaded: objects the plugin creates point into it.
    std::mem::forget(library);
    Ok(())
}

/// The plugin libraries (`*.so`, `*.dylib`, `*.dll`) in the directories of
/// `LUMIS_PLUGIN_PATH`, sorted for a reproducible registration order.
pub fn libraries_on_search_path() -> Result<Vec<PathBuf>> {
    let Some(value) = std::env::var_os(PLUGIN_PATH_VAR) else {
        return Ok(Vec::new());
    };
    let mut found = Vec::new();
    for dir in std::env::split_paths(&value).filter(|d| !d.as_os_str().is_empty()) {
        let entries = std::fs::read_dir(&dir).map_err(|e| {
            Error::msg(format!(
                "{PLUGIN_PATH_VAR} names '{}', which cannot be read: {e}",
                dir.display()
            ))
        })?;
        let mut libs: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                p.extension()
                    .is_some_and(|x| x == std::env::consts::DLL_EXTENSION)
            })
            .collect();
        libs.sort();
        found.extend(libs);
    }
    Ok(found)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn missing_file_and_non_library_have_their_own_errors() {
        let mut r = Registry::new();
        let err = load_library(Path::new("/no/such/libplugin.so"), &mut r).unwrap_err();
        assert!(err.message.contains("does not exist"), "{err}");
        let text = std::env::temp_dir().join(format!("lumis-not-a-lib-{}.so", std::process::id()));
        std::fs::write(&text, b"not an ELF file").unwrap();
        let err = load_library(&text, &mut r).unwrap_err();
        std::fs::remove_file(&text).unwrap();
        assert!(
            err.message.contains("not a loadable shared library"),
            "{err}"
        );
        let fifo = std::env::temp_dir().join(format!("lumis-fifo-{}.so", std::process::id()));
        if std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .is_ok_and(|s| s.success())
        {
            let err = load_library(&fifo, &mut r).unwrap_err();
            std::fs::remove_file(&fifo).unwrap();
            assert!(err.message.contains("not a regular file"), "{err}");
        }
        assert!(
            load_library(Path::new("/dev/null"), &mut r)
                .unwrap_err()
                .message
                .contains("not a regular file"),
            "{err}"
        );
    }

    #[test]
    fn library_without_entry_point_is_refused() {
        // libm is a real shared library that is not a lumis plugin.
        let libm = [
            "/lib/x86_64-linux-gnu/libm.so.6",
            "/usr/lib/x86_64-linux-gnu/libm.so.6",
            "/lib64/libm.so.6",
        ]
        .into_iter()
        .map(Path::new)
        .find(|p| p.exists());
        let Some(libm) = libm else {
            eprintln!(
                "no libm found at the usual paths; entry-point test covered by tests/plugins.rs"
            );
            return;
        };
        let err = load_library(libm, &mut Registry::new()).unwrap_err();
        assert!(
            err.message
                .contains("no lumis_plugin_declaration_m entry point"),
            "{err}"
        );
    }
}
