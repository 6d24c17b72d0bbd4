//! Scoring a model on a dataset (thesis section 6.1–6.3): the four metrics per sample, their
//! summaries, the per-band mean absolute error, and SVG plots of the results.

use crate::error::{LearnError, Result};
use crate::train::{spds_on_grid, EpochRecord, TrainingSet};
use plotters::prelude::*;
use serde::{Deserialize, Serialize};
use spdcam_core::spectral::Grid;
use spdcam_core::spectral_error::{compare, summarise, SpectralMetrics, Summary};
use spdcam_infer::model::Model;
use spdcam_present::plot::{plot_error, spds_svg, svg};

/// Summaries of the four metrics over a set.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MetricSummaries {
    /// RMSE of the max-normalised spectra.
    pub rmse: Summary,
    /// Goodness-of-fit coefficient.
    pub gfc: Summary,
    /// Spectral angle (radians).
    pub sam: Summary,
    /// Spectral information divergence.
    pub sid: Summary,
}

/// A model scored on a dataset.
#[derive(Debug, Clone)]
pub struct Evaluation {
    /// The grid of the SPDs below.
    pub grid: Grid,
    /// The metrics of each sample, in dataset order.
    pub per_sample: Vec<SpectralMetrics>,
    /// Their summaries.
    pub summary: MetricSummaries,
    /// Mean absolute error of the max-normalised SPDs per band.
    pub band_mae: Vec<f64>,
    /// True SPDs (max-normalised), row-major.
    pub truths: Vec<f64>,
    /// Estimated SPDs (max-normalised), row-major.
    pub estimates: Vec<f64>,
}

impl Evaluation {
    /// Sample indices ordered from the best (highest GFC) to the worst.
    pub fn ranking(&self) -> Vec<usize> {
        let mut idx: Vec<usize> = (0..self.per_sample.len()).collect();
        idx.sort_by(|&a, &b| self.per_sample[b].gfc.total_cmp(&self.per_sample[a].gfc));
        idx
    }
}

/// Scores `model` on every sample of `set`.
pub fn evaluate(model: &Model, set: &TrainingSet) -> Result<Evaluation> {
    model.check_features(&set.columns.feature_names, &set.info.path)?;
    if set.samples.is_empty() {
        return Err(LearnError::invalid(format!(
            "{}: the dataset has no samples",
            set.info.path
        )));
    }
    let grid = model.grid();
    let d = grid.count;
    let truths = spds_on_grid(&set.samples, &set.columns, &grid)?;
    let estimates = model.estimate_rows(&set.samples.features)?;
    let n = set.samples.len();
    let mut per_sample = Vec::with_capacity(n);
    let mut band_mae = vec![0.0; d];
    for i in 0..n {
        let t = &truths[i * d..(i + 1) * d];
        let e = &estimates[i * d..(i + 1) * d];
        per_sample.push(compare(t, e)?);
        for (m, (a, b)) in band_mae.iter_mut().zip(t.iter().zip(e)) {
            *m += (a - b).abs() / n as f64;
        }
    }
    let column = |f: fn(&SpectralMetrics) -> f64| -> Result<Summary> {
        Ok(summarise(&per_sample.iter().map(f).collect::<Vec<_>>())?)
    };
    let summary = MetricSummaries {
        rmse: column(|m| m.rmse)?,
        gfc: column(|m| m.gfc)?,
        sam: column(|m| m.sam)?,
        sid: column(|m| m.sid)?,
    };
    Ok(Evaluation {
        grid,
        per_sample,
        summary,
        band_mae,
        truths,
        estimates,
    })
}

/// Training and validation loss per epoch (log scale), the best epoch marked.
pub fn loss_curve_svg(log: &[EpochRecord], best_epoch: usize) -> Result<String> {
    if log.is_empty() {
        return Err(LearnError::invalid("no epochs to plot"));
    }
    let values = log.iter().flat_map(|r| [r.train_loss, r.val_loss]);
    let lo = values.clone().fold(f64::INFINITY, f64::min).max(1e-12);
    let hi = values.fold(0.0, f64::max).max(lo * 10.0);
    Ok(svg((900, 520), |root| {
        let mut chart = ChartBuilder::on(&root)
            .caption("Training loss (MSE of scaled targets)", ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(70)
            .build_cartesian_2d(
                1f64..(log.len().max(2) as f64),
                (lo * 0.8..hi * 1.2).log_scale(),
            )
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .x_desc("epoch")
            .y_desc("loss")
            .draw()
            .map_err(plot_error)?;
        let series = [
            (
                "training",
                BLUE,
                log.iter()
                    .map(|r| (r.epoch as f64, r.train_loss))
                    .collect::<Vec<_>>(),
            ),
            (
                "validation",
                RED,
                log.iter().map(|r| (r.epoch as f64, r.val_loss)).collect(),
            ),
        ];
        for (name, colour, points) in series {
            chart
                .draw_series(LineSeries::new(points, colour.stroke_width(2)))
                .map_err(plot_error)?
                .label(name)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
        }
        let best = best_epoch as f64;
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(best, lo * 0.8), (best, hi * 1.2)],
                BLACK.mix(0.4),
            )))
            .map_err(plot_error)?
            .label(format!("kept: epoch {best_epoch}"))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.mix(0.4)));
        chart
            .configure_series_labels()
            .border_style(BLACK)
            .background_style(WHITE.mix(0.8))
            .draw()
            .map_err(plot_error)?;
        Ok(())
    })?)
}

