//! `#[plugin_interface]`: the wrappers of a trait object (the panic guard
//! of a loaded plugin, the profiler's stages) generated from the trait's
//! own declaration, so that a method added to the trait is forwarded by
//! every wrapper the moment it is declared.
//!
//! For a trait `T`, the expansion is the trait itself (with the helper
//! attributes below removed) and
//!
//! ```text
//! impl<C, H> T for ::lumis_api::wrap::Wrapped<C, H>
//! where C: Deref (+ DerefMut if a method takes `&mut self`) + Send + Sync,
//!       C::Target: T, H: ::lumis_api::wrap::CallHook
//! ```
//!
//! whose every method, provided or required, runs the wrapped object's
//! method through the hook (`hook.call("T::method", || inner.method(..))`).
//! A method whose call faulted answers with its `#[on_fault(expr)]` (the
//! arguments, and the fault as `fault`, are in scope), else with
//! `Neutral::neutral()` of its return type. A returned `Box<dyn X>` (a
//! sampler's clone) is wrapped in turn with the hook's `child()`. The lanes
//! a batched method writes into its `out` argument are shown to the hook
//! (`seen`) after the call.
//!
//! `#[wrappers_answer(expr)]` on a method makes every wrapper answer it
//! without asking the wrapped object: for a method whose answer would let
//! the caller step around the wrapper (`Scene::as_any`).
//!
//! With `#[plugin_interface(lane_view = Lane)]`, the expansion also
//! implements `T` for `Lane<'_>`, one lane of a batch (`lanes`, `index`):
//! a `&mut self` method calls the batch's method of the same name with
//! the lane first, `samples_per_pixel` is the batch's, and any other
//! `&self` method asks the lane's own copy (`clone_lane`).

use proc_macro2::TokenStream;
use quote::{format_ident, quote};
use syn::parse::{Parse, ParseStream};
use syn::{
    Attribute, Expr, FnArg, Ident, ItemTrait, Pat, PathArguments, ReturnType, TraitItem,
    TraitItemFn, Type,
};

/// The attribute's arguments: `lane_view = Ident`, optionally.
pub struct Args {
    lane_view: Option<Ident>,
}

impl Parse for Args {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        if input.is_empty() {
            return Ok(Self { lane_view: None });
        }
        let key: Ident = input.parse()?;
        if key != "lane_view" {
            return Err(syn::Error::new(key.span(), "expected `lane_view = Type`"));
        }
        input.parse::<syn::Token![=]>()?;
        Ok(Self {
            lane_view: Some(input.parse()?),
        })
    }
}

/// One method as the wrappers see it.
struct Method {
    sig: syn::Signature,
    /// The argument names, `arg{i}` where the declaration has a pattern.
    args: Vec<Ident>,
    /// Whether argument `i` is a `&mut` reference (passed reborrowed).
    mutable_refs: Vec<bool>,
    takes_mut_self: bool,
    on_fault: Option<Expr>,
    wrappers_answer: Option<Expr>,
}

pub fn expand(args: Args, mut item: ItemTrait) -> syn::Result<TokenStream> {
    let mut methods = Vec::new();
    for trait_item in &mut item.items {
        if let TraitItem::Fn(method) = trait_item {
            methods.push(read_method(method)?);
        }
    }
    let wrapped = wrapped_impl(&item, &methods);
    let lane_view = match &args.lane_view {
        Some(view) => lane_view_impl(&item, &methods, view),
        None => TokenStream::new(),
    };
    Ok(quote! {
        #item
        #wrapped
        #lane_view
    })
}

