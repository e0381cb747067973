//! A converge study's variants: the TOML list of overrides, each with the
//! image it is measured on.

use lumis_core::doc::{self, Node, Value};
use lumis_core::{Error, Result};
use lumis_files::{FileKind, MIB};

/// Which image of a render a variant is measured on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MeasuredImage {
    /// The film's image (`NAME.exr`).
    #[default]
    Raw,
    /// The `[denoiser]`'s image (`NAME.denoised.exr`); the denoiser's time
    /// counts in the variant's.
    Denoised,
}

impl MeasuredImage {
    const NAMES: &'static str = "\"raw\" or \"denoised\"";

    fn parse(text: &str) -> Option<Self> {
        match text {
            "raw" => Some(Self::Raw),
            "denoised" => Some(Self::Denoised),
            _ => None,
        }
    }
}

/// One variant: a name, its scene overrides and the image measured.
#[derive(Debug, Clone, PartialEq)]
pub struct Variant {
    pub name: String,
    pub set: Vec<String>,
    pub image: MeasuredImage,
}

/// Reads `[[variant]]` tables, with located errors.
pub fn parse_variants(text: &str, path: &str) -> Result<Vec<Variant>> {
    let root = doc::parse(text, path)?;
    let mut variants = Vec::new();
    for entry in &root.entries {
        let Value::Array(items) = &entry.node.value else {
            return Err(Error::at(
                &entry.key_location,
                "expected [[variant]] tables only",
            ));
        };
        if entry.key != "variant" {
            return Err(Error::at(
                &entry.key_location,
                format!("unknown key '{}'; expected [[variant]]", entry.key),
            ));
        }
        for item in items {
            variants.push(variant_of(item)?);
        }
    }
    if variants.is_empty() {
        return Err(Error::msg(format!("{path}: no [[variant]] tables")));
    }
    Ok(variants)
}

/// One variant's table (`name`, `set`, `image`), from a file or built in
/// code with its values located.
pub fn variant_of(item: &Node) -> Result<Variant> {
    let Value::Table(table) = &item.value else {
        return Err(Error::at(&item.location, "each variant must be a table"));
    };
    for key in table.keys() {
        if !["name", "set", "image"].contains(&key) {
            return Err(Error::at(
                &table.entry(key).unwrap().key_location,
                format!("unknown variant key '{key}'; accepted: name, set, image"),
            ));
        }
    }
    let Some(Value::String(name)) = table.get("name").map(|n| &n.value) else {
        return Err(Error::at(&item.location, "variant needs name = \"...\""));
    };
    let mut set = Vec::new();
    if let Some(node) = table.get("set") {
        let bad = || {
            Error::at(
                &node.location,
                format!("variant \"{name}\": set must be an array of \"key.path=value\" strings"),
            )
        };
        let Value::Array(values) = &node.value else {
            return Err(bad());
        };
        for v in values {
            match &v.value {
                Value::String(s) if s.contains('=') => set.push(s.clone()),
                _ => return Err(bad()),
            }
        }
    }
    let image = match table.get("image") {
        None => MeasuredImage::default(),
        Some(node) => match &node.value {
            Value::String(text) => MeasuredImage::parse(text),
            _ => None,
        }
        .ok_or_else(|| {
            Error::at(
                &node.location,
                format!("variant \"{name}\": image must be {}", MeasuredImage::NAMES),
            )
        })?,
    };
    Ok(Variant {
        name: name.clone(),
        set,
        image,
    })
}

/// A variants file is a short TOML list written by hand.
pub(super) const VARIANTS_FILE: FileKind = FileKind::new("variants", 16 * MIB);
