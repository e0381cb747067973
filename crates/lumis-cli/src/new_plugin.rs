//! `lumis new-plugin`: writes a standalone plugin crate, one small working
//! example per plugin kind, from the templates in `templates/`.
//!
//! The crate depends on this lumis by path: a plugin must be built against
//! the very `lumis-api` the host was built from (its interface fingerprint
//! and compiler version are checked at load), so by default the source tree
//! this binary was built from, which it records at compile time.

use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};
use lumis_core::{Error, PluginKind, Result};

#[derive(Args, Debug, Clone)]
pub struct NewPluginArgs {
    /// The crate and the plugin's `type` name: lower-case ASCII letters,
    /// digits, `-` and `_`, starting with a letter. The crate is written to
    /// the directory NAME, which must not exist.
    pub name: String,
    /// Which kind of plugin to start from.
    #[arg(long, value_enum)]
    pub kind: NewPluginKind,
    /// The lumis source tree to build against (default: the one this
    /// `lumis` was built from).
    #[arg(long, value_name = "DIR")]
    pub lumis_path: Option<PathBuf>,
}

/// The kinds `new-plugin` has a template for.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum NewPluginKind {
    Bsdf,
    Light,
    Sampler,
    LightSampler,
    Integrator,
}

/// One kind's template: its library, its tests, and what its README says.
struct Template {
    lib: &'static str,
    check: &'static str,
    /// How a scene uses the plugin.
    scene: &'static str,
}

const CARGO_TOML: &str = include_str!("../templates/Cargo.toml");
const README: &str = include_str!("../templates/README.md");
const GITIGNORE: &str = include_str!("../templates/gitignore");

impl NewPluginKind {
    fn plugin_kind(self) -> PluginKind {
        match self {
            Self::Bsdf => PluginKind::Bsdf,
            Self::Light => PluginKind::Light,
            Self::Sampler => PluginKind::Sampler,
            Self::LightSampler => PluginKind::LightSampler,
            Self::Integrator => PluginKind::Integrator,
        }
    }

    /// The name `--kind` takes.
    fn label(self) -> &'static str {
        match self {
            Self::Bsdf => "bsdf",
            Self::Light => "light",
            Self::Sampler => "sampler",
            Self::LightSampler => "light-sampler",
            Self::Integrator => "integrator",
        }
    }

    fn template(self) -> Template {
        match self {
            Self::Bsdf => Template {
                lib: include_str!("../templates/bsdf/lib.rs"),
                check: include_str!("../templates/bsdf/check.rs"),
                scene: "[[bsdf]]\nname = \"matte\"\ntype = \"{{plugin}}\"\nreflectance = [0.8, 0.6, 0.4]",
            },
            Self::Light => Template {
                lib: include_str!("../templates/light/lib.rs"),
                check: include_str!("../templates/light/check.rs"),
                scene: "[[shape]]\ntype = \"quad\"\ncorner = [-0.5, 1.9, -0.5]\nedge_u = [1, 0, 0]\nedge_v = [0, 0, 1]\nbsdf = \"white\"\nemission = { type = \"{{plugin}}\", radiance = [10, 10, 10] }",
            },
            Self::Sampler => Template {
                lib: include_str!("../templates/sampler/lib.rs"),
                check: include_str!("../templates/sampler/check.rs"),
                scene: "[sampler]\ntype = \"{{plugin}}\"\nstrata = 8",
            },
            Self::LightSampler => Template {
                lib: include_str!("../templates/light-sampler/lib.rs"),
                check: include_str!("../templates/light-sampler/check.rs"),
                scene: "[light_sampler]\ntype = \"{{plugin}}\"",
            },
            Self::Integrator => Template {
                lib: include_str!("../templates/integrator/lib.rs"),
                check: include_str!("../templates/integrator/check.rs"),
                scene: "[integrator]\ntype = \"{{plugin}}\"\nmax_depth = 8",
            },
        }
    }
}

/// The lumis source tree this binary was built from, if it is still there.
pub fn built_from_tree() -> Option<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    if is_lumis_tree(&root) {
        root.canonicalize().ok()
    } else {
        None
    }
}

fn is_lumis_tree(dir: &Path) -> bool {
    ["lumis-api", "lumis-core", "lumis-sampling", "lumis-check"]
        .iter()
        .all(|c| dir.join("crates").join(c).join("Cargo.toml").is_file())
}

/// Refuses a name that is not a valid crate and plugin name, or that a
/// built-in plugin of the same kind already has.
pub fn check_name(name: &str, kind: NewPluginKind) -> Result<()> {
    let expected = "expected lower-case ASCII letters, digits, '-' and '_', starting with a letter, at most 64 characters";
    let valid = name.len() <= 64
        && name.starts_with(|c: char| c.is_ascii_lowercase())
        && name
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-' || c == '_');
    if !valid {
        return Err(Error::msg(format!(
            "invalid plugin name \"{name}\": {expected}"
        )));
    }
    // Names a library crate cannot take: they would shadow the standard
    // crates, or are keywords once `-` becomes `_`.
    let reserved = [
        "std",
        "core",
        "alloc",
        "test",
        "proc_macro",
        "self",
        "crate",
        "super",
    ];
    if reserved.contains(&name.replace('-', "_").as_str()) {
        return Err(Error::msg(format!(
            "invalid plugin name \"{name}\": a Rust crate cannot be called that"
        )));
    }
    let builtin = lumis_app::builtin_registry()?;
    if builtin.find(kind.plugin_kind(), name).is_some() {
        return Err(Error::msg(format!(
            "invalid plugin name \"{name}\": a built-in {} plugin has it already",
            kind.label()
        )));
    }
    Ok(())
}

