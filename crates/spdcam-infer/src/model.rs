//! A trained model and its file, `.spdm`: one self-contained binary file.
//!
//! ```text
//! magic      8 bytes  "SPDCAMMD"
//! version    u32 LE   FORMAT_VERSION
//! header     u64 LE length, then UTF-8 JSON (ModelHeader): architecture, grid, chart,
//!                      camera, feature names, scalings, PCA basis and mean (or channel
//!                      spectra), training record, and the parameter list (name, shape)
//! weights    u64 LE length, then the parameters' values, f32 LE, in the header's order
//! checksum   u64 LE   FNV-1a 64 of every byte before it
//! ```
//!
//! Reading checks all of it, so a wrong, damaged or incompatible file is an error naming what
//! is wrong, never a panic.

use crate::colour_map::ColourMap;
use crate::error::{InferError, Result};
use crate::network::{Architecture, Network, Parameter};
use crate::record::TrainingRecord;
use crate::scale::{FeatureScaler, TargetScaler};
use crate::target::Target;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use spdcam_core::photo::ChartTemplate;
use spdcam_core::spectral::Grid;
use std::path::Path;

/// The first bytes of every model file.
pub const MAGIC: &[u8; 8] = b"SPDCAMMD";
/// The version of the file layout and header this build writes (and the newest it reads).
pub const FORMAT_VERSION: u32 = 1;
/// The usual file extension.
pub const EXTENSION: &str = "spdm";

/// Name and shape of one stored parameter array.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TensorEntry {
    /// `layer.weight` or `layer.bias`.
    pub name: String,
    /// The array's shape.
    pub shape: Vec<usize>,
}

/// Everything in a model file but the weights.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelHeader {
    /// Always `spdcam-model`.
    pub format: String,
    /// [`FORMAT_VERSION`] of the writer.
    pub format_version: u32,
    /// Version of the spdcam that wrote it.
    pub spdcam_version: String,
    /// The network's layers.
    pub architecture: Architecture,
    /// Feature column names, in input order (`p01_r, p01_g, …`).
    pub feature_names: Vec<String>,
    /// The chart the model was trained for, when known.
    pub chart: Option<String>,
    /// The camera the model was trained for, when known.
    pub camera: Option<String>,
    /// The training chart as photos show it (grid, feature patches, neutral patches), so a
    /// photo can be analysed with the model file alone; `None` when no photo shows it.
    #[serde(default)]
    pub photo_chart: Option<ChartTemplate>,
    /// Input scaling.
    pub feature_scaler: FeatureScaler,
    /// What the network predicts and how an SPD is made from it.
    pub target: Target,
    /// Target scaling.
    pub target_scaler: TargetScaler,
    /// A correction of the light's colour fitted on validation photos after training
    /// (`spdcam colour-map fit`); `None`: the spectrum as the network gives it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub colour_map: Option<ColourMap>,
    /// The grid of the estimated SPDs.
    pub grid: Grid,
    /// How it was trained.
    pub training: TrainingRecord,
    /// The stored parameter arrays, in order.
    pub tensors: Vec<TensorEntry>,
}

/// A trained model: scalings, target decoding and network.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    header: ModelHeader,
    network: Network,
    /// FNV-1a 64 of the network's parameter values, the fixed part of
    /// [`Model::fingerprint`], hashed once when the model is made (the weights never change
    /// after).
    parameters_hash: u64,
}

/// FNV-1a 64's offset basis (Fowler, Noll, Vo; IETF draft-eastlake-fnv).
const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

fn fnv1a(bytes: &[u8]) -> u64 {
    fnv1a_on(FNV_OFFSET, bytes)
}

/// FNV-1a 64 of `bytes` continued from the state `hash` (FNV hashes byte by byte, so hashing
/// two pieces in turn is hashing them joined).
fn fnv1a_on(mut hash: u64, bytes: &[u8]) -> u64 {
    for &b in bytes {
        hash ^= u64::from(b);
        hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
    }
    hash
}

