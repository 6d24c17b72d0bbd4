//! Where a command's human messages go: standard output, unless standard output carries
//! the command's data (`-o -`, `--features -`, `--json`), when they go to standard error so
//! that the data stays clean for the program reading it.

use std::fmt::Display;

/// The destination of a command's messages for one run.
#[derive(Debug, Clone, Copy)]
pub struct Messages {
    to_stderr: bool,
}

impl Messages {
    /// Messages for a run whose standard output carries data when `stdout_carries_data`.
    pub fn new(stdout_carries_data: bool) -> Messages {
        Messages {
            to_stderr: stdout_carries_data,
        }
    }

    /// Prints one message line; a failed write to standard output is an error (see
    /// [`crate::stdout`]).
    pub fn say(&self, text: impl Display) -> anyhow::Result<()> {
        if self.to_stderr {
            eprintln!("{text}");
            Ok(())
        } else {
            crate::outln!("{text}")
        }
    }
}
