//! The plugin interface's fingerprint: a hash of what a plugin library and
//! its host must agree on, so that a plugin built against a lumis-api
//! whose interface changed is refused at load instead of crashing, and a
//! plugin built against one whose interface did not change keeps loading.
//!
//! Rust has no stable ABI, so the agreement is on source: the same
//! compiler (checked apart) compiling the same declarations lays out the
//! same types and vtables. What counts is the interface, read with `syn`:
//!
//! - every type's definition whatever its visibility (structs, enums,
//!   unions, aliases, traits): a private field of a type that crosses the
//!   boundary (the `Params` a plugin reads) is part of its layout;
//! - the signatures of public functions and methods, and of every method
//!   of a trait or a trait implementation;
//! - public constants and statics with their values (the ABI version),
//!   public re-exports, and exported macros (`lumis_plugin!` expands in the
//!   plugin).
//!
//! Not counted: function bodies (a plugin calls its own copy), private
//! functions and constants, comments and documentation of either kind,
//! formatting, and anything under `#[cfg(test)]`.

use quote::ToTokens;
use syn::visit_mut::VisitMut;
use syn::{Attribute, ImplItem, Item, TraitItem, Visibility};

/// The interface of one source file as text: its declarations, with
/// bodies, documentation and tests removed; `syn`'s error where the file
/// does not parse.
pub fn interface(source: &str) -> syn::Result<String> {
    let file = syn::parse_file(source)?;
    let mut out = Vec::new();
    for item in file.items {
        collect(item, &mut out);
    }
    Ok(out.join("\n"))
}

/// Appends the interface of `item` to `out`, one declaration a line.
fn collect(mut item: Item, out: &mut Vec<String>) {
    if is_test_only(item_attrs(&item)) {
        return;
    }
    StripDocs.visit_item_mut(&mut item);
    match item {
        Item::Struct(_)
        | Item::Enum(_)
        | Item::Union(_)
        | Item::Type(_)
        | Item::ExternCrate(_)
        | Item::ForeignMod(_) => out.push(item.to_token_stream().to_string()),
        Item::Trait(mut t) => {
            t.items.retain(|i| !is_test_only(trait_item_attrs(i)));
            for trait_item in &mut t.items {
                if let TraitItem::Fn(f) = trait_item {
                    f.default = None;
                    f.semi_token = Some(Default::default());
                }
            }
            out.push(t.to_token_stream().to_string());
        }
        Item::Fn(f) if is_public(&f.vis) => {
            out.push(format!(
                "{} {}",
                f.vis.to_token_stream(),
                f.sig.to_token_stream()
            ));
        }
        Item::Const(c) if is_public(&c.vis) => out.push(c.to_token_stream().to_string()),
        Item::Static(s) if is_public(&s.vis) => out.push(s.to_token_stream().to_string()),
        Item::Use(u) if is_public(&u.vis) => out.push(u.to_token_stream().to_string()),
        Item::Macro(m) if m.attrs.iter().any(|a| a.path().is_ident("macro_export")) => {
            out.push(m.to_token_stream().to_string())
        }
        Item::Impl(imp) => {
            let in_trait = imp.trait_.is_some();
            let mut header = imp.clone();
            header.items.clear();
            let mut lines = vec![header.to_token_stream().to_string()];
            for impl_item in imp.items {
                match impl_item {
                    ImplItem::Fn(f)
                        if !is_test_only(&f.attrs) && (in_trait || is_public(&f.vis)) =>
                    {
                        lines.push(format!(
                            "{} {}",
                            f.vis.to_token_stream(),
                            f.sig.to_token_stream()
                        ))
                    }
                    ImplItem::Const(c) if in_trait || is_public(&c.vis) => {
                        lines.push(c.to_token_stream().to_string())
                    }
                    ImplItem::Type(t) => lines.push(t.to_token_stream().to_string()),
                    _ => {}
                }
            }
            out.push(lines.join(" "));
        }
        Item::Mod(m) => {
            if let Some((_, items)) = m.content {
                out.push(format!("mod {} {{", m.ident));
                for item in items {
                    collect(item, out);
                }
                out.push("}".into());
            }
        }
        _ => {}
    }
}

fn is_public(vis: &Visibility) -> bool {
    matches!(vis, Visibility::Public(_))
}

/// `#[cfg(test)]`, or any `cfg` that names `test`.
fn is_test_only(attrs: &[Attribute]) -> bool {
    attrs.iter().any(|a| {
        a.path().is_ident("cfg")
            && a.meta
                .to_token_stream()
                .into_iter()
                .any(|t| t.to_string().contains("test"))
    })
}

fn item_attrs(item: &Item) -> &[Attribute] {
    match item {
        Item::Const(i) => &i.attrs,
        Item::Enum(i) => &i.attrs,
        Item::Fn(i) => &i.attrs,
        Item::Impl(i) => &i.attrs,
        Item::Macro(i) => &i.attrs,
        Item::Mod(i) => &i.attrs,
        Item::Static(i) => &i.attrs,
        Item::Struct(i) => &i.attrs,
        Item::Trait(i) => &i.attrs,
        Item::Type(i) => &i.attrs,
        Item::Union(i) => &i.attrs,
        Item::Use(i) => &i.attrs,
        _ => &[],
    }
}

