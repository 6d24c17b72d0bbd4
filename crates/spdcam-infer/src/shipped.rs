//! The models shipped inside spdcam, one per chart people own, with what was measured on
//! each (its trust calibration and light-kind priors), keyed by the chart registry's
//! [`KnownChart`]; and the set of models an estimate chooses from: the model whose features
//! a photo's chart gives.

use crate::error::{InferError, Result};
use crate::model::Model;
use rayon::prelude::*;
use spdcam_core::chart::{shown_chart_name, KnownChart};

/// A model shipped inside the program and what was measured on it: `models/<chart>.spdm`
/// (made by the seeded commands in the README), `<chart>.trust.json` (`spdcam trust
/// calibrate`) and `<chart>.kinds.json` (the light-kind priors).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Shipped {
    /// The chart the model is trained on ([`KnownChart::model_chart`] of those it reads).
    pub chart: KnownChart,
    /// The model's `.spdm` bytes.
    pub model: &'static [u8],
    /// Its trust calibration's JSON.
    pub calibration: &'static str,
    /// Its light-kind priors' JSON.
    pub kinds: &'static str,
}

/// The shipped model of `$chart`, its files named by the chart's machine name `$file`.
macro_rules! shipped {
    ($chart:expr, $file:literal) => {
        Shipped {
            chart: $chart,
            model: include_bytes!(concat!("../../../models/", $file, ".spdm")),
            calibration: include_str!(concat!("../../../models/", $file, ".trust.json")),
            kinds: include_str!(concat!("../../../models/", $file, ".kinds.json")),
        }
    };
}

/// The shipped models, in the order an estimate tries them.
pub(crate) const SHIPPED: [Shipped; 2] = [
    shipped!(KnownChart::Sg96, "colorchecker_sg96"),
    shipped!(KnownChart::ColorChecker24, "colorchecker24"),
];

/// A raw model shipped inside the program and its trust calibration:
/// `models/<chart>.raw.spdm` (made by the README's recipe), the model that reads a raw
/// photo's patches as XYZ through the file's matrices (`spdcam generate --raw`), whose
/// spectrum replaces the chart's model's on raw photos ([`crate::Estimator::with_raw_models`]),
/// and `<chart>.raw.trust.json` (`spdcam trust calibrate --raw-model`), fitted on raw scene
/// photos.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ShippedRaw {
    /// The chart the model reads.
    pub chart: KnownChart,
    /// The model's `.spdm` bytes.
    pub model: &'static [u8],
    /// Its trust calibration's JSON.
    pub calibration: &'static str,
}

/// The shipped raw model of `$chart`, its files named by the chart's machine name `$file`.
macro_rules! shipped_raw {
    ($chart:expr, $file:literal) => {
        ShippedRaw {
            chart: $chart,
            model: include_bytes!(concat!("../../../models/", $file, ".raw.spdm")),
            calibration: include_str!(concat!("../../../models/", $file, ".raw.trust.json")),
        }
    };
}

/// The shipped raw models, one per chart that has one.
pub(crate) const SHIPPED_RAW: [ShippedRaw; 2] = [
    shipped_raw!(KnownChart::Sg96, "colorchecker_sg96"),
    shipped_raw!(KnownChart::ColorChecker24, "colorchecker24"),
];

impl ShippedRaw {
    /// The model as messages name it: `the shipped ColorChecker 24 raw model`.
    pub fn name(&self) -> String {
        format!("the shipped {} raw model", self.chart.shown_name())
    }
}

impl Shipped {
    /// The model as messages name it: `the shipped ColorChecker 24 model`.
    pub fn name(&self) -> String {
        format!("the shipped {} model", self.chart.shown_name())
    }
}

/// A model with the name messages use for it.
#[derive(Debug, Clone)]
pub struct NamedModel {
    /// `the shipped ColorChecker 24 model` (the chart as people know it,
    /// [`KnownChart::shown_name`]) or the model file's path.
    pub name: String,
    /// The model.
    pub model: Model,
}

