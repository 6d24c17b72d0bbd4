//! A model's uncertainty calibration: the bands and metric intervals of an estimate from its
//! spread, the GFC to expect of it, and the levels above which a self-check is doubtful; the
//! calibrations shipped with the models.

use super::local_margin::{photo_coordinates, LocalMargin};
use super::self_check::SelfCheck;
use crate::error::{InferError, Result};
use crate::model::Model;
use serde::{Deserialize, Serialize};
use spdcam_core::colorimetry::{uv_to_cct_duv, xy_to_uv1960, Observer};
use spdcam_core::spectral::{Grid, Spd};
use std::collections::BTreeMap;
use std::sync::OnceLock;

/// A band around the SPD on its wavelengths (written to JSON as the edges' values).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Band {
    /// The lower edge, never below 0.
    #[serde(serialize_with = "values_of")]
    pub lower: Spd,
    /// The upper edge.
    #[serde(serialize_with = "values_of")]
    pub upper: Spd,
}

/// A spectrum written as its values only (its grid is written beside it).
fn values_of<S: serde::Serializer>(spd: &Spd, s: S) -> std::result::Result<S::Ok, S::Error> {
    spd.values().serialize(s)
}

/// Per-wavelength 68 % and 95 % bands and the GFC to expect.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Uncertainty {
    /// Where the true (peak-normalised) SPD lies with 68 % probability, per wavelength.
    pub band68: Band,
    /// The same at 95 %.
    pub band95: Band,
    /// The GFC such estimates reach, in the median: the calibration's [`GfcModel`].
    pub expected_gfc: f64,
    /// The GFC 95 % of such estimates reach at least: the expected GFC moved by the 95 %
    /// margin of the calibration photos most like this one ([`LocalMargin`]), or by the
    /// pooled margin ([`GfcModel::at_least95`]) where the photo cannot be placed among them.
    /// An estimate is called `ok` only where this is not poor.
    pub gfc_at_least95: f64,
    /// The margin used: how many times 1 − GFC may exceed its expected value for 95 % of
    /// such estimates (e to the margin of ln(1 − GFC)).
    pub gfc_margin_factor: f64,
    /// Whether that margin was taken among the calibration photos most like this one
    /// (`true`) or pooled over them all.
    pub gfc_margin_local: bool,
    /// The mean spread of the perturbed estimates (see [`Perturbed::spread`](super::spread::Perturbed::spread)).
    pub difficulty: f64,
    /// How many times the bands and intervals are widened because the estimated light
    /// explains this photo worse than it explains a typical calibration photo
    /// ([`TrustCalibration::widening`]); 1 when it explains it as well or better.
    pub widening: f64,
    /// Half-widths of the 68 % and 95 % intervals of the single-number metrics, by key
    /// ([`registry::calibrated`](spdcam_core::quality::registry::calibrated)): "Ra 82 ± 4" is `cri_ra` ± `half95`. Only metrics the calibration
    /// measured and the perturbed copies define.
    pub metrics: BTreeMap<String, MetricInterval>,
}

/// The calibrated half-widths of one metric's intervals, in the metric's unit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MetricInterval {
    /// The true value lies within ± this of the estimate's with 68 % probability.
    pub half68: f64,
    /// The same at 95 %.
    pub half95: f64,
}

/// One metric's calibration: the same scaled-residual conformal rule as the bands (see
/// [`TrustCalibration`]) with the metric's spread over the perturbed copies, plus a floor that
/// follows the expected GFC, as the scale ([`MetricCalibration::unit`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MetricCalibration {
    /// The metric's key ([`registry::METRICS`](spdcam_core::quality::registry::METRICS)).
    pub key: String,
    /// The median of |error| / (widening · gap factor) on the calibration photos
    /// ([`MetricCalibration::gap_factor`]; the median absolute error where the factor is 1).
    pub floor: f64,
    /// The 68 % quantile of |error| / [`MetricCalibration::unit`].
    pub scale68: f64,
    /// The 95 % quantile of the same.
    pub scale95: f64,
    /// How many calibration photos defined the metric (for the estimate and the truth).
    pub photos: usize,
    /// The power of the expected 1 − GFC in the floor: 0 keeps one floor for every photo;
    /// larger, the floor shrinks for estimates the calibration expects to be good and grows
    /// for the others. 0 in calibrations made before it existed.
    #[serde(default)]
    pub gap_power: f64,
    /// The calibration photos' median expected 1 − GFC, where the gap factor is 1.
    #[serde(default)]
    pub gap_reference: f64,
}

