//! `#[derive(ParamChoice)]`: a fieldless enum as a string parameter.

use proc_macro2::TokenStream;
use quote::quote;
use syn::spanned::Spanned;
use syn::{Data, DeriveInput, Fields, LitStr};

pub fn expand(input: &DeriveInput) -> syn::Result<TokenStream> {
    if !input.generics.params.is_empty() {
        return Err(syn::Error::new(
            input.generics.span(),
            "ParamChoice: a choice has no generics",
        ));
    }
    let Data::Enum(data) = &input.data else {
        return Err(syn::Error::new(
            input.ident.span(),
            "ParamChoice derives for a fieldless enum",
        ));
    };
    let mut variants = Vec::new();
    let mut names: Vec<LitStr> = Vec::new();
    for variant in &data.variants {
        if !matches!(variant.fields, Fields::Unit) {
            return Err(syn::Error::new(
                variant.span(),
                "ParamChoice: every variant is a plain name, without fields",
            ));
        }
        if let Some((_, d)) = &variant.discriminant {
            // The variants' numbers index the names in a default.
            return Err(syn::Error::new(
                d.span(),
                "ParamChoice: variants are numbered in order; remove the discriminant",
            ));
        }
        let mut name = LitStr::new(&kebab(&variant.ident.to_string()), variant.ident.span());
        for attr in variant.attrs.iter().filter(|a| a.path().is_ident("choice")) {
            name = attr.parse_args()?;
        }
        if let Some(same) = names.iter().find(|n| n.value() == name.value()) {
            return Err(syn::Error::new(
                name.span(),
                format!("ParamChoice: \"{}\" names two variants", same.value()),
            ));
        }
        variants.push(&variant.ident);
        names.push(name);
    }
    if variants.is_empty() {
        return Err(syn::Error::new(
            input.ident.span(),
            "ParamChoice: a choice needs variants",
        ));
    }
    let name = &input.ident;
    let core = quote!(::lumis_api::params);
    Ok(quote! {
        impl #core::ParamChoice for #name {
            const VARIANTS: &'static [Self] = &[#(#name::#variants),*];
            const NAMES: &'static [&'static str] = &[#(#names),*];

            fn name(self) -> &'static str {
                match self {
                    #(#name::#variants => #names,)*
                }
            }
        }

        impl #core::FromParam for #name {
            fn from_node(node: &::lumis_api::doc::Node) -> ::core::result::Result<Self, ::std::string::String> {
                #core::choice_from_node(node)
            }
        }

        impl #core::Param for #name {
            const TYPE: #core::ParamType = #core::ParamType::String;
            const CHOICES: &'static [&'static str] = <#name as #core::ParamChoice>::NAMES;
        }
    })
}

/// `SolidAngle` as `solid-angle`.
fn kebab(ident: &str) -> String {
    let mut out = String::new();
    let mut previous_lower = false;
    for c in ident.chars() {
        if c.is_uppercase() {
            if previous_lower {
                out.push('-');
            }
            out.extend(c.to_lowercase());
            previous_lower = false;
        } else {
            out.push(c);
            previous_lower = c.is_lowercase() || c.is_ascii_digit();
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::kebab;

    #[test]
    fn names_are_kebab_case() {
        assert_eq!(kebab("SolidAngle"), "solid-angle");
        assert_eq!(kebab("MultiSample"), "multi-sample");
        assert_eq!(kebab("Ggx"), "ggx");
        assert_eq!(kebab("None"), "none");
    }
}
