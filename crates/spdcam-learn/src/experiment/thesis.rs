//! One model trained on one of the thesis's virtual sets and scored on its `_val` part: a
//! row of `spdcam experiment thesis`'s results.

use super::sets::{channels, load_part, SetName};
use crate::error::Result;
use crate::evaluate::{evaluate, Evaluation};
use crate::train::{train, Backend, Progress, Schedule, TrainOptions, TrainingSet};
use spdcam_core::spectral::Grid;
use spdcam_infer::network::Architecture;
use spdcam_infer::scale::RowScale;
use spdcam_infer::target::TargetKind;
use std::path::Path;

/// Share of the `_train` part held out to select the epoch.
pub const VAL_SPLIT: f64 = 0.1;

/// One set's parts: `_train` to train on, `_val` to test on.
pub struct SetParts {
    /// The set.
    pub set: SetName,
    /// The `_train` part.
    pub train: TrainingSet,
    /// The `_val` part, the test set.
    pub test: TrainingSet,
}

impl SetParts {
    /// Reads `set`'s parts from the thesis's data `root` (holding `virtual/` and
    /// `telelumen_24_channels.csv`).
    pub fn read(set: SetName, root: &Path) -> Result<SetParts> {
        let ch = channels(set, root)?;
        Ok(SetParts {
            set,
            train: load_part(set, "train", root, &ch)?,
            test: load_part(set, "val", root, &ch)?,
        })
    }
}

/// How the experiment trains each model: the training options of `architecture` (rows
/// scaled by their maximum, [`VAL_SPLIT`] held out, on the CPU).
pub fn train_options(
    architecture: Architecture,
    schedule: Schedule,
    target: TargetKind,
    grid: Grid,
    seed: u64,
) -> TrainOptions {
    TrainOptions {
        architecture,
        row_scale: RowScale::Max,
        target,
        grid,
        schedule,
        seed,
        val_split: VAL_SPLIT,
        backend: Backend::Cpu,
    }
}

/// One model trained and scored on one set.
#[derive(Debug, Clone)]
pub struct ThesisRow {
    /// The set.
    pub set: SetName,
    /// The model's name in the tables.
    pub model: String,
    /// The scores on the set's `_val` part.
    pub evaluation: Evaluation,
    /// The mean GFC the thesis published for this set and architecture, where it has one.
    pub thesis_gfc: Option<f64>,
    /// Epochs run.
    pub epochs_run: usize,
    /// The epoch kept.
    pub best_epoch: usize,
    /// Seconds of the whole training run.
    pub train_seconds: f64,
    /// Mean seconds per epoch (0 without epochs: the closed-form ridge).
    pub seconds_per_epoch: f64,
    /// Samples trained on.
    pub train_samples: usize,
}

impl ThesisRow {
    /// Trains a model with `options` on `parts`' `_train` part (named `name` in the tables)
    /// and scores it on the `_val` part; `report` hears the training's progress.
    pub fn measure(
        parts: &SetParts,
        name: &str,
        options: &TrainOptions,
        report: &mut dyn FnMut(Progress),
    ) -> Result<ThesisRow> {
        let trained = train(&parts.train, None, options, report)?;
        let evaluation = evaluate(&trained.model, &parts.test)?;
        let t = trained.model.training();
        let seconds_per_epoch = if trained.log.is_empty() {
            0.0
        } else {
            trained.log.iter().map(|r| r.seconds).sum::<f64>() / trained.log.len() as f64
        };
        let thesis_gfc = match options.architecture {
            Architecture::Cnn1d(_) => parts.set.thesis_gfc().0,
            Architecture::Mlp(_) => parts.set.thesis_gfc().1,
            _ => None,
        };
        Ok(ThesisRow {
            set: parts.set,
            model: name.to_string(),
            evaluation,
            thesis_gfc,
            epochs_run: t.epochs_run,
            best_epoch: t.best_epoch,
            train_seconds: t.seconds,
            seconds_per_epoch,
            train_samples: t.train_samples,
        })
    }

    /// The row of the results table (`| set | model | GFC mean | GFC std | RMSE | SAM | SID |
    /// thesis GFC | epochs (best) | train s | s/epoch |`), with its line end.
    pub fn table_line(&self) -> String {
        let s = &self.evaluation.summary;
        format!(
            "| {} | {} | {:.5} | {:.5} | {:.4} | {:.4} | {:.4} | {} | {} ({}) | {:.0} | {:.2} |\n",
            self.set.label(),
            self.model,
            s.gfc.mean,
            s.gfc.std,
            s.rmse.mean,
            s.sam.mean,
            s.sid.mean,
            self.thesis_gfc
                .map_or("–".to_string(), |g| format!("{g:.4}")),
            self.epochs_run,
            self.best_epoch,
            self.train_seconds,
            self.seconds_per_epoch
        )
    }

    /// The row as the JSON object of `results.json`.
    pub fn json(&self) -> serde_json::Value {
        serde_json::json!({
            "set": self.set.label(), "model": self.model, "metrics": self.evaluation.summary,
            "thesis_gfc": self.thesis_gfc, "epochs_run": self.epochs_run,
            "best_epoch": self.best_epoch, "train_seconds": self.train_seconds,
            "seconds_per_epoch": self.seconds_per_epoch, "train_samples": self.train_samples,
            "test_samples": self.evaluation.per_sample.len(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::gaussian_set;

    #[test]
    fn a_linear_row_has_no_thesis_number_and_no_epochs() {
        let data = gaussian_set(200, 24, 1, 2);
        let parts = SetParts {
            set: SetName::G1,
            train: data.clone(),
            test: gaussian_set(20, 24, 9, 2),
        };
        let options = train_options(
            Architecture::Linear { ridge: 0.0 },
            Schedule::thesis(),
            TargetKind::Pca(spdcam_infer::pca::Components::default()),
            Grid::ESTIMATION,
            1,
        );
        let row = ThesisRow::measure(&parts, "linear", &options, &mut |_| {}).unwrap();
        assert_eq!(row.thesis_gfc, None);
        assert_eq!(row.seconds_per_epoch, 0.0);
        assert!(row.table_line().starts_with("| G1 | linear | "));
        assert!(row.table_line().contains(" | – | "));
        assert_eq!(row.json()["test_samples"], 20);
        assert_eq!(row.json()["train_samples"], row.train_samples);
    }
}
