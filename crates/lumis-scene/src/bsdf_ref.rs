//! A shape's reference to a `[[bsdf]]` by name, resolved once the BSDFs
//! are created.

use lumis_core::Location;

/// `bsdf = "white"` as written, with where it was written.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BsdfRef {
    pub name: String,
    pub location: Location,
}
