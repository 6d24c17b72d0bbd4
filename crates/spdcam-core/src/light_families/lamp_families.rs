//! Light families grounded in real lamps. Each family is a physical model of one kind of
//! lamp (a phosphor-converted white LED, a mix of coloured LEDs, a fluorescent tube, a
//! discharge lamp, a filament) whose parameters are *fitted* to measured lamps of that kind
//! by least squares ([`fit_lamp`]); a draw picks one fitted lamp and moves its parameters by
//! a kernel-density step whose bandwidth comes from the spread of the fitted parameters
//! (Scott's rule, D. W. Scott, *Multivariate Density Estimation*, Wiley 1992, eq. 6.42:
//! h = σ n^(−1/(d+4))), within the range the fitted lamps span. So the family's spread is the
//! measured lamps' own, not chosen by hand.
//!
//! Line positions: mercury 404.66, 435.83, 546.07 and the 576.96/579.07 nm doublet; sodium
//! 588.99/589.59 (D), 568.8, 615.4 and 498.3 nm; thallium 535.05; indium 410.18 and 451.13;
//! lithium 670.78 nm (NIST Atomic Spectra Database, A. Kramida et al., version 5.11, air
//! wavelengths). Rare-earth phosphor lines: Tb³⁺ ⁵D₄→⁷F₆…₃ at 488, 544, 586, 621 nm and Eu³⁺
//! ⁵D₀→⁷F₁…₄ at 593, 611, 627, 650, 707 nm (Blasse & Grabmaier, *Luminescent Materials*,
//! 1994, ch. 4 and 10).

use super::bands::Shape;
use super::fit::{levenberg_marquardt, nnls};
use super::lamp_library::{LampLibrary, LampType};
use crate::error::{Error, Result};
use crate::spectral::{normalise_peak, Grid};
use crate::spectral_error;
use nalgebra::{DMatrix, DVector};
use rand::rngs::SmallRng;
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// The fitted parameters the program ships (`spdcam lamps fit` writes them).
const SHIPPED_FITS: &str = include_str!("../../../../data/lamp_fits.json");

/// Mercury, sodium and rare-earth phosphor lines of fluorescent tubes (nm).
const FLUORESCENT_LINES: [f64; 13] = [
    404.66, 435.83, 546.07, 578.0, // Hg (576.96/579.07 doublet as one)
    488.0, 544.0, 586.0, 621.0, // Tb³⁺
    593.0, 611.0, 627.0, 650.0, 707.0, // Eu³⁺
];
/// Lines of high-intensity discharge lamps (nm): Hg, Na, Tl, In, Li.
const DISCHARGE_LINES: [f64; 12] = [
    404.66, 435.83, 546.07, 578.0, // Hg
    589.3, 568.8, 615.4, 498.3,  // Na (D doublet as one)
    535.05, // Tl
    410.18, 451.13, // In
    670.78, // Li
];

/// How a non-linear parameter is moved by a draw: additively, or additively in its
/// logarithm (widths and temperatures, which scale).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scale {
    Linear,
    Log,
}

/// One non-linear parameter of a family's model.
#[derive(Debug, Clone, Copy)]
struct Param {
    name: &'static str,
    lower: f64,
    upper: f64,
    scale: Scale,
}

const fn p(name: &'static str, lower: f64, upper: f64, scale: Scale) -> Param {
    Param {
        name,
        lower,
        upper,
        scale,
    }
}

impl LampType {
    /// The lamp types with a physical model, fitted to measured lamps of the type: every
    /// type but [`LampType::Other`] and [`LampType::Daylight`] (daylight has its own CIE
    /// recipe).
    pub const MODELLED: [LampType; 6] = [
        LampType::PhosphorLed,
        LampType::HybridLed,
        LampType::MixedLed,
        LampType::Fluorescent,
        LampType::Hid,
        LampType::Incandescent,
    ];

    /// Whether the type has a physical model ([`LampType::MODELLED`]).
    pub fn has_model(self) -> bool {
        LampType::MODELLED.contains(&self)
    }

