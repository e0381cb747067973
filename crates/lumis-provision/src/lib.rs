//! Finds a native library for a build script, or fetches the official
//! binaries once.
//!
//! Routes, in order:
//! 1. the system: `pkg-config`, else the library on the linker's default
//!    search path (`ldconfig -p`);
//! 2. an environment variable naming an extracted release
//!    (`$DIR/lib/libNAME.so`);
//! 3. the official shared libraries inside a PyPI wheel, fetched once with
//!    `python3 -m pip download` into a cache outside the source tree
//!    (`$CACHE_VAR`, else `$XDG_CACHE_HOME/lumis/NAME-VERSION`, else
//!    `~/.cache/lumis/NAME-VERSION`), libraries in its `lib/`.
//!
//! [`NativeLibrary::provision`] prints the link search path and the rpath of
//! the crate's own test binaries, and `cargo:libdir` so that the crates
//! depending on it put the directory into their binaries' rpath
//! ([`rpath_of_dependencies`]).

mod wheel;

use std::env;
use std::path::PathBuf;
use std::process::Command;

pub use wheel::Wheel;

/// For the build script of a crate with binaries or tests that load a
/// provisioned library: puts the directory of each library its direct
/// dependencies provisioned (the `DEP_<LINKS>_LIBDIR` cargo hands it) into
/// their rpath, so they run without `LD_LIBRARY_PATH`.
pub fn rpath_of_dependencies() {
    for (var, dir) in env::vars() {
        if var.starts_with("DEP_") && var.ends_with("_LIBDIR") {
            println!("cargo:rustc-link-arg=-Wl,-rpath,{dir}");
        }
    }
}

/// What a `-sys`-style crate links, and where it may be found.
#[derive(Debug, Clone, Copy)]
pub struct NativeLibrary {
    /// The crate whose build script this is, for messages.
    pub crate_name: &'static str,
    /// What the library is, for messages ("Embree 4").
    pub title: &'static str,
    /// The name after `-l`: the linker wants `lib{link_name}.so`.
    pub link_name: &'static str,
    /// The versioned file the program loads (`libembree4.so.4`), which a
    /// system install must provide beside the plain name.
    pub soname: &'static str,
    /// The pkg-config package and the least version accepted.
    pub pkg_config: (&'static str, &'static str),
    /// The variable naming an extracted release (`EMBREE_DIR`).
    pub dir_var: &'static str,
    /// The variable naming the wheel's cache (`LUMIS_EMBREE_CACHE`).
    pub cache_var: &'static str,
    /// The cache's directory under `lumis/` (`embree-4.4.0`).
    pub cache_name: &'static str,
    pub wheel: Wheel,
    /// Further lines of the "install one of" message.
    pub hints: &'static [&'static str],
}

impl NativeLibrary {
    /// Finds the library and tells cargo where it is; panics with every
    /// route tried and what to install when none works.
    pub fn provision(&self) {
        for var in [self.dir_var, self.cache_var, "PKG_CONFIG_PATH", "PYTHON"] {
            println!("cargo:rerun-if-env-changed={var}");
        }
        let mut tried = Vec::new();
        let found = self
            .find_system(&mut tried)
            .or_else(|| self.find_release(&mut tried))
            .or_else(|| self.fetch_wheel(&mut tried));
        let Some(lib_dir) = found else {
            panic!("{}", self.not_found(&tried));
        };
        // A library on the default search path needs no directory.
        if let Some(dir) = lib_dir {
            let dir = dir.display();
            println!("cargo:rustc-link-search=native={dir}");
            println!("cargo:rustc-link-arg=-Wl,-rpath,{dir}");
            println!("cargo:libdir={dir}");
        }
    }

    fn library(&self) -> String {
        format!("lib{}.so", self.link_name)
    }

    /// `Some(None)`: on the default search path.
    fn find_system(&self, tried: &mut Vec<String>) -> Option<Option<PathBuf>> {
        let (package, version) = self.pkg_config;
        match pkg_config::Config::new()
            .cargo_metadata(false)
            .atleast_version(version)
            .probe(package)
        {
            Ok(lib) => return Some(lib.link_paths.first().cloned()),
            Err(e) => {
                let first_line = e.to_string().lines().next().unwrap_or("").to_string();
                tried.push(format!("pkg-config {package}: {first_line}"));
            }
        }
        let listed = Command::new("ldconfig")
            .arg("-p")
            .output()
            .map(|out| String::from_utf8_lossy(&out.stdout).into_owned())
            .unwrap_or_default();
        let library = self.library();
        if listed.contains(&format!("{} ", self.soname)) && listed.contains(&format!("{library} "))
        {
            return Some(None);
        }
        tried.push(format!(
            "default search path: `ldconfig -p` lists no {library} (with {})",
            self.soname
        ));
        None
    }

    fn find_release(&self, tried: &mut Vec<String>) -> Option<Option<PathBuf>> {
        let Some(root) = env::var_os(self.dir_var) else {
            tried.push(format!("{}: not set", self.dir_var));
            return None;
        };
        let root = PathBuf::from(root);
        let library = self.library();
        for sub in ["lib", "lib64", "."] {
            let dir = root.join(sub);
            if dir.join(&library).exists() {
                return Some(Some(dir));
            }
        }
        tried.push(format!(
            "{}={}: no {library} in lib/, lib64/ or the directory itself",
            self.dir_var,
            root.display()
        ));
        None
    }

    fn cache_dir(&self) -> Option<PathBuf> {
        if let Some(dir) = env::var_os(self.cache_var) {
            return Some(PathBuf::from(dir));
        }
        let base = env::var_os("XDG_CACHE_HOME")
            .map(PathBuf::from)
            .or_else(|| env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))?;
        Some(base.join("lumis").join(self.cache_name))
    }

    fn fetch_wheel(&self, tried: &mut Vec<String>) -> Option<Option<PathBuf>> {
        let requirement = self.wheel.requirement;
        let target = env::var("TARGET").unwrap_or_default();
        if target != "x86_64-unknown-linux-gnu" {
            tried.push(format!(
                "PyPI wheel {requirement}: only built for x86_64 Linux, not {target}"
            ));
            return None;
        }
        let Some(cache) = self.cache_dir() else {
            tried.push(format!(
                "PyPI wheel: no cache directory (set {} or HOME)",
                self.cache_var
            ));
            return None;
        };
        let lib = cache.join("lib");
        if lib.join(self.library()).exists() {
            return Some(Some(lib));
        }
        match self.wheel.unpack_into(&cache, self.link_name) {
            Ok(()) => Some(Some(lib)),
            Err(e) => {
                tried.push(format!(
                    "PyPI wheel {requirement} into {}: {e}",
                    cache.display()
                ));
                None
            }
        }
    }

    fn not_found(&self, tried: &[String]) -> String {
        let (package, version) = self.pkg_config;
        let mut message = format!(
            "\n\n{}: {} was not found. Routes tried:\n",
            self.crate_name, self.title
        );
        for t in tried {
            message += &format!("  - {t}\n");
        }
        message += &format!(
            "\nInstall one of:\n  \
             - {} with its pkg-config file `{package}` >= {version}, or its library on the default search path,\n  \
             - a release, then `export {}=/path/to/it` (containing lib/{}),\n  \
             - Python 3 with pip and access to PyPI, so the `{}` wheel can be fetched.\n",
            self.title,
            self.dir_var,
            self.library(),
            self.wheel.requirement
        );
        for hint in self.hints {
            message += &format!("{hint}\n");
        }
        message
    }
}
