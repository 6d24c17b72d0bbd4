//! Approximate absolute levels of an estimate from the photo's EXIF exposure: illuminance,
//! PPFD, melanopic EDI and the SPD as spectral irradiance.
//!
//! ```text
//! EXIF (N, t, ISO) + neutral patch's linear value y ─► luminance L (ISO 12232 SOS,
//!     spdcam_core::photo::exposure) ─► illuminance E = π·L / ρ_Y (a Lambertian patch of
//!     luminance factor ρ_Y under the estimated light) ─► PPFD = E·PPF/lx,
//!     melanopic EDI = E·M-EDER (CIE S 026), E_e(λ) = E·S(λ) / (683.002·Σ S·V·Δλ)
//! ```
//!
//! Every neutral feature patch of the chart that is neither clipped nor dark and renders
//! between 0.05 and 0.6 of the output's white (where tone curves are nearest linear) gives
//! one illuminance; the median is the answer. The result rests on the camera's ISO rating,
//! its tone curve and the lens's vignetting, so it is approximate (tens of per cent): every
//! output says so.
//!
//! A raw photo is read on its sensor values instead, by ISO 12232's saturation-based speed
//! ([`Exposure::luminance_from_raw`]): a neutral patch's green raw value v (a share of the
//! white level above black, read on the mosaic) had the luminance
//! L = v · (78 / S) · N² / (q · t), every neutral patch neither clipped nor nearly black
//! counting. The green photosites stand for the luminance: a neutral patch's green is its
//! luminance when the camera's green sensitivity, weighted by the light, is shaped as the
//! CIE V(λ) in the proportion it has under the light the ISO was rated for. The EXIF ISO is
//! taken as the saturation speed, which a camera rated by SOS or by noise, or with
//! headroom above its white level, does not give exactly; under a light unlike the
//! rating's, the green's share of luminance changes (the built-in Nikon D5100's by −21 %
//! under CIE A against daylight at 5500 K): see [`APPROXIMATE_RAW`].

use crate::error::Result;
use serde::Serialize;
use spdcam_core::chart::Chart;
use spdcam_core::colorimetry::Observer;
use spdcam_core::colorimetry::{linear_srgb_to_xyz, srgb_decode};
use spdcam_core::photo::{Exposure, PhotoAnalysis};
use spdcam_core::quality::uv::{xy_to_uv1976, xyz_to_uv1976};
use spdcam_core::quality::LightingMetrics;
use spdcam_core::spectral::Spd;

/// CIE 015:2018 maximum luminous efficacy K_m of photopic vision, lm/W.
pub const LUMINOUS_EFFICACY_LM_PER_W: f64 = 683.002;
/// The linear output values (0–1 of white) a patch may have to count: tone curves are
/// nearest linear around the SOS grey (0.18).
const USABLE_VALUES: (f64, f64) = (0.05, 0.6);
/// What every absolute number carries.
pub const APPROXIMATE: &str = "approximate (tens of per cent): from the EXIF exposure by the \
     ISO 12232 standard output sensitivity, assuming the camera's ISO rating, a linear tone \
     curve near mid-grey and a lens factor of 0.65; vignetting, exposure correction in the \
     camera and a chart that is not square to the light change it";

/// What every absolute number read from a raw file carries.
pub const APPROXIMATE_RAW: &str = "approximate (tens of per cent): from the EXIF exposure \
     by the ISO 12232 saturation-based speed (the white level reached at 78/ISO lux·s), \
     assuming the EXIF ISO is the sensor's saturation speed, the green photosites stand \
     for luminance as under the light the ISO was rated for, and a lens factor of 0.65; \
     a light unlike the rating's (tungsten against daylight: tens of per cent on some \
     sensors), vignetting and a chart that is not square to the light change it";

/// The absolute levels of a photo's estimate, or why there are none.
pub type Absolute = std::result::Result<AbsoluteLevel, String>;

/// The estimate in absolute units.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AbsoluteLevel {
    /// Illuminance on the chart, lux.
    pub illuminance_lux: f64,
    /// Photosynthetic photon flux density (400–700 nm), µmol·m⁻²·s⁻¹.
    pub ppfd_umol_m2_s: Option<f64>,
    /// Melanopic equivalent daylight (D65) illuminance, lux (CIE S 026).
    pub melanopic_edi_lux: Option<f64>,
    /// The SPD as spectral irradiance on the chart, W·m⁻²·nm⁻¹, on the estimate's
    /// wavelengths.
    pub spectral_irradiance_w_m2_nm: Vec<f64>,
    /// The exposure the numbers rest on.
    pub exposure: Exposure,
    /// The neutral feature patches used (1-based feature numbers) and each one's
    /// illuminance, lux.
    pub patches: Vec<(usize, f64)>,
    /// How approximate the numbers are, and why.
    pub note: &'static str,
}