    /// One line on the type's model, for `spdcam list lighting`.
    pub fn describe_model(self) -> &'static str {
        match self {
            LampType::PhosphorLed => "phosphor-converted white LEDs: a blue/violet pump (Ohno 2005 LED, 400–475 nm) and two phosphor bands (Gaussian in energy)",
            LampType::HybridLed => "hybrid white LEDs: pump, two phosphor bands and a direct red LED (590–670 nm)",
            LampType::MixedLed => "mixed-colour LEDs (RGB, RGBA…): four Ohno 2005 LEDs anywhere in 400–700 nm",
            LampType::Fluorescent => "fluorescent tubes: Hg lines, Tb³⁺/Eu³⁺ phosphor lines and three broad phosphor bands",
            LampType::Hid => "high-intensity discharge (sodium, mercury, metal halide): Hg/Na/Tl/In/Li lines and four broad bands",
            LampType::Incandescent => "incandescent and halogen filaments: Planck's law through a smooth filter",
            LampType::Other | LampType::Daylight => "no physical model",
        }
    }

    /// The non-linear parameters and their physical bounds.
    fn params(self) -> Vec<Param> {
        use Scale::{Linear, Log};
        let pump = [
            p("pump_nm", 400.0, 475.0, Linear),
            p("pump_half_width_nm", 6.0, 40.0, Log),
        ];
        let phosphor = |k: usize, lowest_nm: f64| {
            let names = [
                ("phosphor1_nm", "phosphor1_sigma_ev"),
                ("phosphor2_nm", "phosphor2_sigma_ev"),
                ("phosphor3_nm", "phosphor3_sigma_ev"),
            ];
            [
                p(names[k].0, lowest_nm, 700.0, Linear),
                p(names[k].1, 0.04, 0.6, Log),
            ]
        };
        let lines = [
            p("line_shift_nm", -12.0, 12.0, Linear),
            p("line_sigma_nm", 1.0, 10.0, Log),
        ];
        match self {
            LampType::PhosphorLed => [pump, phosphor(0, 470.0), phosphor(1, 470.0)].concat(),
            LampType::HybridLed => [
                &pump[..],
                &phosphor(0, 470.0),
                &phosphor(1, 470.0),
                &[
                    p("red_led_nm", 590.0, 680.0, Linear),
                    p("red_led_half_width_nm", 5.0, 35.0, Log),
                ],
            ]
            .concat(),
            LampType::MixedLed => {
                let names = [
                    ("led1_nm", "led1_half_width_nm"),
                    ("led2_nm", "led2_half_width_nm"),
                    ("led3_nm", "led3_half_width_nm"),
                    ("led4_nm", "led4_half_width_nm"),
                ];
                names
                    .iter()
                    .flat_map(|&(c, w)| [p(c, 400.0, 700.0, Linear), p(w, 5.0, 60.0, Log)])
                    .collect()
            }
            LampType::Fluorescent => [
                &lines[..],
                &phosphor(0, 400.0),
                &phosphor(1, 400.0),
                &phosphor(2, 400.0),
            ]
            .concat(),
            LampType::Hid => {
                let band = |c: &'static str, w: &'static str| {
                    [p(c, 380.0, 780.0, Linear), p(w, 0.02, 0.8, Log)]
                };
                [
                    &lines[..],
                    &band("band1_nm", "band1_sigma_ev"),
                    &band("band2_nm", "band2_sigma_ev"),
                    &band("band3_nm", "band3_sigma_ev"),
                    &band("band4_nm", "band4_sigma_ev"),
                ]
                .concat()
            }
            LampType::Other | LampType::Daylight => Vec::new(),
            LampType::Incandescent => vec![
                p("cct_k", 1500.0, 6500.0, Log),
                p("filter_tilt", -3.0, 3.0, Linear),
                p("filter_curve", -3.0, 3.0, Linear),
            ],
        }
    }

    /// Starting points of the fit (several, as the fit has local minima).
    fn starts(self) -> Vec<Vec<f64>> {
        match self {
            LampType::PhosphorLed => vec![
                vec![450.0, 12.0, 540.0, 0.15, 610.0, 0.12],
                vec![450.0, 12.0, 560.0, 0.2, 640.0, 0.1],
                vec![410.0, 10.0, 520.0, 0.15, 620.0, 0.12],
                vec![445.0, 12.0, 500.0, 0.2, 590.0, 0.15],
            ],
            LampType::HybridLed => vec![
                vec![450.0, 12.0, 530.0, 0.15, 580.0, 0.15, 620.0, 10.0],
                vec![410.0, 10.0, 540.0, 0.15, 600.0, 0.15, 630.0, 10.0],
                vec![450.0, 12.0, 560.0, 0.15, 600.0, 0.2, 650.0, 10.0],
            ],
            LampType::MixedLed => vec![
                vec![450.0, 12.0, 530.0, 15.0, 590.0, 10.0, 625.0, 10.0],
                vec![460.0, 12.0, 520.0, 15.0, 560.0, 20.0, 640.0, 10.0],
                vec![445.0, 12.0, 505.0, 15.0, 595.0, 10.0, 640.0, 10.0],
            ],
            LampType::Fluorescent => vec![
                vec![0.0, 3.0, 450.0, 0.15, 480.0, 0.15, 580.0, 0.15],
                vec![0.0, 3.0, 450.0, 0.15, 580.0, 0.15, 630.0, 0.15],
                vec![0.0, 3.0, 480.0, 0.15, 580.0, 0.15, 650.0, 0.15],
                vec![-8.0, 3.0, 450.0, 0.15, 580.0, 0.15, 630.0, 0.15],
            ],
            LampType::Hid => vec![
                vec![0.0, 3.0, 450.0, 0.15, 530.0, 0.15, 590.0, 0.15, 640.0, 0.15],
                vec![0.0, 3.0, 420.0, 0.15, 500.0, 0.15, 570.0, 0.15, 620.0, 0.15],
                vec![0.0, 3.0, 480.0, 0.15, 560.0, 0.15, 600.0, 0.15, 680.0, 0.15],
            ],
            LampType::Incandescent => vec![
                vec![2800.0, 0.0, 0.0],
                vec![2000.0, 0.0, 0.0],
                vec![3500.0, 0.0, 0.0],
            ],
            LampType::Other | LampType::Daylight => Vec::new(),
        }
    }

    /// The shapes of the model at parameters `theta`, in a fixed order (their heights are
    /// the linear parameters).
    fn shapes(self, theta: &[f64]) -> Vec<Shape> {
        let led = |c: f64, w: f64| Shape::LedOhno2005 {
            peak_nm: c,
            half_width_nm: w,
        };
        let band = |c: f64, s: f64| Shape::PhosphorBand {
            peak_nm: c,
            sigma_ev: s,
        };
        let lines = |list: &[f64], shift: f64, sigma: f64| -> Vec<Shape> {
            list.iter()
                .map(|&c| Shape::Line {
                    centre_nm: c + shift,
                    sigma_nm: sigma,
                })
                .collect()
        };
        let t = theta;
        match self {
            LampType::PhosphorLed => vec![led(t[0], t[1]), band(t[2], t[3]), band(t[4], t[5])],
            LampType::HybridLed => vec![
                led(t[0], t[1]),
                band(t[2], t[3]),
                band(t[4], t[5]),
                led(t[6], t[7]),
            ],
            LampType::MixedLed => (0..4).map(|k| led(t[2 * k], t[2 * k + 1])).collect(),
            LampType::Fluorescent => {
                let mut s = lines(&FLUORESCENT_LINES, t[0], t[1]);
                s.extend((0..3).map(|k| band(t[2 + 2 * k], t[3 + 2 * k])));
                s
            }
            LampType::Hid => {
                let mut s = lines(&DISCHARGE_LINES, t[0], t[1]);
                s.extend((0..4).map(|k| band(t[2 + 2 * k], t[3 + 2 * k])));
                s
            }
            LampType::Other | LampType::Daylight => Vec::new(),
            LampType::Incandescent => vec![Shape::Filament {
                cct_k: t[0],
                tilt: t[1],
                curve: t[2],
            }],
        }
    }

    /// The names of the non-linear parameters, in order.
    pub fn parameter_names(self) -> Vec<&'static str> {
        self.params().iter().map(|q| q.name).collect()
    }

    /// Puts interchangeable shapes in a canonical order (phosphor bands and LEDs by
    /// wavelength), so that the same slot means the same kind of band across lamps.
    fn canonical(self, theta: &mut [f64], heights: &mut [f64]) {
        let (start, count, first_height) = match self {
            LampType::PhosphorLed | LampType::HybridLed => (2, 2, 1),
            LampType::MixedLed => (0, 4, 0),
            LampType::Fluorescent => (2, 3, FLUORESCENT_LINES.len()),
            LampType::Hid => (2, 4, DISCHARGE_LINES.len()),
            LampType::Incandescent | LampType::Other | LampType::Daylight => return,
        };
        let mut slots: Vec<([f64; 2], f64)> = (0..count)
            .map(|k| {
                (
                    [theta[start + 2 * k], theta[start + 2 * k + 1]],
                    heights[first_height + k],
                )
            })
            .collect();
        slots.sort_by(|a, b| a.0[0].total_cmp(&b.0[0]));
        for (k, (pair, h)) in slots.into_iter().enumerate() {
            theta[start + 2 * k] = pair[0];
            theta[start + 2 * k + 1] = pair[1];
            heights[first_height + k] = h;
        }
    }
}