/// The smallest expected 1 − GFC the floor's gap factor uses.
const GAP_FACTOR_FLOOR: f64 = 1e-5;

impl MetricCalibration {
    /// How much the floor is scaled for an estimate whose expected GFC is 1 − `expected_gap`:
    /// (expected_gap / [`gap_reference`](Self::gap_reference))^[`gap_power`](Self::gap_power),
    /// 1 with no power. A locally weighted conformal scale (Lei et al. 2018, JASA 113:
    /// 1094–1111, section 5.2) whose weight is the expected error of the shape.
    pub fn gap_factor(&self, expected_gap: f64) -> f64 {
        if self.gap_power == 0.0 || self.gap_reference <= 0.0 {
            return 1.0;
        }
        (expected_gap.max(GAP_FACTOR_FLOOR) / self.gap_reference).powf(self.gap_power)
    }

    /// The unit of the conformal scaling of one photo: (floor · gap factor + spread) ·
    /// widening.
    pub fn unit(&self, spread: f64, expected_gap: f64, widening: f64) -> f64 {
        (self.floor * self.gap_factor(expected_gap) + spread) * widening
    }
}

impl Band {
    /// The mean width (SPD peak = 1).
    pub fn mean_width(&self) -> f64 {
        let n = self.upper.len().max(1) as f64;
        self.upper
            .iter()
            .zip(self.lower.iter())
            .map(|(u, l)| u - l)
            .sum::<f64>()
            / n
    }
}

/// A model's uncertainty calibration: measured once on held-out virtual photos of held-out
/// lamps (`spdcam trust calibrate`), a small JSON file per model.
///
/// The band is a scaled-residual conformal band (Lei et al. 2018, "Distribution-free
/// predictive inference for regression", JASA 113: 1094–1111, section 5.2, locally weighted
/// residuals): with the spread s(λ) of the perturbed estimates, a floor f(λ) (the median
/// absolute error at λ) and the widening w ≥ 1 of a photo the estimate explains worse than
/// a typical calibration photo ([`TrustCalibration::widening`]), the q-quantile of
/// |error(λ)| / ((f(λ) + s(λ))·w) over the calibration photos times (f(λ) + s(λ))·w is the
/// band's half-width. The expected GFC comes from [`GfcModel`] (not widened: on the real
/// Telelumen dev photos scaling 1 − GFC by w or w² made it two to four times too
/// pessimistic, while the estimate's shape alone came within 0.02 of their median GFC).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrustCalibration {
    /// The calibrated model's [`Model::fingerprint`].
    pub model: String,
    /// The model's chart.
    pub chart: String,
    /// How the calibration photos were made.
    pub method: String,
    /// The model's wavelengths (nm).
    pub wavelength_nm: Vec<f64>,
    /// f(λ): the median absolute error of the peak-normalised estimate.
    pub floor: Vec<f64>,
    /// The 68 % quantile of |error| / (f + s), per wavelength.
    pub scale68: Vec<f64>,
    /// The 95 % quantile of the same.
    pub scale95: Vec<f64>,
    /// The expected GFC of an estimate from its shape and difficulty.
    pub gfc_model: GfcModel,
    /// The median self-check residual ([`SelfCheck::mean`]) on the calibration photos, when
    /// the chart's reflectances were at hand: the residual of a typical photo, against which
    /// [`TrustCalibration::widening`] measures a photo's.
    pub residual_reference: Option<f64>,
    /// The 99th percentile of the difficulty on the calibration photos: harder photos are
    /// unlike the lights the model knows, or many lights give nearly the same photo.
    pub difficulty_doubtful: f64,
    /// The 99th percentile of the self-check's mean residual on the calibration photos, when
    /// the chart's reflectances were at hand; above it the estimate is doubtful.
    pub self_check_doubtful: Option<f64>,
    /// Per single-number metric, its interval's calibration (absent from older files).
    #[serde(default)]
    pub metrics: Vec<MetricCalibration>,
    /// The 99th percentile of the self-check's half-to-half residual ([`SelfCheck::split`])
    /// on the calibration photos; above it the estimate is doubtful.
    pub split_doubtful: Option<f64>,
    /// The 99th percentile of the self-check's colour gradient across the chart
    /// ([`SelfCheck::colour_gradient`]) on the calibration photos; above it the estimate is
    /// doubtful (absent from older files).
    #[serde(default)]
    pub colour_gradient_doubtful: Option<f64>,
    /// The 99th percentile of the self-check's glare ([`SelfCheck::glare`]) on the
    /// calibration photos; above it the estimate is doubtful (absent from older files).
    #[serde(default)]
    pub glare_doubtful: Option<f64>,
    /// The 99th percentile of the self-check's two-lights ratio ([`SelfCheck::two_lights`])
    /// on the calibration photos; above it the estimate is doubtful (absent from older
    /// files).
    #[serde(default)]
    pub two_lights_doubtful: Option<f64>,
    /// The 99th percentile of the number of clipped feature patches on the calibration
    /// photos (saturated colours clip a channel under narrow-band light, and the model was
    /// trained with them); more make the estimate doubtful.
    pub clipped_doubtful: usize,
    /// Real photos among the calibration photos (the real-camera study's validation photos,
    /// `spdcam trust calibrate --real`): they join the bands, the expected GFC, the metric
    /// intervals and the clipping and difficulty levels; 0 for virtual photos alone.
    #[serde(default)]
    pub real_photos: usize,
    /// Scene photos per validation lamp it was fitted on (`spdcam trust calibrate
    /// --scenes`): the chart in a cluttered scene through the whole camera chain, found and
    /// sampled as a user's photo is; they join what the real photos join. 0: none.
    #[serde(default)]
    pub scenes_per_lamp: usize,
    /// The expected GFC's margin among the calibration photos most like a photo (absent from
    /// older files, and where the calibration photos had no self-check: then the pooled
    /// [`GfcModel::gap_margin95`] serves every photo).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub local_margin: Option<LocalMargin>,
}