/// FNV-1a 64 of `network`'s parameter values as f32 little-endian bytes, in forward order.
fn parameters_hash(network: &Network) -> u64 {
    network
        .parameters()
        .iter()
        .flat_map(|p| &p.data)
        .fold(FNV_OFFSET, |hash, v| fnv1a_on(hash, &v.to_le_bytes()))
}

/// Reads little-endian numbers from a byte slice, with errors instead of panics.
struct Cursor<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        let end = self.at.checked_add(n)?;
        let out = self.bytes.get(self.at..end)?;
        self.at = end;
        Some(out)
    }

    fn u32(&mut self) -> Option<u32> {
        Some(u32::from_le_bytes(self.take(4)?.try_into().ok()?))
    }

    fn u64(&mut self) -> Option<u64> {
        Some(u64::from_le_bytes(self.take(8)?.try_into().ok()?))
    }
}

#[cfg(test)]
thread_local! {
    /// How often this thread ran a model ([`Model::estimate_rows`]): what the tests count to
    /// show that a photo is worked through once.
    pub(crate) static RUNS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

impl Model {
    /// Puts a model together after training; the chart and camera are those of the
    /// training data (`training.data`).
    pub fn assemble(
        network: Network,
        feature_scaler: FeatureScaler,
        target: Target,
        target_scaler: TargetScaler,
        grid: Grid,
        feature_names: Vec<String>,
        training: TrainingRecord,
    ) -> Result<Model> {
        let header = ModelHeader {
            format: "spdcam-model".into(),
            format_version: FORMAT_VERSION,
            spdcam_version: env!("CARGO_PKG_VERSION").into(),
            architecture: network.architecture().clone(),
            feature_names,
            chart: training.data.chart.clone(),
            camera: training.data.camera.clone(),
            photo_chart: None,
            feature_scaler,
            target,
            target_scaler,
            colour_map: None,
            grid,
            training,
            tensors: network
                .parameters()
                .iter()
                .map(|p| TensorEntry {
                    name: p.name.clone(),
                    shape: p.shape.clone(),
                })
                .collect(),
        };
        let model = Model {
            parameters_hash: parameters_hash(&network),
            header,
            network,
        };
        model.validate()?;
        Ok(model)
    }

    /// The ensemble of `members` ([`Architecture::Average`]): one model whose outputs are the
    /// mean of theirs. They must read the same features the same way and predict the same
    /// target (trained on one dataset with the same scaling and PCA settings). Its record
    /// is the first member's, with the average's architecture, the members' summed training
    /// time and their mean validation loss and GFC (the average itself was not validated).
    pub fn average(members: &[Model]) -> Result<Model> {
        let first = members
            .first()
            .ok_or_else(|| InferError::invalid("an average needs members, got none"))?;
        let (a, mut network_list) = (&first.header, Vec::with_capacity(members.len()));
        for (i, m) in members.iter().enumerate() {
            let b = &m.header;
            let differs = |what: &str| {
                Err(InferError::invalid(format!(
                    "member {} differs from the first in its {what}; the members of an average \
                     must be trained on one dataset with the same scaling and target",
                    i + 1
                )))
            };
            if b.feature_names != a.feature_names {
                return differs("feature names");
            }
            if b.feature_scaler != a.feature_scaler {
                return differs("feature scaling");
            }
            if b.target != a.target || b.target_scaler != a.target_scaler {
                return differs("target");
            }
            if b.grid != a.grid || b.chart != a.chart || b.camera != a.camera {
                return differs("grid, chart or camera");
            }
            if b.colour_map.is_some() {
                return Err(InferError::invalid(format!(
                    "member {} carries a colour map; average the models without one, then \
                     fit a map to the average (`spdcam colour-map fit`)",
                    i + 1
                )));
            }
            network_list.push(m.network.clone());
        }
        let network = Network::average(&network_list)?;
        let n = members.len() as f64;
        let mut training = a.training.clone();
        training.options.architecture = network.architecture().clone();
        training.seconds = members.iter().map(|m| m.training().seconds).sum();
        training.val_loss = members.iter().map(|m| m.training().val_loss).sum::<f64>() / n;
        training.val_gfc = members.iter().map(|m| m.training().val_gfc).sum::<f64>() / n;
        let mut model = Model::assemble(
            network,
            a.feature_scaler.clone(),
            a.target.clone(),
            a.target_scaler.clone(),
            a.grid,
            a.feature_names.clone(),
            training,
        )?;
        model.header.photo_chart = a.photo_chart.clone();
        Ok(model)
    }

    /// Checks that all the parts agree with each other.
    fn validate(&self) -> Result<()> {
        let h = &self.header;
        h.architecture.validate()?;
        h.feature_scaler.validate()?;
        h.target.validate()?;
        h.target_scaler.validate()?;
        let inputs = self.network.inputs();
        let outputs = self.network.outputs();
        if h.feature_names.len() != inputs || h.feature_scaler.width() != inputs {
            return Err(InferError::invalid(format!(
                "the model has {} feature names and {} feature scalings for a network of {inputs} inputs",
                h.feature_names.len(),
                h.feature_scaler.width()
            )));
        }
        if h.target.len() != outputs || h.target_scaler.width() != outputs {
            return Err(InferError::invalid(format!(
                "the model has {} targets and {} target scalings for a network of {outputs} outputs",
                h.target.len(),
                h.target_scaler.width()
            )));
        }
        if let Some(map) = &h.colour_map {
            if h.target.pca().is_none() {
                return Err(InferError::invalid(
                    "the model's colour map needs a PCA target; its target is channel weights",
                ));
            }
            map.validate(h.grid.count)?;
        }
        if h.target.spd_len() != h.grid.count {
            return Err(InferError::invalid(format!(
                "the model's SPDs have {} values for a grid of {} ({})",
                h.target.spd_len(),
                h.grid.count,
                h.grid.label()
            )));
        }
        Ok(())
    }

    /// Sets how far the spectrum is moved to the predicted colour
    /// ([`crate::colour_head::ColourHead::pull`]); an error for a model without colour
    /// outputs.
    pub fn set_colour_pull(&mut self, pull: f64) -> Result<()> {
        match &mut self.header.target {
            Target::PcaColour(p) => {
                p.colour = p.colour.clone().with_pull(pull)?;
                Ok(())
            }
            _ => Err(InferError::invalid(
                "the model has no colour outputs (train it with --target pca-colour)",
            )),
        }
    }

    /// Sets (or, with `None`, removes) the correction of the light's colour
    /// ([`ColourMap`]); an error for a model without a PCA target or a map for another grid.
    pub fn set_colour_map(&mut self, map: Option<ColourMap>) -> Result<()> {
        let before = std::mem::replace(&mut self.header.colour_map, map);
        if let Err(e) = self.validate() {
            self.header.colour_map = before;
            return Err(e);
        }
        Ok(())
    }

    /// The header (everything but the weights).
    pub fn header(&self) -> &ModelHeader {
        &self.header
    }

    /// FNV-1a 64 of the network's parameter values (f32 LE, in order) and, where the model
    /// has one, of its colour map's numbers (f64 LE), as 16 hex digits: tells this model's
    /// estimates from another's, so a calibration is used only for the model it was
    /// measured on.
    pub fn fingerprint(&self) -> String {
        let mut hash = self.parameters_hash;
        if let Some(map) = &self.header.colour_map {
            let numbers = [
                map.mired.slope,
                map.mired.offset,
                map.duv.slope,
                map.duv.offset,
            ];
            for v in numbers {
                hash = fnv1a_on(hash, &v.to_le_bytes());
            }
        }
        format!("{hash:016x}")
    }

    /// The network.
    pub fn network(&self) -> &Network {
        &self.network
    }

    /// The grid of the estimated SPDs.
    pub fn grid(&self) -> Grid {
        self.header.grid
    }

    /// The feature column names the model reads, in order.
    pub fn feature_names(&self) -> &[String] {
        &self.header.feature_names
    }

    /// The input scaling.
    pub fn feature_scaler(&self) -> &FeatureScaler {
        &self.header.feature_scaler
    }

    /// The target space.
    pub fn target(&self) -> &Target {
        &self.header.target
    }

    /// The target scaling.
    pub fn target_scaler(&self) -> &TargetScaler {
        &self.header.target_scaler
    }

    /// How it was trained.
    pub fn training(&self) -> &TrainingRecord {
        &self.header.training
    }

    /// Whether it reads a raw photo's patches as XYZ through the file's matrices
    /// (trained on `spdcam generate --raw`, [`spdcam_core::dataset::Pipeline::Raw`]) rather
    /// than encoded colours.
    pub fn reads_raw_xyz(&self) -> bool {
        /// The pipeline of a dataset's origin, or of the set it was split from.
        fn pipeline(origin: &serde_json::Value) -> Option<&str> {
            match origin.get("pipeline") {
                Some(p) => p.as_str(),
                None => pipeline(origin.get("source")?),
            }
        }
        self.training().data.origin.as_ref().and_then(pipeline) == Some("raw")
    }

    /// Refuses, naming it `name` and saying how one is made, a model that does not read raw
    /// patches ([`Model::reads_raw_xyz`]) where a raw model is asked for.
    pub fn require_raw_xyz(&self, name: &str) -> Result<()> {
        if self.reads_raw_xyz() {
            Ok(())
        } else {
            Err(InferError::invalid(format!(
                "{name} does not read raw patches: a raw model is trained on `spdcam generate \
                 --raw`"
            )))
        }
    }

    /// The training chart as photos show it, when known.
    pub fn photo_chart(&self) -> Option<&ChartTemplate> {
        self.header.photo_chart.as_ref()
    }

    /// Records how photos show the training chart; its features must be the model's inputs.
    pub fn set_photo_chart(&mut self, template: ChartTemplate) -> Result<()> {
        self.check_features(&template.feature_names, &format!("chart {}", template.name))?;
        self.header.photo_chart = Some(template);
        Ok(())
    }

    /// A one-line description: architecture, inputs, targets, grid, chart and camera, and
    /// the colour map where the model has one.
    pub fn describe(&self) -> String {
        let h = &self.header;
        let target = match &h.target {
            Target::Pca(p) => format!(
                "{} PCA components ({:.2} % of the variance)",
                p.len(),
                100.0 * p.explained_variance()
            ),
            Target::PcaColour(p) => format!(
                "{} PCA components ({:.2} % of the variance) and the light's u′v′",
                p.pca.len(),
                100.0 * p.pca.explained_variance()
            ),
            Target::Weights(c) => format!("{} channel weights", c.names.len()),
        };
        format!(
            "{} on {} features → {target}, SPD {} nm; chart {}, camera {}",
            h.architecture.label(),
            h.feature_names.len(),
            h.grid.label(),
            h.chart.as_deref().unwrap_or("unknown"),
            h.camera.as_deref().unwrap_or("unknown")
        ) + if h.colour_map.is_some() {
            "; white light's colour mapped (`spdcam colour-map fit`)"
        } else {
            ""
        }
    }

    /// Checks that features with these column names (from `source`) fit the model.
    pub fn check_features(&self, names: &[String], source: &str) -> Result<()> {
        if names == self.header.feature_names.as_slice() {
            return Ok(());
        }
        let show = |n: &[String]| match n {
            [] => "none".to_string(),
            [only] => only.clone(),
            [first, .., last] => format!("{first}…{last}"),
        };
        let chart = self
            .header
            .chart
            .as_deref()
            .map(|c| format!(" (chart {c})"))
            .unwrap_or_default();
        Err(InferError::invalid(format!(
            "{source}: {} feature columns ({}) do not match the model's {} ({}){chart}; \
             the features must come from the chart the model was trained for",
            names.len(),
            show(names),
            self.header.feature_names.len(),
            show(&self.header.feature_names)
        )))
    }

    /// SPD estimates for rows of features (row-major, in the model's column order, on any
    /// brightness scale): one max-normalised SPD on [`Model::grid`] per row.
    pub fn estimate_rows(&self, features: &[f64]) -> Result<Vec<f64>> {
        #[cfg(test)]
        RUNS.with(|runs| runs.set(runs.get() + 1));
        let x = self.header.feature_scaler.transform(features)?;
        let outputs = self.network.forward(&x)?;
        let k = self.network.outputs();
        let d = self.header.grid.count;
        let rows = outputs.len() / k;
        let mut spds = vec![0.0; rows * d];
        let decoder = self.header.target.decoder(self.header.colour_map.as_ref());
        let decode = |(out, spd): (&[f32], &mut [f64])| {
            let mut t = vec![0.0; k];
            self.header.target_scaler.unscale_into(out, &mut t);
            decoder.decode_into(&t, spd);
        };
        if rows > 512 {
            outputs
                .par_chunks(k)
                .zip(spds.par_chunks_mut(d))
                .for_each(decode);
        } else {
            outputs.chunks(k).zip(spds.chunks_mut(d)).for_each(decode);
        }
        Ok(spds)
    }

    /// The SPD estimate for one row of features.
    pub fn estimate(&self, features: &[f64]) -> Result<Vec<f64>> {
        if features.len() != self.network.inputs() {
            return Err(InferError::invalid(format!(
                "{} features given, the model reads {}",
                features.len(),
                self.network.inputs()
            )));
        }
        self.estimate_rows(features)
    }

    /// The model as the bytes of a `.spdm` file.
    pub fn to_bytes(&self) -> Result<Vec<u8>> {
        let header = serde_json::to_vec(&self.header)
            .map_err(|e| InferError::invalid(format!("encoding the model header: {e}")))?;
        let blob_len: usize = self.network.parameter_count() * 4;
        let mut out = Vec::with_capacity(8 + 4 + 8 + header.len() + 8 + blob_len + 8);
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        out.extend_from_slice(&(header.len() as u64).to_le_bytes());
        out.extend_from_slice(&header);
        out.extend_from_slice(&(blob_len as u64).to_le_bytes());
        for p in self.network.parameters() {
            for v in &p.data {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
        let checksum = fnv1a(&out);
        out.extend_from_slice(&checksum.to_le_bytes());
        Ok(out)
    }

    /// Writes the model to `path` atomically.
    pub fn save(&self, path: &Path) -> Result<()> {
        spdcam_core::fsio::write_atomic(path, &self.to_bytes()?)?;
        Ok(())
    }

    /// Reads a model file (at most [`spdcam_core::limits::MODEL_BYTES`]).
    pub fn load(path: &Path) -> Result<Model> {
        let bytes = spdcam_core::fsio::read_limited(path, &spdcam_core::limits::MODEL_BYTES)?;
        Model::from_bytes(&bytes).map_err(|e| match e {
            InferError::ModelFile { message, .. } => InferError::ModelFile {
                path: path.to_path_buf(),
                message,
            },
            other => InferError::ModelFile {
                path: path.to_path_buf(),
                message: other.to_string(),
            },
        })
    }

    /// A model from the bytes of a `.spdm` file.
    pub fn from_bytes(bytes: &[u8]) -> Result<Model> {
        let bad = |message: String| InferError::ModelFile {
            path: "<bytes>".into(),
            message,
        };
        if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
            return Err(bad(format!(
                "not a spdcam model file (a .{EXTENSION} file starts with {:?})",
                String::from_utf8_lossy(MAGIC)
            )));
        }
        let mut c = Cursor { bytes, at: 8 };
        let truncated = || bad("the file is truncated".into());
        let version = c.u32().ok_or_else(truncated)?;
        if version == 0 {
            return Err(bad(
                "model format version 0, which no spdcam writes: the file is damaged".into(),
            ));
        }
        if version > FORMAT_VERSION {
            return Err(bad(format!(
                "model format version {version}; this spdcam reads versions 1 to {FORMAT_VERSION} \
                 (a newer spdcam wrote it?)"
            )));
        }
        if bytes.len() < 8 + 4 + 8 + 8 + 8 {
            return Err(truncated());
        }
        let body = &bytes[..bytes.len() - 8];
        let stored = u64::from_le_bytes(
            bytes[bytes.len() - 8..]
                .try_into()
                .map_err(|_| truncated())?,
        );
        // The checksum is summed beside the reading (both are passes over megabytes); a
        // mismatch wins over whatever the reading found.
        let (intact, model) = rayon::join(|| fnv1a(body) == stored, || Self::from_body(body));
        if !intact {
            return Err(bad(
                "the file is damaged (checksum mismatch): it was cut short or changed".into(),
            ));
        }
        model
    }

    /// The model in `body`, the bytes of a `.spdm` file up to its checksum, whose magic and
    /// version have been checked.
    fn from_body(body: &[u8]) -> Result<Model> {
        let bad = |message: String| InferError::ModelFile {
            path: "<bytes>".into(),
            message,
        };
        let truncated = || bad("the file is truncated".into());
        let mut c = Cursor {
            bytes: body,
            at: 12,
        };
        let header_len = c.u64().ok_or_else(truncated)? as usize;
        let header_bytes = c.take(header_len).ok_or_else(truncated)?;
        let header: ModelHeader = serde_json::from_slice(header_bytes)
            .map_err(|e| bad(format!("the model header is not valid: {e}")))?;
        if header.format != "spdcam-model" {
            return Err(bad(format!(
                "the header names the format '{}', not 'spdcam-model'",
                header.format
            )));
        }
        let blob_len = c.u64().ok_or_else(truncated)? as usize;
        let blob = c.take(blob_len).ok_or_else(truncated)?;
        if c.at != body.len() {
            return Err(bad("unexpected bytes after the weights".into()));
        }
        let expected: usize = header
            .tensors
            .iter()
            .map(|t| t.shape.iter().product::<usize>())
            .sum();
        if expected.checked_mul(4) != Some(blob_len) {
            return Err(bad(format!(
                "the weights hold {blob_len} bytes, the header lists {expected} values"
            )));
        }
        let read_network = || {
            let mut values = blob
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]));
            let parameters: Vec<Parameter> = header
                .tensors
                .iter()
                .map(|t| {
                    let n = t.shape.iter().product();
                    Parameter {
                        name: t.name.clone(),
                        shape: t.shape.clone(),
                        data: values.by_ref().take(n).collect(),
                    }
                })
                .collect();
            let inputs = header.feature_names.len();
            let outputs = header.target.len();
            Network::new(header.architecture.clone(), inputs, outputs, parameters)
                .map_err(|e| bad(format!("the weights do not fit the architecture: {e}")))
        };
        // The weights' bytes are the parameters' values as `parameters_hash` hashes them
        // (f32 LE in forward order, as `to_bytes` writes them): hashed beside the reading.
        let (parameters_hash, network) = rayon::join(|| fnv1a(blob), read_network);
        let model = Model {
            parameters_hash,
            header,
            network: network?,
        };
        model
            .validate()
            .map_err(|e| bad(format!("the model is inconsistent: {e}")))?;
        Ok(model)
    }
}
