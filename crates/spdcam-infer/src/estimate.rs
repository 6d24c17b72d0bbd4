//! What an estimate is: the judged [`Estimate`] with its colorimetry and its score against a
//! truth. The [`crate::Estimator`] makes every estimate, from feature rows
//! ([`crate::FeatureRows`]) or photos analysed as [`crate::PhotoOptions`] say.
//!
//! ```text
//! photo ─► decode ─► detect chart ─► sample (spdcam-core::photo) ─┐
//! features CSV ─► FeatureRows ──────────────────────────────────────┴─► Estimator: model for
//!     the chart ─► SPD ─► judged ─► Estimate (SPD, colorimetry, metrics, verdict, bands)
//! ```

use crate::absolute::{Absolute, ChartLevel};
use crate::error::{InferError, Result};
use crate::places::LightAcrossPlaces;
use crate::trust::Trust;
use serde::Serialize;
use spdcam_core::light_families::LightKind;
use spdcam_core::photo::PhotoAnalysis;
use spdcam_core::quality::LightingMetrics;
use spdcam_core::spectral::Spd;
use spdcam_core::spectral_error;

/// CCT is defined only this near the Planckian locus (|Duv| in CIE 1960 uv).
pub const MAX_CCT_DUV: f64 = 0.05;

/// CIE 1931 xy, and CCT and Duv where the chromaticity is near enough the Planckian locus.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Colorimetry {
    /// CIE 1931 chromaticity.
    pub xy: [f64; 2],
    /// Correlated colour temperature (K); `None` farther than |Duv| 0.05 from the locus.
    pub cct: Option<f64>,
    /// Distance from the Planckian locus in CIE 1960 uv.
    pub duv: Option<f64>,
}

impl Colorimetry {
    /// The colorimetry of `spd` (CIE 1931 2° observer; CCT and Duv by Ohno 2014).
    ///
    /// ```
    /// use spdcam_core::cie_illuminant::StandardIlluminant;
    /// use spdcam_core::spectral::Grid;
    /// use spdcam_infer::estimate::Colorimetry;
    ///
    /// let d65 = StandardIlluminant::D65.spd(&Grid::ESTIMATION)?;
    /// let c = Colorimetry::of(&d65)?;
    /// assert!((c.cct.unwrap() - 6504.0).abs() < 30.0);
    /// assert!(c.label().starts_with("xy (0.31"));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn of(spd: &Spd) -> Result<Colorimetry> {
        Colorimetry::of_metrics(&LightingMetrics::of_spd(spd))
    }

    /// The colorimetry read from a light's `metrics`, which hold its xy, CCT and Duv
    /// computed once (at 1 nm, [`LightingMetrics::of`]); the CCT and Duv only within
    /// [`MAX_CCT_DUV`] of the Planckian locus. An error when the light has no chromaticity
    /// (no visible light).
    pub fn of_metrics(metrics: &LightingMetrics) -> Result<Colorimetry> {
        let xy = metrics.xy.ok_or_else(|| {
            InferError::invalid(format!(
                "the spectrum has no chromaticity: {}",
                metrics
                    .reasons
                    .get("xy")
                    .map_or("no visible light", String::as_str)
            ))
        })?;
        let (cct, duv) = match (metrics.cct_k, metrics.duv) {
            (Some(cct), Some(duv)) if duv.abs() <= MAX_CCT_DUV => (Some(cct), Some(duv)),
            _ => (None, None),
        };
        Ok(Colorimetry { xy, cct, duv })
    }

    /// `xy (0.3127, 0.3290), CCT 6504 K, Duv +0.0032`.
    pub fn label(&self) -> String {
        let mut s = format!("xy ({:.4}, {:.4})", self.xy[0], self.xy[1]);
        match (self.cct, self.duv) {
            (Some(cct), Some(duv)) => s.push_str(&format!(", CCT {cct:.0} K, Duv {duv:+.4}")),
            _ => s.push_str(", no CCT (far from the Planckian locus)"),
        }
        s
    }
}

/// An estimate compared with its true SPD (both peak-normalised, thesis section 4.3).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Score {
    /// Goodness-of-fit coefficient (1 = same shape).
    pub gfc: f64,
    /// Root-mean-square error.
    pub rmse: f64,
}