/// The GFC to expect of an estimate, from the estimate itself: a ridge regression (Hoerl &
/// Kennard 1970) of ln(1 − GFC) on ln(difficulty) and the estimate's coordinates on the
/// first principal components of the calibration photos' estimates, fitted on those photos
/// (`spdcam trust calibrate` chooses the number of components and the penalty by
/// cross-validation over lamps). Narrow-band and spiky estimates come from lights that
/// 96 broadband patches resolve poorly, so the shape says much of how far to trust it; the
/// regression's value is the conditional median of ln(1 − GFC), hence of the GFC. It never
/// extrapolates: each input is held within the range the calibration photos span, and the
/// value within the range of their ln(1 − GFC).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GfcModel {
    /// The mean of the calibration photos' estimates (peak 1), per wavelength.
    pub mean: Vec<f64>,
    /// The principal components used, unit vectors on the model's wavelengths.
    pub components: Vec<Vec<f64>>,
    /// The weights of ln(difficulty), of each component's coordinate, and of a constant 1.
    pub weights: Vec<f64>,
    /// The smallest value of each input ([`GfcModel::inputs`]) on the calibration photos.
    pub low: Vec<f64>,
    /// The largest value of each input on the calibration photos.
    pub high: Vec<f64>,
    /// The smallest and largest ln(1 − GFC) of the calibration photos.
    pub gap_range: [f64; 2],
    /// How far ln(1 − GFC) lies above the regression's prediction for 95 % of the
    /// calibration photos, predicted without their own lamp (cross-validation): the
    /// group-conditional conformal quantile of those residuals (each kind of photo on its
    /// own, as the metric intervals). 0 in calibrations made before it existed.
    #[serde(default)]
    pub gap_margin95: f64,
    /// The same quantile for each kind of calibration photo on its own (`virtual`, `scene`,
    /// `real`) and for all of them pooled (`pooled`): [`GfcModel::gap_margin95`] is the
    /// largest, and this says which kind set it. Empty in calibrations made before it
    /// existed.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub gap_quantiles95: BTreeMap<String, f64>,
}