/// Writes the crate `args.name` into `parent`; returns its directory.
pub fn new_plugin(args: &NewPluginArgs, parent: &Path) -> Result<PathBuf> {
    check_name(&args.name, args.kind)?;
    let lumis = match &args.lumis_path {
        Some(dir) if is_lumis_tree(dir) => dir.canonicalize().map_err(|e| {
            Error::msg(format!("--lumis-path {}: {e}", dir.display()))
        })?,
        Some(dir) => {
            return Err(Error::msg(format!(
                "--lumis-path {}: not a lumis source tree (expected crates/lumis-api, crates/lumis-core, crates/lumis-sampling and crates/lumis-check in it)",
                dir.display()
            )))
        }
        None => built_from_tree().ok_or_else(|| {
            Error::msg(format!(
                "the lumis source tree this binary was built from ({}) is gone: give the lumis checkout to build against with --lumis-path DIR",
                Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").display()
            ))
        })?,
    };
    let dir = parent.join(&args.name);
    if dir.exists() {
        return Err(Error::msg(format!(
            "{} exists already: choose another name or directory (new-plugin never overwrites)",
            dir.display()
        )));
    }
    let template = args.kind.template();
    let lumis_text = lumis.to_str().ok_or_else(|| {
        Error::msg(format!(
            "the lumis path {} is not valid UTF-8, which a Cargo.toml cannot hold",
            lumis.display()
        ))
    })?;
    let fill = |text: &str| {
        text.replace("{{scene}}", template.scene)
            .replace("{{kind}}", args.kind.label())
            .replace("{{crate}}", &args.name)
            .replace("{{plugin}}", &args.name)
            .replace("{{lib}}", &args.name.replace('-', "_"))
            .replace("{{lumis}}", &toml_basic_string_body(lumis_text))
    };
    let files = [
        ("Cargo.toml", CARGO_TOML),
        ("README.md", README),
        (".gitignore", GITIGNORE),
        ("src/lib.rs", template.lib),
        ("tests/check.rs", template.check),
    ];
    for (path, text) in files {
        let path = dir.join(path);
        let written = std::fs::create_dir_all(path.parent().expect("a file in the crate"))
            .and_then(|()| std::fs::write(&path, fill(text)));
        written.map_err(|e| Error::msg(format!("cannot write {}: {e}", path.display())))?;
    }
    Ok(dir)
}

/// `text` escaped for the inside of a TOML basic string.
fn toml_basic_string_body(text: &str) -> String {
    text.replace('\\', "\\\\").replace('"', "\\\"")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_checked() {
        for good in ["my-bsdf", "glow2", "a_b"] {
            check_name(good, NewPluginKind::Bsdf).unwrap();
        }
        for (bad, why) in [
            ("", "starting with a letter"),
            ("My-bsdf", "lower-case"),
            ("2d", "starting with a letter"),
            ("a b", "lower-case"),
            ("../x", "lower-case"),
            ("core", "cannot be called"),
            ("diffuse", "built-in bsdf"),
        ] {
            let err = check_name(bad, NewPluginKind::Bsdf)
                .unwrap_err()
                .to_string();
            assert!(err.contains(why), "{bad}: {err}");
        }
        check_name("diffuse", NewPluginKind::Light).unwrap();
    }

    #[test]
    fn every_placeholder_is_filled() {
        let parent = tempfile::tempdir().unwrap();
        for kind in NewPluginKind::value_variants() {
            let args = NewPluginArgs {
                name: format!("my-{}", kind.label()),
                kind: *kind,
                lumis_path: None,
            };
            let dir = new_plugin(&args, parent.path()).unwrap();
            for file in ["Cargo.toml", "README.md", "src/lib.rs", "tests/check.rs"] {
                let text = std::fs::read_to_string(dir.join(file)).unwrap();
                // A placeholder is `{{word}}`; `{{ ` is a brace escaped in
                // a format string.
                let left = text.split("{{").skip(1).find(|rest| {
                    rest.split_once("}}")
                        .is_some_and(|(word, _)| word.chars().all(|c| c.is_ascii_lowercase()))
                });
                assert!(left.is_none(), "{kind:?} {file}: {{{{{}", left.unwrap());
            }
            let err = new_plugin(&args, parent.path()).unwrap_err().to_string();
            assert!(err.contains("exists already"), "{err}");
        }
    }

    #[test]
    fn a_missing_lumis_tree_is_an_error() {
        let parent = tempfile::tempdir().unwrap();
        let args = NewPluginArgs {
            name: "glow".into(),
            kind: NewPluginKind::Light,
            lumis_path: Some(parent.path().to_path_buf()),
        };
        let err = new_plugin(&args, parent.path()).unwrap_err().to_string();
        assert!(err.contains("not a lumis source tree"), "{err}");
        assert!(!parent.path().join("glow").exists());
    }
}