impl Score {
    /// The score of `estimate` against `truth`, bare values of one grid: the row-level form
    /// for rows of model output; [`Score::of_spd`] is the typed form that checks the grids.
    ///
    /// ```
    /// use spdcam_infer::estimate::Score;
    ///
    /// // Peak-normalised first: a brighter copy of the same shape scores perfectly.
    /// let score = Score::of(&[0.5, 1.0, 0.25], &[1.0, 2.0, 0.5])?;
    /// assert_eq!((score.gfc, score.rmse), (1.0, 0.0));
    /// # Ok::<(), spdcam_infer::InferError>(())
    /// ```
    pub fn of(truth: &[f64], estimate: &[f64]) -> Result<Score> {
        let t = spdcam_core::spectral::normalise_by_max(truth);
        let e = spdcam_core::spectral::normalise_by_max(estimate);
        Ok(Score {
            gfc: spectral_error::gfc(&t, &e)?,
            rmse: spectral_error::rmse(&t, &e)?,
        })
    }

    /// The score of `estimate` against `truth`; an error when they are on different grids.
    ///
    /// ```
    /// use spdcam_core::spectral::{Grid, Spd};
    /// use spdcam_infer::estimate::Score;
    ///
    /// let grid = Grid::parse("400-600:100")?;
    /// let truth = Spd::new(grid, vec![0.5, 1.0, 0.25])?;
    /// let score = Score::of_spd(&truth, &Spd::new(grid, vec![1.0, 2.0, 0.5])?)?;
    /// assert_eq!((score.gfc, score.rmse), (1.0, 0.0));
    /// let elsewhere = Spd::new(Grid::parse("500-700:100")?, vec![0.5, 1.0, 0.25])?;
    /// assert!(Score::of_spd(&truth, &elsewhere).is_err());
    /// # Ok::<(), spdcam_infer::InferError>(())
    /// ```
    pub fn of_spd(truth: &Spd, estimate: &Spd) -> Result<Score> {
        let (t, e) = (truth.normalised_by_max(), estimate.normalised_by_max());
        Ok(Score {
            gfc: spectral_error::gfc_spd(&t, &e)?,
            rmse: spectral_error::rmse_spd(&t, &e)?,
        })
    }
}

/// One estimate of the light: its SPD, what it means, and where it came from.
#[derive(Debug, Clone)]
pub struct Estimate {
    /// The photo's file name, or `estimate_N` for feature rows.
    pub name: String,
    /// The model that made it.
    pub model: String,
    /// The kind of light the estimate was told of ([`crate::kind_prior`]); `Unknown` when
    /// none was named.
    pub light: LightKind,
    /// The relative SPD, peak 1, on the estimator's wavelengths.
    pub spd: Spd,
    /// xy, CCT, Duv of the model's whole estimate (on the model's wavelengths, whatever
    /// part of them [`Estimate::spd`] shows).
    pub colorimetry: Colorimetry,
    /// The lighting-quality metrics (CRI, TM-30, α-opic, S/P, PPF, blue-light hazard;
    /// `spdcam_core::quality`) of the model's whole estimate, computed on the model's
    /// wavelengths only.
    pub metrics: LightingMetrics,
    /// The score against a true SPD, when one was given.
    pub truth: Option<Score>,
    /// The analysis of the photo, for estimates from photos.
    pub photo: Option<PhotoAnalysis>,
    /// How far the estimate can be trusted (verdict, reasons, self-check, bands), when
    /// judged.
    pub trust: Option<Trust>,
    /// For photos: the approximate absolute levels from the EXIF exposure, or why there are
    /// none.
    pub absolute: Option<Absolute>,
    /// For photos: the light on the chart read on its grey patches, its level in the
    /// photo's linear units and the greys' colour ([`crate::absolute::chart_level`]),
    /// comparable between the charts of one photo; `None` when it could not be read.
    pub light_level: Option<ChartLevel>,
    /// For one of several charts in a photo: how the light compares across its places
    /// ([`crate::places`]), the same on each of them.
    pub across_places: Option<LightAcrossPlaces>,
}