impl GfcModel {
    /// The regression's inputs for `spd` (peak 1) of mean spread `difficulty`.
    pub fn inputs(&self, spd: &[f64], difficulty: f64) -> Vec<f64> {
        let mut x = Vec::with_capacity(self.components.len() + 2);
        x.push(difficulty.max(f64::MIN_POSITIVE).ln());
        for c in &self.components {
            x.push(
                c.iter()
                    .zip(spd.iter().zip(&self.mean))
                    .map(|(a, (v, m))| a * (v - m))
                    .sum(),
            );
        }
        x.push(1.0);
        x
    }

    /// The predicted ln(1 − GFC) of estimates like `spd` (peak 1) of mean spread
    /// `difficulty`, inside the calibration photos' range.
    fn predicted_gap(&self, spd: &[f64], difficulty: f64) -> f64 {
        let z: f64 = self
            .inputs(spd, difficulty)
            .iter()
            .zip(self.low.iter().zip(&self.high))
            .zip(&self.weights)
            .map(|((x, (lo, hi)), w)| w * x.clamp(*lo, *hi))
            .sum();
        let [lowest, highest] = self.gap_range;
        z.clamp(lowest, highest)
    }

    /// The median GFC of estimates like `spd` (peak 1) of mean spread `difficulty`.
    pub fn expected(&self, spd: &[f64], difficulty: f64) -> f64 {
        (1.0 - self.predicted_gap(spd, difficulty).exp()).clamp(0.0, 1.0)
    }

    /// The GFC that 95 % of estimates like `spd` reach at least: the prediction moved by
    /// the calibration's pooled 95 % residual margin ([`GfcModel::gap_margin95`]).
    pub fn at_least95(&self, spd: &[f64], difficulty: f64) -> f64 {
        self.at_least(spd, difficulty, self.gap_margin95)
    }

    /// The prediction of ln(1 − GFC) moved by `margin` (at least 0), as a GFC.
    pub fn at_least(&self, spd: &[f64], difficulty: f64, margin: f64) -> f64 {
        let gap = self.predicted_gap(spd, difficulty) + margin.max(0.0);
        (1.0 - gap.exp()).clamp(0.0, 1.0)
    }

    /// Whether the model's arrays fit `d` wavelengths.
    fn fits(&self, d: usize) -> bool {
        self.mean.len() == d
            && self.components.iter().all(|c| c.len() == d)
            && self.weights.len() == self.components.len() + 2
            && self.low.len() == self.weights.len()
            && self.high.len() == self.weights.len()
            && self.low.iter().zip(&self.high).all(|(l, h)| l <= h)
            && self.gap_range[0] <= self.gap_range[1]
            && self.weights.iter().all(|w| w.is_finite())
            && self.gap_margin95.is_finite()
    }
}

/// The widening of a photo whose self-check residual is `residual` against the typical
/// residual `reference` (see [`TrustCalibration::widening`]): their ratio, at least 1; 1 when
/// either is unknown.
pub fn widening(residual: Option<f64>, reference: Option<f64>) -> f64 {
    match (residual, reference) {
        (Some(r), Some(reference)) if reference > 0.0 && r.is_finite() => (r / reference).max(1.0),
        _ => 1.0,
    }
}

impl TrustCalibration {
    /// Whether the self-check `check` exceeds any of this calibration's doubtful levels:
    /// the residual, the half-to-half residual, the colour gradient, the glare or the
    /// two-lights ratio.
    pub fn flags(&self, check: &SelfCheck) -> bool {
        let above =
            |value: Option<f64>, level: Option<f64>| value.zip(level).is_some_and(|(v, l)| v > l);
        above(Some(check.mean), self.self_check_doubtful)
            || above(Some(check.split), self.split_doubtful)
            || above(check.colour_gradient, self.colour_gradient_doubtful)
            || above(Some(check.glare), self.glare_doubtful)
            || above(Some(check.two_lights), self.two_lights_doubtful)
    }

