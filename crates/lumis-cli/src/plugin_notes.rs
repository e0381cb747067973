//! A plugin's module documentation (`SourceFile::notes`) as a section of
//! the book: rustdoc's Markdown with what only rustdoc understands taken
//! out, so the plugin reference renders the text its source file holds.

/// The notes without their first paragraph (rustdoc's summary line, which
/// the reference already gives as the plugin's doc line), headings moved
/// below the plugin's own (`####`), and intra-doc links (`[`Bsdf`]`,
/// `[text](crate::path)`) reduced to their text.
pub fn book_notes(notes: &str) -> String {
    let body = match notes.trim().split_once("\n\n") {
        Some((_, body)) => body.trim(),
        None => return String::new(),
    };
    let mut out = String::with_capacity(body.len());
    let mut in_code = false;
    for line in body.lines() {
        if line.trim_start().starts_with("```") {
            in_code = !in_code;
            out.push_str(line);
        } else if in_code {
            out.push_str(line);
        } else if line.starts_with('#') {
            out.push_str("###");
            out.push_str(line);
        } else {
            out.push_str(&without_intra_doc_links(line));
        }
        out.push('\n');
    }
    out
}

/// `[text](target)` whose target is a Rust path (no `/`, `.` or `#`
/// that a file or an anchor would have) becomes `text`, and `[text]`
/// followed by neither `(` nor `[` becomes `text`; web and book links,
/// and code spans, stay.
fn without_intra_doc_links(line: &str) -> String {
    let mut out = String::with_capacity(line.len());
    let mut rest = line;
    while let Some(open) = rest.find(['[', '`']) {
        out.push_str(&rest[..open]);
        let bracket = &rest[open..];
        if let Some(code) = bracket.strip_prefix('`') {
            // An inline code span, copied as it is.
            let end = code.find('`').map_or(bracket.len(), |e| e + 2);
            out.push_str(&bracket[..end]);
            rest = &bracket[end..];
            continue;
        }
        let Some(close) = bracket.find(']') else {
            out.push_str(bracket);
            return out;
        };
        let (label, tail) = (&bracket[..=close], &bracket[close + 1..]);
        let text = &label[1..label.len() - 1];
        let target = tail
            .strip_prefix('(')
            .and_then(|t| t.find(')'))
            .map(|end| &tail[1..=end]);
        let consumed = match target {
            // `[text](target)`, the target without its parentheses
            Some(target) => {
                let link_end = label.len() + 1 + target.len() + 1;
                if is_rust_path(target) {
                    out.push_str(text);
                } else {
                    out.push_str(&bracket[..link_end]);
                }
                link_end
            }
            // `[text][reference]`: left for Markdown
            None if tail.starts_with('[') => {
                let end = tail.find(']').map_or(tail.len(), |e| e + 1);
                out.push_str(&bracket[..label.len() + end]);
                label.len() + end
            }
            None if is_rust_path(text.trim_matches('`')) => {
                out.push_str(text);
                label.len()
            }
            None => {
                out.push_str(label);
                label.len()
            }
        };
        rest = &bracket[consumed..];
    }
    out.push_str(rest);
    out
}

/// A Rust item path as an intra-doc link names it (`Bsdf`,
/// `crate::bsdf::Bsdf::pdf`, `trait@Bsdf`, `Self::eval()`).
fn is_rust_path(target: &str) -> bool {
    !target.is_empty()
        && target.chars().all(|c| {
            c.is_alphanumeric() || matches!(c, '_' | ':' | '@' | '(' | ')' | '!' | '<' | '>')
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drops_the_summary_and_moves_headings_down() {
        let notes = "`x`: summary\n\n# How\n\nText.\n```text\n# not a heading\n```";
        assert_eq!(
            book_notes(notes),
            "#### How\n\nText.\n```text\n# not a heading\n```\n"
        );
        assert_eq!(book_notes("only a summary"), "");
    }

    #[test]
    fn intra_doc_links_become_text_and_other_links_stay() {
        assert_eq!(
            without_intra_doc_links("see [`Bsdf::pdf`] and [the code](crate::bsdf::pdf)."),
            "see `Bsdf::pdf` and the code."
        );
        assert_eq!(
            without_intra_doc_links("[MIS](studies/mis.md), [web](https://x.org/a), [1, 2]"),
            "[MIS](studies/mis.md), [web](https://x.org/a), [1, 2]"
        );
        assert_eq!(
            without_intra_doc_links("[a][b] and [open"),
            "[a][b] and [open"
        );
        assert_eq!(
            without_intra_doc_links("`[film]` and `a"),
            "`[film]` and `a"
        );
    }
}