/// The spectrum of `family` at `theta` with shape heights `heights`, on `wavelengths`.
pub fn model_spectrum(
    family: LampType,
    theta: &[f64],
    heights: &[f64],
    wavelengths: &[f64],
) -> Vec<f64> {
    let mut spd = vec![0.0; wavelengths.len()];
    for (shape, &h) in family.shapes(theta).iter().zip(heights) {
        if h > 0.0 {
            for (s, v) in spd.iter_mut().zip(shape.sample(wavelengths)) {
                *s += h * v;
            }
        }
    }
    spd
}

/// One lamp's fitted parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FittedLamp {
    /// The lamp's name in the library.
    pub name: String,
    /// The non-linear parameters ([`LampType::parameter_names`] order).
    pub theta: Vec<f64>,
    /// The shapes' heights, scaled so the model spectrum's maximum is 1.
    pub heights: Vec<f64>,
    /// GFC of the fitted model against the measured SPD on 400–700 nm.
    pub gfc: f64,
}

/// The lamps one family was fitted to.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FamilyFit {
    /// The spectral model the lamps were fitted with.
    pub family: LampType,
    /// The names of its non-linear parameters, in [`FittedLamp::theta`] order.
    pub parameter_names: Vec<String>,
    /// Every lamp fitted, with its parameters.
    pub lamps: Vec<FittedLamp>,
}