    /// Reads a calibration from JSON (`shown` names it in errors), its arrays checked to
    /// agree in length and its wavelengths to be evenly spaced.
    pub fn from_json(text: &str, shown: &str) -> Result<TrustCalibration> {
        let c: TrustCalibration =
            serde_json::from_str(text).map_err(|e| InferError::invalid(format!("{shown}: {e}")))?;
        let d = c.wavelength_nm.len();
        if d == 0
            || c.floor.len() != d
            || c.scale68.len() != d
            || c.scale95.len() != d
            || !c.gfc_model.fits(d)
            || c.local_margin.as_ref().is_some_and(|l| !l.fits())
        {
            return Err(InferError::invalid(format!(
                "{shown}: the calibration's arrays do not agree in length"
            )));
        }
        let grid = c
            .grid()
            .map_err(|e| InferError::invalid(format!("{shown}: {e}")))?;
        if grid.wavelengths() != c.wavelength_nm {
            return Err(InferError::invalid(format!(
                "{shown}: the calibration's wavelengths are not evenly spaced"
            )));
        }
        Ok(c)
    }

    /// The calibration's wavelengths as a grid (the model's).
    fn grid(&self) -> Result<Grid> {
        let w = &self.wavelength_nm;
        let step = match w.as_slice() {
            [first, second, ..] => second - first,
            _ => 1.0,
        };
        let first = w.first().copied().unwrap_or(0.0);
        Ok(Grid::from_parts(first, step, w.len())?)
    }

    /// How many times worse than a typical calibration photo the estimated light explains
    /// a photo whose self-check residual is `residual`: the residual over the calibration's
    /// median, at least 1 (and 1 without a self-check). A photo the light explains k times
    /// worse (flare, uneven light, a camera unlike the calibration's) is taken to carry k
    /// times the calibration's errors: its bands and intervals are k times as wide.
    pub fn widening(&self, residual: Option<f64>) -> f64 {
        widening(residual, self.residual_reference)
    }

    /// The bands, expected GFC and metric intervals of `spd` (the model's peak-normalised
    /// estimate) whose perturbed estimates spread by `spread` per wavelength and by
    /// `metric_spread` per metric ([`Perturbed`](super::spread::Perturbed)), and whose
    /// self-check is `check` (`None` without one).
    pub fn uncertainty(
        &self,
        spd: &[f64],
        spread: &[f64],
        metric_spread: &BTreeMap<String, f64>,
        check: Option<&SelfCheck>,
    ) -> Result<Uncertainty> {
        let residual = check.map(|c| c.mean);
        let d = self.floor.len();
        if spd.len() != d || spread.len() != d {
            return Err(InferError::invalid(format!(
                "the calibration has {d} wavelengths, the estimate {}",
                spd.len()
            )));
        }
        let grid = self.grid()?;
        let widening = self.widening(residual);
        let half = |scale: &[f64], k: usize| scale[k] * (self.floor[k] + spread[k]) * widening;
        let band = |scale: &[f64]| -> Result<Band> {
            Ok(Band {
                lower: Spd::new(
                    grid,
                    (0..d).map(|k| (spd[k] - half(scale, k)).max(0.0)).collect(),
                )?,
                upper: Spd::new(grid, (0..d).map(|k| spd[k] + half(scale, k)).collect())?,
            })
        };
        let difficulty = spread.iter().sum::<f64>() / d as f64;
        let expected_gfc = self.gfc_model.expected(spd, difficulty);
        let local = match &self.local_margin {
            Some(local) => photo_coordinates(
                expected_gfc,
                estimate_cct(&grid, spd)?,
                residual,
                check.and_then(|c| c.veil.as_ref()).map(|v| v.share),
            )
            .map(|x| local.margin95(&x)),
            None => None,
        };
        let margin = local.unwrap_or(self.gfc_model.gap_margin95).max(0.0);
        Ok(Uncertainty {
            band68: band(&self.scale68)?,
            band95: band(&self.scale95)?,
            expected_gfc,
            gfc_at_least95: self.gfc_model.at_least(spd, difficulty, margin),
            gfc_margin_factor: margin.exp(),
            gfc_margin_local: local.is_some(),
            difficulty,
            widening,
            metrics: self
                .metrics
                .iter()
                .filter_map(|m| {
                    let s = *metric_spread.get(&m.key)?;
                    let unit = m.unit(s, 1.0 - expected_gfc, widening);
                    Some((
                        m.key.clone(),
                        MetricInterval {
                            half68: m.scale68 * unit,
                            half95: m.scale95 * unit,
                        },
                    ))
                })
                .collect(),
        })
    }
}