/// Best, median and worst estimates (by GFC) against the truth (thesis Fig. 6.6).
pub fn best_median_worst_svg(e: &Evaluation) -> Result<String> {
    let rank = e.ranking();
    let d = e.grid.count;
    let picks = [
        ("best", rank[0]),
        ("median", rank[rank.len() / 2]),
        ("worst", rank[rank.len() - 1]),
    ];
    let mut series = Vec::new();
    for (label, i) in picks {
        let gfc = e.per_sample[i].gfc;
        series.push((
            format!("{label} (row {}) truth", i + 1),
            e.truths[i * d..(i + 1) * d].to_vec(),
        ));
        series.push((
            format!("{label} estimate, GFC {gfc:.4}"),
            e.estimates[i * d..(i + 1) * d].to_vec(),
        ));
    }
    Ok(spds_svg(
        "Best, median and worst estimates",
        &e.grid,
        &series,
    )?)
}

/// Mean absolute error per band (thesis Fig. 6.4).
pub fn band_mae_svg(e: &Evaluation) -> Result<String> {
    let top = e.band_mae.iter().copied().fold(0.0, f64::max).max(1e-9) * 1.1;
    let grid = e.grid;
    Ok(svg((900, 480), |root| {
        let mut chart = ChartBuilder::on(&root)
            .caption("Mean absolute error per band", ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(64)
            .build_cartesian_2d(grid.start_nm..grid.end_nm(), 0.0..top)
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .x_desc("wavelength (nm)")
            .y_desc("MAE (relative power)")
            .draw()
            .map_err(plot_error)?;
        let points: Vec<(f64, f64)> = e
            .band_mae
            .iter()
            .enumerate()
            .map(|(k, v)| (grid.wavelength(k), *v))
            .collect();
        chart
            .draw_series(LineSeries::new(points, BLUE.stroke_width(2)))
            .map_err(plot_error)?;
        Ok(())
    })?)
}

/// Box plots of the four metrics (thesis Fig. 6.3): box from the first to the third
/// quartile, the median line, whiskers to the 5th and 95th percentiles.
pub fn boxplots_svg(e: &Evaluation) -> Result<String> {
    let metrics: [(&str, Vec<f64>); 4] = [
        ("RMSE", e.per_sample.iter().map(|m| m.rmse).collect()),
        ("GFC", e.per_sample.iter().map(|m| m.gfc).collect()),
        ("SAM (rad)", e.per_sample.iter().map(|m| m.sam).collect()),
        ("SID", e.per_sample.iter().map(|m| m.sid).collect()),
    ];
    Ok(svg((1000, 420), |root| {
        let panels = root.split_evenly((1, 4));
        for ((name, mut values), panel) in metrics.into_iter().zip(panels) {
            values.sort_by(f64::total_cmp);
            let q = |p: f64| values[((values.len() - 1) as f64 * p).round() as usize];
            let (p5, q1, q2, q3, p95) = (q(0.05), q(0.25), q(0.5), q(0.75), q(0.95));
            let (lo, hi) = (values[0], values[values.len() - 1]);
            let pad = ((hi - lo) * 0.05).max(1e-9);
            let mut chart = ChartBuilder::on(&panel)
                .caption(name, ("sans-serif", 18))
                .margin(12)
                .y_label_area_size(60)
                .build_cartesian_2d(0f64..2f64, (lo - pad)..(hi + pad))
                .map_err(plot_error)?;
            chart
                .configure_mesh()
                .disable_x_mesh()
                .disable_x_axis()
                .draw()
                .map_err(plot_error)?;
            let lines = [
                vec![(1.0, p5), (1.0, q1)],
                vec![(1.0, q3), (1.0, p95)],
                vec![(0.8, p5), (1.2, p5)],
                vec![(0.8, p95), (1.2, p95)],
                vec![(0.6, q2), (1.4, q2)],
            ];
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(0.6, q1), (1.4, q3)],
                    BLUE.mix(0.3).filled(),
                )))
                .map_err(plot_error)?;
            chart
                .draw_series(
                    lines
                        .into_iter()
                        .map(|l| PathElement::new(l, BLACK.stroke_width(2))),
                )
                .map_err(plot_error)?;
            let outliers: Vec<(f64, f64)> = values
                .iter()
                .filter(|v| **v < p5 || **v > p95)
                .map(|v| (1.0, *v))
                .collect();
            chart
                .draw_series(
                    outliers
                        .into_iter()
                        .map(|p| Circle::new(p, 2, RED.mix(0.5))),
                )
                .map_err(plot_error)?;
        }
        Ok(())
    })?)
}