/// The absolute levels of the estimate `spd` (any scale) with `metrics`, from the photo
/// `analysis` of the feature patches (`unusable`: clipped or dark, per feature patch) of the
/// chart `chart_name`, whose reflectances on the estimate's grid are `chart` (`None` when
/// not at hand); the reason instead when they cannot be had (no EXIF exposure, chart
/// reflectances not at hand, no usable neutral patch).
pub fn absolute_level(
    analysis: &PhotoAnalysis,
    chart_name: &str,
    chart: Option<&Chart>,
    spd: &Spd,
    metrics: &LightingMetrics,
    unusable: &[bool],
) -> Result<Absolute> {
    let Some(exposure) = analysis.exposure else {
        return Ok(Err(
            "the photo's EXIF gives no aperture, exposure time and ISO".into(),
        ));
    };
    let Some(chart) = chart else {
        return Ok(Err(format!(
            "the reflectances of {chart_name} are not at hand (the data directory holds them)"
        )));
    };
    let level = match chart_level(analysis, chart_name, chart, spd, unusable)? {
        Ok(level) => level,
        Err(reason) => return Ok(Err(reason)),
    };
    // The luminance is linear in the linear value: each patch's illuminance and the median
    // are the level's, scaled. A raw value (the green photosites, linear on the sensor)
    // relates to exposure by the saturation-based speed, a rendered one by the SOS.
    let raw = analysis.raw.is_some();
    let lux = |ratio: f64| {
        std::f64::consts::PI
            * if raw {
                exposure.luminance_from_raw(ratio)
            } else {
                exposure.luminance(ratio)
            }
    };
    let illuminance_lux = lux(level.level);
    let found: Vec<(usize, f64)> = level.patches.iter().map(|&(k, r)| (k, lux(r))).collect();
    let grid = spd.grid();
    let observer = Observer::cie1931(grid)?;
    let luminous: f64 = observer
        .cmf(1)
        .iter()
        .zip(spd.iter())
        .map(|(v, s)| v * s)
        .sum::<f64>()
        * grid.step_nm
        * LUMINOUS_EFFICACY_LM_PER_W;
    let scale = illuminance_lux / luminous;
    Ok(Ok(AbsoluteLevel {
        illuminance_lux,
        ppfd_umol_m2_s: metrics.ppf_per_lux.map(|p| p * illuminance_lux),
        melanopic_edi_lux: metrics.mel_der.map(|m| m * illuminance_lux),
        spectral_irradiance_w_m2_nm: spd.iter().map(|s| s * scale).collect(),
        exposure,
        patches: found,
        note: if raw { APPROXIMATE_RAW } else { APPROXIMATE },
    }))
}

/// The light on a chart as the photo shows it, read on its grey patches: its level in the
/// photo's linear units, the greys' colour, and the patches it was read from.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChartLevel {
    /// The median over the patches used of y / ρ_Y (see [`chart_level`]).
    pub level: f64,
    /// The CIE 1976 u′v′ of the grey patches used as the photo renders them (their mean
    /// linear sRGB); for a raw photo, the light's chromaticity through the file's matrices.
    /// Under one light every chart's greys share it, whatever the model reads of them.
    pub grey_uv_prime: [f64; 2],
    /// The neutral feature patches used (1-based feature numbers), each with its y / ρ_Y.
    pub patches: Vec<(usize, f64)>,
}

/// The light's level on the chart of `analysis` in the photo's linear units: over the
/// chart's neutral feature patches that are usable (not `unusable`: clipped or dark), the
/// median of y / ρ_Y, where ρ_Y is the patch's luminance factor under `spd` and y its linear
/// value: for an encoded photo its sRGB-decoded luminance (0–1 of white), counted only
/// between 0.05 and 0.6 of white where tone curves are nearest linear; for a raw photo the
/// sensor's green channel read on the mosaic (linear, before any development). The charts
/// of one photo share its exposure, so the ratio of two charts' levels is the ratio of the
/// light on them. The reason instead when no patch can be used.
pub fn chart_level(
    analysis: &PhotoAnalysis,
    chart_name: &str,
    chart: &Chart,
    spd: &Spd,
    unusable: &[bool],
) -> Result<std::result::Result<ChartLevel, String>> {
    let grid = spd.grid();
    chart
        .reflectances
        .require_grid(grid, "the chart of the light's level")?;
    let observer = Observer::cie1931(grid)?;
    let patches = chart.feature_patches.len();
    if analysis.features.len() != 3 * patches {
        return Ok(Err(format!(
            "the photo's features are not those of {chart_name}"
        )));
    }
    let raw = analysis.raw.is_some();
    let mut grey_sum = [0.0f64; 3];
    let mut found: Vec<(usize, f64)> = chart
        .neutral_features()
        .into_iter()
        .filter(|&(k, _)| !unusable.get(k).copied().unwrap_or(false))
        .filter_map(|(k, _)| {
            let patch = chart.feature_patches[k];
            let y = if raw {
                f64::from(analysis.patches.get(patch)?.camera_rgb?[1])
            } else {
                let rgb: [f64; 3] = std::array::from_fn(|c| {
                    srgb_decode(f64::from(analysis.features[3 * k + c]) / 255.0)
                });
                let y = linear_srgb_to_xyz(rgb)[1];
                if !(USABLE_VALUES.0..=USABLE_VALUES.1).contains(&y) {
                    return None;
                }
                // The greys' colour, each grey weighed alike whatever its lightness.
                (0..3).for_each(|c| grey_sum[c] += rgb[c] / y);
                y
            };
            let factor = observer.reflectance_to_xyz(chart.reflectances.item(patch), spd)[1];
            (factor > 0.0 && factor.is_finite() && y > 0.0).then(|| (k + 1, y / factor))
        })
        .collect();
    if found.is_empty() {
        return Ok(Err(if raw {
            format!("no neutral patch of {chart_name} is read on the sensor without clipping")
        } else {
            format!(
                "no neutral patch of {chart_name} is rendered between {} and {} of white \
                 without clipping",
                USABLE_VALUES.0, USABLE_VALUES.1
            )
        }));
    }
    let mut values: Vec<f64> = found.iter().map(|p| p.1).collect();
    values.sort_by(f64::total_cmp);
    let n = values.len();
    let level = if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    };
    found.sort_by_key(|p| p.0);
    let grey_uv_prime = match &analysis.raw {
        Some(reading) => xy_to_uv1976(reading.light_xy),
        None => xyz_to_uv1976(linear_srgb_to_xyz(grey_sum)),
    };
    Ok(Ok(ChartLevel {
        level,
        grey_uv_prime,
        patches: found,
    }))
}
