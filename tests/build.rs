//! Puts the library directories found by lumis-embree (Embree) and
//! lumis-denoise (Open Image Denoise) into the rpath of these end-to-end
//! tests.
fn main() {
    for dir in ["DEP_LUMIS_EMBREE_LIBDIR", "DEP_LUMIS_OIDN_LIBDIR"] {
        if let Ok(dir) = std::env::var(dir) {
            println!("cargo:rustc-link-arg=-Wl,-rpath,{dir}");
        }
    }
}
