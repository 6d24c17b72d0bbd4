//! Feature rows into estimates: rows in memory, each checked for holding the chart's
//! patches, and rows streamed a block at a time.

use super::{Estimator, ModelSpds};
use crate::error::{InferError, Result};
use crate::estimate::Estimate;
use crate::feature_rows::FeatureRows;
use crate::stream::{check_feature_rows, row_name, FeatureBlock, FeatureStream};
use crate::trust::{feature_scale, Identity, PhotoFlags};
use rayon::prelude::*;
use spdcam_core::advice::Sampled;
use std::ops::Range;

impl Estimator {
    /// Whether each of the feature rows `features` holds the patches of the model's chart:
    /// the statistics of [`crate::trust::chart_identity`], the shuffled one under the model's
    /// estimate when the chart's reflectances are at hand. [`Estimator::estimate_rows`] and
    /// [`Estimator::stream`] refuse a row when they find anything against the chart.
    pub fn row_identities(&self, features: &FeatureRows, source: &str) -> Result<Vec<Identity>> {
        let index = self.choose(&features.names, source)?;
        let model_spds = self.run_model(index, features, source)?.told;
        let width = features.names.len().max(1);
        let d = self.named(index).model.grid().count.max(1);
        features
            .values
            .par_chunks(width)
            .zip(model_spds.par_chunks(d))
            .map(|(row, spd)| self.row_identity(index, row, spd))
            .collect()
    }

    /// The identity of one feature row whose SPD under model `index` is `spd`.
    fn row_identity(&self, index: usize, row: &[f64], spd: &[f64]) -> Result<Identity> {
        let judge = &self.prepared.trust[index];
        let scale = feature_scale(row);
        let mut identity = judge.identity.of_row(row, scale);
        if let Some(check) = &judge.check {
            judge
                .identity
                .add_shuffled(&mut identity, row, scale, &[], (check, spd))?;
        }
        Ok(identity)
    }

    /// Refuses the first of feature rows `values` (row-major, the first being row
    /// `first_row`, 0-based) that does not behave like model `index`'s chart, with the SPDs
    /// `model_spds` the model made of them (see [`crate::trust::chart_identity`]).
    fn require_chart_rows(
        &self,
        index: usize,
        values: &[f64],
        model_spds: &[f64],
        source: &str,
        first_row: usize,
    ) -> Result<()> {
        let identity = &self.prepared.trust[index].identity;
        let width = self.named(index).model.feature_names().len().max(1);
        let d = self.named(index).model.grid().count.max(1);
        let failed = values
            .par_chunks(width)
            .zip(model_spds.par_chunks(d))
            .enumerate()
            .find_map_first(|(k, (row, spd))| {
                self.row_identity(index, row, spd)
                    .and_then(|found| {
                        identity.require(&found, Sampled::Row(first_row + k + 1), source)
                    })
                    .err()
            });
        failed.map_or(Ok(()), Err)
    }