/// Reads `method`'s signature and takes its helper attributes off.
fn read_method(method: &mut TraitItemFn) -> syn::Result<Method> {
    let on_fault = take_attribute(&mut method.attrs, "on_fault")?;
    let wrappers_answer = take_attribute(&mut method.attrs, "wrappers_answer")?;
    let mut sig = method.sig.clone();
    let mut args = Vec::new();
    let mut mutable_refs = Vec::new();
    let mut takes_mut_self = false;
    let mut has_receiver = false;
    for (i, input) in sig.inputs.iter_mut().enumerate() {
        match input {
            FnArg::Receiver(receiver) => {
                has_receiver = true;
                takes_mut_self = receiver.mutability.is_some();
            }
            FnArg::Typed(typed) => {
                let name = match &*typed.pat {
                    Pat::Ident(ident) => ident.ident.clone(),
                    _ => format_ident!("arg{i}"),
                };
                *typed.pat = syn::parse_quote!(#name);
                mutable_refs
                    .push(matches!(&*typed.ty, Type::Reference(r) if r.mutability.is_some()));
                args.push(name);
            }
        }
    }
    if !has_receiver {
        return Err(syn::Error::new(
            sig.ident.span(),
            "a plugin interface's methods take `&self` or `&mut self`, so wrappers can forward them",
        ));
    }
    Ok(Method {
        sig,
        args,
        mutable_refs,
        takes_mut_self,
        on_fault,
        wrappers_answer,
    })
}

/// Removes `#[name(expr)]` from `attrs`, returning its expression.
fn take_attribute(attrs: &mut Vec<Attribute>, name: &str) -> syn::Result<Option<Expr>> {
    let Some(at) = attrs.iter().position(|a| a.path().is_ident(name)) else {
        return Ok(None);
    };
    let attribute = attrs.remove(at);
    attribute.parse_args::<Expr>().map(Some)
}

/// The call arguments: `&mut` references reborrowed, so that the fault
/// answer may still use them.
fn call_args(method: &Method) -> Vec<TokenStream> {
    method
        .args
        .iter()
        .zip(&method.mutable_refs)
        .map(|(name, &mutable)| {
            if mutable {
                quote!(&mut *#name)
            } else {
                quote!(#name)
            }
        })
        .collect()
}

/// `Box<dyn X>`: a plugin object the wrapped one made.
fn returns_boxed_object(output: &ReturnType) -> bool {
    let ReturnType::Type(_, ty) = output else {
        return false;
    };
    let Type::Path(path) = &**ty else {
        return false;
    };
    let Some(last) = path.path.segments.last() else {
        return false;
    };
    if last.ident != "Box" {
        return false;
    }
    let PathArguments::AngleBracketed(generics) = &last.arguments else {
        return false;
    };
    matches!(
        generics.args.first(),
        Some(syn::GenericArgument::Type(Type::TraitObject(_)))
    )
}

fn wrapped_impl(item: &ItemTrait, methods: &[Method]) -> TokenStream {
    let name = &item.ident;
    let needs_mut = methods.iter().any(|m| m.takes_mut_self);
    let deref_mut = needs_mut.then(|| quote!(+ ::core::ops::DerefMut));
    let bodies = methods.iter().map(|method| {
        let sig = &method.sig;
        if let Some(answer) = &method.wrappers_answer {
            let args = &method.args;
            return quote! {
                #[inline]
                #sig {
                    let _ = (#(&#args,)*);
                    #answer
                }
            };
        }
        let ident = &sig.ident;
        let label = format!("{name}::{ident}");
        let args = call_args(method);
        let parts = if method.takes_mut_self {
            quote!(let (inner, hook) = ::lumis_api::wrap::Wrapped::parts_mut(self);)
        } else {
            quote!(let (inner, hook) = ::lumis_api::wrap::Wrapped::parts(self);)
        };
        let value = if returns_boxed_object(&sig.output) {
            quote!(::std::boxed::Box::new(::lumis_api::wrap::Wrapped::new(
                value,
                ::lumis_api::wrap::CallHook::child(hook),
            )))
        } else {
            quote!(value)
        };
        // A batched method's answers are its `out` lanes.
        let seen = method
            .args
            .iter()
            .zip(&method.mutable_refs)
            .find(|(name, &mutable)| mutable && *name == "out")
            .map(|(out, _)| quote!(::lumis_api::wrap::CallHook::seen(hook, &*#out);));
        let fault = match &method.on_fault {
            Some(answer) => quote!(#answer),
            None => quote!(::lumis_api::wrap::Neutral::neutral()),
        };
        quote! {
            #[inline]
            #sig {
                #parts
                match ::lumis_api::wrap::CallHook::call(hook, #label, || inner.#ident(#(#args),*)) {
                    ::core::result::Result::Ok(value) => {
                        #seen
                        #value
                    }
                    ::core::result::Result::Err(fault) => {
                        let _ = &fault;
                        #fault
                    }
                }
            }
        }
    });
    quote! {
        impl<C, H> #name for ::lumis_api::wrap::Wrapped<C, H>
        where
            C: ::core::ops::Deref #deref_mut + ::core::marker::Send + ::core::marker::Sync,
            C::Target: #name,
            H: ::lumis_api::wrap::CallHook,
        {
            #(#bodies)*
        }
    }
}

fn lane_view_impl(item: &ItemTrait, methods: &[Method], view: &Ident) -> TokenStream {
    let name = &item.ident;
    let bodies = methods.iter().map(|method| {
        let sig = &method.sig;
        let ident = &sig.ident;
        let args = call_args(method);
        let body = if method.takes_mut_self {
            quote!(self.lanes.#ident(self.index, #(#args),*))
        } else if ident == "samples_per_pixel" {
            quote!(self.lanes.samples_per_pixel())
        } else {
            quote!(self.lanes.clone_lane(self.index).#ident(#(#args),*))
        };
        quote! {
            #[inline]
            #sig {
                #body
            }
        }
    });
    quote! {
        impl #name for #view<'_> {
            #(#bodies)*
        }
    }
}
