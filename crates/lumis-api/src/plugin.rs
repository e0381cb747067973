//! The declaration a dynamically loaded plugin exports.
//!
//! Rust has no stable ABI, so a plugin library is only sound to use when it
//! was built by the same rustc from the same lumis-api as the host. The
//! declaration carries both, the fingerprint of the plugin interface (a
//! hash of lumis-api's declarations, the layouts of its types and the
//! signatures of its public functions but not their bodies, comments or
//! tests, and of the versions of the crates whose types cross the
//! boundary; `lumis-fingerprint`, run by the build script), and an ABI version
//! that comes first so it can always be read; the host checks all four
//! before calling anything else. The host's own code (its document parser,
//! registry and records) is not in the interface: it changes without
//! refusing a plugin.

use crate::error::Result;
use crate::registrar::Registrar;

/// Bumped whenever [`PluginDeclaration`] changes shape, the one thing a
/// host reads before it can compare fingerprints (which see the traits).
pub const PLUGIN_ABI_VERSION: u32 = 11;
/// The compiler that built this copy of lumis-api.
pub const RUSTC_VERSION: &str = env!("LUMIS_RUSTC_VERSION");
/// The version of this copy of lumis-api.
pub const API_VERSION: &str = env!("CARGO_PKG_VERSION");
/// The fingerprint of this copy's plugin interface, 16 hex digits: two
/// lumis-apis with the same version whose traits differ have different
/// fingerprints (`lumis-fingerprint`).
pub const INTERFACE_FINGERPRINT: &str = env!("LUMIS_INTERFACE_FINGERPRINT");
/// What the symbol [`lumis_plugin!`](crate::lumis_plugin) exports begins
/// with; the crate's name follows ([`entry_point`]).
pub const ENTRY_POINT_PREFIX: &str = "lumis_plugin_declaration_";

/// The symbol a plugin library whose crate is `crate_name` exports
/// (`lumis_plugin_declaration_my_bsdf`). Named after the crate, as CPython
/// names an extension's `PyInit_<module>`, so that several plugin crates
/// link into one binary (a test of them together) without a clash; the
/// host finds it from the library's file name, `lib<crate>.so`.
pub fn entry_point(crate_name: &str) -> String {
    format!("{ENTRY_POINT_PREFIX}{crate_name}")
}

const TEXT: usize = 128;

/// What a plugin library declares about itself. `repr(C)` with the ABI
/// version first, and plain byte arrays for the versions, so a host can read
/// them from any library before trusting anything else in it.
#[repr(C)]
pub struct PluginDeclaration {
    pub abi_version: u32,
    rustc_version: [u8; TEXT],
    api_version: [u8; TEXT],
    interface_fingerprint: [u8; TEXT],
    /// Called by the host with its registry once the versions match.
    pub register: fn(&mut dyn Registrar) -> Result<()>,
}

const fn text(s: &str) -> [u8; TEXT] {
    let bytes = s.as_bytes();
    let mut out = [0u8; TEXT];
    let mut i = 0;
    while i < bytes.len() && i < TEXT - 1 {
        out[i] = bytes[i];
        i += 1;
    }
    out
}

fn read_text(bytes: &[u8; TEXT]) -> String {
    let end = bytes.iter().position(|&b| b == 0).unwrap_or(TEXT);
    String::from_utf8_lossy(&bytes[..end]).into_owned()
}

impl PluginDeclaration {
    /// The declaration of a plugin built against this lumis-api.
    pub const fn new(register: fn(&mut dyn Registrar) -> Result<()>) -> Self {
        Self {
            abi_version: PLUGIN_ABI_VERSION,
            rustc_version: text(RUSTC_VERSION),
            api_version: text(API_VERSION),
            interface_fingerprint: text(INTERFACE_FINGERPRINT),
            register,
        }
    }

    /// A declaration with explicit versions, for testing the loader's
    /// checks against libraries built elsewhere.
    #[doc(hidden)]
    pub const fn with_versions(
        abi_version: u32,
        rustc_version: &str,
        api_version: &str,
        interface_fingerprint: &str,
        register: fn(&mut dyn Registrar) -> Result<()>,
    ) -> Self {
        Self {
            abi_version,
            rustc_version: text(rustc_version),
            api_version: text(api_version),
            interface_fingerprint: text(interface_fingerprint),
            register,
        }
    }

    pub fn rustc_version(&self) -> String {
        read_text(&self.rustc_version)
    }

    pub fn api_version(&self) -> String {
        read_text(&self.api_version)
    }

    pub fn interface_fingerprint(&self) -> String {
        read_text(&self.interface_fingerprint)
    }
}

/// Exports a plugin's entry point. In the plugin crate (built with
/// `crate-type = ["cdylib", "rlib"]`):
///
/// ```ignore
/// use lumis_api::Registrar;
///
/// pub fn register(registry: &mut dyn Registrar) -> lumis_api::Result<()> {
///     registry.add_bsdf(MY_SPEC, |p| Ok(std::sync::Arc::new(MyBsdf::from_params(p)?)))
/// }
/// lumis_api::lumis_plugin!(register);
/// ```
///
/// The entry point, `lumis_plugin_declaration_<crate name>`
/// ([`entry_point`]), only returns a pointer to a static, so no panic can
/// cross it. `register` runs under the plugin's own `catch_unwind`, and so
/// do the factories it adds and the plugins they make ([`crate::guard`]): a
/// panic in the plugin is an error the host reports, not an abort.
#[macro_export]
macro_rules! lumis_plugin {
    ($register:path) => {
        #[allow(unsafe_code)]
        #[export_name = concat!("lumis_plugin_declaration_", env!("CARGO_CRATE_NAME"))]
        pub extern "C" fn lumis_plugin_declaration() -> *const $crate::plugin::PluginDeclaration {
            fn register_guarded(registry: &mut dyn $crate::Registrar) -> $crate::Result<()> {
                $crate::guard::register_guarded(registry, $register)
            }
            static DECLARATION: $crate::plugin::PluginDeclaration =
                $crate::plugin::PluginDeclaration::new(register_guarded);
            &DECLARATION
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn declaration_carries_versions() {
        let d = PluginDeclaration::new(|_| Ok(()));
        assert_eq!(d.abi_version, PLUGIN_ABI_VERSION);
        assert!(
            d.rustc_version().starts_with("rustc "),
            "{}",
            d.rustc_version()
        );
        assert_eq!(d.api_version(), API_VERSION);
        assert_eq!(d.interface_fingerprint(), INTERFACE_FINGERPRINT);
        assert_eq!(INTERFACE_FINGERPRINT.len(), 16);
    }
}
