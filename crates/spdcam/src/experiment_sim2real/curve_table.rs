//! `spdcam sim2real --finetune`: the fine-tuning learning curve as a Markdown table, beside
//! two ridge baselines on the same photos.

use super::ridge::{inputs, score, target};
use super::{Sim2realArgs, GRID};
use crate::sim2real_curve::{learning_curve, CurveOptions};
use anyhow::Result;
use spdcam_core::dataset::MeasuredPhotos;
use spdcam_core::fsio::write_atomic;
use spdcam_learn::model::Model;
use spdcam_learn::ridge::Ridge;
use std::path::Path;

/// Writes the fine-tuning learning curve of the model at `path` on every real set, beside
/// two linear baselines on the same photos: ridge on the photos alone, and the virtual
/// ridge `prior` corrected by the photos (shrunk towards it); both choose their penalty by
/// cross-validation on the photos.
pub(super) fn curve_table(
    args: &Sim2realArgs,
    path: &Path,
    sets: &[(&str, MeasuredPhotos)],
    prior: &Ridge,
) -> Result<()> {
    let model = Model::load(path)?;
    let options = CurveOptions {
        sizes: args.sizes.clone(),
        folds: args.folds.max(2),
        seed: 1,
        choose: args.choose,
    };
    const COLUMNS: [&str; 3] = ["fine-tuned", "ridge", "ridge towards virtual"];
    let mut md = format!(
        "| real photos used | {} |\n|---:|{}\n",
        sets.iter()
            .map(|(n, _)| format!("{n}: {}", COLUMNS.join(" | ")))
            .collect::<Vec<_>>()
            .join(" | "),
        "---:|".repeat(COLUMNS.len() * sets.len())
    );
    let curves = sets
        .iter()
        .map(|(name, set)| {
            let baselines = |train: &[usize], test: &[usize]| -> Result<Vec<f64>> {
                let x: Vec<Vec<f64>> = train.iter().map(|&i| inputs(&set.features[i])).collect();
                let y: Vec<Vec<f64>> = train.iter().map(|&i| target(&set.spds[i])).collect();
                [None, Some(prior)]
                    .into_iter()
                    .map(|p| score(&Ridge::fit_cv(&x, &y, 5, p)?, set, test))
                    .collect()
            };
            let curve = learning_curve(&model, set, &GRID, &options, &baselines)?;
            eprintln!("{name}: {:?}", curve.points);
            Ok(curve)
        })
        .collect::<Result<Vec<_>>>()?;
    let cell = |v: Option<f64>| v.map_or("–".to_string(), |v| format!("{v:.4}"));
    for (row, &size) in args.sizes.iter().enumerate() {
        md += &format!("| {size} |");
        for curve in &curves {
            let point = &curve.points[row];
            md += &format!(" {} |", cell(point.tuned));
            for k in 0..COLUMNS.len() - 1 {
                md += &format!(" {} |", cell(point.baselines.get(k).copied().flatten()));
            }
        }
        md.push('\n');
    }
    md += &format!(
        "\nMean GFC (400–700 nm; the model at 5 nm, ridge at 10 nm) on the photos of the test \
         fold, {}-fold cross-validated; the photos used come from the other folds (seeded \
         random picks). Model: `{}` ({}), fine-tuned {}. Ridge: features ÷ their mean → SPD, \
         the penalty chosen by 5-fold cross-validation on the photos used; towards virtual: \
         shrunk towards the ridge trained on {} virtual samples (randomised cameras, \
         in-camera stage and lighting gradient) instead of towards zero.\n",
        options.folds,
        path.display(),
        model.describe(),
        if args.choose {
            "as `spdcam finetune` without recipe flags: the recipe chosen by 5-fold \
             cross-validation on the photos used among the model unchanged, the network \
             recipes (for a network) and ridge on the photos at three penalties"
        } else {
            "with its output layer kept, all layers, learning rate 2e-4, batch ≤ 16, about \
             150 steps"
        },
        args.count
    );
    write_atomic(&args.output, md.as_bytes())?;
    print!("{md}");
    Ok(())
}
