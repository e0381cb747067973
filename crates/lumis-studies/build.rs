//! Puts the directories of the native libraries that lumis-embree (Embree)
//! and lumis-denoise (Open Image Denoise) provisioned into the rpath of
//! this crate's binaries and tests.
fn main() {
    lumis_provision::rpath_of_dependencies();
}