/// The models an estimate may use; each feature layout (chart) picks its own.
#[derive(Debug, Clone)]
pub struct ModelSet {
    models: Vec<NamedModel>,
}

impl ModelSet {
    /// The models shipped inside spdcam.
    ///
    /// ```
    /// use spdcam_infer::ModelSet;
    ///
    /// use spdcam_core::chart::KnownChart;
    ///
    /// let models = ModelSet::shipped()?;
    /// let cc24 = models.for_known(KnownChart::ColorChecker24).unwrap();
    /// assert_eq!(cc24.name, "the shipped ColorChecker 24 model");
    /// assert_eq!(cc24.model.feature_names().len(), 72);
    /// # Ok::<(), spdcam_infer::InferError>(())
    /// ```
    pub fn shipped() -> Result<ModelSet> {
        // Read in parallel: each read checks the file's checksum and hashes the weights.
        let models = SHIPPED
            .par_iter()
            .map(|shipped| {
                let name = shipped.name();
                let model = Model::from_bytes(shipped.model)
                    .map_err(|e| InferError::invalid(format!("{name} is damaged: {e}")))?;
                Ok(NamedModel { name, model })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(ModelSet { models })
    }

    /// The raw models shipped inside spdcam (`models/<chart>.raw.spdm`), named as messages
    /// name them: `the shipped ColorChecker 24 raw model`.
    pub fn shipped_raw() -> Result<Vec<NamedModel>> {
        SHIPPED_RAW
            .iter()
            .map(|shipped| {
                let name = shipped.name();
                let model = Model::from_bytes(shipped.model)
                    .map_err(|e| InferError::invalid(format!("{name} is damaged: {e}")))?;
                Ok(NamedModel { name, model })
            })
            .collect()
    }

    /// One model, named `name` (e.g. its file's path).
    pub fn single(model: Model, name: impl Into<String>) -> ModelSet {
        ModelSet {
            models: vec![NamedModel {
                name: name.into(),
                model,
            }],
        }
    }

    /// The models, in order.
    pub fn models(&self) -> &[NamedModel] {
        &self.models
    }

    /// The model that reads exactly these feature columns.
    pub fn for_features(&self, names: &[String]) -> Option<&NamedModel> {
        self.models
            .iter()
            .find(|m| m.model.feature_names() == names)
    }

    /// The model trained for the chart named `chart`.
    pub fn for_chart(&self, chart: &str) -> Option<&NamedModel> {
        self.models
            .iter()
            .find(|m| m.model.header().chart.as_deref() == Some(chart))
    }

    /// The model that reads a photo of `chart`: the one trained for its
    /// [`KnownChart::model_chart`] (the Digital SG's 96-patch model for the whole SG).
    pub fn for_known(&self, chart: KnownChart) -> Option<&NamedModel> {
        self.for_chart(chart.model_chart()?.name())
    }

    /// The model for feature columns `names` (from `source`), or an error that names the
    /// charts and column counts the set's models read.
    ///
    /// ```
    /// use spdcam_infer::ModelSet;
    ///
    /// use spdcam_core::chart::KnownChart;
    ///
    /// let models = ModelSet::shipped()?;
    /// let sg = models.for_known(KnownChart::Sg140).unwrap();
    /// let chosen = models.require(sg.model.feature_names(), "photo.csv")?;
    /// assert_eq!(chosen.name, sg.name);
    /// let err = models.require(&["red".to_string()], "other.csv").unwrap_err();
    /// assert!(err.to_string().starts_with("other.csv: no model reads these 1 feature columns"));
    /// # Ok::<(), spdcam_infer::InferError>(())
    /// ```
    pub fn require(&self, names: &[String], source: &str) -> Result<&NamedModel> {
        if let Some(m) = self.for_features(names) {
            return Ok(m);
        }
        // One model reads this many columns: its own check names the column that differs.
        let same_count: Vec<&NamedModel> = self
            .models
            .iter()
            .filter(|m| m.model.feature_names().len() == names.len())
            .collect();
        if let [only] = same_count.as_slice() {
            only.model.check_features(names, source)?;
        }
        Err(InferError::invalid(format!(
            "{source}: no model reads these {} feature columns; the models are for {}",
            names.len(),
            self.known()
        )))
    }

    /// The models' charts as people know them and how many features each reads
    /// (`ColorChecker 24 (72 features), …`), the one list every "no model reads these
    /// columns" message names.
    pub fn known(&self) -> String {
        self.models
            .iter()
            .map(|m| {
                format!(
                    "{} ({} features)",
                    m.model
                        .header()
                        .chart
                        .as_deref()
                        .map_or_else(|| "unknown chart".to_string(), shown_chart_name),
                    m.model.feature_names().len()
                )
            })
            .collect::<Vec<_>>()
            .join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shipped_raw_models_read_raw_patches_of_a_shipped_models_chart() {
        let set = ModelSet::shipped().unwrap();
        let raw = ModelSet::shipped_raw().unwrap();
        assert_eq!(raw.len(), SHIPPED_RAW.len());
        for (ShippedRaw { chart, .. }, named) in SHIPPED_RAW.iter().zip(&raw) {
            assert!(named.model.reads_raw_xyz(), "{}", named.name);
            assert!(!set.for_known(*chart).unwrap().model.reads_raw_xyz());
            assert_eq!(named.model.header().chart.as_deref(), Some(chart.name()));
            assert_eq!(
                named.model.grid(),
                set.for_known(*chart).unwrap().model.grid()
            );
            // Its own calibration, fitted on raw scene photos, with CCT and Duv intervals
            // of the light's colour as raw files read it.
            let calibration = crate::trust::calibration_for(&named.model)
                .unwrap()
                .unwrap_or_else(|| panic!("{}: no calibration", named.name));
            assert_eq!(calibration.chart, chart.name());
            assert!(calibration.method.starts_with("raw scene photos"));
            for key in ["cct_k", "duv"] {
                assert!(calibration.metrics.iter().any(|m| m.key == key), "{key}");
            }
        }
    }

    #[test]
    fn shipped_models_load_and_each_names_its_chart() {
        let set = ModelSet::shipped().unwrap();
        assert_eq!(set.models().len(), SHIPPED.len());
        for shipped in SHIPPED {
            let chart = shipped.chart.name();
            assert_eq!(shipped.chart.model_chart(), Some(shipped.chart));
            let m = set.for_known(shipped.chart).unwrap();
            assert_eq!(m.model.header().chart.as_deref(), Some(chart));
            assert!(
                m.model.photo_chart().is_some(),
                "{chart}: no photo template"
            );
            let found = set.for_features(m.model.feature_names()).unwrap();
            assert_eq!(found.name, m.name);
        }
    }

    #[test]
    fn features_of_a_known_count_in_another_order_name_the_column() {
        let set = ModelSet::shipped().unwrap();
        let mut names = set
            .for_known(KnownChart::ColorChecker24)
            .unwrap()
            .model
            .feature_names()
            .to_vec();
        names.reverse();
        let err = set.require(&names, "f.csv").unwrap_err().to_string();
        assert!(err.contains("f.csv") && err.contains("p24_b"), "{err}");
    }

    #[test]
    fn unknown_features_name_the_known_charts() {
        let set = ModelSet::shipped().unwrap();
        let err = set
            .require(&["a".to_string(), "b".to_string()], "f.csv")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("f.csv") && err.contains("ColorChecker 24 (72 features)"),
            "{err}"
        );
        assert!(
            err.contains("ColorChecker Digital SG (288 features)"),
            "{err}"
        );
    }
}
