//! Puts the Embree library directory found by lumis-embree into the rpath of
//! these end-to-end tests.
fn main() {
    if let Ok(dir) = std::env::var("DEP_LUMIS_EMBREE_LIBDIR") {
        println!("cargo:rustc-link-arg=-Wl,-rpath,{dir}");
    }
}
