//! `lumis plugins`: what `type = "..."` accepts, from the plugins'
//! own declarations.

use std::fmt::Write;

use lumis_core::params::ParamDefault;
use lumis_core::{PluginKind, Registry};

/// Every registered plugin by kind, with its parameters.
pub fn plugin_listing(registry: &Registry) -> String {
    let mut out = String::new();
    let plugins = registry.plugins();
    for kind in PluginKind::ALL {
        let _ = writeln!(out, "[{}]", kind.table_name());
        for p in plugins.iter().filter(|p| p.spec.kind == kind) {
            let _ = writeln!(out, "  type = \"{}\"  ({})", p.spec.name, p.source);
            let _ = writeln!(out, "    {}", p.spec.doc);
            for param in p.spec.params {
                let default = match param.default {
                    ParamDefault::Required => "required".to_string(),
                    ParamDefault::Value(v) => format!("default {v}"),
                    ParamDefault::Absent => "optional".to_string(),
                };
                let _ = writeln!(
                    out,
                    "    {:<12} {:<12} {:<22} {}",
                    param.name,
                    param.ty.name(),
                    default,
                    param.doc
                );
            }
        }
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_every_builtin_with_its_parameters() {
        let text = plugin_listing(&crate::builtin_registry().unwrap());
        for needle in [
            "[sampler]",
            "type = \"independent\"  (built-in)",
            "[integrator]",
            "max_depth",
            "default 8",
            "reflectance",
            "required",
        ] {
            assert!(text.contains(needle), "listing lacks '{needle}':\n{text}");
        }
    }
}