/// Every family's fits, as `spdcam lamps fit` writes them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LampFits {
    /// What the lamps are and how they were fitted.
    pub method: String,
    /// One entry per family.
    pub families: Vec<FamilyFit>,
}

impl LampFits {
    /// The fits the program ships.
    pub fn shipped() -> Result<LampFits> {
        LampFits::from_json(SHIPPED_FITS, "the shipped lamp fits")
    }

    /// Fits from JSON text (`source` names it in errors).
    pub fn from_json(text: &str, source: &str) -> Result<LampFits> {
        let fits: LampFits = serde_json::from_str(text)
            .map_err(|e| Error::parse(source, format!("not lamp fits: {e}")))?;
        for f in &fits.families {
            if !f.family.has_model() {
                return Err(Error::parse(
                    source,
                    format!("{} lamps have no physical model", f.family.name()),
                ));
            }
            let d = f.family.params().len();
            let k = f.family.shapes(&vec![500.0; d]).len();
            if let Some(bad) = f
                .lamps
                .iter()
                .find(|l| l.theta.len() != d || l.heights.len() != k)
            {
                return Err(Error::parse(
                    source,
                    format!(
                        "{} lamp '{}' has {} parameters and {} heights; the family has {d} and {k}",
                        f.family.name(),
                        bad.name,
                        bad.theta.len(),
                        bad.heights.len()
                    ),
                ));
            }
        }
        Ok(fits)
    }

    /// The fit of one family.
    pub fn family(&self, family: LampType) -> Option<&FamilyFit> {
        self.families.iter().find(|f| f.family == family)
    }
}

