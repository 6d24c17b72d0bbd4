//! `estimate --features`: feature rows streamed through the model a block at a time.

use super::print::{print_estimates, report_item, verdict_line, write_report};
use super::row_lines::RowLines;
use super::truth::read_truths;
use super::{quiet, EstimateArgs, LayoutArg, DETAILED_MAX};
use crate::plot_file::write_plot;
use crate::{outln, stdout};
use anyhow::{bail, Result};
use spdcam_core::fsio;
use spdcam_core::spectral::{Grid, SpectralSet};
use spdcam_infer::estimate::Score;
use spdcam_infer::estimator::EstimatedBlock;
use spdcam_infer::stream::{
    long_header, long_rows, row_name, FeatureStream, Layout, WIDE_LAYOUT_MAX_ROWS,
};
use spdcam_infer::trust::Uncertainty;
use spdcam_infer::{Estimate, Estimator, RowStream};
use spdcam_present::plot::spds_band_svg;
use std::io::Write;
use std::path::Path;

/// Rows judged at a time when every row is judged (`--json`, one line per row): enough to
/// keep the cores busy, few enough that lines come out as the rows are estimated.
const JUDGED_AT_ONCE: usize = 64;

/// What `estimate --features` keeps while it streams: the first estimates (to print and
/// plot), the scores against the truths, and the count.
pub(super) struct FeatureRun {
    model: String,
    grid: Grid,
    truths: Option<SpectralSet>,
    /// The first [`DETAILED_MAX`] estimates, judged.
    first: Vec<Estimate>,
    rows: usize,
    /// (sum of GFC, sum of RMSE) over the scored estimates.
    score_sums: (f64, f64),
    /// Every SPD while the output may still be laid out wide (row-major).
    wide: Option<Vec<f64>>,
    layout: Option<Layout>,
    lines: RowLines,
}

impl FeatureRun {
    /// The truth of row `row`: the only one, or the row's own.
    fn truth(&self, row: usize) -> Result<Option<&[f64]>> {
        let Some(set) = &self.truths else {
            return Ok(None);
        };
        match set.len() {
            1 => Ok(Some(set.item(0))),
            n if row < n => Ok(Some(set.item(row))),
            n => bail!("{n} true SPDs for more estimates; give one, or one per estimate"),
        }
    }

    /// Takes a block of estimated rows: scores, keeps the first judged estimates, prints
    /// each row's JSON line or summary line, writes the SPDs.
    fn add(
        &mut self,
        stream: &RowStream,
        block: &EstimatedBlock,
        out: &mut Option<&mut dyn Write>,
    ) -> Result<()> {
        let width = self.grid.count;
        let spds = &block.spds;
        let scores: Vec<Option<Score>> = spds
            .chunks_exact(width)
            .enumerate()
            .map(|(k, spd)| match self.truth(block.first_row + k)? {
                Some(t) => Ok(Some(Score::of(t, spd)?)),
                None => Ok(None),
            })
            .collect::<Result<_>>()?;
        for s in scores.iter().flatten() {
            self.score_sums.0 += s.gfc;
            self.score_sums.1 += s.rmse;
        }
        let judged = match self.lines {
            RowLines::None => DETAILED_MAX
                .saturating_sub(self.first.len())
                .min(block.rows),
            RowLines::Json | RowLines::Summary => block.rows,
        };
        for start in (0..judged).step_by(JUDGED_AT_ONCE) {
            let end = (start + JUDGED_AT_ONCE).min(judged);
            for (k, mut e) in (start..end).zip(stream.estimates(block, start..end)?) {
                e.truth = scores[k];
                self.lines.print(&self.first, block.first_row + k, &e)?;
                if self.first.len() < DETAILED_MAX {
                    self.first.push(e);
                }
            }
        }
        self.rows += block.rows;
        if let Some(out) = out {
            if let Some(wide) = &mut self.wide {
                wide.extend_from_slice(spds);
                if self.layout.is_none() && self.rows > WIDE_LAYOUT_MAX_ROWS {
                    self.layout = Some(Layout::Long);
                    let held = std::mem::take(wide);
                    self.wide = None;
                    out.write_all(long_header(&self.grid).as_bytes())?;
                    out.write_all(&long_rows(&held, width, 0))?;
                }
            } else {
                if block.first_row == 0 {
                    out.write_all(long_header(&self.grid).as_bytes())?;
                }
                out.write_all(&long_rows(spds, width, block.first_row))?;
            }
        }
        Ok(())
    }

    /// Writes the estimates held for the wide layout.
    fn finish(&mut self, out: &mut Option<&mut dyn Write>) -> Result<()> {
        if let (Some(out), Some(wide)) = (out, self.wide.take()) {
            let width = self.grid.count;
            let set = SpectralSet::on_grid(
                &self.grid,
                (0..self.rows).map(row_name).collect(),
                wide.chunks_exact(width).map(<[f64]>::to_vec).collect(),
            )?;
            out.write_all(set.to_csv_string().as_bytes())?;
        }
        Ok(())
    }
}

