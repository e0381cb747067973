//! Puts the directories of the native libraries that lumis-embree (Embree)
//! and lumis-denoise (Open Image Denoise) provisioned into the rpath of
//! the Python module, so that `import lumis` finds them.
fn main() {
    lumis_provision::rpath_of_dependencies();
}