    /// Judged estimates for feature rows, each labelled `estimate_N` (1-based), by the
    /// model for their columns; `source` names the rows in errors. The rows are judged in
    /// parallel.
    ///
    /// ```
    /// use spdcam_core::builtin::{self, DataDir};
    /// use spdcam_core::camera::sensor::Sensitivities;
    /// use spdcam_core::camera::{Camera, CameraConfig};
    /// use spdcam_core::chart::Chart;
    /// use spdcam_core::cie_illuminant::StandardIlluminant;
    /// use spdcam_core::spectral::Grid;
    /// use spdcam_infer::{Estimator, FeatureRows};
    ///
    /// // The ColorChecker 24 under illuminant A, through the virtual camera.
    /// let grid = Grid::SIMULATION;
    /// let table = &builtin::CAMERAS[0];
    /// let sensitivities = Sensitivities::new(table.name, &table.load()?, &grid)?;
    /// let chart = Chart::colorchecker24(&grid)?;
    /// let names = chart.feature_names();
    /// let camera = Camera::new(&sensitivities, chart, CameraConfig::default(), &grid)?;
    /// let a = StandardIlluminant::A.spd(&grid)?;
    /// let (mut raw, mut row) = (Vec::new(), Vec::new());
    /// camera.features_fast(&camera.light(&a)?, &mut raw, &mut row);
    /// let values = row.iter().map(|&v| f64::from(v)).collect();
    ///
    /// let estimator = Estimator::shipped(DataDir::new(None), Grid::ESTIMATION)?;
    /// let rows = FeatureRows::from_values(names, values, "rendered")?;
    /// let estimate = &estimator.estimate_rows(&rows, "rendered")?[0];
    /// assert_eq!(estimate.name, "estimate_1");
    /// // A warm light: a CCT near illuminant A's 2856 K.
    /// let cct = estimate.colorimetry.cct.unwrap();
    /// assert!((2300.0..3500.0).contains(&cct), "{cct}");
    /// assert!(estimate.trust.is_some());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn estimate_rows(&self, features: &FeatureRows, source: &str) -> Result<Vec<Estimate>> {
        let index = self.choose(&features.names, source)?;
        let model_spds = self.run_model(index, features, source)?;
        self.require_chart_rows(index, &features.values, &model_spds.told, source, 0)?;
        let width = features.names.len();
        let d = self.named(index).model.grid().count;
        features
            .values
            .par_chunks(width)
            .zip(model_spds.told.par_chunks(d))
            .zip(model_spds.own().par_chunks(d))
            .enumerate()
            .map(|(i, ((row, spd), own))| {
                self.judged(
                    index,
                    row_name(i),
                    spd.to_vec(),
                    own,
                    row,
                    None,
                    &PhotoFlags::default(),
                    None,
                )
            })
            .collect()
    }

    /// Feature rows from `stream`, estimated a block at a time (see [`RowStream`]); the
    /// model is the one for the stream's columns.
    ///
    /// ```
    /// use spdcam_core::builtin::{self, DataDir};
    /// use spdcam_core::camera::sensor::Sensitivities;
    /// use spdcam_core::camera::{Camera, CameraConfig};
    /// use spdcam_core::chart::Chart;
    /// use spdcam_core::cie_illuminant::StandardIlluminant;
    /// use spdcam_core::spectral::Grid;
    /// use spdcam_infer::stream::FeatureStream;
    /// use spdcam_infer::Estimator;
    ///
    /// // Two rows of the ColorChecker 24 through the virtual camera, under A and D65.
    /// let grid = Grid::SIMULATION;
    /// let table = &builtin::CAMERAS[0];
    /// let sensitivities = Sensitivities::new(table.name, &table.load()?, &grid)?;
    /// let chart = Chart::colorchecker24(&grid)?;
    /// let names = chart.feature_names();
    /// let camera = Camera::new(&sensitivities, chart, CameraConfig::default(), &grid)?;
    /// let mut text = names.join(",") + "\n";
    /// for light in [StandardIlluminant::A, StandardIlluminant::D65] {
    ///     let (mut raw, mut row) = (Vec::new(), Vec::new());
    ///     camera.features_fast(&camera.light(&light.spd(&grid)?)?, &mut raw, &mut row);
    ///     let cells: Vec<String> = row.iter().map(|v| v.to_string()).collect();
    ///     text.push_str(&(cells.join(",") + "\n"));
    /// }
    ///
    /// let estimator = Estimator::shipped(DataDir::new(None), Grid::ESTIMATION)?;
    /// let file = FeatureStream::new(Box::new(std::io::Cursor::new(text)), "rows.csv")?;
    /// let mut stream = estimator.stream(file, "rows.csv")?;
    /// let block = stream.next_block()?.unwrap();
    /// assert_eq!((block.rows, block.spds.len()), (2, 2 * 61));
    /// // The full judged estimate of a row, only when it is wanted.
    /// let second = stream.estimate(&block, 1)?;
    /// assert_eq!(second.name, "estimate_2");
    /// assert_eq!(second.spd.values(), &block.spds[61..]);
    /// assert!(stream.next_block()?.is_none());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn stream(&self, stream: FeatureStream, source: &str) -> Result<RowStream<'_>> {
        let index = self.choose(stream.names(), source)?;
        self.map(index)?;
        Ok(RowStream {
            estimator: self,
            stream,
            index,
            source: source.to_string(),
            rows: 0,
            ahead: None,
        })
    }
}

/// Feature rows read a block at a time and estimated by one model (see
/// [`Estimator::stream`]): time linear in the rows, memory bounded whatever their number.
/// The SPDs of a block come cheap; [`RowStream::estimate`] makes the full judged estimate
/// of any row of it.
pub struct RowStream<'a> {
    estimator: &'a Estimator,
    stream: FeatureStream,
    index: usize,
    source: String,
    rows: usize,
    /// The block after the one last handed out, read and parsed while that one was
    /// estimated (`None` before the first block).
    ahead: Option<Result<Option<FeatureBlock>>>,
}