fn trait_item_attrs(item: &TraitItem) -> &[Attribute] {
    match item {
        TraitItem::Fn(i) => &i.attrs,
        TraitItem::Const(i) => &i.attrs,
        TraitItem::Type(i) => &i.attrs,
        _ => &[],
    }
}

/// Removes documentation (`///`, `//!`, `#[doc]`) wherever it is.
struct StripDocs;

impl VisitMut for StripDocs {
    fn visit_attributes_mut(&mut self, attrs: &mut Vec<Attribute>) {
        attrs.retain(|a| !a.path().is_ident("doc"));
    }
}

/// FNV-1a (64 bit) over each source's path and interface, in the order
/// given, then the requirements of the crates whose types cross the
/// plugin boundary. Panics, naming the file, where a source does not
/// parse: the build that asks stops there.
pub fn fingerprint(sources: &[(String, String)], boundary_crates: &[String]) -> u64 {
    let mut hash = 0xcbf2_9ce4_8422_2325u64;
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            hash = (hash ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
        }
        // A separator, so that ("ab", "c") and ("a", "bc") differ.
        hash = (hash ^ 0xff).wrapping_mul(0x0000_0100_0000_01b3);
    };
    for (path, text) in sources {
        eat(path.as_bytes());
        let interface = interface(text)
            .unwrap_or_else(|e| panic!("{path} does not parse, so its interface is unknown: {e}"));
        eat(interface.as_bytes());
    }
    for requirement in boundary_crates {
        eat(requirement.as_bytes());
    }
    hash
}

#[cfg(test)]
mod tests {
    use super::*;

    const GLAM: &str = "glam = \"=0.34.3\"";

    fn of(text: &str) -> u64 {
        fingerprint(&[("src/bsdf.rs".into(), text.into())], &[GLAM.into()])
    }

    /// A trait, a type that crosses the boundary with a private field, a
    /// public function, a private one, and tests.
    const BASE: &str = r#"
//! Scattering.
/// A BSDF.
pub trait Bsdf {
    fn f(&self) -> f32;
    fn pdf(&self) -> f32 { 0.5 }
}
pub struct Registry {
    plugins: Vec<u32>,
}
impl Registry {
    pub fn add(&mut self, p: u32) { self.plugins.push(p); }
    fn count(&self) -> usize { self.plugins.len() }
}
fn helper() -> u32 { 1 }
pub const ABI: u32 = 10;
#[cfg(test)]
mod tests {
    #[test]
    fn adds() { assert_eq!(1, 1); }
}
"#;

    #[test]
    fn bodies_comments_and_tests_keep_the_fingerprint() {
        let base = of(BASE);
        let kept = [
            // A private body.
            BASE.replace("fn helper() -> u32 { 1 }", "fn helper() -> u32 { 2 + 3 }"),
            // A public function's body.
            BASE.replace("self.plugins.push(p); }", "self.plugins.insert(0, p); }"),
            // A trait's default body.
            BASE.replace("{ 0.5 }", "{ 0.25 }"),
            // A private function's signature.
            BASE.replace("fn count(&self) -> usize", "fn count(&self, at: u8) -> u64"),
            // Line and block comments, documentation and formatting.
            BASE.replace(
                "pub struct Registry {",
                "/* kept */ pub struct   Registry { // the host's",
            ),
            BASE.replace("/// A BSDF.", "/// A BSDF, documented anew.\n/** more */"),
            // A test.
            BASE.replace("assert_eq!(1, 1)", "assert_eq!(2, 2)"),
        ];
        for text in kept {
            assert_eq!(of(&text), base, "{text}");
        }
    }

    #[test]
    fn the_interface_changes_the_fingerprint() {
        let base = of(BASE);
        let changed = [
            // A method added to a trait.
            BASE.replace(
                "fn f(&self) -> f32;",
                "fn f(&self) -> f32;\n    fn g(&self) -> f32;",
            ),
            // A public signature.
            BASE.replace(
                "pub fn add(&mut self, p: u32)",
                "pub fn add(&mut self, p: u64)",
            ),
            // A crossing type's private field.
            BASE.replace(
                "plugins: Vec<u32>,",
                "plugins: Vec<u32>,\n    guard: Option<u8>,",
            ),
            // A public constant's value.
            BASE.replace("pub const ABI: u32 = 10;", "pub const ABI: u32 = 11;"),
        ];
        for text in changed {
            assert_ne!(of(&text), base, "{text}");
        }
        // A boundary crate's version, and a file's path.
        let other_glam = fingerprint(
            &[("src/bsdf.rs".into(), BASE.into())],
            &["glam = \"=0.35.0\"".into()],
        );
        assert_ne!(other_glam, base);
        let moved = fingerprint(&[("src/other.rs".into(), BASE.into())], &[GLAM.into()]);
        assert_ne!(moved, base);
    }
}
