//! Fetching the shared libraries out of a PyPI wheel.

use std::env;
use std::fs;
use std::path::Path;
use std::process::Command;

/// A wheel holding the official binaries.
#[derive(Debug, Clone, Copy)]
pub struct Wheel {
    /// What pip downloads (`embreex==4.4.0.post1`).
    pub requirement: &'static str,
    /// Interpreter and platform tags, pinned so that any Python 3 with pip
    /// downloads the x86_64 Linux wheel (only its libraries are wanted).
    pub tags: &'static [&'static str],
    /// The wheel's directory of libraries (`embreex.libs/`).
    pub dir: &'static str,
    /// The files of `dir` to keep; empty: all of them.
    pub files: &'static [&'static str],
}

impl Wheel {
    /// Downloads the wheel and unpacks its libraries into `cache/lib`, with
    /// `lib{link_name}.so` pointing at the library of that name. Works in a
    /// sibling staging directory and renames it, so an interrupted build
    /// never leaves a half-filled cache behind; the wheel is not kept.
    pub fn unpack_into(&self, cache: &Path, link_name: &str) -> Result<(), String> {
        let parent = cache.parent().ok_or("cache directory has no parent")?;
        fs::create_dir_all(parent)
            .map_err(|e| format!("cannot create {}: {e}", parent.display()))?;
        let staging = parent.join(format!(".{link_name}-staging-{}", std::process::id()));
        let _ = fs::remove_dir_all(&staging);
        fs::create_dir_all(&staging).map_err(|e| e.to_string())?;
        let result = self.download_into(&staging, link_name).and_then(|()| {
            let _ = fs::remove_dir_all(cache);
            fs::rename(staging.join("cache"), cache)
                .map_err(|e| format!("cannot move into {}: {e}", cache.display()))
        });
        let _ = fs::remove_dir_all(&staging);
        result
    }

    fn download_into(&self, staging: &Path, link_name: &str) -> Result<(), String> {
        let python = env::var("PYTHON").unwrap_or_else(|_| "python3".into());
        let requirement = self.requirement;
        let status = Command::new(&python)
            .args(["-m", "pip", "download", "--quiet", "--no-deps"])
            .arg("--only-binary=:all:")
            .args(self.tags)
            .arg("--dest")
            .arg(staging)
            .arg(requirement)
            .status()
            .map_err(|e| format!("cannot run `{python} -m pip`: {e}"))?;
        if !status.success() {
            return Err(format!(
                "`{python} -m pip download {requirement}` failed ({status})"
            ));
        }
        let wheel = fs::read_dir(staging)
            .map_err(|e| e.to_string())?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .find(|p| p.extension().is_some_and(|x| x == "whl"))
            .ok_or("pip reported success but no .whl file was written")?;

        // A wheel is a zip file; Python's zipfile reads it without a new
        // dependency here.
        let unpack = "import sys, zipfile, os\n\
            z = zipfile.ZipFile(sys.argv[1])\n\
            prefix, out, wanted = sys.argv[2], sys.argv[3], set(sys.argv[4:])\n\
            for n in z.namelist():\n\
            \x20   base = os.path.basename(n)\n\
            \x20   if n.startswith(prefix) and base and (not wanted or base in wanted):\n\
            \x20       open(os.path.join(out, base), 'wb').write(z.read(n))\n";
        let lib = staging.join("cache").join("lib");
        fs::create_dir_all(&lib).map_err(|e| e.to_string())?;
        let status = Command::new(&python)
            .args(["-c", unpack])
            .arg(&wheel)
            .arg(self.dir)
            .arg(&lib)
            .args(self.files)
            .status()
            .map_err(|e| e.to_string())?;
        if !status.success() {
            return Err(format!("unpacking {} failed", wheel.display()));
        }
        let unpacked: Vec<String> = fs::read_dir(&lib)
            .map_err(|e| e.to_string())?
            .filter_map(|e| e.ok())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect();
        if let Some(missing) = self
            .files
            .iter()
            .find(|f| !unpacked.iter().any(|u| u == *f))
        {
            return Err(format!("the wheel holds no {}{missing}", self.dir));
        }
        // The linker wants the plain name; the wheel holds the versioned
        // file (`libNAME.so.2`, or auditwheel's `libNAME-HASH.so.4`).
        let stem = format!("lib{link_name}");
        if unpacked.contains(&format!("{stem}.so")) {
            return Ok(());
        }
        let target = unpacked
            .iter()
            .find(|n| {
                n.strip_prefix(&stem)
                    .is_some_and(|rest| rest.starts_with('.') || rest.starts_with('-'))
            })
            .ok_or(format!("the wheel holds no {stem} shared library"))?;
        std::os::unix::fs::symlink(target, lib.join(format!("{stem}.so")))
            .map_err(|e| e.to_string())
    }
}
