//! A command's output on standard output, written so that a failed write (a full disk, a
//! closed file) ends the command with a clear error instead of a panic: `println!` panics
//! ("failed printing to stdout") when the write fails, these return the error.
//!
//! A reader that stops reading (`spdcam … | head`) still ends spdcam quietly: `main` leaves
//! SIGPIPE at its default, so such a write never returns.

use anyhow::{anyhow, Error, Result};
use std::fmt::Arguments;
use std::io::{self, Write};

/// Writes `args` and a newline to standard output and flushes them, so that a failure is
/// seen at the line that failed. Use through [`outln!`](crate::outln).
pub fn write_line(args: Arguments<'_>) -> Result<()> {
    let mut out = io::stdout().lock();
    out.write_fmt(args)
        .and_then(|()| out.write_all(b"\n"))
        .and_then(|()| out.flush())
        .map_err(error)
}

/// The error of a failed write to standard output: "could not write to standard output:
/// No space left on device", without the OS's error number.
pub fn error(e: io::Error) -> Error {
    let text = e.to_string();
    let reason = match text.find(" (os error") {
        Some(at) => &text[..at],
        None => &text,
    };
    anyhow!("could not write to standard output: {reason}")
}

/// [`error`] for an I/O error that `e` carries (a write to standard output that failed);
/// any other error as it is.
pub fn io_error(e: Error) -> Error {
    match e.downcast::<io::Error>() {
        Ok(io) => error(io),
        Err(e) => e,
    }
}

/// `println!` that returns the error of a failed write instead of panicking:
/// `outln!("{n} estimates")?`.
#[macro_export]
macro_rules! outln {
    () => {
        $crate::stdout::write_line(format_args!(""))
    };
    ($($arg:tt)*) => {
        $crate::stdout::write_line(format_args!($($arg)*))
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_error_says_what_failed_without_the_os_number() {
        let e = error(io::Error::from_raw_os_error(28)).to_string();
        assert_eq!(
            e,
            "could not write to standard output: No space left on device"
        );
    }
}
