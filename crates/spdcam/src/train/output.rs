//! What training shows and writes beside the model: the progress of its epochs, the training
//! log CSV and the loss curve (named after the model file by default).

use anyhow::Result;
use spdcam_core::fsio;
use spdcam_learn::evaluate::loss_curve_svg;
use spdcam_learn::train::{EpochRecord, Progress};
use std::path::{Path, PathBuf};

/// `path` with its extension replaced by `suffix` (e.g. `.log.csv`).
pub fn sibling(path: &Path, suffix: &str) -> PathBuf {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!("{stem}{suffix}"))
}

/// A progress reporter: a bar per run on a terminal (epoch, loss, validation loss and GFC),
/// one plain line per epoch when stderr is not a terminal.
pub fn reporter(epochs: usize) -> (impl FnMut(Progress), Option<indicatif::ProgressBar>) {
    use std::io::IsTerminal;
    let bar = std::io::stderr().is_terminal().then(|| {
        let style = indicatif::ProgressStyle::with_template(
            "{elapsed_precise} [{wide_bar}] epoch {pos}/{len}, ETA {eta} {msg}",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
        indicatif::ProgressBar::new(epochs as u64).with_style(style)
    });
    let handle = bar.clone();
    let report = move |p: Progress| {
        let Progress::Epoch(r) = p else {
            return;
        };
        let line = format!(
            "loss {:.3e}, val loss {:.3e}, val GFC {:.5}, {:.1} s/epoch",
            r.train_loss, r.val_loss, r.val_gfc, r.seconds
        );
        match &bar {
            Some(bar) => {
                bar.set_position(r.epoch as u64);
                bar.set_message(line);
            }
            // Not a terminal (a log file, a batch job): one plain line per epoch.
            None => eprintln!("epoch {}/{epochs}: {line}", r.epoch),
        }
    };
    (report, handle)
}

/// Writes the training log CSV and the loss curve.
pub fn write_log(log: &[EpochRecord], best: usize, csv: &Path, svg: &Path) -> Result<()> {
    let mut text = String::from("epoch,train_loss,val_loss,val_gfc,lr,seconds\n");
    for r in log {
        text.push_str(&format!(
            "{},{:.6e},{:.6e},{:.6},{:.3e},{:.3}\n",
            r.epoch, r.train_loss, r.val_loss, r.val_gfc, r.lr, r.seconds
        ));
    }
    fsio::write_atomic(csv, text.as_bytes())?;
    fsio::write_atomic(svg, loss_curve_svg(log, best)?.as_bytes())?;
    println!("  log:      {}", csv.display());
    println!("  plot:     {}", svg.display());
    Ok(())
}
