//! The core error type, and [`printable`]: the one way error text quotes input.

use std::borrow::Cow;
use std::fmt::Write as _;

use thiserror::Error;

/// A command-line flag (or a combination of flags) whose value the command
/// cannot use, found after parsing (a range, a combination, a flag of
/// another mode): the user's command line is wrong, not the data. The CLI
/// exits with 2 (a usage error, as for what its parser rejects) when this is
/// anywhere in an error's chain, and with 1 for everything else. The
/// message names the flag and what it expects.
#[derive(Debug, Error, PartialEq, Eq)]
#[error("{0}")]
pub struct UsageError(pub String);

impl UsageError {
    /// The error for `message` (a `String` from a flag check).
    pub fn new(message: impl Into<String>) -> Self {
        Self(message.into())
    }
}

/// Errors raised when a core type is constructed from inconsistent parts.
///
/// Constructors validate their input in release builds too: invalid data is an
/// error, never a debug assertion.
#[derive(Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum CoreError {
    /// A buffer does not have the length its declared shape implies.
    #[error("{what}: expected {expected} values, found {found}")]
    ShapeMismatch {
        /// Which buffer.
        what: &'static str,
        /// Length implied by the declared shape.
        expected: usize,
        /// Actual length.
        found: usize,
    },
    /// A value that must be finite is NaN or infinite.
    #[error("{field} is not finite ({value})")]
    NotFinite {
        /// Field name, with its unit.
        field: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A value is outside its allowed range.
    #[error("{field} = {value} is out of range: {expected}")]
    OutOfRange {
        /// Field name, with its unit.
        field: &'static str,
        /// The offending value.
        value: f64,
        /// What was expected, in words.
        expected: &'static str,
    },
    /// Timestamps that must increase strictly do not.
    #[error("{what}: time goes backwards or repeats at index {index} ({previous_t_ns} ns then {t_ns} ns)")]
    NonMonotonicTime {
        /// Which sequence of timestamps.
        what: &'static str,
        /// Index of the first offending element.
        index: usize,
        /// The timestamp before it.
        previous_t_ns: i64,
        /// The offending timestamp.
        t_ns: i64,
    },
}

/// Fails with [`CoreError::NotFinite`] unless `value` is finite.
pub(crate) fn ensure_finite(field: &'static str, value: f64) -> Result<(), CoreError> {
    if value.is_finite() { Ok(()) } else { Err(CoreError::NotFinite { field, value }) }
}

/// Fails with [`CoreError::ShapeMismatch`] unless `found == expected`.
pub(crate) fn ensure_len(what: &'static str, expected: usize, found: usize) -> Result<(), CoreError> {
    if expected == found { Ok(()) } else { Err(CoreError::ShapeMismatch { what, expected, found }) }
}

/// `input` as text that is safe to print on one terminal line: control
/// characters (newlines, escape sequences, NUL, ...) and Unicode
/// bidirectional-override characters become `\n`, `\r`, `\t`, `\xNN` or
/// `\u{NNNN}`, bytes that are not UTF-8 become `\xNN`; everything else,
/// including printable non-ASCII text, is kept. Error messages that quote
/// input (a line of a log, a field of a CSV, a file name) pass it through
/// here, so a corrupt file cannot garble the terminal or split one error
/// over several lines.
///
/// Backslashes are kept as they are, so the result is idempotent: printing
/// it through `printable` again changes nothing.
///
/// ```
/// use mmtrack_core::error::printable;
/// assert_eq!(printable("1.0 \u{1b}[31mred\n"), "1.0 \\x1b[31mred\\n");
/// assert_eq!(printable(&b"ok\xff"[..]), "ok\\xff");
/// assert_eq!(printable("Straße 5 m"), "Straße 5 m");
/// ```
pub fn printable<T: AsRef<[u8]> + ?Sized>(input: &T) -> Cow<'_, str> {
    let bytes = input.as_ref();
    if let Ok(text) = std::str::from_utf8(bytes)
        && !text.chars().any(needs_escape)
    {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(bytes.len() + 16);
    for chunk in bytes.utf8_chunks() {
        for c in chunk.valid().chars() {
            match c {
                '\n' => out.push_str("\\n"),
                '\r' => out.push_str("\\r"),
                '\t' => out.push_str("\\t"),
                c if needs_escape(c) && u32::from(c) < 0x100 => {
                    let _ = write!(out, "\\x{:02x}", u32::from(c));
                }
                c if needs_escape(c) => {
                    let _ = write!(out, "\\u{{{:04x}}}", u32::from(c));
                }
                c => out.push(c),
            }
        }
        for byte in chunk.invalid() {
            let _ = write!(out, "\\x{byte:02x}");
        }
    }
    Cow::Owned(out)
}