/// `estimate --features`: the rows of the features CSV streamed through the model for their
/// columns a block at a time by the estimator, the SPDs written as they come (long layout),
/// so that time is linear in the rows and memory bounded whatever their number. The full
/// judged estimates (colorimetry, lighting metrics, verdict, bands) are made only for what
/// is printed: the estimates shown in full (up to 20), the plot's title, every estimate of
/// `--json` (one JSON object per line, JSON Lines, as it is made), and without `-o` beyond 20
/// rows every estimate's summary line (as it is made).
pub(super) fn run_features(args: &EstimateArgs, path: &Path, estimator: &Estimator) -> Result<()> {
    let source = path.display().to_string();
    let mut stream = estimator.stream(FeatureStream::open(path)?, &source)?;
    let grid = *estimator.grid();
    let mut run = FeatureRun {
        model: stream.model_name().to_string(),
        grid,
        truths: args
            .truth
            .as_deref()
            .map(|t| read_truths(t, &grid))
            .transpose()?,
        first: Vec::new(),
        rows: 0,
        score_sums: (0.0, 0.0),
        wide: (args.layout != Some(LayoutArg::Long)).then(Vec::new),
        layout: args.layout.map(|l| match l {
            LayoutArg::Wide => Layout::Wide,
            LayoutArg::Long => Layout::Long,
        }),
        lines: if args.photo.json {
            RowLines::Json
        } else if args.output.is_none() {
            RowLines::Summary
        } else {
            RowLines::None
        },
    };
    let mut estimate_all = |out: &mut Option<&mut dyn Write>| -> Result<()> {
        while let Some(block) = stream.next_block()? {
            run.add(&stream, &block, out)?;
        }
        if run.rows == 0 {
            bail!("{source}: no rows of features below the header");
        }
        run.finish(out)
    };
    match &args.output {
        None => estimate_all(&mut None)?,
        Some(out) if fsio::is_stdout(out) => {
            let mut lock = std::io::BufWriter::new(std::io::stdout().lock());
            estimate_all(&mut Some(&mut lock as &mut dyn Write)).map_err(stdout::io_error)?;
            lock.flush().map_err(stdout::error)?;
        }
        Some(out) => {
            let mut failure = None;
            let written = fsio::write_atomic_with(out, |w| {
                estimate_all(&mut Some(w as &mut dyn Write)).map_err(|e| {
                    failure = Some(e);
                    std::io::Error::other("no estimates written")
                })
            });
            if let Some(e) = failure {
                return Err(e);
            }
            written?;
        }
    }
    let detailed = run.rows <= DETAILED_MAX;
    if let Some(report) = &args.report {
        let items = run
            .first
            .iter()
            .enumerate()
            .map(|(row, e)| report_item(e, None, run.truth(row)?.map(<[f64]>::to_vec)))
            .collect::<Result<Vec<_>>>()?;
        let title = if run.rows > items.len() {
            format!(
                "The light of {source}: the first {} of {} rows",
                items.len(),
                run.rows
            )
        } else {
            format!("The light of {source}")
        };
        write_report(report, &title, &items)?;
    }
    if let Some(plot) = &args.plot {
        let series: Vec<(String, Vec<f64>)> = run
            .first
            .iter()
            .map(|e| (e.name.clone(), e.spd.to_vec()))
            .collect();
        let title = if run.rows == 1 {
            format!("Estimated SPD: {}", run.first[0].colorimetry.label())
        } else {
            format!("Estimated SPDs ({} of {})", series.len(), run.rows)
        };
        let bands: Vec<Option<&Uncertainty>> = run
            .first
            .iter()
            .map(|e| e.trust.as_ref().and_then(|t| t.uncertainty.as_ref()))
            .collect();
        let truths = (0..series.len())
            .map(|row| run.truth(row))
            .collect::<Result<Vec<_>>>()?;
        write_plot(
            plot,
            &spds_band_svg(&title, &grid, &series, &bands, &truths)?,
        )?;
    }
    if quiet(args) {
        for e in &run.first {
            if let Some(trust) = &e.trust {
                eprintln!("{}", verdict_line(&e.name, trust));
            }
        }
        if run.rows > run.first.len() {
            let every = if args.photo.json {
                "every row's is in its JSON line"
            } else {
                "--json gives every one"
            };
            eprintln!(
                "(verdicts of the first {} of {} rows; {every})",
                run.first.len(),
                run.rows
            );
        }
        return Ok(());
    }
    if detailed {
        print_estimates(&run.first, args, None)?;
        return Ok(());
    }
    outln!("{} estimates with {}", run.rows, run.model)?;
    if run.truths.is_some() {
        outln!(
            "against the true SPDs: mean GFC {:.4}, mean RMSE {:.4} (both peak-normalised)",
            run.score_sums.0 / run.rows as f64,
            run.score_sums.1 / run.rows as f64
        )?;
    }
    match &args.output {
        Some(out) => {
            let layout = if run.layout == Some(Layout::Wide) {
                "wide"
            } else {
                "long"
            };
            outln!("SPDs ({layout} layout) → {}", out.display())?;
        }
        None => outln!(
            "the SPDs are not written: -o FILE.csv writes them as CSV, --json every number of \
             each estimate as JSON Lines"
        )?,
    }
    if let Some(plot) = &args.plot {
        outln!("plot → {}", plot.display())?;
    }
    if let Some(report) = &args.report {
        outln!("report → {}", report.display())?;
    }
    Ok(())
}
