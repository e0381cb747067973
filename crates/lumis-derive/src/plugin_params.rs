//! `#[derive(PluginParams)]`: the declaration, the reader and the keys of
//! a struct of parameters.

use proc_macro2::TokenStream;
use quote::{format_ident, quote, quote_spanned};
use syn::spanned::Spanned;
use syn::{Data, DeriveInput, Field, Fields, GenericArgument, LitStr, PathArguments, Type};

use crate::attrs::{doc_line, ParamAttrs};

/// What one field contributes to each generated item.
struct Generated {
    /// An element of the list of parts the declaration concatenates.
    spec_part: TokenStream,
    /// `field: <read>` in the struct expression of `read`.
    read: TokenStream,
    /// `field: <type>` in the keys struct, and its value.
    key_field: TokenStream,
    key_value: TokenStream,
}

pub fn expand(input: &DeriveInput) -> syn::Result<TokenStream> {
    if !input.generics.params.is_empty() {
        return Err(syn::Error::new(
            input.generics.span(),
            "PluginParams: a struct of parameters has no generics (its declaration is a constant)",
        ));
    }
    let Data::Struct(data) = &input.data else {
        return Err(syn::Error::new(
            input.ident.span(),
            "PluginParams derives for a struct; a choice is an enum deriving ParamChoice",
        ));
    };
    let Fields::Named(fields) = &data.fields else {
        return Err(syn::Error::new(
            input.ident.span(),
            "PluginParams: one named field per parameter",
        ));
    };
    let generated = fields
        .named
        .iter()
        .map(field)
        .collect::<syn::Result<Vec<_>>>()?;

    let name = &input.ident;
    let vis = &input.vis;
    let keys = format_ident!("{name}Keys");
    let keys_doc =
        format!("The scene keys of `{name}`'s parameters, for messages about their values.");
    let parts = generated.iter().map(|g| &g.spec_part);
    let reads = generated.iter().map(|g| &g.read);
    let key_fields = generated.iter().map(|g| &g.key_field);
    let key_values = generated.iter().map(|g| &g.key_value);
    let core = quote!(::lumis_api::params);

    Ok(quote! {
        #[doc = #keys_doc]
        #[derive(Clone, Copy)]
        #[allow(dead_code)]
        #vis struct #keys {
            #(#key_fields,)*
        }

        impl #core::PluginParams for #name {
            const SPECS: &'static [#core::ParamSpec] = {
                const PARTS: &[&[#core::ParamSpec]] = &[#(#parts),*];
                const ALL: [#core::ParamSpec; #core::total_len(PARTS)] = #core::concat(PARTS);
                &ALL
            };
            type Keys = #keys;
            const KEYS: #keys = #keys {
                #(#key_values,)*
            };

            fn read(params: &#core::Params) -> ::lumis_api::Result<Self> {
                ::core::result::Result::Ok(Self {
                    #(#reads,)*
                })
            }
        }

        // Evaluated at compile time, so a declaration that contradicts
        // itself (two parameters of one name, a default of the wrong type,
        // out of range or among no choice) does not compile.
        const _: () = #core::check_unique(<#name as #core::PluginParams>::SPECS);
    })
}

fn field(field: &Field) -> syn::Result<Generated> {
    let ident = field.ident.as_ref().expect("named fields");
    let vis = &field.vis;
    let ty = &field.ty;
    let attrs = ParamAttrs::parse(&field.attrs)?;
    let span = field.span();
    // Spanned at the field, so an error in its declaration points there.
    let core = quote_spanned!(span=> ::lumis_api::params);

    if attrs.flatten {
        if attrs.rename.is_some() || attrs.default.is_some() || attrs.range.is_some() {
            return Err(syn::Error::new(
                span,
                "a flattened group takes only default(name = value, ...)",
            ));
        }
        let group = quote!(<#ty as #core::PluginParams>);
        let mut spec_part = quote!(#group::SPECS);
        if !attrs.group_defaults.is_empty() {
            let len = quote!({ #group::SPECS.len() });
            let mut specs = quote!(#core::concat::<#len>(&[#group::SPECS]));
            for (key, value) in &attrs.group_defaults {
                let value = value.tokens(None, key.span())?;
                specs = quote_spanned!(key.span()=> #core::override_default::<#len>(#specs, #key, #value));
            }
            spec_part = quote!(&#specs);
        }
        return Ok(Generated {
            spec_part,
            read: quote!(#ident: #group::read(params)?),
            key_field: quote!(#vis #ident: #group::Keys),
            key_value: quote!(#ident: #group::KEYS),
        });
    }
    if !attrs.group_defaults.is_empty() {
        return Err(syn::Error::new(
            span,
            "default(name = value) changes a flattened group's defaults; use default = value",
        ));
    }

    let key = attrs
        .rename
        .clone()
        .unwrap_or_else(|| LitStr::new(&ident.to_string(), ident.span()));
    let doc = doc_line(&field.attrs);
    if doc.is_empty() {
        return Err(syn::Error::new(
            span,
            "a parameter needs a /// comment: it is its description in `lumis plugins`",
        ));
    }
    let optional = option_inner(ty);
    let value_type = optional.unwrap_or(ty);
    let param = quote!(<#value_type as #core::Param>);
    let mut spec = match (&attrs.default, optional) {
        (Some(_), Some(_)) => {
            return Err(syn::Error::new(
                span,
                "an Option parameter may be absent; it takes no default",
            ))
        }
        (Some(default), None) => {
            let value = default.tokens(Some(ty), span)?;
            quote_spanned!(span=> #core::ParamSpec::with_default(#key, #param::TYPE, #value, #doc))
        }
        (None, Some(_)) => quote!(#core::ParamSpec::optional(#key, #param::TYPE, #doc)),
        (None, None) => quote!(#core::ParamSpec::required(#key, #param::TYPE, #doc)),
    };
    if let Some(range) = &attrs.range {
        let (min, max) = (&range.0, &range.1);
        spec = quote_spanned!(span=> #spec.in_range(#min, #max));
    }
    spec = quote_spanned!(span=> #spec.one_of(#param::CHOICES));
    let read = match optional {
        Some(inner) => quote!(#ident: params.optional_value::<#inner>(#key)?),
        None => quote!(#ident: params.value::<#ty>(#key)?),
    };
    Ok(Generated {
        spec_part: quote!(&[#spec]),
        read,
        key_field: quote!(#vis #ident: &'static str),
        key_value: quote!(#ident: #key),
    })
}

/// `T` of a field of type `Option<T>`.
fn option_inner(ty: &Type) -> Option<&Type> {
    let Type::Path(path) = ty else {
        return None;
    };
    let last = path.path.segments.last()?;
    if last.ident != "Option" {
        return None;
    }
    let PathArguments::AngleBracketed(args) = &last.arguments else {
        return None;
    };
    match args.args.first() {
        Some(GenericArgument::Type(inner)) if args.args.len() == 1 => Some(inner),
        _ => None,
    }
}
