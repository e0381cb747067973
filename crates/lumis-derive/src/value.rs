//! Default values as written in `#[param(default = ...)]`: the literals of
//! a scene file, or a variant of a choice, turned into a
//! `lumis_api::params::ParamValue` constant.

use proc_macro2::{Span, TokenStream};
use quote::{quote, quote_spanned};
use syn::parse::{Parse, ParseStream};
use syn::spanned::Spanned;
use syn::{bracketed, parenthesized, Lit, Path, Token, Type};

/// A default as written.
pub enum Value {
    Bool(bool),
    /// An integer's tokens, sign included.
    Int(TokenStream),
    /// A float's tokens, sign included.
    Float(TokenStream),
    Str(String),
    Array(Vec<Value>),
    /// A variant of a choice enum: `Ggx` (of the field's type) or
    /// `Distribution::Ggx`.
    Variant(Path),
}

impl Parse for Value {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        if input.peek(syn::token::Bracket) {
            let content;
            bracketed!(content in input);
            let items = content.parse_terminated(Value::parse, Token![,])?;
            return Ok(Value::Array(items.into_iter().collect()));
        }
        if input.peek(Token![-]) {
            let minus: Token![-] = input.parse()?;
            return match input.parse::<Lit>()? {
                Lit::Int(i) => Ok(Value::Int(quote_spanned!(i.span()=> #minus #i))),
                Lit::Float(f) => Ok(Value::Float(quote_spanned!(f.span()=> #minus #f))),
                other => Err(syn::Error::new(other.span(), "only numbers take a sign")),
            };
        }
        if input.peek(Lit) {
            return match input.parse::<Lit>()? {
                Lit::Bool(b) => Ok(Value::Bool(b.value)),
                Lit::Int(i) if i.suffix().is_empty() => Ok(Value::Int(quote!(#i))),
                Lit::Float(f) if f.suffix().is_empty() => Ok(Value::Float(quote!(#f))),
                Lit::Str(s) => Ok(Value::Str(s.value())),
                other => Err(syn::Error::new(
                    other.span(),
                    "a default is written as in a scene file: true, 16, 0.5, \"text\", [..], or a choice's variant",
                )),
            };
        }
        Ok(Value::Variant(input.parse()?))
    }
}

impl Value {
    /// The `ParamValue` constant. A variant is of `field_type` when there
    /// is one (a field's own default), else of the enum its path names (a
    /// flattened group's default, `Sampling::SolidAngle`).
    pub fn tokens(&self, field_type: Option<&Type>, span: Span) -> syn::Result<TokenStream> {
        let value = quote!(::lumis_api::params::ParamValue);
        Ok(match self {
            Value::Bool(b) => quote!(#value::Bool(#b)),
            Value::Int(i) => quote!(#value::Int(#i)),
            Value::Float(f) => quote!(#value::Float(#f)),
            Value::Str(s) => quote!(#value::Str(#s)),
            Value::Array(items) => {
                let items = items
                    .iter()
                    .map(|v| v.tokens(None, span))
                    .collect::<syn::Result<Vec<_>>>()?;
                quote!(#value::Array(&[#(#items),*]))
            }
            Value::Variant(path) => {
                let (enum_type, variant) = match (path.segments.len(), field_type) {
                    (1, Some(ty)) => (quote!(#ty), quote!(<#ty>::#path)),
                    (_, Some(ty)) => (quote!(#ty), quote!(#path)),
                    (1, None) => {
                        return Err(syn::Error::new(
                            path.span(),
                            "name the choice's enum too, e.g. Sampling::SolidAngle",
                        ))
                    }
                    (_, None) => {
                        let mut enum_path = path.clone();
                        enum_path.segments.pop();
                        enum_path.segments.pop_punct();
                        (quote!(#enum_path), quote!(#path))
                    }
                };
                // A const of the enum's type: a variant of another enum
                // does not compile. Variants are numbered in order (the
                // derive refuses explicit discriminants), so the number
                // indexes the names.
                quote_spanned! {span=> {
                    const VARIANT: #enum_type = #variant;
                    #value::Str(
                        <#enum_type as ::lumis_api::params::ParamChoice>::NAMES[VARIANT as usize],
                    )
                }}
            }
        })
    }
}

/// `(min, max)` of `#[param(range = (min, max))]`, as `f64` tokens.
pub struct Range(pub TokenStream, pub TokenStream);

impl Parse for Range {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let content;
        parenthesized!(content in input);
        let min = number(&content)?;
        content.parse::<Token![,]>()?;
        let max = number(&content)?;
        if !content.is_empty() {
            return Err(content.error("a range is (min, max)"));
        }
        Ok(Range(min, max))
    }
}

fn number(input: ParseStream) -> syn::Result<TokenStream> {
    match input.parse::<Value>()? {
        Value::Int(t) | Value::Float(t) => Ok(quote!((#t) as f64)),
        _ => Err(input.error("a range's bounds are numbers")),
    }
}
