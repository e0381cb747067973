//! What a field says about its parameter: `#[param(...)]` and its `///`
//! comment.

use syn::{Attribute, Expr, Ident, Lit, LitStr, Meta};

use crate::value::{Range, Value};

/// The parsed `#[param(...)]` attributes of one field.
#[derive(Default)]
pub struct ParamAttrs {
    pub rename: Option<LitStr>,
    pub default: Option<Value>,
    pub range: Option<Range>,
    pub flatten: bool,
    /// `default(key = value, ...)` on a flattened group.
    pub group_defaults: Vec<(LitStr, Value)>,
}

impl ParamAttrs {
    pub fn parse(attrs: &[Attribute]) -> syn::Result<Self> {
        let mut out = Self::default();
        for attr in attrs.iter().filter(|a| a.path().is_ident("param")) {
            attr.parse_nested_meta(|meta| {
                if meta.path.is_ident("rename") {
                    out.rename = Some(meta.value()?.parse()?);
                } else if meta.path.is_ident("range") {
                    out.range = Some(meta.value()?.parse()?);
                } else if meta.path.is_ident("flatten") {
                    out.flatten = true;
                } else if meta.path.is_ident("default") {
                    if meta.input.peek(syn::Token![=]) {
                        out.default = Some(meta.value()?.parse()?);
                    } else {
                        meta.parse_nested_meta(|inner| {
                            let key: &Ident = inner
                                .path
                                .get_ident()
                                .ok_or_else(|| inner.error("expected a parameter's name"))?;
                            let key = LitStr::new(&key.to_string(), key.span());
                            out.group_defaults.push((key, inner.value()?.parse()?));
                            Ok(())
                        })?;
                    }
                } else {
                    return Err(meta.error(
                        "expected default = ..., range = (min, max), rename = \"...\", flatten or default(name = ...)",
                    ));
                }
                Ok(())
            })?;
        }
        Ok(out)
    }
}

/// The `///` comment as one line: its lines trimmed and joined by spaces.
pub fn doc_line(attrs: &[Attribute]) -> String {
    let mut words = Vec::new();
    for attr in attrs.iter().filter(|a| a.path().is_ident("doc")) {
        if let Meta::NameValue(nv) = &attr.meta {
            if let Expr::Lit(expr) = &nv.value {
                if let Lit::Str(text) = &expr.lit {
                    let text = text.value();
                    let line = text.trim();
                    if !line.is_empty() {
                        words.push(line.to_string());
                    }
                }
            }
        }
    }
    words.join(" ")
}
