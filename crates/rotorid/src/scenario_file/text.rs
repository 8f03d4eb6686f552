//! A scenario file's text and where things are in it: the reader every section's parser
//! (`parse`, `acquisition`, `finite_element`) reports lines and values through.

use std::ops::Range;

use toml_edit::Key;

/// Parses one scenario file's text; `origin` (the file name) prefixes every message.
pub(super) struct Parser<'a> {
    pub(super) origin: &'a str,
    pub(super) text: &'a str,
}

impl Parser<'_> {
    /// 1-based line of byte offset `pos`.
    pub(super) fn line(&self, pos: usize) -> usize {
        let pos = pos.min(self.text.len());
        self.text.as_bytes()[..pos]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            + 1
    }

    pub(super) fn key_line(&self, key: Option<&Key>) -> Option<usize> {
        key.and_then(Key::span).map(|s| self.line(s.start))
    }

    /// The source text of `span`, on one line; `{...}` for a table that has none (the
    /// implicit table of a dotted key).
    pub(super) fn written(&self, span: Option<Range<usize>>) -> String {
        match span.and_then(|s| self.text.get(s)) {
            Some(t) => t.split_whitespace().collect::<Vec<_>>().join(" "),
            None => "{...}".to_owned(),
        }
    }
}