/// The CCT (K) of `spd` on `grid` (CIE 1931 2°; Ohno 2014 through
/// [`uv_to_cct_duv`]), `None` where it has none (too far from the Planckian locus or black).
pub fn estimate_cct(grid: &Grid, spd: &[f64]) -> Result<Option<f64>> {
    // The estimation grid's observer is resampled once: every estimate asks for it.
    static ESTIMATION: OnceLock<Observer> = OnceLock::new();
    let xy = if *grid == Grid::ESTIMATION {
        let observer = match ESTIMATION.get() {
            Some(o) => o,
            None => {
                let o = Observer::cie1931(grid)?;
                ESTIMATION.get_or_init(|| o)
            }
        };
        observer.spd_to_xy(spd)
    } else {
        Observer::cie1931(grid)?.spd_to_xy(spd)
    };
    if !xy.iter().all(|v| v.is_finite()) {
        return Ok(None);
    }
    Ok(uv_to_cct_duv(xy_to_uv1960(xy)).ok().map(|(cct, _)| cct))
}

/// The shipped calibration measured on `model` (`models/<chart>.trust.json` or, for a
/// shipped raw model, `models/<chart>.raw.trust.json`, made by `spdcam trust calibrate`), if
/// any.
pub fn calibration_for(model: &Model) -> Result<Option<TrustCalibration>> {
    let fingerprint = model.fingerprint();
    let shipped = crate::shipped::SHIPPED
        .iter()
        .map(|s| (s.name(), s.calibration))
        .chain(
            crate::shipped::SHIPPED_RAW
                .iter()
                .map(|s| (s.name(), s.calibration)),
        );
    for (model_name, json) in shipped {
        let c = TrustCalibration::from_json(json, &format!("{model_name}'s calibration"))?;
        if c.model == fingerprint {
            return Ok(Some(c));
        }
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shipped::ModelSet;

    #[test]
    fn widening_is_the_residual_over_the_typical_one_and_never_narrows() {
        assert_eq!(widening(Some(0.09), Some(0.03)), 3.0);
        assert_eq!(widening(Some(0.01), Some(0.03)), 1.0);
        assert_eq!(widening(None, Some(0.03)), 1.0);
        assert_eq!(widening(Some(0.09), None), 1.0);
        assert_eq!(widening(Some(f64::NAN), Some(0.03)), 1.0);
        assert_eq!(widening(Some(0.09), Some(0.0)), 1.0);
    }

    #[test]
    fn the_expected_gfc_follows_its_regression() {
        // ln(1 − GFC) = −4 + 0.5·ln(difficulty) + 2·(coordinate on the one component).
        let model = GfcModel {
            mean: vec![0.5, 0.5],
            components: vec![vec![0.6, 0.8]],
            weights: vec![0.5, 2.0, -4.0],
            low: vec![-10.0, -1.0, 1.0],
            high: vec![0.0, 1.0, 1.0],
            gap_range: [-20.0, 0.0],
            gap_margin95: 0.0,
            gap_quantiles95: BTreeMap::new(),
        };
        let (spd, difficulty) = ([1.0, 0.25], 0.04);
        let coordinate = 0.6 * 0.5 + 0.8 * -0.25;
        let want = 1.0 - (-4.0 + 0.5 * 0.04f64.ln() + 2.0 * coordinate).exp();
        assert!((model.expected(&spd, difficulty) - want).abs() < 1e-12);
        assert_eq!(
            model.inputs(&spd, difficulty),
            vec![0.04f64.ln(), coordinate, 1.0]
        );
        // Without a margin the 95 % floor is the median; a margin of ln 3 triples 1 − GFC.
        assert!((model.at_least95(&spd, difficulty) - want).abs() < 1e-12);
        let wider = GfcModel {
            gap_margin95: 3.0f64.ln(),
            ..model.clone()
        };
        let floor = wider.at_least95(&spd, difficulty);
        assert!(
            ((1.0 - floor) / (1.0 - want) - 3.0).abs() < 1e-9,
            "{floor} {want}"
        );
        // Inputs beyond the calibration's range are held at its edge, and so is the value.
        let narrow = GfcModel {
            low: vec![-10.0, 0.2, 1.0],
            ..model.clone()
        };
        let held = 1.0 - (-4.0 + 0.5 * 0.04f64.ln() + 2.0 * 0.2).exp();
        assert!((narrow.expected(&spd, difficulty) - held).abs() < 1e-12);
        let wild = GfcModel {
            weights: vec![0.0, 0.0, 5.0],
            gap_range: [-20.0, -3.0],
            gap_margin95: 0.0,
            ..model
        };
        assert!((wild.expected(&spd, difficulty) - (1.0 - (-3.0f64).exp())).abs() < 1e-12);
    }

    /// A calibration on `wavelength_nm` with bands of floor 0.1 and scales 1 and 2, an
    /// expected GFC of 1 − e⁻³ for every estimate, a typical residual of 0.05 and `metrics`.
    fn test_calibration(
        wavelength_nm: Vec<f64>,
        metrics: Vec<MetricCalibration>,
    ) -> TrustCalibration {
        let d = wavelength_nm.len();
        TrustCalibration {
            model: "0".into(),
            chart: "c".into(),
            method: "m".into(),
            wavelength_nm,
            floor: vec![0.1; d],
            scale68: vec![1.0; d],
            scale95: vec![2.0; d],
            gfc_model: GfcModel {
                mean: vec![0.5; d],
                components: Vec::new(),
                weights: vec![0.0, -3.0],
                low: vec![-10.0, 1.0],
                high: vec![0.0, 1.0],
                gap_range: [-10.0, 0.0],
                gap_margin95: 0.0,
                gap_quantiles95: BTreeMap::new(),
            },
            residual_reference: Some(0.05),
            difficulty_doubtful: 1.0,
            self_check_doubtful: None,
            metrics,
            split_doubtful: None,
            colour_gradient_doubtful: None,
            glare_doubtful: None,
            two_lights_doubtful: None,
            clipped_doubtful: 0,
            real_photos: 0,
            scenes_per_lamp: 0,
            local_margin: None,
        }
    }

    /// A self-check of mean residual `mean`, nothing else found.
    fn check_of(mean: f64) -> SelfCheck {
        SelfCheck {
            mean,
            split: 0.0,
            worst: 0.0,
            worst_patches: Vec::new(),
            colour_gradient: None,
            glare: 0.0,
            two_lights: 0.0,
            veil: None,
        }
    }

    #[test]
    fn the_gfc_margin_is_the_local_one_where_the_photo_can_be_placed_else_the_pooled_one() {
        // On 300–800 nm so that the estimate has a CCT.
        let wavelengths: Vec<f64> = (0..51).map(|k| 300.0 + 10.0 * f64::from(k)).collect();
        let mut cal = test_calibration(wavelengths.clone(), Vec::new());
        cal.gfc_model.gap_margin95 = 5.0f64.ln();
        let d = wavelengths.len();
        let (spd, spread) = (vec![1.0; d], vec![0.0; d]);
        let expected_gap = (-3.0f64).exp();
        let at_least = |factor: f64| 1.0 - expected_gap * factor;
        let pooled = cal
            .uncertainty(&spd, &spread, &BTreeMap::new(), Some(&check_of(0.04)))
            .unwrap();
        assert!(!pooled.gfc_margin_local);
        assert!((pooled.gfc_at_least95 - at_least(5.0)).abs() < 1e-12);
        // Calibration photos all alike, their residuals ln 2 at most: the margin is ln 2.
        let cct = estimate_cct(&cal.grid().unwrap(), &spd).unwrap();
        let x = photo_coordinates(1.0 - expected_gap, cct, Some(0.04), None).unwrap();
        let photos: Vec<_> = (0..20)
            .map(|k| (x, 2.0f64.ln() * f64::from(k) / 19.0))
            .collect();
        cal.local_margin = LocalMargin::fit(&photos, 20);
        let local = cal
            .uncertainty(&spd, &spread, &BTreeMap::new(), Some(&check_of(0.04)))
            .unwrap();
        assert!(local.gfc_margin_local);
        assert!((local.gfc_margin_factor - 2.0).abs() < 1e-12);
        assert!((local.gfc_at_least95 - at_least(2.0)).abs() < 1e-12);
        // Without a self-check the photo cannot be placed: the pooled margin.
        let unplaced = cal
            .uncertainty(&spd, &spread, &BTreeMap::new(), None)
            .unwrap();
        assert!(!unplaced.gfc_margin_local);
        assert!((unplaced.gfc_at_least95 - at_least(5.0)).abs() < 1e-12);
    }

    #[test]
    fn bands_widen_with_the_residual_and_the_expected_gfc_does_not_move() {
        let cal = test_calibration(vec![400.0, 410.0], Vec::new());
        let (spd, spread) = ([1.0, 0.5], [0.05, 0.05]);
        let plain = cal
            .uncertainty(&spd, &spread, &BTreeMap::new(), Some(&check_of(0.04)))
            .unwrap();
        let wide = cal
            .uncertainty(&spd, &spread, &BTreeMap::new(), Some(&check_of(0.1)))
            .unwrap();
        assert_eq!((plain.widening, wide.widening), (1.0, 2.0));
        // Half-width 2 × (0.1 + 0.05) = 0.3, doubled by the widening.
        assert!((plain.band95.upper[0] - 1.3).abs() < 1e-12);
        assert!((wide.band95.upper[0] - 1.6).abs() < 1e-12);
        assert_eq!(wide.band95.lower[1], 0.0);
        assert_eq!(plain.expected_gfc, wide.expected_gfc);
        assert!((plain.expected_gfc - (1.0 - (-3.0f64).exp())).abs() < 1e-12);
    }

    #[test]
    fn metric_intervals_follow_the_expected_gfc() {
        let metric = |key: &str, gap_power: f64| MetricCalibration {
            key: key.into(),
            floor: 0.02,
            scale68: 1.0,
            scale95: 2.0,
            photos: 100,
            gap_power,
            gap_reference: 0.01,
        };
        // Expected GFC 1 − e⁻³ (constant regression): 1 − GFC = 0.0498, five times the
        // reference 0.01.
        let gap = (-3.0f64).exp();
        let cal = test_calibration(
            vec![400.0, 410.0],
            vec![metric("cri_ra", 1.0), metric("duv", 0.0)],
        );
        let spreads: BTreeMap<String, f64> = [("cri_ra", 0.5), ("duv", 0.001)]
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect();
        // Widening 2 (residual 0.1 over 0.05).
        let u = cal
            .uncertainty(&[1.0, 0.5], &[0.0; 2], &spreads, Some(&check_of(0.1)))
            .unwrap();
        // Ra: its floor scaled by (gap / reference)¹.
        let want = 2.0 * (0.02 * gap / 0.01 + 0.5) * 2.0;
        assert!((u.metrics["cri_ra"].half95 - want).abs() < 1e-12);
        assert!((u.metrics["cri_ra"].half68 - want / 2.0).abs() < 1e-12);
        // Duv: one floor, as calibrations made before the power read.
        assert!((u.metrics["duv"].half95 - 2.0 * 0.021 * 2.0).abs() < 1e-12);
        let old = r#"{"key":"duv","floor":0.02,"scale68":1.0,"scale95":2.0,"photos":9}"#;
        let read: MetricCalibration = serde_json::from_str(old).unwrap();
        let want = MetricCalibration {
            gap_reference: 0.0,
            photos: 9,
            ..metric("duv", 0.0)
        };
        assert_eq!(read, want);
    }

    #[test]
    fn shipped_models_carry_their_calibrations() {
        for m in ModelSet::shipped().unwrap().models() {
            let c = calibration_for(&m.model).unwrap().expect("a calibration");
            assert_eq!(Some(c.chart.as_str()), m.model.header().chart.as_deref());
            assert_eq!(c.floor.len(), m.model.grid().count);
            assert!(c.scale68.iter().zip(&c.scale95).all(|(a, b)| a <= b));
        }
    }

    #[test]
    fn a_calibration_whose_arrays_disagree_is_refused() {
        let text = r#"{"model":"0","chart":"c","method":"m","wavelength_nm":[400,410],
            "floor":[0.1],"scale68":[1,1],"scale95":[2,2],
            "gfc_model":{"mean":[0.5,0.5],"components":[],"weights":[0.0,-3.0],
                "low":[-9.0,1.0],"high":[0.0,1.0],"gap_range":[-9.0,0.0]},
            "residual_reference":null,"difficulty_doubtful":0.1,"self_check_doubtful":null,"split_doubtful":null,
            "clipped_doubtful":0}"#;
        let err = TrustCalibration::from_json(text, "c.json")
            .unwrap_err()
            .to_string();
        assert!(err.contains("c.json"), "{err}");
    }
}
