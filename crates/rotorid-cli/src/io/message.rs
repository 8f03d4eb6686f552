//! The text of an error as `main` prints it: the error and its causes, joined by `: `.
//!
//! The library errors put their cause in their own message (`FILE: No such file or
//! directory`), so that a caller printing only the error (the Python exceptions, the fleet's
//! results) loses nothing, and they also report it as their `source`. Printing the whole
//! chain as anyhow's `{:#}` does would then say it twice; here a cause whose text the
//! message so far already ends with is left out.

use std::fmt::Write as _;

/// `err` and its causes, each once (module doc).
pub fn error_message(err: &anyhow::Error) -> String {
    let mut out = String::new();
    for cause in err.chain() {
        let text = cause.to_string();
        if out.is_empty() {
            out = text;
        } else if !out.ends_with(&text) {
            // writing to a String cannot fail
            let _ = write!(out, ": {text}");
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use anyhow::Context as _;

    fn not_found() -> std::io::Error {
        std::io::Error::new(std::io::ErrorKind::NotFound, "No such file or directory")
    }

    #[test]
    fn a_cause_the_message_already_ends_with_is_said_once() {
        let e = rotorid_io::ReadError::Io {
            file: "a.tdms".into(),
            source: not_found(),
        };
        // (anyhow's own chain says it twice)
        let err = anyhow::Error::new(e);
        assert_eq!(
            format!("{err:#}"),
            "a.tdms: No such file or directory: No such file or directory"
        );
        assert_eq!(error_message(&err), "a.tdms: No such file or directory");
    }

    #[test]
    fn contexts_and_causes_not_in_the_message_are_all_said() {
        let err = Err::<(), _>(not_found())
            .context("cannot write est.csv")
            .context("identify")
            .unwrap_err();
        assert_eq!(
            error_message(&err),
            "identify: cannot write est.csv: No such file or directory"
        );
        let err = anyhow::anyhow!("plain");
        assert_eq!(error_message(&err), "plain");
    }
}