/// Fits `family`'s model to one measured SPD on `grid` (least squares over the whole grid,
/// the best of several starts); the GFC is measured on 400–700 nm.
pub fn fit_lamp(family: LampType, name: &str, spd: &[f64], grid: &Grid) -> Result<FittedLamp> {
    if !family.has_model() {
        return Err(Error::invalid(format!(
            "lamp '{name}': {} lamps have no physical model to fit",
            family.label()
        )));
    }
    let wavelengths = grid.wavelengths();
    if spd.len() != wavelengths.len() {
        return Err(Error::invalid(format!(
            "lamp '{name}': {} values for the {} of {grid}",
            spd.len(),
            wavelengths.len()
        )));
    }
    let params = family.params();
    let lower: Vec<f64> = params.iter().map(|q| q.lower).collect();
    let upper: Vec<f64> = params.iter().map(|q| q.upper).collect();
    let target = DVector::from_column_slice(spd);
    let design = |theta: &[f64]| -> DMatrix<f64> {
        let shapes = family.shapes(theta);
        let mut a = DMatrix::zeros(wavelengths.len(), shapes.len());
        for (k, s) in shapes.iter().enumerate() {
            for (i, v) in s.sample(&wavelengths).into_iter().enumerate() {
                a[(i, k)] = v;
            }
        }
        a
    };
    let residuals = |theta: &[f64]| -> Vec<f64> {
        let a = design(theta);
        let h = nnls(&a, &target);
        (a * h - &target).iter().copied().collect()
    };
    let best = family
        .starts()
        .iter()
        .map(|start| levenberg_marquardt(&residuals, start, &lower, &upper, 150))
        .min_by(|a, b| a.cost.total_cmp(&b.cost))
        .ok_or_else(|| Error::invalid("a lamp family without starting points"))?;
    let mut theta = best.x;
    let a = design(&theta);
    let mut heights: Vec<f64> = nnls(&a, &target).iter().copied().collect();
    let model: Vec<f64> = (a * DVector::from_column_slice(&heights))
        .iter()
        .copied()
        .collect();
    let max = model.iter().cloned().fold(0.0, f64::max);
    if max.is_nan() || max <= 0.0 {
        return Err(Error::invalid(format!(
            "lamp '{name}': the {} model fits it with zero light",
            family.name()
        )));
    }
    heights.iter_mut().for_each(|h| *h /= max);
    family.canonical(&mut theta, &mut heights);
    Ok(FittedLamp {
        name: name.to_string(),
        theta,
        heights,
        gfc: visible_gfc(spd, &model, grid),
    })
}

/// Fits every family to the lamps `lamps` (positions in `library`) of its type, in parallel.
/// A family with no lamp of its type is an error.
pub fn fit_families(library: &LampLibrary, lamps: &[usize]) -> Result<Vec<FamilyFit>> {
    LampType::MODELLED
        .iter()
        .map(|&family| {
            let own: Vec<usize> = lamps
                .iter()
                .copied()
                .filter(|&i| library.types[i] == family)
                .collect();
            if own.is_empty() {
                return Err(Error::invalid(format!(
                    "no lamps of type {} to fit the {} family to",
                    family.label(),
                    family.name()
                )));
            }
            let fitted = own
                .par_iter()
                .map(|&i| fit_lamp(family, &library.names[i], &library.spds[i], &library.grid))
                .collect::<Result<Vec<_>>>()?;
            Ok(FamilyFit {
                family,
                parameter_names: family
                    .parameter_names()
                    .into_iter()
                    .map(String::from)
                    .collect(),
                lamps: fitted,
            })
        })
        .collect()
}

/// GFC of two SPDs on `grid` over 400–700 nm (the estimation range).
pub fn visible_gfc(a: &[f64], b: &[f64], grid: &Grid) -> f64 {
    let pick = |s: &[f64]| -> Vec<f64> {
        (0..s.len())
            .filter(|&k| (400.0 - 1e-9..=700.0 + 1e-9).contains(&grid.wavelength(k)))
            .map(|k| s[k])
            .collect()
    };
    spectral_error::gfc(&pick(a), &pick(b)).unwrap_or(0.0)
}

