//! The models shipped inside spdcam, one per chart people own, and the set of models an
//! estimate chooses from: the model whose features a photo's chart gives.

use crate::error::{InferError, Result};
use crate::model::Model;
use spdcam_core::chart::{shown_chart_name, KnownChart};

/// The shipped models: chart name and `.spdm` bytes (`models/<chart>.spdm`, each made by the
/// seeded commands in the README).
const SHIPPED: &[(&str, &[u8])] = &[
    (
        KnownChart::Sg96.name(),
        include_bytes!("../../../models/colorchecker_sg96.spdm"),
    ),
    (
        KnownChart::ColorChecker24.name(),
        include_bytes!("../../../models/colorchecker24.spdm"),
    ),
];

/// A model with the name messages use for it.
#[derive(Debug, Clone)]
pub struct NamedModel {
    /// `the shipped ColorChecker 24 model` (the chart as people know it) or the model file's
    /// path.
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
    /// let models = ModelSet::shipped()?;
    /// let cc24 = models.for_chart("colorchecker24").unwrap();
    /// assert_eq!(cc24.name, "the shipped ColorChecker 24 model");
    /// assert_eq!(cc24.model.feature_names().len(), 72);
    /// # Ok::<(), spdcam_infer::InferError>(())
    /// ```
    pub fn shipped() -> Result<ModelSet> {
        let models = SHIPPED
            .iter()
            .map(|(chart, bytes)| {
                let model = Model::from_bytes(bytes).map_err(|e| {
                    InferError::invalid(format!("the shipped {chart} model is damaged: {e}"))
                })?;
                Ok(NamedModel {
                    name: format!("the shipped {} model", shown_chart_name(chart)),
                    model,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(ModelSet { models })
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

    /// The model for feature columns `names` (from `source`), or an error that names the
    /// charts and column counts the set's models read.
    ///
    /// ```
    /// use spdcam_infer::ModelSet;
    ///
    /// let models = ModelSet::shipped()?;
    /// let sg = models.for_chart("colorchecker_sg96").unwrap();
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

    /// The models' charts and how many features each reads (`colorchecker24 (72 features),
    /// …`), the one list every "no model reads these columns" message names.
    pub fn known(&self) -> String {
        self.models
            .iter()
            .map(|m| {
                format!(
                    "{} ({} features)",
                    m.model.header().chart.as_deref().unwrap_or("unknown chart"),
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
    fn shipped_models_load_and_each_names_its_chart() {
        let set = ModelSet::shipped().unwrap();
        assert_eq!(set.models().len(), SHIPPED.len());
        for (chart, _) in SHIPPED {
            let m = set.for_chart(chart).unwrap();
            assert_eq!(m.model.header().chart.as_deref(), Some(*chart));
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
            .for_chart("colorchecker24")
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
            err.contains("f.csv") && err.contains("colorchecker24"),
            "{err}"
        );
        assert!(err.contains("colorchecker_sg96 (288 features)"), "{err}");
    }
}