impl Estimate {
    /// The estimate as JSON: `name`, `model`, `light` (the kind of light named, when one
    /// was), `wavelength_nm`, `spd`, `colorimetry`,
    /// `metrics` (every [`LightingMetrics`] key), `truth`, and for photos `photo` (chart, method, confidence, corners, homography, features and
    /// `features_by_name`, every patch with its statistics and flags, warnings). Judged
    /// estimates add `verdict`, `reasons`, `self_check` ({mean, worst, worst_patches} or
    /// null), `expected_gfc`, `band_widening` (≥ 1: how much the bands were widened for a
    /// photo the estimate explains worse than the calibration photos), `band68` and `band95`
    /// ({lower, upper} on the SPD's wavelengths) and `metric_uncertainty` ({key: {half68,
    /// half95}} for the single-number metrics), the last five null without a calibration. Photo estimates add
    /// `absolute` (approximate illuminance, PPFD, melanopic EDI and spectral irradiance from
    /// the EXIF exposure, see [`crate::absolute`]) or, when there is none, `absolute: null`
    /// and `absolute_reason`, and `light_level` (the chart's level in the photo's linear
    /// units and its greys' u′v′, or null); one of several charts in a photo has `photo.place` ({number, of,
    /// centre}) and `across_places` (see [`crate::places::LightAcrossPlaces`]).
    pub fn to_json(&self) -> Result<serde_json::Value> {
        let mut v = serde_json::json!({
            "name": self.name,
            "model": self.model,
            "wavelength_nm": self.spd.grid().wavelengths(),
            "spd": self.spd.values(),
            "colorimetry": self.colorimetry,
            "metrics": self.metrics,
            "truth": self.truth,
        });
        if self.light != LightKind::Unknown {
            v["light"] = serde_json::json!(self.light);
        }
        if let Some(a) = &self.photo {
            v["photo"] = analysis_json(a)?;
            v["light_level"] = serde_json::json!(self.light_level);
        }
        if let Some(across) = &self.across_places {
            v["across_places"] = serde_json::json!(across);
        }
        match &self.absolute {
            Some(Ok(level)) => v["absolute"] = serde_json::json!(level),
            Some(Err(reason)) => {
                v["absolute"] = serde_json::Value::Null;
                v["absolute_reason"] = serde_json::json!(reason);
            }
            None => {}
        }
        if let Some(t) = &self.trust {
            let u = t.uncertainty.as_ref();
            v["verdict"] = serde_json::json!(t.verdict);
            v["reasons"] = serde_json::json!(t.reasons);
            v["self_check"] = serde_json::json!(t.self_check);
            v["expected_gfc"] = serde_json::json!(u.map(|u| u.expected_gfc));
            v["band_widening"] = serde_json::json!(u.map(|u| u.widening));
            v["band68"] = serde_json::json!(u.map(|u| &u.band68));
            v["band95"] = serde_json::json!(u.map(|u| &u.band95));
            // Intervals of metrics the estimate defines only.
            v["metric_uncertainty"] = serde_json::json!(u.map(|u| u
                .metrics
                .iter()
                .filter(|(key, _)| self.metrics.scalar(key).is_some())
                .collect::<std::collections::BTreeMap<_, _>>()));
        }
        Ok(v)
    }

    /// Compares the estimate with `truth` (on the estimate's grid; an error otherwise) and
    /// keeps the score.
    pub fn score_against(&mut self, truth: &Spd) -> Result<()> {
        self.truth = Some(Score::of_spd(truth, &self.spd)?);
        Ok(())
    }
}

/// One photo analysis as JSON, with the features also keyed by column name.
pub fn analysis_json(analysis: &PhotoAnalysis) -> Result<serde_json::Value> {
    let mut v = serde_json::to_value(analysis)
        .map_err(|e| InferError::invalid(format!("encoding the analysis: {e}")))?;
    let named: serde_json::Map<String, serde_json::Value> = analysis
        .feature_names
        .iter()
        .zip(&analysis.features)
        .map(|(n, f)| (n.clone(), serde_json::json!(f)))
        .collect();
    if let Some(obj) = v.as_object_mut() {
        obj.insert("features_by_name".into(), serde_json::Value::Object(named));
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use spdcam_core::spectral::Grid;

    #[test]
    fn the_typed_score_equals_the_row_level_one_and_checks_the_grids() {
        let grid = Grid::ESTIMATION;
        let bump = |mu: f64| -> Vec<f64> {
            grid.wavelengths()
                .iter()
                .map(|l| (-((l - mu) / 50.0).powi(2)).exp())
                .collect()
        };
        let (t, e) = (bump(520.0), bump(560.0));
        let typed = Score::of_spd(
            &Spd::new(grid, t.clone()).unwrap(),
            &Spd::new(grid, e.clone()).unwrap(),
        )
        .unwrap();
        assert_eq!(typed, Score::of(&t, &e).unwrap());
        assert!(typed.gfc < 1.0 && typed.rmse > 0.0);
        let shifted = Grid::from_parts(405.0, 5.0, grid.count).unwrap();
        let err =
            Score::of_spd(&Spd::new(grid, t).unwrap(), &Spd::new(shifted, e).unwrap()).unwrap_err();
        assert!(err.to_string().contains("different grids"), "{err}");
    }
}