/// An error and its causes as one line, `outer: inner: innermost`, each part
/// once, with no control characters: the message of every front end (the
/// CLI's `error:` line, the Python package's exceptions).
///
/// Our error types name only their own part and leave the wrapped error to the
/// chain, but a context may repeat what the error below it says (a path given
/// as context to an error that names the path), and other crates' errors may
/// repeat their source in their message. So, for each cause after the first:
/// it is left out when the part before it already ends with it (or equals it),
/// and it replaces the part before it when it starts with that part. A
/// multi-line cause is folded ([`fold_snippet`]: a TOML parse error's source
/// snippet becomes the quoted line). Quoted input was escaped where it was
/// quoted; [`printable`] again here keeps any other line break visible as
/// `\n` rather than breaking the line.
///
/// `chain` is the error's own message followed by its causes', outermost
/// first (`anyhow::Error::chain`, or [`std::error::Error::source`] followed).
pub fn one_line<I, D>(chain: I) -> String
where
    I: IntoIterator<Item = D>,
    D: std::fmt::Display,
{
    let mut parts: Vec<String> = Vec::new();
    for cause in chain {
        let text = fold_snippet(cause.to_string().trim_end());
        if text.is_empty() {
            continue;
        }
        match parts.last() {
            Some(last) if *last == text || last.ends_with(&format!(": {text}")) => continue,
            Some(last) if text.starts_with(&format!("{last}: ")) => {
                parts.pop();
            }
            _ => {}
        }
        parts.push(text);
    }
    printable(&parts.join(": ")).into_owned()
}

/// A multi-line message with an annotated source snippet (the style of TOML
/// parse errors: a heading, gutter lines `  |`, numbered source lines
/// `3 | bins = "x"`, caret lines `  |    ^^^`, then the message) as one line:
/// `heading (`source line`): message`. Gutter and caret lines are dropped,
/// each numbered source line is kept quoted, other lines are joined with
/// `": "`. A single-line message is returned as it is.
#[must_use]
pub fn fold_snippet(text: &str) -> String {
    if !text.contains('\n') {
        return text.to_string();
    }
    let (mut parts, mut sources): (Vec<&str>, Vec<String>) = (Vec::new(), Vec::new());
    for line in text.lines().map(str::trim_end) {
        let trimmed = line.trim_start();
        let gutter = trimmed.split_once('|').filter(|(number, _)| number.trim().chars().all(|c| c.is_ascii_digit()));
        match gutter {
            Some((number, source)) if !number.trim().is_empty() => sources.push(format!("`{}`", source.trim())),
            Some(_) => {}
            None if trimmed.is_empty() => {}
            None => parts.push(trimmed),
        }
    }
    let Some((heading, rest)) = parts.split_first() else { return sources.join(" ") };
    let mut out = (*heading).to_string();
    if !sources.is_empty() {
        out = format!("{out} ({})", sources.join(" "));
    }
    for part in rest {
        out.push_str(": ");
        out.push_str(part);
    }
    out
}

/// Characters that must not reach a terminal as they are: C0/C1 controls and
/// DEL, and the bidirectional-text overrides that reorder what is shown.
fn needs_escape(c: char) -> bool {
    c.is_control() || matches!(c, '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
}

#[cfg(test)]
mod tests {
    use super::{fold_snippet, one_line, printable};

    /// A TOML parse error (the `toml` crate's own message) is one readable
    /// line naming the position, the offending source line and the problem,
    /// with no escaped line breaks.
    #[test]
    fn a_toml_parse_error_folds_to_one_line_with_its_source_line() {
        let unclosed = toml::from_str::<toml::Table>("seed = 1\ngarbage = [").unwrap_err();
        let line = one_line(["bad.toml: not valid TOML".to_string(), unclosed.to_string()]);
        assert_eq!(
            line,
            "bad.toml: not valid TOML: TOML parse error at line 2, column 12 (`garbage = [`): unclosed array, expected `]`"
        );
        #[derive(Debug, serde::Deserialize)]
        #[allow(dead_code)]
        struct Sensor {
            bins: usize,
        }
        let wrong = toml::from_str::<Sensor>("bins = \"x\"").unwrap_err().to_string();
        let folded = fold_snippet(&wrong);
        assert!(folded.starts_with("TOML parse error at line 1, column 8 (`bins = \"x\"`): invalid type"), "{folded}");
        assert!(!folded.contains('\n') && !one_line([&wrong]).contains("\\n"), "{folded}");
        assert_eq!(fold_snippet("one line: a | b"), "one line: a | b");
    }

    #[test]
    fn printable_escapes_controls_and_invalid_bytes_and_keeps_the_rest() {
        assert_eq!(printable("plain text, 5 m"), "plain text, 5 m");
        assert!(matches!(printable("plain"), std::borrow::Cow::Borrowed(_)), "nothing to escape: no copy");
        assert_eq!(printable("a\tb\r\nc\0"), "a\\tb\\r\\nc\\x00");
        assert_eq!(printable("\u{1b}[2J\u{7f}\u{9b}"), "\\x1b[2J\\x7f\\x9b");
        assert_eq!(printable("abc\u{202e}def"), "abc\\u{202e}def");
        assert_eq!(printable(&[b'$', 0x01, 0xff, 0xfe, b'x'][..]), "$\\x01\\xff\\xfex");
        assert_eq!(printable("Zürich → 北京"), "Zürich → 北京");
        // Idempotent: nothing left to escape the second time.
        let once = printable(&b"\x1b[31m\xc3(\n"[..]).into_owned();
        assert_eq!(printable(&once), once);
        assert!(once.chars().all(|c| !c.is_control()), "{once}");
    }
}
