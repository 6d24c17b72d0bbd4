//! What `estimate --features` prints of each row as the row is estimated.

use super::print::summary_line;
use super::DETAILED_MAX;
use crate::outln;
use anyhow::Result;
use spdcam_infer::Estimate;

/// What `estimate --features` writes of each row as it is estimated, besides the SPDs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum RowLines {
    /// Nothing: the first [`DETAILED_MAX`] rows are judged and printed at the end.
    None,
    /// `--json`: every row judged, one JSON object per line (JSON Lines).
    Json,
    /// No `-o`: beyond [`DETAILED_MAX`] rows, every row judged, one summary line each.
    Summary,
}

impl RowLines {
    /// Prints what `self` asks of row `row` (0-based), judged as `e`: its JSON line, or,
    /// from the row after the first [`DETAILED_MAX`], its summary line (the first rows'
    /// lines, held in `first` till then, printed first).
    pub(super) fn print(self, first: &[Estimate], row: usize, e: &Estimate) -> Result<()> {
        match self {
            RowLines::None => {}
            RowLines::Json => outln!("{}", serde_json::to_string(&e.to_json()?)?)?,
            RowLines::Summary if row < DETAILED_MAX => {}
            RowLines::Summary => {
                if row == DETAILED_MAX {
                    outln!(
                        "more than {DETAILED_MAX} rows: one line per estimate as it is made \
                     (CIE xy, CCT, Duv, verdict); -o FILE.csv writes the SPDs, --json \
                     every number as JSON Lines"
                    )?;
                    for held in first {
                        outln!("{}", summary_line(held))?;
                    }
                }
                outln!("{}", summary_line(e))?;
            }
        }
        Ok(())
    }
}
