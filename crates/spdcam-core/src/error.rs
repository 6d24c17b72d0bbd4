//! The error type of the simulation library: every variant names what is wrong and where.

use std::path::PathBuf;

/// Errors of spdcam-core. Messages name the file, line, column or value that is wrong.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be read or written.
    #[error("{}: {}", path.display(), io_words(source))]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// What the operating system said.
        #[source]
        source: std::io::Error,
    },
    /// A spectral CSV (or other table) is malformed; `source_name` is the file or built-in name.
    #[error("{source_name}: {message}")]
    Parse {
        /// The file or built-in table.
        source_name: String,
        /// What is wrong, and where in it.
        message: String,
    },
    /// A value is out of its valid range or inconsistent with another one.
    #[error("{0}")]
    Invalid(String),
    /// A name was not found among the known ones.
    #[error("unknown {kind} '{name}'; valid: {valid}")]
    UnknownName {
        /// What kind of thing was named (`camera`, `chart`, …).
        kind: &'static str,
        /// The name given.
        name: String,
        /// The names that are known, comma-separated.
        valid: String,
    },
    /// An image could not be decoded or encoded.
    #[error("{context}: {message}")]
    Image {
        /// The image file or what it was for.
        context: String,
        /// The decoder's or encoder's message.
        message: String,
    },
}

impl Error {
    /// Shorthand for [`Error::Invalid`].
    pub fn invalid(message: impl Into<String>) -> Self {
        Error::Invalid(message.into())
    }

    /// Shorthand for [`Error::Parse`].
    pub fn parse(source_name: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Parse {
            source_name: source_name.into(),
            message: message.into(),
        }
    }

    /// Wraps an I/O error with the path it concerns.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
}

/// What the operating system said about a file, in words that say what to do for the
/// errors a person meets most (a wrong path, a file they may not read, a folder given for a
/// file); the system's own words otherwise.
fn io_words(source: &std::io::Error) -> String {
    use std::io::ErrorKind;
    match source.kind() {
        ErrorKind::NotFound => {
            "no such file or folder: check the path's spelling, and that it is relative to \
             the folder the command runs in"
                .into()
        }
        ErrorKind::PermissionDenied => {
            "permission denied: this user may not open it (check its permissions)".into()
        }
        ErrorKind::IsADirectory => "is a folder: give a file in it".into(),
        _ => source.to_string(),
    }
}

/// A number for a message, short whatever its size: as written (`0.8`, `1500`) between
/// 1e-4 and 1e6, else in scientific notation (`1e300`, `2.5e-320`), so that a huge value
/// does not become a 300-digit line.
pub fn short_number(value: f64) -> String {
    let size = value.abs();
    if value == 0.0 || !value.is_finite() || (1e-4..1e6).contains(&size) {
        format!("{value}")
    } else {
        format!("{value:e}")
    }
}

/// At most this many names are listed in one message.
const LISTED_NAMES: usize = 10;

/// Names for a one-line message: all of them joined by ", " when there are few, else the
/// first `LISTED_NAMES` (10) and how many there are (a file with 2000 columns must not make a
/// 13 kB error line).
pub fn brief_list<S: AsRef<str>>(names: &[S]) -> String {
    let shown: Vec<&str> = names.iter().take(LISTED_NAMES).map(AsRef::as_ref).collect();
    if names.len() <= LISTED_NAMES {
        shown.join(", ")
    } else {
        format!("{}, … ({} in all)", shown.join(", "), names.len())
    }
}

/// Result with the library's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_file_says_what_to_do() {
        let missing = std::io::Error::from(std::io::ErrorKind::NotFound);
        let text = Error::io("missing.jpg", missing).to_string();
        assert!(
            text.starts_with("missing.jpg: no such file or folder: check the path"),
            "{text}"
        );
        let other = std::io::Error::other("disk on fire");
        assert_eq!(Error::io("x", other).to_string(), "x: disk on fire");
    }

    #[test]
    fn long_name_lists_are_cut() {
        assert_eq!(brief_list(&["a", "b"]), "a, b");
        let many: Vec<String> = (0..2000).map(|i| format!("column_{i}")).collect();
        let text = brief_list(&many);
        assert!(text.ends_with("column_9, … (2000 in all)"), "{text}");
        assert!(text.len() < 200);
    }
}