/// Draws lamps of one family around its fitted lamps.
#[derive(Debug, Clone, PartialEq)]
pub struct LampDraws {
    family: LampType,
    lamps: Vec<FittedLamp>,
    /// Per non-linear parameter: the kernel bandwidth (in the parameter's scale) and the
    /// range draws stay in.
    theta_kernel: Vec<Kernel>,
    /// Per shape: the bandwidth of its log height (relative to the lamp's total).
    height_kernel: Vec<f64>,
    wavelengths: Vec<f64>,
    spread: f64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Kernel {
    bandwidth: f64,
    lower: f64,
    upper: f64,
    scale: Scale,
}

impl LampDraws {
    /// Draws for `family` from `fits`, on `grid`, with the kernel bandwidths multiplied by
    /// `spread` (1 = Scott's rule; 0 = the fitted lamps themselves).
    pub fn new(fits: &LampFits, family: LampType, grid: &Grid, spread: f64) -> Result<Self> {
        let fit = fits
            .family(family)
            .filter(|f| !f.lamps.is_empty())
            .ok_or_else(|| {
                Error::invalid(format!(
                    "no lamps are fitted to the {} family; run `spdcam lamps fit`",
                    family.name()
                ))
            })?;
        if !(spread.is_finite() && (0.0..=10.0).contains(&spread)) {
            return Err(Error::invalid(format!(
                "lamp:{}: spread {} is outside 0–10",
                family.name(),
                crate::error::short_number(spread)
            )));
        }
        let params = family.params();
        let n = fit.lamps.len() as f64;
        let scott = n.powf(-1.0 / (params.len() as f64 + 4.0));
        let to_scale = |v: f64, s: Scale| if s == Scale::Log { v.ln() } else { v };
        let theta_kernel = params
            .iter()
            .enumerate()
            .map(|(k, q)| {
                let values: Vec<f64> = fit
                    .lamps
                    .iter()
                    .map(|l| to_scale(l.theta[k], q.scale))
                    .collect();
                let (lo, hi) = values
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                        (a.min(v), b.max(v))
                    });
                let bandwidth = scott * std_dev(&values);
                Kernel {
                    bandwidth,
                    lower: (lo - bandwidth).max(to_scale(q.lower, q.scale)),
                    upper: (hi + bandwidth).min(to_scale(q.upper, q.scale)),
                    scale: q.scale,
                }
            })
            .collect();
        let shapes = fit.lamps[0].heights.len();
        let height_kernel = (0..shapes)
            .map(|k| {
                let logs: Vec<f64> = fit
                    .lamps
                    .iter()
                    .filter(|l| l.heights[k] > 0.0)
                    .map(|l| (l.heights[k] / l.heights.iter().sum::<f64>()).ln())
                    .collect();
                scott * std_dev(&logs)
            })
            .collect();
        Ok(LampDraws {
            family,
            lamps: fit.lamps.clone(),
            theta_kernel,
            height_kernel,
            wavelengths: grid.wavelengths(),
            spread,
        })
    }

    /// The family drawn from.
    pub fn family(&self) -> LampType {
        self.family
    }

    /// How many fitted lamps the draws centre on.
    pub fn lamp_count(&self) -> usize {
        self.lamps.len()
    }

    /// One lamp: a fitted lamp at random, its parameters moved by the kernel; maximum 1.
    pub fn draw(&self, rng: &mut SmallRng) -> Vec<f64> {
        let lamp = &self.lamps[rng.random_range(0..self.lamps.len())];
        let mut normal = || -> f64 { StandardNormal.sample(rng) };
        let theta: Vec<f64> = lamp
            .theta
            .iter()
            .zip(&self.theta_kernel)
            .map(|(&v, k)| {
                let x = if k.scale == Scale::Log { v.ln() } else { v };
                let moved = (x + self.spread * k.bandwidth * normal())
                    .clamp(k.lower.min(x), k.upper.max(x));
                if k.scale == Scale::Log {
                    moved.exp()
                } else {
                    moved
                }
            })
            .collect();
        let heights: Vec<f64> = lamp
            .heights
            .iter()
            .zip(&self.height_kernel)
            .map(|(&h, &bw)| h * (self.spread * bw * normal()).exp())
            .collect();
        let mut spd = model_spectrum(self.family, &theta, &heights, &self.wavelengths);
        if normalise_peak(&mut spd).is_err() {
            // Every height of a fitted lamp is non-negative and one is positive, so the
            // spectrum is dark only if the lamp itself was; fall back to it unmoved.
            spd = model_spectrum(self.family, &lamp.theta, &lamp.heights, &self.wavelengths);
            normalise_peak(&mut spd).ok();
        }
        spd
    }
}

