//! Finds Intel Open Image Denoise 2 (`-l OpenImageDenoise`, `src/ffi.rs`):
//! the system's, else `OIDN_DIR`, else Intel's official 2.5.1 runtime inside
//! the `pyoidn` 2.5.1.0 wheel on PyPI, fetched once into
//! `$LUMIS_OIDN_CACHE`, else `$XDG_CACHE_HOME/lumis/oidn-2.5.1`, else
//! `~/.cache/lumis/oidn-2.5.1` (see `crates/lumis-provision`). Dependents
//! read `DEP_LUMIS_OIDN_LIBDIR`.

use lumis_provision::{NativeLibrary, Wheel};

fn main() {
    NativeLibrary {
        crate_name: "lumis-denoise",
        title: "Open Image Denoise 2",
        link_name: "OpenImageDenoise",
        soname: "libOpenImageDenoise.so.2",
        pkg_config: ("OpenImageDenoise", "2.0"),
        dir_var: "OIDN_DIR",
        cache_var: "LUMIS_OIDN_CACHE",
        cache_name: "oidn-2.5.1",
        wheel: Wheel {
            requirement: "pyoidn==2.5.1.0",
            tags: &["--platform", "manylinux2014_x86_64"],
            // What the CPU device needs. The wheel stores copies, not
            // symlinks, so only the sonames are kept; they find each other
            // through their `$ORIGIN/../lib` rpath, which is why the cache
            // keeps them in a `lib/` directory.
            dir: "pyoidn/oidn/lib/",
            files: &[
                "libOpenImageDenoise.so.2",
                "libOpenImageDenoise_core.so.2.5.1",
                "libOpenImageDenoise_device_cpu.so.2.5.1",
                "libtbb.so.12",
            ],
        },
        hints: &[],
    }
    .provision();
}