/// One block of a [`RowStream`]: the rows' features and their SPDs.
#[derive(Debug, Clone)]
pub struct EstimatedBlock {
    /// The number (0-based) of the block's first row among all rows.
    pub first_row: usize,
    /// Number of rows.
    pub rows: usize,
    /// The features, row-major.
    pub features: Vec<f64>,
    /// The SPDs on the estimator's grid, peak 1, row-major.
    pub spds: Vec<f64>,
    /// The SPDs on the model's grid, as the judge takes them.
    model_spds: Vec<f64>,
    /// The model's own SPDs before a named kind of light moved them (`None` when none was
    /// named: they are `model_spds`).
    own_spds: Option<Vec<f64>>,
}

/// The SPDs of one block of feature rows (named `names`, from `source`) by model `index`,
/// after refusing rows that say nothing about the light or are not the model's chart.
fn estimate_block(
    estimator: &Estimator,
    index: usize,
    names: &[String],
    source: &str,
    block: FeatureBlock,
) -> Result<EstimatedBlock> {
    check_feature_rows(&block.values, names, source, block.first_row, true)?;
    let ModelSpds {
        told: model_spds,
        own,
        ..
    } = estimator.told_of_light(
        index,
        estimator.named(index).model.estimate_rows(&block.values)?,
    )?;
    estimator.require_chart_rows(index, &block.values, &model_spds, source, block.first_row)?;
    let spds = estimator.map(index)?.apply(model_spds.clone());
    Ok(EstimatedBlock {
        first_row: block.first_row,
        rows: block.rows,
        features: block.values,
        spds,
        model_spds,
        own_spds: own,
    })
}

impl RowStream<'_> {
    /// The name of the model estimating the rows.
    pub fn model_name(&self) -> &str {
        &self.estimator.named(self.index).name
    }

    /// The next block of rows with their SPDs, or `None` after the last. Rows that say
    /// nothing about the light, or that are not the model's chart
    /// ([`crate::trust::chart_identity`]), are refused, naming the row (1-based in the file).
    pub fn next_block(&mut self) -> Result<Option<EstimatedBlock>> {
        let read = match self.ahead.take() {
            Some(read) => read?,
            None => self.stream.next_block(self.rows)?,
        };
        let Some(block) = read else {
            return Ok(None);
        };
        // The next block is read and parsed while this one is estimated: reading has parts
        // that run on one core (the file, the line breaks) which would otherwise leave the
        // other idle.
        let next_first = block.first_row + block.rows;
        let names = self.stream.names().to_vec();
        let (estimator, index, source) = (self.estimator, self.index, self.source.as_str());
        let stream = &mut self.stream;
        let (estimated, ahead) = rayon::join(
            || estimate_block(estimator, index, &names, source, block),
            || stream.next_block(next_first),
        );
        let estimated = estimated?;
        self.ahead = Some(ahead);
        self.rows += estimated.rows;
        Ok(Some(estimated))
    }

    /// The full judged estimate of row `k` of `block`, named `estimate_N` after its place
    /// among all rows: the SPD the block holds, not estimated again.
    pub fn estimate(&self, block: &EstimatedBlock, k: usize) -> Result<Estimate> {
        Ok(self.estimates(block, k..k + 1)?.remove(0))
    }

    /// The full judged estimates of rows `rows` of `block`, in order, as
    /// [`RowStream::estimate`] makes each: judged in parallel, since judging (the self-check,
    /// the perturbed spread, the lighting metrics) costs far more than the SPD.
    pub fn estimates(&self, block: &EstimatedBlock, rows: Range<usize>) -> Result<Vec<Estimate>> {
        if rows.start >= rows.end || rows.end > block.rows {
            return Err(InferError::invalid(format!(
                "rows {}..{} of a block of {} rows",
                rows.start, rows.end, block.rows
            )));
        }
        let width = self.stream.names().len();
        let d = self.estimator.named(self.index).model.grid().count;
        let (estimator, index) = (self.estimator, self.index);
        rows.into_par_iter()
            .map(|k| {
                let own = block.own_spds.as_ref().unwrap_or(&block.model_spds);
                estimator.judged(
                    index,
                    row_name(block.first_row + k),
                    block.model_spds[k * d..(k + 1) * d].to_vec(),
                    &own[k * d..(k + 1) * d],
                    &block.features[k * width..(k + 1) * width],
                    None,
                    &PhotoFlags::default(),
                    None,
                )
            })
            .collect()
    }
}