/// The sample standard deviation (0 for fewer than two values).
fn std_dev(values: &[f64]) -> f64 {
    let n = values.len();
    if n < 2 {
        return 0.0;
    }
    let mean = values.iter().sum::<f64>() / n as f64;
    (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    fn grid() -> Grid {
        Grid::SIMULATION
    }

    /// Each family's fit recovers a spectrum made by its own model.
    #[test]
    fn fits_recover_their_own_model() {
        let cases: [(LampType, Vec<f64>, Vec<f64>); 4] = [
            (
                LampType::PhosphorLed,
                vec![452.0, 11.0, 545.0, 0.17, 615.0, 0.11],
                vec![0.8, 0.9, 0.5],
            ),
            (
                LampType::MixedLed,
                vec![455.0, 11.0, 530.0, 17.0, 590.0, 9.0, 632.0, 10.0],
                vec![0.5, 0.9, 0.4, 0.7],
            ),
            (LampType::Incandescent, vec![2900.0, 0.4, -0.3], vec![1.0]),
            (
                LampType::Fluorescent,
                vec![0.0, 2.5, 450.0, 0.2, 490.0, 0.25, 600.0, 0.12],
                [
                    vec![0.2, 0.5, 0.9, 0.2],
                    vec![0.1, 0.6, 0.1, 0.1],
                    vec![0.05, 1.0, 0.2, 0.1, 0.05],
                    vec![0.1, 0.1, 0.2],
                ]
                .concat(),
            ),
        ];
        let wl = grid().wavelengths();
        for (family, theta, heights) in cases {
            let spd = model_spectrum(family, &theta, &heights, &wl);
            let fitted = fit_lamp(family, "x", &spd, &grid()).unwrap();
            assert!(fitted.gfc > 0.9995, "{family:?}: {}", fitted.gfc);
        }
    }

    #[test]
    fn a_type_without_a_model_is_refused() {
        let spd = vec![1.0; grid().count];
        for t in [LampType::Other, LampType::Daylight] {
            assert!(!t.has_model());
            let err = fit_lamp(t, "x", &spd, &grid()).unwrap_err().to_string();
            assert!(err.contains("no physical model"), "{err}");
        }
        let text =
            r#"{"method":"m","families":[{"family":"other","parameter_names":[],"lamps":[]}]}"#;
        let err = LampFits::from_json(text, "fits.json")
            .unwrap_err()
            .to_string();
        assert!(err.contains("no physical model"), "{err}");
        assert_eq!(LampType::MODELLED.len(), LampType::ALL.len() - 2);
    }

    #[test]
    fn draws_stay_near_the_fitted_lamps_and_spread_zero_repeats_them() {
        let wl = grid().wavelengths();
        let lamps: Vec<FittedLamp> = [440.0, 450.0, 460.0]
            .iter()
            .map(|&pump| {
                let theta = vec![pump, 11.0, 550.0, 0.17, 615.0, 0.11];
                let heights = vec![0.5, 0.9, 0.4];
                let spd = model_spectrum(LampType::PhosphorLed, &theta, &heights, &wl);
                let max = spd.iter().cloned().fold(0.0, f64::max);
                FittedLamp {
                    name: format!("pump {pump}"),
                    theta,
                    heights: heights.iter().map(|h| h / max).collect(),
                    gfc: 1.0,
                }
            })
            .collect();
        let fits = LampFits {
            method: "test".into(),
            families: vec![FamilyFit {
                family: LampType::PhosphorLed,
                parameter_names: vec![],
                lamps: lamps.clone(),
            }],
        };
        let mut rng = SmallRng::seed_from_u64(5);
        let exact = LampDraws::new(&fits, LampType::PhosphorLed, &grid(), 0.0).unwrap();
        for _ in 0..10 {
            let spd = exact.draw(&mut rng);
            let best = lamps
                .iter()
                .map(|l| {
                    let m = model_spectrum(LampType::PhosphorLed, &l.theta, &l.heights, &wl);
                    visible_gfc(&spd, &m, &grid())
                })
                .fold(0.0, f64::max);
            assert!(best > 1.0 - 1e-12);
        }
        let draws = LampDraws::new(&fits, LampType::PhosphorLed, &grid(), 1.0).unwrap();
        let peaks: Vec<f64> = (0..200)
            .map(|_| {
                let spd = draws.draw(&mut rng);
                let blue = (0..spd.len())
                    .filter(|&k| wl[k] < 500.0)
                    .max_by(|&a, &b| spd[a].total_cmp(&spd[b]))
                    .unwrap();
                wl[blue]
            })
            .collect();
        // The pump varies (the fitted pumps span 440–460 nm) but stays in their range
        // widened by one bandwidth (10 · 3^(−0.1) ≈ 8 nm).
        assert!(peaks.iter().any(|&p| p != peaks[0]));
        assert!(
            peaks.iter().all(|&p| (430.0..=470.0).contains(&p)),
            "{peaks:?}"
        );
        // A family without fitted lamps is an error that says what to run.
        let err = LampDraws::new(&fits, LampType::Hid, &grid(), 1.0).unwrap_err();
        assert!(err.to_string().contains("spdcam lamps fit"));
    }

    #[test]
    fn the_shipped_fits_parse() {
        let fits = LampFits::shipped().unwrap();
        for f in &fits.families {
            assert_eq!(f.parameter_names, f.family.parameter_names());
        }
    }
}
