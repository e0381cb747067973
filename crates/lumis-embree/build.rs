//! Finds Embree 4 for `embree4-sys` (which only says `-l embree4`): the
//! system's, else `EMBREE_DIR`, else the runtime inside the `embreex`
//! 4.4.0.post1 wheel on PyPI, fetched once into `$LUMIS_EMBREE_CACHE`, else
//! `$XDG_CACHE_HOME/lumis/embree-4.4.0`, else `~/.cache/lumis/embree-4.4.0`
//! (see `crates/lumis-provision`). Dependents read `DEP_LUMIS_EMBREE_LIBDIR`.

use lumis_provision::{NativeLibrary, Wheel};

fn main() {
    NativeLibrary {
        crate_name: "lumis-embree",
        title: "Embree 4",
        link_name: "embree4",
        soname: "libembree4.so.4",
        pkg_config: ("embree4", "4.0"),
        dir_var: "EMBREE_DIR",
        cache_var: "LUMIS_EMBREE_CACHE",
        cache_name: "embree-4.4.0",
        wheel: Wheel {
            requirement: "embreex==4.4.0.post1",
            tags: &[
                "--python-version",
                "3.11",
                "--platform",
                "manylinux_2_28_x86_64",
            ],
            dir: "embreex.libs/",
            files: &[],
        },
        hints: &[
            "Building the bindings also needs libclang (Debian: `apt-get install libclang-dev`).",
        ],
    }
    .provision();
}
