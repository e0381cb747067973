//! `source_file!()`: the file a plugin is declared in and that file's
//! module documentation, so that the plugin reference renders the same
//! text rustdoc does and one file holds a plugin's code and its
//! description (as Mitsuba 3's plugins carry theirs).

use proc_macro2::{Span, TokenStream};
use quote::quote;

pub fn expand() -> syn::Result<TokenStream> {
    // The file the macro is written in, as rustc was given it; absent only
    // where no file backs the code (a tool expanding macros on its own).
    let notes = match proc_macro::Span::call_site().local_file() {
        Some(path) => {
            let text = std::fs::read_to_string(&path).map_err(|err| {
                syn::Error::new(
                    Span::call_site(),
                    format!(
                        "cannot read {} for its module documentation: {err}",
                        path.display()
                    ),
                )
            })?;
            module_doc(&text)
        }
        None => String::new(),
    };
    Ok(quote! {
        ::lumis_api::SourceFile { path: ::core::file!(), notes: #notes }
    })
}

/// The `//!` lines at the head of a Rust file, without their markers.
fn module_doc(text: &str) -> String {
    let mut lines = Vec::new();
    for line in text.lines().map(str::trim_start) {
        match line.strip_prefix("//!") {
            Some(doc) => lines.push(doc.strip_prefix(' ').unwrap_or(doc)),
            None if lines.is_empty() && line.is_empty() => continue,
            None => break,
        }
    }
    lines.join("\n")
}

#[cfg(test)]
mod tests {
    use super::module_doc;

    #[test]
    fn module_doc_is_the_leading_inner_comment() {
        let text = "\n//! Title\n//!\n//!  indented\nuse x;\n//! not this\n";
        assert_eq!(module_doc(text), "Title\n\n indented");
        assert_eq!(module_doc("use x;\n//! late\n"), "");
    }
}
