//! Estimates of known spectra for the tests of what is shown of an estimate.

use spdcam_core::cie_illuminant::StandardIlluminant;
use spdcam_core::quality::LightingMetrics;
use spdcam_core::spectral::{Grid, Spd};
use spdcam_infer::estimate::{Colorimetry, Estimate};
use spdcam_infer::trust::{Band, MetricInterval, Trust, Uncertainty, Verdict};

/// An `ok` estimate of `spd` whose metrics have the 95 % half-widths `halves`.
pub(crate) fn estimate_of(spd: Spd, halves: &[(&str, f64)]) -> Estimate {
    let band = Band {
        lower: Spd::new(*spd.grid(), spd.iter().map(|v| 0.9 * v).collect()).unwrap(),
        upper: Spd::new(*spd.grid(), spd.iter().map(|v| 1.1 * v).collect()).unwrap(),
    };
    Estimate {
        name: "test".into(),
        model: "test model".into(),
        light: Default::default(),
        colorimetry: Colorimetry::of(&spd).unwrap(),
        metrics: LightingMetrics::from_samples(&spd.grid().wavelengths(), &spd),
        truth: None,
        photo: None,
        trust: Some(Trust {
            verdict: Verdict::Ok,
            reasons: Vec::new(),
            self_check: None,
            uncertainty: Some(Uncertainty {
                band68: band.clone(),
                band95: band,
                expected_gfc: 0.995,
                gfc_at_least95: 0.98,
                gfc_margin_factor: 2.0,
                gfc_margin_local: true,
                difficulty: 0.01,
                widening: 1.0,
                metrics: halves
                    .iter()
                    .map(|&(k, h)| {
                        let i = MetricInterval {
                            half68: h / 2.0,
                            half95: h,
                        };
                        (k.to_string(), i)
                    })
                    .collect(),
            }),
        }),
        absolute: None,
        light_level: None,
        across_places: None,
        spd,
    }
}

/// D65 on 400–700 nm, CCT ± 150 K and Δuv ± 0.002 at 95 %.
pub(crate) fn estimate_of_d65() -> Estimate {
    let spd = StandardIlluminant::D65.spd(&Grid::ESTIMATION).unwrap();
    estimate_of(spd, &[("cct_k", 150.0), ("duv", 0.002)])
}
